//! Receding-horizon control: plan with CEM on a model, apply the first action to the real environment,
//! replan.

use super::{Cem, CemIteration};
use crate::control::{run_episode, Agent, BatchDynamics, ReturnObjective};
use crate::data::Rollout;
use crate::envs::Env;
use crate::error::{Error, Result};
use crate::run::Monitor;
use crate::util::seeding::derive_seed;

/// One executed MPC step, with what the model expected of it.
pub struct MpcStep<'a> {
    pub t: usize,
    pub state: &'a [f64],
    pub action: &'a [f64],
    pub reward: f64,
    /// The state the model predicted after this action (mean over its particles).
    pub predicted_next: &'a [f64],
    /// The state the environment reached.
    pub next_state: &'a [f64],
}

/// CEM MPC on any batched dynamics (the simulator's own equations or a learned model): at step `t` it plans
/// from the env state with the model's randomness keyed by `seed` and `t`, and acts with the plan's first
/// action. `on_iteration(t, it)` sees every CEM refit.
pub struct MpcAgent<'a, F: FnMut(usize, &CemIteration)> {
    model: &'a dyn BatchDynamics,
    cem: &'a mut Cem,
    seed: u64,
    predicted: Vec<f64>,
    on_iteration: F,
}

impl<'a, F: FnMut(usize, &CemIteration)> MpcAgent<'a, F> {
    pub fn new(model: &'a dyn BatchDynamics, cem: &'a mut Cem, seed: u64, on_iteration: F) -> Self {
        let predicted = vec![0.0; cem.config().horizon * model.state_dim()];
        MpcAgent { model, cem, seed, predicted, on_iteration }
    }

    /// The state the model predicts after the last action (mean over its particles).
    pub fn predicted_next(&self) -> &[f64] {
        &self.predicted[..self.model.state_dim()]
    }
}

/// A plan that failed at episode step `t`, with the step in its message.
pub fn planning_failed(t: usize, error: Error) -> Error {
    Error::diverged(format!("episode step {}: {error}", t + 1))
}

impl<F: FnMut(usize, &CemIteration)> Agent for MpcAgent<'_, F> {
    fn reset(&mut self) -> Result<()> {
        self.cem.reset();
        Ok(())
    }

    fn act(&mut self, t: usize, state: &[f64], _observation: &[f64]) -> Result<Vec<f64>> {
        let horizon = self.cem.config().horizon;
        let objective = ReturnObjective::new(self.model, state, derive_seed(self.seed, &[t as u64, 0]));
        let on_iteration = &mut self.on_iteration;
        let plan = self.cem.plan(&objective, |it| on_iteration(t, it)).map_err(|e| planning_failed(t, e))?;
        let seed = derive_seed(self.seed, &[t as u64, 1]);
        self.model.rollout(state, &plan, horizon, seed, &mut [0.0], Some(&mut self.predicted));
        Ok(plan[..self.model.action_dim()].to_vec())
    }
}

/// Runs one MPC episode of `steps` from the environment's current state, planning on `model` (the simulator's
/// own equations or a learned model). `seed` keys the model's randomness. `on_iteration(t, it)` sees every CEM
/// refit, `on_step` every executed step.
#[allow(clippy::too_many_arguments)]
pub fn run_mpc_episode(
    env: &mut dyn Env,
    model: &dyn BatchDynamics,
    cem: &mut Cem,
    steps: usize,
    seed: u64,
    monitor: &dyn Monitor,
    on_iteration: impl FnMut(usize, &CemIteration),
    mut on_step: impl FnMut(&MpcStep),
) -> Result<Rollout> {
    let mut agent = MpcAgent::new(model, cem, seed, on_iteration);
    run_episode(env, &mut agent, steps, monitor, |step, _, agent| {
        on_step(&MpcStep {
            t: step.t,
            state: &step.state,
            action: &step.action,
            reward: step.reward,
            predicted_next: agent.predicted_next(),
            next_state: &step.next_state,
        });
        Ok(())
    })
}
