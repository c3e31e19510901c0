//! Windows of a dataset encoded with the encoder's means, and GPs conditioned on them: how `plan` turns
//! evidence rollouts into dynamics, and how training's validation checks the planner's view.

use super::data::Windows;
use super::dynamics::{Evidence, LatentDynamics};
use super::latent_gp::LatentScale;
use super::vae::{encode_rows, VaeNet};
use crate::error::{Error, Result};
use crate::models::gp::GpHypers;
use crate::nn::tensor::inference_device;

/// Encoder means of the windows `rows`, widened to f64; an error when any is not finite.
pub fn encoded_means(vae: &VaeNet, windows: &Windows, rows: &[usize]) -> Result<Vec<f64>> {
    let latents = widened_means(vae, &windows.observations(rows).0, windows.kind.input_len());
    if latents.iter().any(|v| !v.is_finite()) {
        return Err(Error::diverged("the encoder gave non-finite latents"));
    }
    Ok(latents)
}

/// GPs with the hyperparameters `gps` (transition, reward) conditioned on the windows `rows`, encoded with the
/// encoder's means.
pub fn condition_on_rows(
    vae: &VaeNet,
    gps: (&[GpHypers], &GpHypers),
    scale: LatentScale,
    windows: &Windows,
    rows: &[usize],
) -> Result<LatentDynamics> {
    let (obs, next) = windows.observations(rows);
    let (actions, rewards) = windows.actions_and_rewards(rows);
    let width = windows.kind.input_len();
    let latents = widened_means(vae, &obs, width);
    let next_latents = widened_means(vae, &next, width);
    let evidence = Evidence { latents: &latents, actions: &actions, next_latents: &next_latents, rewards: &rewards };
    LatentDynamics::condition(gps.0, gps.1, scale, &evidence)
}

fn widened_means(vae: &VaeNet, obs: &[f32], width: usize) -> Vec<f64> {
    encode_rows(vae, obs, width, &inference_device()).0.into_iter().map(f64::from).collect()
}
