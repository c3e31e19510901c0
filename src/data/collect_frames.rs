//! `collect --images`: rendered frames of every state of a pendulum dataset (DLGPD's observations).

use super::frames::FrameInfo;
use super::Dataset;
use crate::envs::pendulum::render::{PendulumRenderer, FRAME_BYTES, FRAME_SIZE};
use crate::envs::EnvName;
use crate::error::{Error, Result};
use crate::run::Monitor;

pub const PENDULUM_RENDERER: &str = "gym-pendulum";

/// Refuses before any work when the frames of `states` states would not fit the budget.
pub fn check_frames_size(env: &EnvName, states: f64) -> Result<()> {
    if !matches!(env, EnvName::Pendulum(_)) {
        return Err(Error::config(format!(
            "--images renders the pendulum (pendulum[:variant]); '{}' has no renderer",
            env.canonical()
        )));
    }
    crate::util::budget::check(
        &format!("--images: {states} frames"),
        states * FRAME_BYTES as f64,
        "collect fewer rollouts or steps",
    )
}

/// Renders θ (the first state dimension) of every state, t = 0 … T of each rollout, into `data.frames`.
pub fn add_pendulum_frames(data: &mut Dataset, monitor: &dyn Monitor) -> Result<()> {
    let rollouts = crate::data::Rollout::group(&data.steps)
        .map_err(|i| Error::data(format!("message {i} does not continue its rollout")))?;
    let mut renderer = PendulumRenderer::new();
    let total = rollouts.len() as u64;
    let mut frames = Vec::with_capacity(data.steps.len() + rollouts.len());
    for (k, (_, rollout)) in rollouts.iter().enumerate() {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        frames.extend(rollout.states.iter().map(|state| renderer.frame(state[0])));
        monitor.progress("render frames", k as u64 + 1, total);
    }
    data.frames = frames;
    data.meta.frames = Some(FrameInfo { width: FRAME_SIZE, height: FRAME_SIZE, renderer: PENDULUM_RENDERER.into() });
    Ok(())
}
