//! DLGPD's Gaussian-process terms of the training loss on one batch of encoded transitions, in f64 with
//! their gradients for the latents, so that the encoder learns through them (thesis eq. 3.16, as the authors'
//! code computes it):
//!
//! - one transition GP per latent dimension d on inputs X = [(s − m)/σ̂, a], where m and σ̂ (the unbiased
//!   std + 1e-2) are the batch statistics of the current latents and carry gradients; its prior mean is
//!   X_d·σ̂_d + m_d with the unscaling factors held constant (so its value is s_d), its kernel
//!   σ̂_d²·α_d²·k_SE with σ̂_d constant, its noise σ_d² in raw units, and it is scored on the raw next latents;
//! - the reward GP on [s, a] with s detached, its prior mean the batch's smallest reward;
//! - every GP's negative log marginal likelihood and Gamma(1, 5) log prior divided by the batch size, and
//!   the SNR penalty of all of them.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::models::gp::{GpHypers, ObjectiveGradients};

/// Added to the batch std before standardizing (the authors' 1e-2).
pub const STD_FLOOR: f64 = 1e-2;

/// Batch statistics of the current latents: column means and unbiased std + [`STD_FLOOR`].
#[derive(Clone, Debug, PartialEq)]
pub struct LatentScale {
    pub mean: Vec<f64>,
    pub std: Vec<f64>,
}

impl LatentScale {
    /// Statistics of `latents` (rows × dims, row-major); at least two rows.
    pub fn of(latents: &[f64], dims: usize) -> Result<LatentScale> {
        let rows = latents.len() / dims.max(1);
        if dims == 0 || rows < 2 || rows * dims != latents.len() {
            return Err(Error::data(format!(
                "latent batch of {} values: expected at least 2 rows of {dims}",
                latents.len()
            )));
        }
        let mean: Vec<f64> =
            (0..dims).map(|c| (0..rows).map(|b| latents[b * dims + c]).sum::<f64>() / rows as f64).collect();
        let std = (0..dims)
            .map(|c| {
                let ss: f64 = (0..rows).map(|b| (latents[b * dims + c] - mean[c]).powi(2)).sum();
                (ss / (rows - 1) as f64).sqrt() + STD_FLOOR
            })
            .collect();
        Ok(LatentScale { mean, std })
    }

    /// [(s − m)/σ̂, a] per row.
    pub fn inputs(&self, latents: &[f64], actions: &[f64]) -> Vec<f64> {
        let dims = self.mean.len();
        let scaled: Vec<f64> =
            latents.iter().enumerate().map(|(i, s)| (s - self.mean[i % dims]) / self.std[i % dims]).collect();
        latent_action_rows(&scaled, actions, dims)
    }

    /// Pulls gradients on the standardized latents `d_scaled` (rows × dims) back to the raw latents, through
    /// the batch mean and std (which depend on every row).
    pub fn backward(&self, latents: &[f64], d_scaled: &[f64]) -> Vec<f64> {
        let dims = self.mean.len();
        let rows = latents.len() / dims;
        let mut out = vec![0.0; latents.len()];
        for c in 0..dims {
            let (m, s) = (self.mean[c], self.std[c]);
            let unfloored = s - STD_FLOOR;
            let mean_g = (0..rows).map(|b| d_scaled[b * dims + c]).sum::<f64>() / rows as f64;
            let centred_g: f64 = (0..rows).map(|b| d_scaled[b * dims + c] * (latents[b * dims + c] - m)).sum();
            for b in 0..rows {
                let centred = latents[b * dims + c] - m;
                // d std / d s_b = (s_b − m) / ((n − 1) std); a zero std (all rows equal) has no slope to follow.
                let d_std = if unfloored > 0.0 { centred / ((rows - 1) as f64 * unfloored) } else { 0.0 };
                out[b * dims + c] = (d_scaled[b * dims + c] - mean_g) / s - centred_g / (s * s) * d_std;
            }
        }
        out
    }
}

/// Rows of latent ⊕ action, the reward GP's inputs (raw, unstandardized).
pub fn latent_action_rows(latents: &[f64], actions: &[f64], dims: usize) -> Vec<f64> {
    let rows = latents.len() / dims.max(1);
    let action_dim = actions.len() / rows.max(1);
    let mut out = Vec::with_capacity(rows * (dims + action_dim));
    for b in 0..rows {
        out.extend_from_slice(&latents[b * dims..(b + 1) * dims]);
        out.extend_from_slice(&actions[b * action_dim..(b + 1) * action_dim]);
    }
    out
}

/// The GP terms' value, its parts, and the gradients for the latents and every GP's raw hyperparameters.
#[derive(Clone, Debug)]
pub struct GpTerms {
    pub value: f64,
    /// Σ_d (−mll_d − log prior_d) / B over the transition GPs.
    pub transition: f64,
    /// The reward GP's (−mll − log prior) / B.
    pub reward: f64,
    /// SNR penalty summed over all GPs.
    pub snr: f64,
    pub d_latents: Vec<f64>,
    pub d_next_latents: Vec<f64>,
    /// Per transition GP, then the reward GP, SNR penalty included. Only the raw-hyperparameter fields of
    /// these are for the optimizer: the latents' gradients are `d_latents`/`d_next_latents` (the reward GP's
    /// inputs are detached and its targets are data).
    pub d_hypers: Vec<ObjectiveGradients>,
    /// Largest diagonal jitter any factorization needed.
    pub jitter: f64,
}

