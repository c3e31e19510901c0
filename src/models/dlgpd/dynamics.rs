//! The GPs conditioned on evidence, for planning: DLGPD's adaptation is to swap this evidence (encoded
//! rollouts of the system at hand) while the hyperparameters and the latent standardization stay as trained.
//! As in the authors' code, each transition GP is conditioned in the standardized space (prior mean = the
//! standardized current latent, targets = the standardized next latents, noise σ_d² in those units); its
//! predictions are unscaled, and the noise σ_d² is added once more in raw units to the predictive variance.
//! The reward GP works on raw latents ⊕ actions with the smallest evidence reward as its prior mean.

use super::latent_gp::{latent_action_rows, LatentScale};
use crate::error::{Error, Result};
use crate::models::gp::{ConditionedGp, GpHypers};

#[derive(Clone, Debug)]
pub struct LatentDynamics {
    scale: LatentScale,
    transition: Vec<ConditionedGp>,
    reward: ConditionedGp,
    reward_floor: f64,
    action_dim: usize,
}

/// Encoded evidence: rows of current latents, actions, next latents and rewards (encoder means).
pub struct Evidence<'a> {
    pub latents: &'a [f64],
    pub actions: &'a [f64],
    pub next_latents: &'a [f64],
    pub rewards: &'a [f64],
}

impl LatentDynamics {
    pub fn condition(
        transition: &[GpHypers],
        reward: &GpHypers,
        scale: LatentScale,
        evidence: &Evidence,
    ) -> Result<LatentDynamics> {
        let dims = transition.len();
        let rows = evidence.rewards.len();
        if dims == 0
            || scale.mean.len() != dims
            || rows == 0
            || evidence.latents.len() != rows * dims
            || evidence.next_latents.len() != rows * dims
            || !evidence.actions.len().is_multiple_of(rows)
        {
            return Err(Error::data(format!(
                "GP evidence: {} latents, {} next latents, {} actions and {rows} rewards do not make rows of a \
                 {dims}-d latent",
                evidence.latents.len(),
                evidence.next_latents.len(),
                evidence.actions.len()
            )));
        }
        let action_dim = evidence.actions.len() / rows;
        let inputs = scale.inputs(evidence.latents, evidence.actions);
        let width = dims + action_dim;
        let transition = (0..dims)
            .map(|d| {
                let targets: Vec<f64> =
                    (0..rows).map(|b| (evidence.next_latents[b * dims + d] - scale.mean[d]) / scale.std[d]).collect();
                let prior_mean: Vec<f64> = (0..rows).map(|b| inputs[b * width + d]).collect();
                transition[d].condition(&inputs, &targets, &prior_mean)
            })
            .collect::<Result<Vec<_>>>()?;
        let raw_inputs = latent_action_rows(evidence.latents, evidence.actions, dims);
        let reward_floor = evidence.rewards.iter().copied().fold(f64::INFINITY, f64::min);
        let reward = reward.condition(&raw_inputs, evidence.rewards, &vec![reward_floor; rows])?;
        Ok(LatentDynamics { scale, transition, reward, reward_floor, action_dim })
    }

    /// Transitions the GPs are conditioned on.
    pub fn evidence_len(&self) -> usize {
        self.reward.len()
    }

    pub fn action_dim(&self) -> usize {
        self.action_dim
    }

    pub fn latent_dim(&self) -> usize {
        self.transition.len()
    }

    /// Largest diagonal jitter the evidence needed (0 when none).
    pub fn jitter(&self) -> f64 {
        self.transition.iter().chain(std::iter::once(&self.reward)).map(|g| g.jitter()).fold(0.0, f64::max)
    }

    /// Mean and predictive variance (raw units, observation noise included) of the next latent for rows of
    /// (latent, action).
    pub fn step(&self, latents: &[f64], actions: &[f64]) -> Result<(Vec<f64>, Vec<f64>)> {
        let dims = self.latent_dim();
        let rows = latents.len() / dims;
        let inputs = self.scale.inputs(latents, actions);
        let width = dims + self.action_dim;
        let (mut mean, mut variance) = (vec![0.0; rows * dims], vec![0.0; rows * dims]);
        for (d, gp) in self.transition.iter().enumerate() {
            let prior: Vec<f64> = (0..rows).map(|b| inputs[b * width + d]).collect();
            let p = gp.predict(&inputs, &prior, true)?;
            let (m, s) = (self.scale.mean[d], self.scale.std[d]);
            for b in 0..rows {
                mean[b * dims + d] = p.mean[b] * s + m;
                variance[b * dims + d] = p.variance[b] * s * s + gp.noise();
            }
        }
        Ok((mean, variance))
    }

