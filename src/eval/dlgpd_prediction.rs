//! How well a conditioned DLGPD model predicts the rewards a planner optimizes, on held-out rollouts: the
//! check that separates a model that cannot see the pendulum from a planner that cannot find the swing-up.
//! Open loop as CEM uses it: encode the first two observations (encoder mean), roll the latent mean forward
//! with the rollout's own actions through the transition GPs, and read the reward GP's mean at every step.

use serde::Serialize;

use nalgebra::{DMatrix, DVector};

use crate::data::{Dataset, Rollout};
use crate::error::{Error, Result};
use crate::models::dlgpd::data::Windows;
use crate::models::dlgpd::dynamics::LatentDynamics;
use crate::models::dlgpd::job::TrainedDlgpd;
use crate::models::dlgpd::train::encode_rows;
use crate::nn::tensor::inference_device;

/// Reward prediction errors of one conditioned model on held-out rollouts of one system.
#[derive(Clone, Debug, Serialize)]
pub struct RewardPrediction {
    /// RMSE of the open-loop reward prediction h steps after the encoded start, h = 0, 1, ….
    pub open_loop_rmse: Vec<f64>,
    /// RMSE of the reward GP at the encoding of every step's own observations (no dynamics involved).
    pub encoded_rmse: f64,
    /// RMSE of the best constant: the held-out rewards' own mean (their standard deviation).
    pub constant_rmse: f64,
    /// R² of cos θ, sin θ and θ̇ regressed linearly on the latent means (in sample). The GPs predict each
    /// latent dimension around its current value; a latent that holds the velocity only through a
    /// nonlinear fold gives them a harder function to learn than one near-linear in the state.
    pub linear_probe_r2: [f64; 3],
    pub rollouts: usize,
}

/// Predict the rewards of `held_out` (random-action rollouts of the system at hand) with `dynamics`.
pub fn reward_prediction(
    trained: &TrainedDlgpd,
    dynamics: &LatentDynamics,
    held_out: &Dataset,
    seed: u64,
) -> Result<RewardPrediction> {
    let windows = Windows::from_dataset(held_out, trained.run.observation, seed)?;
    let all: Vec<usize> = (0..windows.len()).collect();
    let (obs, _) = windows.observations(&all);
    let (actions, rewards) = windows.actions_and_rewards(&all);
    let action_dim = windows.action_dim;
    let width = trained.run.observation.input_len();
    let dims = trained.run.config.latent_dim;
    let latents: Vec<f64> =
        encode_rows(&trained.vae, &obs, width, &inference_device()).0.into_iter().map(f64::from).collect();
    if latents.iter().any(|v| !v.is_finite()) {
        return Err(Error::Diverged("the encoder gave non-finite latents for the held-out rollouts".into()));
    }
    let linear_probe_r2 = linear_probe(&latents, dims, &window_states(held_out, &windows)?)?;
    let encoded = dynamics.reward_mean(&latents, &actions)?;
    let encoded_rmse = rmse(encoded.iter().zip(&rewards).map(|(p, r)| p - r));
    let mean_reward = rewards.iter().sum::<f64>() / rewards.len() as f64;
    let constant_rmse = rmse(rewards.iter().map(|r| r - mean_reward));

    // Each rollout's windows in time order; the open loop runs over the shortest one.
    let mut starts: Vec<usize> = Vec::new();
    for row in 0..windows.len() {
        if row == 0 || windows.rollout[row] != windows.rollout[row - 1] {
            starts.push(row);
        }
    }
    let ends: Vec<usize> = starts.iter().skip(1).copied().chain(std::iter::once(windows.len())).collect();
    let horizon = starts.iter().zip(&ends).map(|(s, e)| e - s).min().unwrap_or(0);
    let mut state: Vec<f64> = starts.iter().flat_map(|&s| latents[s * dims..(s + 1) * dims].to_vec()).collect();
    let mut open_loop_rmse = Vec::with_capacity(horizon);
    for h in 0..horizon {
        let step_actions: Vec<f64> =
            starts.iter().flat_map(|&s| actions[(s + h) * action_dim..(s + h + 1) * action_dim].to_vec()).collect();
        let predicted = dynamics.reward_mean(&state, &step_actions)?;
        open_loop_rmse.push(rmse(predicted.iter().zip(&starts).map(|(p, &s)| p - rewards[s + h])));
        if h + 1 < horizon {
            state = dynamics.step(&state, &step_actions)?.0;
        }
    }
    if open_loop_rmse.iter().any(|v| !v.is_finite()) {
        return Err(Error::Diverged("the open-loop latent rollout of the held-out rollouts went non-finite".into()));
    }
    Ok(RewardPrediction { open_loop_rmse, encoded_rmse, constant_rmse, linear_probe_r2, rollouts: starts.len() })
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
        let weights = svd.solve(&y, 1e-12).map_err(|e| Error::Diverged(format!("latent probe: {e}")))?;
        let residual = &design * weights - &y;
        let mean = y.mean();
        let total: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
        *out = if total > 0.0 { 1.0 - residual.norm_squared() / total } else { f64::NAN };
    }
    Ok(r2)
}

fn rmse(errors: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = errors.fold((0.0, 0usize), |(s, n), e| (s + e * e, n + 1));
    (sum / count.max(1) as f64).sqrt()
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
