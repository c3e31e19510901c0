//! Whether a conditioned DLGPD model's latent dynamics respond to the action as the system does. From the
//! start of each held-out rollout the simulator runs twice, once with the largest and once with the smallest
//! action held for a few steps; the model rolls its latent mean forward from the same encoded start with the
//! same actions. The response is the model's latent difference between the two branches projected on the
//! encoded true difference: 1 is right, 0 means the model ignores the action, and a planner on it then has
//! nothing to choose between.

use serde::Serialize;

use crate::data::collect::{replay, ReplaySettings};
use crate::data::collect_frames::add_pendulum_frames;
use crate::data::{Dataset, Rollout};
use crate::envs::pendulum::PendulumVariant;
use crate::envs::EnvName;
use crate::error::{Error, Result};
use crate::models::dlgpd::data::{ObservationKind, Windows};
use crate::models::dlgpd::dynamics::LatentDynamics;
use crate::models::dlgpd::evidence::encoded_means;
use crate::models::dlgpd::job::TrainedDlgpd;
use crate::run::NullMonitor;

/// Steps of held action after which the response is reported.
pub const RESPONSE_HORIZONS: [usize; 3] = [1, 5, 10];

#[derive(Clone, Debug, Serialize)]
pub struct ActionResponse {
    pub horizon: usize,
    /// Σ⟨Δ_model, Δ_true⟩ / Σ|Δ_true|² over the held-out starts, where Δ is the latent difference between the
    /// largest-action and the smallest-action branch (the true one encoded from the simulator's frames).
    pub response: f64,
    /// RMS |Δ_true| over the RMS spread of the held-out latents around their mean: how visible the action's
    /// effect is in the encoding at all.
    pub true_effect: f64,
}

/// The action response of `dynamics` on the starts of `held_out` (rollouts of `variant`); `spread` is the RMS
/// distance of the held-out latents from their mean.
pub fn action_response(
    trained: &TrainedDlgpd,
    dynamics: &LatentDynamics,
    held_out: &Dataset,
    variant: &PendulumVariant,
    spread: f64,
    seed: u64,
) -> Result<Vec<ActionResponse>> {
    let rollouts = Rollout::group(&held_out.steps)
        .map_err(|i| Error::data(format!("held-out message {i} does not continue its rollout")))?;
    let env = EnvName::Pendulum(variant.clone());
    let spec = env.build()?.spec();
    let (low, high) = (spec.action_low.clone(), spec.action_high.clone());
    let longest = RESPONSE_HORIZONS.iter().copied().max().unwrap_or(0);
    let dims = dynamics.latent_dim();
    let mut sums = vec![(0.0, 0.0); RESPONSE_HORIZONS.len()];
    for (_, rollout) in &rollouts {
        let (Some(start), Some(first_action)) = (rollout.states.first(), rollout.actions.first()) else {
            continue;
        };
        let mut true_latents = Vec::with_capacity(2);
        for held in [&high, &low] {
            // The first action only makes the start's frame pair; the held action begins with the pair.
            let mut actions = vec![first_action.clone()];
            actions.extend(std::iter::repeat_n(held.clone(), longest + 1));
            true_latents.push(branch_latents(trained, &env, start, actions, seed)?);
        }
        // Both branches share the start's frames; the model starts both from the first branch's encoding.
        let start_latent = &true_latents[0][..dims];
        let model_latents = [
            rollout_means(dynamics, start_latent, &high, longest)?,
            rollout_means(dynamics, start_latent, &low, longest)?,
        ];
        for (k, &h) in RESPONSE_HORIZONS.iter().enumerate() {
            let at = |latents: &[f64]| latents[h * dims..(h + 1) * dims].to_vec();
            let true_delta: Vec<f64> =
                at(&true_latents[0]).iter().zip(at(&true_latents[1])).map(|(a, b)| a - b).collect();
            let model_delta: Vec<f64> =
                at(&model_latents[0]).iter().zip(at(&model_latents[1])).map(|(a, b)| a - b).collect();
            sums[k].0 += model_delta.iter().zip(&true_delta).map(|(m, t)| m * t).sum::<f64>();
            sums[k].1 += true_delta.iter().map(|t| t * t).sum::<f64>();
        }
    }
    let starts = rollouts.len().max(1) as f64;
    Ok(RESPONSE_HORIZONS
        .iter()
        .zip(sums)
        .map(|(&horizon, (projected, true_square))| ActionResponse {
            horizon,
            response: if true_square > 0.0 { projected / true_square } else { f64::NAN },
            true_effect: if spread > 0.0 { (true_square / starts).sqrt() / spread } else { f64::NAN },
        })
        .collect())
}

/// Encoded means of a replayed branch's frame pairs: row h is the pair after h held actions.
fn branch_latents(
    trained: &TrainedDlgpd,
    env: &EnvName,
    start: &[f64],
    actions: Vec<Vec<f64>>,
    seed: u64,
) -> Result<Vec<f64>> {
    let mut branch = replay(&ReplaySettings {
        env: env.clone(),
        actions,
        init_state: Some(start.to_vec()),
        instance_seed: None,
        seed,
        command_line: "mbrl eval dlgpd (action response)".into(),
    })?;
    if matches!(trained.run.details.observation, ObservationKind::Images { .. }) {
        add_pendulum_frames(&mut branch, &NullMonitor)?;
    }
    let windows = Windows::from_dataset(&branch, trained.run.details.observation, seed)?;
    let rows: Vec<usize> = (0..windows.len()).collect();
    encoded_means(&trained.vae, &windows, &rows)
}

/// The model's latent means after 0 … `steps` applications of `action` from `start`, end to end.
fn rollout_means(dynamics: &LatentDynamics, start: &[f64], action: &[f64], steps: usize) -> Result<Vec<f64>> {
    let mut out = start.to_vec();
    let mut latent = start.to_vec();
    for _ in 0..steps {
        latent = dynamics.step(&latent, action)?.0;
        out.extend_from_slice(&latent);
    }
    Ok(out)
}
