//! Receding-horizon control: plan with CEM on a model, apply the first action to the real environment,
//! replan.

use super::{Cem, CemIteration, ReturnObjective};
use crate::data::Rollout;
use crate::envs::{Dynamics, Env};
use crate::error::{Error, Result};
use crate::run::Monitor;

/// Runs one MPC episode of `steps` from the environment's current state. `on_iteration(t, it)` sees every
/// CEM refit, `on_step(t, state, action, reward)` every executed step.
pub fn run_mpc_episode(
    env: &mut dyn Env,
    model: &dyn Dynamics,
    cem: &mut Cem,
    steps: usize,
    monitor: &dyn Monitor,
    mut on_iteration: impl FnMut(usize, &CemIteration),
    mut on_step: impl FnMut(usize, &[f64], &[f64], f64),
) -> Result<Rollout> {
    let action_dim = model.action_dim();
    cem.reset();
    let mut rollout = Rollout::start(env.state(), env.observe());
    for t in 0..steps {
        if monitor.is_cancelled() {
            return Err(Error::Cancelled);
        }
        let state = env.state();
        let plan = cem.plan(&ReturnObjective { dynamics: model, init: &state }, |it| on_iteration(t, it));
        let action = plan[..action_dim].to_vec();
        let step = env.step(&action);
        on_step(t, &state, &action, step.reward);
        rollout.push(action, step.reward, env.state(), step.obs);
        if step.done {
            break;
        }
    }
    Ok(rollout)
}
