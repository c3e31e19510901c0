//! How well conditioned GPs predict the rewards a planner optimizes, open loop as CEM uses them: encode a
//! rollout's first two observations (encoder mean), roll the latent mean forward with the rollout's own
//! actions through the transition GPs, and read the reward GP's mean at every step. Training logs it on the
//! held-out rollouts; `eval dlgpd` reports it on fresh rollouts of each setting.

use serde::Serialize;

use super::data::Windows;
use super::dynamics::LatentDynamics;
use crate::error::{Error, Result};

/// Reward prediction errors of one conditioned model on some rollouts.
#[derive(Clone, Debug, Serialize)]
pub struct RewardErrors {
    /// RMSE of the open-loop reward prediction h steps after the encoded start, h = 0, 1, ….
    pub open_loop_rmse: Vec<f64>,
    /// RMSE of the reward GP at the encoding of every step's own observations (no dynamics involved).
    pub encoded_rmse: f64,
    /// RMSE of the best constant: the rewards' own mean (their standard deviation).
    pub constant_rmse: f64,
    pub rollouts: usize,
}

/// Score `dynamics` on the windows `rows` (whole rollouts, each in time order); `latents` are their
/// encoder means ([`encoded_means`](super::evidence::encoded_means)). The open loop runs over the shortest rollout.
pub fn reward_errors(
    dynamics: &LatentDynamics,
    windows: &Windows,
    rows: &[usize],
    latents: &[f64],
) -> Result<RewardErrors> {
    let dims = dynamics.latent_dim();
    let action_dim = windows.action_dim;
    if rows.is_empty() || latents.len() != rows.len() * dims {
        return Err(Error::data(format!("{} latents for {} windows of a {dims}-d latent", latents.len(), rows.len())));
    }
    let (actions, rewards) = windows.actions_and_rewards(rows);
    let encoded = dynamics.reward_mean(latents, &actions)?;
    let encoded_rmse = rmse(encoded.iter().zip(&rewards).map(|(p, r)| p - r));
    let mean_reward = rewards.iter().sum::<f64>() / rewards.len() as f64;
    let constant_rmse = rmse(rewards.iter().map(|r| r - mean_reward));

    let starts: Vec<usize> =
        (0..rows.len()).filter(|&i| i == 0 || windows.rollout[rows[i]] != windows.rollout[rows[i - 1]]).collect();
    let ends: Vec<usize> = starts.iter().skip(1).copied().chain(std::iter::once(rows.len())).collect();
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
        return Err(Error::diverged("the open-loop latent rollout went non-finite"));
    }
    Ok(RewardErrors { open_loop_rmse, encoded_rmse, constant_rmse, rollouts: starts.len() })
}

fn rmse(errors: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = errors.fold((0.0, 0usize), |(s, n), e| (s + e * e, n + 1));
    (sum / count.max(1) as f64).sqrt()
}
