//! How well a conditioned DLGPD model predicts the rewards a planner optimizes, on held-out rollouts of a
//! setting (open loop, as `models::dlgpd::prediction` computes it), and how linearly its latent holds the
//! pendulum's state: the check that separates a model that cannot see the pendulum from a planner that
//! cannot find the swing-up.

use serde::Serialize;

use nalgebra::{DMatrix, DVector};

use super::dlgpd_action_response::{action_response, ActionResponse};
use crate::data::{Dataset, Rollout};
use crate::envs::pendulum::PendulumVariant;
use crate::error::{Error, Result};
use crate::models::dlgpd::data::Windows;
use crate::models::dlgpd::dynamics::LatentDynamics;
use crate::models::dlgpd::evidence::encoded_means;
use crate::models::dlgpd::job::TrainedDlgpd;
use crate::models::dlgpd::prediction::{reward_errors, RewardErrors};

/// Reward prediction errors of one conditioned model on held-out rollouts of one system, and the probe.
#[derive(Clone, Debug, Serialize)]
pub struct RewardPrediction {
    #[serde(flatten)]
    pub errors: RewardErrors,
    /// R² of cos θ, sin θ and θ̇ regressed linearly on the latent means (in sample). The GPs predict each
    /// latent dimension around its current value; a latent that holds the velocity only through a
    /// nonlinear fold gives them a harder function to learn than one near-linear in the state.
    pub linear_probe_r2: [f64; 3],
    /// How the model's latent answers a held extreme action, against the encoded simulator's answer.
    pub action_response: Vec<ActionResponse>,
}

/// Predict the rewards of `held_out` (random-action rollouts of `variant`, the system at hand) with
/// `dynamics`.
pub fn reward_prediction(
    trained: &TrainedDlgpd,
    dynamics: &LatentDynamics,
    held_out: &Dataset,
    variant: &PendulumVariant,
    seed: u64,
) -> Result<RewardPrediction> {
    let windows = Windows::from_dataset(held_out, trained.run.details.observation, seed)?;
    let rows: Vec<usize> = (0..windows.len()).collect();
    let latents = encoded_means(&trained.vae, &windows, &rows)?;
    let dims = dynamics.latent_dim();
    let linear_probe_r2 = linear_probe(&latents, dims, &window_states(held_out, &windows)?)?;
    let action_response = action_response(trained, dynamics, held_out, variant, rms_spread(&latents, dims), seed)?;
    Ok(RewardPrediction {
        errors: reward_errors(dynamics, &windows, &rows, &latents)?,
        linear_probe_r2,
        action_response,
    })
}

/// RMS distance of latent rows from their mean.
fn rms_spread(latents: &[f64], dims: usize) -> f64 {
    let rows = latents.len() / dims.max(1);
    if rows == 0 {
        return f64::NAN;
    }
    let mean: Vec<f64> = (0..dims).map(|d| latents.iter().skip(d).step_by(dims).sum::<f64>() / rows as f64).collect();
    let square: f64 =
        latents.chunks(dims).map(|z| z.iter().zip(&mean).map(|(v, m)| (v - m).powi(2)).sum::<f64>()).sum();
    (square / rows as f64).sqrt()
}

/// The simulator state (θ, θ̇) of each window's newer observation, in window order.
fn window_states(held_out: &Dataset, windows: &Windows) -> Result<Vec<[f64; 2]>> {
    let rollouts = Rollout::group(&held_out.steps)
        .map_err(|i| Error::data(format!("held-out message {i} does not continue its rollout")))?;
    let states: Vec<[f64; 2]> =
        rollouts.iter().flat_map(|(_, r)| (1..r.len()).map(move |k| [r.states[k][0], r.states[k][1]])).collect();
    if states.len() != windows.len() {
        return Err(Error::data(format!("{} held-out states for {} windows", states.len(), windows.len())));
    }
    Ok(states)
}

fn linear_probe(latents: &[f64], dims: usize, states: &[[f64; 2]]) -> Result<[f64; 3]> {
    let rows = states.len();
    let design = DMatrix::from_fn(rows, dims + 1, |r, c| if c < dims { latents[r * dims + c] } else { 1.0 });
    let svd = design.clone().svd(true, true);
    let mut r2 = [0.0; 3];
    for (which, out) in r2.iter_mut().enumerate() {
        let target = |s: &[f64; 2]| match which {
            0 => s[0].cos(),
            1 => s[0].sin(),
            _ => s[1],
        };
        let y = DVector::from_iterator(rows, states.iter().map(target));
        let weights = svd.solve(&y, 1e-12).map_err(|e| Error::diverged(format!("latent probe: {e}")))?;
        let residual = &design * weights - &y;
        let mean = y.mean();
        let total: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
        *out = if total > 0.0 { 1.0 - residual.norm_squared() / total } else { f64::NAN };
    }
    Ok(r2)
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    fn states(rows: usize) -> Vec<[f64; 2]> {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        (0..rows).map(|_| [rng.random_range(-3.0..3.0), rng.random_range(-8.0..8.0)]).collect()
    }

    #[test]
    fn a_latent_linear_in_the_state_probes_perfectly() {
        let states = states(200);
        let latents: Vec<f64> =
            states.iter().flat_map(|s| [2.0 * s[0].cos() - s[1], s[0].sin() + 0.5, 0.1 * s[1] + 3.0]).collect();
        let r2 = linear_probe(&latents, 3, &states).unwrap();
        assert!(r2.iter().all(|v| (v - 1.0).abs() < 1e-9), "{r2:?}");
    }

    #[test]
    fn a_velocity_held_only_through_a_fold_probes_near_zero() {
        let states = states(2000);
        // |θ̇| and the angle, but not the velocity's sign: linear in nothing that predicts θ̇.
        let latents: Vec<f64> = states.iter().flat_map(|s| [s[0].cos(), s[0].sin(), s[1].abs()]).collect();
        let r2 = linear_probe(&latents, 3, &states).unwrap();
        assert!(r2[0] > 0.999 && r2[1] > 0.999, "{r2:?}");
        assert!(r2[2] < 0.02, "{r2:?}");
    }
}
