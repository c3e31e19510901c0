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
    let (obs, _) = windows.observations(rows);
    let latents: Vec<f64> =
        encode_rows(vae, &obs, windows.kind.input_len(), &inference_device()).0.into_iter().map(f64::from).collect();
    if latents.iter().any(|v| !v.is_finite()) {
        return Err(Error::Diverged("the encoder gave non-finite latents".into()));
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
    let device = inference_device();
    let widen = |v: Vec<f32>| v.into_iter().map(f64::from).collect::<Vec<f64>>();
    let latents = widen(encode_rows(vae, &obs, width, &device).0);
    let next_latents = widen(encode_rows(vae, &next, width, &device).0);
    let evidence = Evidence { latents: &latents, actions: &actions, next_latents: &next_latents, rewards: &rewards };
    LatentDynamics::condition(gps.0, gps.1, scale, &evidence)
}
