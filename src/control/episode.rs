//! One loop that runs a controller in an environment. Every controller (CEM MPC on any dynamics, EIG
//! calibration, DLGPD image control, TRADYN navigation, SEADS skill execution) is an [`Agent`]; what differs
//! between them is how they choose an action and what they learn from its outcome, never how the env is
//! stepped, cancelled or recorded.

use crate::data::Rollout;
use crate::envs::Env;
use crate::error::{Error, Result};
use crate::run::Monitor;

/// One executed step, as the agent and the caller see it.
#[derive(Clone, Debug, PartialEq)]
pub struct Transition {
    pub t: usize,
    pub state: Vec<f64>,
    pub observation: Vec<f64>,
    pub action: Vec<f64>,
    pub reward: f64,
    pub next_state: Vec<f64>,
    pub next_observation: Vec<f64>,
    /// The env ended the episode with this step (a SEADS skill ran out, a board was solved).
    pub done: bool,
}

/// A controller: chooses actions from what the env shows and may update its beliefs from each outcome.
pub trait Agent {
    /// Called once before the first action of an episode.
    fn reset(&mut self) -> Result<()> {
        Ok(())
    }

    /// The action for step `t`. Planning agents read the env state (the thesis' planners plan from the true
    /// state); agents that learned from observations read `observation`.
    fn act(&mut self, t: usize, state: &[f64], observation: &[f64]) -> Result<Vec<f64>>;

    /// Sees the transition its action caused, before the caller's `on_step` does.
    fn observe(&mut self, _transition: &Transition) -> Result<()> {
        Ok(())
    }
}

/// Runs `agent` in `env` from the env's current state for at most `limit` steps, stopping early when a step
/// ends the episode or the monitor is cancelled. `on_step` sees every transition with the env after it and the
/// agent (for what it planned), in order.
pub fn run_episode<E: Env + ?Sized, A: Agent + ?Sized>(
    env: &mut E,
    agent: &mut A,
    limit: usize,
    monitor: &dyn Monitor,
    mut on_step: impl FnMut(&Transition, &E, &A) -> Result<()>,
) -> Result<Rollout> {
    agent.reset()?;
    let mut observation = env.observe();
    let mut rollout = Rollout::start(env.state(), observation.clone());
    for t in 0..limit {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        let state = env.state();
        let action = agent.act(t, &state, &observation)?;
        if let Some(bad) = action.iter().find(|a| !a.is_finite()) {
            return Err(Error::diverged(format!("episode step {t}: the agent chose a non-finite action ({bad})")));
        }
        let step = env.step(&action);
        // Caught where it first appears: past this step every later state, plan and report would carry it.
        if !step.reward.is_finite() || env.state().iter().any(|x| !x.is_finite()) {
            return Err(Error::diverged(format!(
                "episode step {t}: the simulator's state or reward became non-finite (state {:?}, reward {}) \
                 after action {action:?}",
                env.state(),
                step.reward
            )));
        }
        let transition = Transition {
            t,
            state,
            observation,
            action,
            reward: step.reward,
            next_state: env.state(),
            next_observation: step.obs,
            done: step.done,
        };
        agent.observe(&transition)?;
        on_step(&transition, env, agent)?;
        let Transition { action, reward, next_state, next_observation, done, .. } = transition;
        observation = next_observation.clone();
        rollout.push(action, reward, next_state, next_observation);
        if done {
            break;
        }
    }
    Ok(rollout)
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;
    use crate::envs::pendulum::{Pendulum, PendulumVariant};
    use crate::run::NullMonitor;

    /// Pushes with +1 until step 3, then −1; counts what it was told.
    struct Bang {
        resets: usize,
        seen: Vec<usize>,
    }

    impl Agent for Bang {
        fn reset(&mut self) -> Result<()> {
            self.resets += 1;
            Ok(())
        }

        fn act(&mut self, t: usize, _state: &[f64], _observation: &[f64]) -> Result<Vec<f64>> {
            Ok(vec![if t < 3 { 1.0 } else { -1.0 }])
        }

        fn observe(&mut self, transition: &Transition) -> Result<()> {
            self.seen.push(transition.t);
            Ok(())
        }
    }

    #[test]
    fn the_episode_records_what_the_env_did_with_the_agents_actions() {
        let mut env = Pendulum::new(PendulumVariant::parse("").unwrap());
        env.reset(&mut rand_chacha::ChaCha8Rng::seed_from_u64(3));
        let mut replay = Pendulum::new(PendulumVariant::parse("").unwrap());
        replay.set_state(&env.state());
        let mut agent = Bang { resets: 0, seen: Vec::new() };
        let mut calls = 0;
        let rollout = run_episode(&mut env, &mut agent, 5, &NullMonitor, |tr, env, _| {
            calls += 1;
            assert_eq!(env.state(), tr.next_state);
            Ok(())
        })
        .unwrap();
        assert_eq!((agent.resets, agent.seen.clone(), calls), (1, vec![0, 1, 2, 3, 4], 5));
        assert_eq!(rollout.len(), 5);
        for (t, action) in rollout.actions.iter().enumerate() {
            let step = replay.step(action);
            assert_eq!(rollout.rewards[t], step.reward);
            assert_eq!(rollout.states[t + 1], replay.state());
        }
        assert_eq!(rollout.actions[3], vec![-1.0]);
    }

    #[test]
    fn an_error_from_the_caller_ends_the_episode() {
        let mut env = Pendulum::new(PendulumVariant::parse("").unwrap());
        let mut agent = Bang { resets: 0, seen: Vec::new() };
        let out = run_episode(&mut env, &mut agent, 5, &NullMonitor, |tr, _, _| {
            if tr.t == 1 {
                Err(Error::cancelled())
            } else {
                Ok(())
            }
        });
        assert!(out.as_ref().is_err_and(|e| e.is_cancelled()));
        assert_eq!(agent.seen, vec![0, 1]);
    }

    /// Acts 0.5 until step 2, then NaN.
    struct Broken;

    impl Agent for Broken {
        fn reset(&mut self) -> Result<()> {
            Ok(())
        }

        fn act(&mut self, t: usize, _state: &[f64], _observation: &[f64]) -> Result<Vec<f64>> {
            Ok(vec![if t < 2 { 0.5 } else { f64::NAN }])
        }
    }

    #[test]
    fn a_non_finite_action_stops_the_episode_at_its_step() {
        let mut env = Pendulum::new(PendulumVariant::parse("").unwrap());
        let mut steps = 0;
        let err = run_episode(&mut env, &mut Broken, 5, &NullMonitor, |_, _, _| {
            steps += 1;
            Ok(())
        })
        .unwrap_err();
        assert!(err.to_string().contains("episode step 2: the agent chose a non-finite action"), "{err}");
        assert_eq!(steps, 2, "the two finite steps ran");
    }

    #[test]
    fn a_simulator_state_turning_non_finite_stops_the_episode_at_that_step() {
        let mut env = Pendulum::new(PendulumVariant::parse("").unwrap());
        env.set_state(&[f64::INFINITY, 0.0]);
        let mut agent = Bang { resets: 0, seen: Vec::new() };
        let err = run_episode(&mut env, &mut agent, 5, &NullMonitor, |_, _, _| Ok(())).unwrap_err();
        assert!(err.to_string().contains("episode step 0: the simulator's state or reward became non-finite"), "{err}");
        assert!(agent.seen.is_empty());
    }
}