    /// The reward GP's posterior mean at rows of (latent, action).
    pub fn reward_mean(&self, latents: &[f64], actions: &[f64]) -> Result<Vec<f64>> {
        let dims = self.latent_dim();
        let rows = latents.len() / dims;
        let inputs = latent_action_rows(latents, actions, dims);
        Ok(self.reward.predict(&inputs, &vec![self.reward_floor; rows], false)?.mean)
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::models::gp::HyperInit;

    /// Evidence from s' = s + 0.1·a (per dimension) and reward −s₀², in a 2-d latent.
    fn evidence(rows: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let latents: Vec<f64> = (0..rows * 2).map(|_| rng.random_range(-1.0..1.0)).collect();
        let actions: Vec<f64> = (0..rows).map(|_| rng.random_range(-2.0..2.0)).collect();
        let next = latents.iter().enumerate().map(|(i, s)| s + 0.1 * actions[i / 2]).collect();
        let rewards = (0..rows).map(|b| -latents[b * 2].powi(2)).collect();
        (latents, actions, next, rewards)
    }

    fn dynamics() -> LatentDynamics {
        let (latents, actions, next, rewards) = evidence(80);
        let mut hypers: Vec<GpHypers> = (0..2).map(|_| GpHypers::new(&HyperInit::dlgpd(3, 1.0)).unwrap()).collect();
        for h in &mut hypers {
            h.raw_noise = -12.0; // near-noiseless: the evidence is exact
        }
        let mut reward = GpHypers::new(&HyperInit::dlgpd(3, 0.1)).unwrap();
        reward.raw_noise = -12.0;
        let scale = LatentScale::of(&latents, 2).unwrap();
        let ev = Evidence { latents: &latents, actions: &actions, next_latents: &next, rewards: &rewards };
        LatentDynamics::condition(&hypers, &reward, scale, &ev).unwrap()
    }

    #[test]
    fn predictions_follow_the_evidence_near_it_and_the_prior_far_from_it() {
        let d = dynamics();
        let (latents, actions, next, rewards) = evidence(80);
        let (mean, variance) = d.step(&latents[..20], &actions[..10]).unwrap();
        for i in 0..20 {
            assert!((mean[i] - next[i]).abs() < 0.02, "row {i}: {} vs {}", mean[i], next[i]);
            assert!(variance[i] < 0.01, "variance at evidence {}", variance[i]);
        }
        let r = d.reward_mean(&latents[..20], &actions[..10]).unwrap();
        for (b, got) in r.iter().enumerate() {
            assert!((got - rewards[b]).abs() < 0.1, "reward {b}: {got} vs {}", rewards[b]);
        }
        // Far away: the prior, i.e. the latent stays where it is, with the prior's variance σ̂²α² + σ².
        let far = [40.0, -40.0];
        let (mean, variance) = d.step(&far, &[0.0]).unwrap();
        assert!((mean[0] - 40.0).abs() < 1e-6 && (mean[1] + 40.0).abs() < 1e-6, "{mean:?}");
        let scale = LatentScale::of(&latents, 2).unwrap();
        let prior_var = scale.std[0].powi(2) * 1.0 + d.transition[0].noise();
        assert!((variance[0] - prior_var).abs() < 1e-6, "{} vs {prior_var}", variance[0]);
        let floor = rewards.iter().copied().fold(f64::INFINITY, f64::min);
        assert!((d.reward_mean(&far, &[0.0]).unwrap()[0] - floor).abs() < 1e-6, "reward prior = smallest reward");
    }

    #[test]
    fn ragged_evidence_is_an_error() {
        let (latents, actions, next, rewards) = evidence(10);
        let hypers: Vec<GpHypers> = (0..2).map(|_| GpHypers::new(&HyperInit::dlgpd(3, 1.0)).unwrap()).collect();
        let reward = GpHypers::new(&HyperInit::dlgpd(3, 1.0)).unwrap();
        let scale = LatentScale::of(&latents, 2).unwrap();
        let ev = Evidence { latents: &latents[1..], actions: &actions, next_latents: &next, rewards: &rewards };
        let e = LatentDynamics::condition(&hypers, &reward, scale, &ev).unwrap_err().to_string();
        assert!(e.contains("evidence"), "{e}");
    }
}