/// Evaluates the terms on a batch: `latents`, `next_latents` (B × L), `actions` (B × A), `rewards` (B).
/// `transition` holds L GPs over L + A inputs, `reward` one over L + A inputs.
pub fn gp_terms(
    transition: &[GpHypers],
    reward: &GpHypers,
    latents: &[f64],
    actions: &[f64],
    next_latents: &[f64],
    rewards: &[f64],
) -> Result<GpTerms> {
    terms_with_unscale(transition, reward, latents, actions, next_latents, rewards, None)
}

/// `unscale`: the constants the prior mean and kernel are unscaled with, `None` for this batch's own
/// statistics (training). Tests freeze them to difference the function whose gradient is returned.
fn terms_with_unscale(
    transition: &[GpHypers],
    reward: &GpHypers,
    latents: &[f64],
    actions: &[f64],
    next_latents: &[f64],
    rewards: &[f64],
    unscale: Option<&LatentScale>,
) -> Result<GpTerms> {
    let dims = transition.len();
    let rows = rewards.len();
    if dims == 0 || latents.len() != rows * dims || next_latents.len() != rows * dims || rows == 0 {
        return Err(Error::data(format!(
            "DLGPD batch: {} latents, {} next latents and {rows} rewards for {dims} transition GPs",
            latents.len(),
            next_latents.len()
        )));
    }
    if !actions.len().is_multiple_of(rows) {
        return Err(Error::data(format!("DLGPD batch: {} action values for {rows} rows", actions.len())));
    }
    let scale = LatentScale::of(latents, dims)?;
    let unscale = unscale.unwrap_or(&scale);
    let inputs = scale.inputs(latents, actions);
    let width = inputs.len() / rows;
    let mut d_inputs = vec![0.0; rows * dims];
    let mut d_next_latents = vec![0.0; rows * dims];
    let mut d_hypers = Vec::with_capacity(dims + 1);
    let (mut transition_value, mut snr, mut jitter) = (0.0, 0.0, 0.0f64);
    let reward_inputs = latent_action_rows(latents, actions, dims);
    let floor = rewards.iter().copied().fold(f64::INFINITY, f64::min);
    // The GPs' factorizations are independent: each on its own thread, summed below in a fixed order.
    let (objectives, reward_objective) = rayon::join(
        || {
            transition
                .par_iter()
                .enumerate()
                .map(|(d, hypers)| {
                    let targets: Vec<f64> = (0..rows).map(|b| next_latents[b * dims + d]).collect();
                    let sigma = unscale.std[d];
                    let prior_mean: Vec<f64> =
                        (0..rows).map(|b| inputs[b * width + d] * sigma + unscale.mean[d]).collect();
                    hypers.objective_scaled(&inputs, &targets, &prior_mean, sigma * sigma)
                })
                .collect::<Vec<_>>()
        },
        || reward.objective(&reward_inputs, rewards, &vec![floor; rows]),
    );
    for ((d, hypers), objective) in transition.iter().enumerate().zip(objectives) {
        let (value, g, gp) = objective?;
        let sigma = unscale.std[d];
        transition_value += value;
        jitter = jitter.max(gp.jitter());
        for b in 0..rows {
            for c in 0..dims {
                d_inputs[b * dims + c] += g.inputs[b * width + c];
            }
            // The prior mean is X_d·σ̂_d + m_d with σ̂_d, m_d held constant.
            d_inputs[b * dims + d] += g.prior_mean[b] * sigma;
            d_next_latents[b * dims + d] += g.targets[b];
        }
        let (penalty, d_signal, d_noise) = hypers.snr_penalty();
        snr += penalty;
        let mut g = g;
        g.raw_outputscale += d_signal;
        g.raw_noise += d_noise;
        d_hypers.push(g);
    }
    let d_latents = scale.backward(latents, &d_inputs);

    let (reward_value, mut g, gp) = reward_objective?;
    jitter = jitter.max(gp.jitter());
    let (penalty, d_signal, d_noise) = reward.snr_penalty();
    snr += penalty;
    g.raw_outputscale += d_signal;
    g.raw_noise += d_noise;
    d_hypers.push(g);

    Ok(GpTerms {
        value: transition_value + reward_value + snr,
        transition: transition_value,
        reward: reward_value,
        snr,
        d_latents,
        d_next_latents,
        d_hypers,
        jitter,
    })
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::models::gp::HyperInit;

    struct Batch {
        latents: Vec<f64>,
        actions: Vec<f64>,
        next: Vec<f64>,
        rewards: Vec<f64>,
    }

    fn batch(rows: usize) -> Batch {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let latents: Vec<f64> = (0..rows * 3).map(|_| rng.random_range(-1.5..1.5)).collect();
        let actions: Vec<f64> = (0..rows).map(|_| rng.random_range(-2.0..2.0)).collect();
        let next: Vec<f64> =
            latents.iter().enumerate().map(|(i, s)| s + 0.1 * actions[i / 3] + rng.random_range(-0.05..0.05)).collect();
        let rewards = (0..rows).map(|b| -latents[b * 3].powi(2) - 0.1 * actions[b].powi(2)).collect();
        Batch { latents, actions, next, rewards }
    }

    fn hypers() -> (Vec<GpHypers>, GpHypers) {
        let mut transition: Vec<GpHypers> = (0..3).map(|_| GpHypers::new(&HyperInit::dlgpd(4, 1.0)).unwrap()).collect();
        for (d, h) in transition.iter_mut().enumerate() {
            h.raw_lengthscales = vec![0.3 * d as f64, -0.2, 0.5, 0.1];
            h.raw_noise = -2.0 - d as f64;
        }
        (transition, GpHypers::new(&HyperInit::dlgpd(4, 2.0)).unwrap())
    }

    /// The loss as a function of the batch with the unscaling constants frozen at the unperturbed batch's
    /// statistics: the function whose gradient `gp_terms` returns.
    fn value(t: &[GpHypers], r: &GpHypers, b: &Batch) -> f64 {
        let frozen = LatentScale::of(&batch(b.rewards.len()).latents, 3).unwrap();
        terms_with_unscale(t, r, &b.latents, &b.actions, &b.next, &b.rewards, Some(&frozen)).unwrap().value
    }

    fn close(what: &str, analytic: f64, numeric: f64) {
        let tol = 1e-5 * analytic.abs().max(numeric.abs()).max(1.0);
        assert!((analytic - numeric).abs() < tol, "{what}: analytic {analytic} vs finite difference {numeric}");
    }

    #[test]
    fn latent_and_hyperparameter_gradients_match_finite_differences() {
        let b = batch(12);
        let (t, r) = hypers();
        let terms = gp_terms(&t, &r, &b.latents, &b.actions, &b.next, &b.rewards).unwrap();
        assert!(terms.value.is_finite() && terms.snr > 0.0 && terms.jitter == 0.0);
        let h = 1e-6;
        for i in 0..b.latents.len() {
            let (mut up, mut down) = (batch(12), batch(12));
            up.latents[i] += h;
            down.latents[i] -= h;
            // The reward GP sees detached latents: move them there only through the transition terms.
            let numeric = (value(&t, &r, &up) - value(&t, &r, &down)) / (2.0 * h);
            let reward_part = {
                let frozen = LatentScale::of(&b.latents, 3).unwrap();
                let f = |x: &Batch| {
                    terms_with_unscale(&t, &r, &x.latents, &x.actions, &x.next, &x.rewards, Some(&frozen))
                        .unwrap()
                        .reward
                };
                (f(&up) - f(&down)) / (2.0 * h)
            };
            close(&format!("latent {i}"), terms.d_latents[i], numeric - reward_part);
        }
        for i in 0..b.next.len() {
            let (mut up, mut down) = (batch(12), batch(12));
            up.next[i] += h;
            down.next[i] -= h;
            close(
                &format!("next latent {i}"),
                terms.d_next_latents[i],
                (value(&t, &r, &up) - value(&t, &r, &down)) / (2.0 * h),
            );
        }
        let poke = |k: usize, field: usize, delta: f64| {
            let (mut t, mut r) = (t.clone(), r.clone());
            let h = if k < 3 { &mut t[k] } else { &mut r };
            match field {
                0 => h.raw_outputscale += delta,
                1 => h.raw_noise += delta,
                c => h.raw_lengthscales[c - 2] += delta,
            }
            value(&t, &r, &b)
        };
        for k in 0..4 {
            let g = &terms.d_hypers[k];
            close(&format!("GP {k} raw outputscale"), g.raw_outputscale, (poke(k, 0, h) - poke(k, 0, -h)) / (2.0 * h));
            close(&format!("GP {k} raw noise"), g.raw_noise, (poke(k, 1, h) - poke(k, 1, -h)) / (2.0 * h));
            for c in 0..4 {
                close(
                    &format!("GP {k} raw lengthscale {c}"),
                    g.raw_lengthscales[c],
                    (poke(k, c + 2, h) - poke(k, c + 2, -h)) / (2.0 * h),
                );
            }
        }
    }

    #[test]
    fn bad_batches_are_errors() {
        let (t, r) = hypers();
        let b = batch(4);
        assert!(gp_terms(&t, &r, &b.latents[1..], &b.actions, &b.next, &b.rewards).is_err());
        assert!(gp_terms(&t, &r, &b.latents[..3], &b.actions[..1], &b.next[..3], &b.rewards[..1]).is_err(), "one row");
        let mut nan = batch(4);
        nan.next[2] = f64::NAN;
        let e = gp_terms(&t, &r, &nan.latents, &nan.actions, &nan.next, &nan.rewards).unwrap_err().to_string();
        assert!(e.contains("targets") && e.contains("NaN"), "{e}");
    }
}
