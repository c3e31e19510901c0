//! Receding-horizon control: plan with CEM on a model, apply the first action to the real environment,
//! replan.

use super::{Cem, CemIteration, ReturnObjective};
use crate::data::Rollout;
use crate::envs::{BatchDynamics, Env};
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
    mut on_iteration: impl FnMut(usize, &CemIteration),
    mut on_step: impl FnMut(&MpcStep),
) -> Result<Rollout> {
    let action_dim = model.action_dim();
    let horizon = cem.config().horizon;
    cem.reset();
    let mut rollout = Rollout::start(env.state(), env.observe());
    let mut predicted = vec![0.0; horizon * model.state_dim()];
    for t in 0..steps {
        if monitor.is_cancelled() {
            return Err(Error::Cancelled);
        }
        let state = env.state();
        let objective = ReturnObjective::new(model, &state, derive_seed(seed, &[t as u64, 0]));
        let plan = cem.plan(&objective, |it| on_iteration(t, it));
        model.rollout(&state, &plan, horizon, derive_seed(seed, &[t as u64, 1]), &mut [0.0], Some(&mut predicted));
        let action = plan[..action_dim].to_vec();
        let step = env.step(&action);
        let next_state = env.state();
        on_step(&MpcStep {
            t,
            state: &state,
            action: &action,
            reward: step.reward,
            predicted_next: &predicted[..model.state_dim()],
            next_state: &next_state,
        });
        rollout.push(action, step.reward, env.state(), step.obs);
        if step.done {
            break;
        }
    }
    Ok(rollout)
}
