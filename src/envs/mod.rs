//! Simulators. Every environment is an [`Env`] for stepping one instance, and exposes its ground-truth
//! dynamics as a pure [`Dynamics`] so planners can use the simulator itself as a reference model.

pub mod ball;
pub mod boards;
pub mod embodiments;
pub mod mountaincar;
pub mod pendulum;
pub mod registry;
pub mod terrain;
pub mod toy;
pub mod unicycle;

use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

pub use registry::{instance_env, parse_env, EnvName, INSTANCE_STREAM};

/// Names, sizes and bounds of an environment.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvSpec {
    pub name: String,
    pub state_names: Vec<String>,
    pub obs_names: Vec<String>,
    pub action_low: Vec<f64>,
    pub action_high: Vec<f64>,
    /// Simulated seconds per `step`.
    pub dt: f64,
    /// Which state dimensions are angles (learned models see them as cos/sin so 2π-equivalent states look alike).
    pub angular: Vec<bool>,
}

impl EnvSpec {
    pub fn state_dim(&self) -> usize {
        self.state_names.len()
    }

    pub fn action_dim(&self) -> usize {
        self.action_low.len()
    }
}

/// The result of one environment step.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    pub obs: Vec<f64>,
    pub reward: f64,
    pub done: bool,
}

pub trait Env {
    fn spec(&self) -> EnvSpec;
    /// Draws a start state; returns the first observation.
    fn reset(&mut self, rng: &mut ChaCha8Rng) -> Vec<f64>;
    fn step(&mut self, action: &[f64]) -> Step;
    fn state(&self) -> Vec<f64>;
    fn set_state(&mut self, state: &[f64]);
    fn observe(&self) -> Vec<f64>;
    /// The hidden parameters of this instance (recorded in datasets).
    fn params(&self) -> serde_json::Value;
    /// For parametrized families: draw new hidden parameters. Fixed environments keep theirs.
    fn sample_instance(&mut self, _rng: &mut ChaCha8Rng) {}
    /// The pure dynamics of this instance, for continuous planners; `None` where planning is symbolic.
    fn dynamics(&self) -> Option<Box<dyn Dynamics>>;
    /// Why `state` cannot be a start state of this env (outside its bounds), if it cannot.
    fn state_error(&self, _state: &[f64]) -> Option<String> {
        None
    }
    /// How `collect` draws random actions in this env.
    fn exploration(&self) -> Exploration {
        Exploration::Uniform
    }
}

/// The random actions of collected data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exploration {
    /// Independent uniform actions within the bounds.
    Uniform,
    /// Gaussian colored noise (power ∝ 1/f^beta) of standard deviation `std`, one sequence of at least
    /// `min_len` samples per action dimension, clipped to the bounds: it travels farther than white noise.
    Colored { beta: f64, std: f64, min_len: usize },
}

/// What a planner rolls out: many candidate action sequences at once from one start state. Implemented by the
/// simulators' own equations (every [`Dynamics`]) and by learned models, which carry their own latent state
/// (ensemble member, particles, hidden state, context) inside `rollout`. The planner never knows which.
pub trait BatchDynamics: Sync + Send {
    fn state_dim(&self) -> usize;
    fn action_dim(&self) -> usize;

    /// Rolls out the candidates in `actions` (back to back, each `horizon × action_dim`) from `init`. Writes each
    /// candidate's return to `returns` and, when `states` is given, its predicted states s_1..s_H
    /// (`[candidate][t][state_dim]`); stochastic models average both over their particles. `seed` keys the
    /// model's own randomness, so the same call gives the same numbers on any thread count.
    fn rollout(
        &self,
        init: &[f64],
        actions: &[f64],
        horizon: usize,
        seed: u64,
        returns: &mut [f64],
        states: Option<&mut [f64]>,
    );

    /// A short description for reports ("ground truth", "PETS ensemble …").
    fn describe(&self) -> String;
}

/// Splits a batch rollout into blocks of `block` candidates run in parallel: each call of `run` gets the blocks'
/// returns, action sequences (`per_actions` values per candidate) and, when asked for, predicted states
/// (`per_states` per candidate). Learned models roll a block out as one matrix batch.
pub fn par_candidate_blocks(
    returns: &mut [f64],
    actions: &[f64],
    states: Option<&mut [f64]>,
    (per_actions, per_states): (usize, usize),
    block: usize,
    run: impl Fn(&mut [f64], &[f64], Option<&mut [f64]>) + Sync,
) {
    let blocks = returns.par_chunks_mut(block).zip(actions.par_chunks(per_actions * block));
    match states {
        None => blocks.for_each(|(ret, cands)| run(ret, cands, None)),
        Some(states) => blocks
            .zip(states.par_chunks_mut(per_states * block))
            .for_each(|((ret, cands), out)| run(ret, cands, Some(out))),
    }
}

impl<T: Dynamics> BatchDynamics for T {
    fn state_dim(&self) -> usize {
        Dynamics::state_dim(self)
    }

    fn action_dim(&self) -> usize {
        Dynamics::action_dim(self)
    }

    fn rollout(
        &self,
        init: &[f64],
        actions: &[f64],
        horizon: usize,
        _seed: u64,
        returns: &mut [f64],
        states: Option<&mut [f64]>,
    ) {
        match states {
            None => self.rollout_returns(init, actions, horizon, returns),
            Some(states) => {
                let (a, d) = (Dynamics::action_dim(self), Dynamics::state_dim(self));
                let per_candidate = horizon * a;
                returns
                    .par_iter_mut()
                    .zip(actions.par_chunks(per_candidate))
                    .zip(states.par_chunks_mut(horizon * d))
                    .for_each(|((ret, seq), out)| {
                        let mut state = init.to_vec();
                        *ret = 0.0;
                        for (action, slot) in seq.chunks(a).zip(out.chunks_mut(d)) {
                            *ret += self.step(&mut state, action);
                            slot.copy_from_slice(&state);
                        }
                    });
            }
        }
    }

    fn describe(&self) -> String {
        "ground truth (the simulator's equations)".into()
    }
}

/// A simulator's dynamics behind a box (what `Env::dynamics` hands out) plan like the dynamics themselves.
impl Dynamics for Box<dyn Dynamics> {
    fn state_dim(&self) -> usize {
        self.as_ref().state_dim()
    }

    fn action_dim(&self) -> usize {
        self.as_ref().action_dim()
    }

    fn step(&self, state: &mut [f64], action: &[f64]) -> f64 {
        self.as_ref().step(state, action)
    }

    fn rollout_returns(&self, init: &[f64], actions: &[f64], horizon: usize, returns: &mut [f64]) {
        self.as_ref().rollout_returns(init, actions, horizon, returns)
    }
}

/// A reward known in closed form, so a learned dynamics model need not learn it.
pub trait RewardFn: Sync + Send {
    fn reward(&self, state: &[f64], action: &[f64], next_state: &[f64]) -> f64;
}

/// What a planner rolls out. Pure: the same state and action always give the same result.
pub trait Dynamics: Sync + Send {
    fn state_dim(&self) -> usize;
    fn action_dim(&self) -> usize;

    /// Advances `state` in place by one step and returns the reward of that transition.
    fn step(&self, state: &mut [f64], action: &[f64]) -> f64;

    /// Returns of many open-loop action sequences from one start state. `actions` holds the candidates
    /// back to back, each `horizon × action_dim`. Candidates are independent, so they run in parallel;
    /// models with a faster batched path override this.
    fn rollout_returns(&self, init: &[f64], actions: &[f64], horizon: usize, returns: &mut [f64]) {
        let per_candidate = horizon * self.action_dim();
        let action_dim = self.action_dim();
        returns.par_iter_mut().zip(actions.par_chunks(per_candidate)).for_each(|(ret, seq)| {
            let mut state = init.to_vec();
            *ret = seq.chunks(action_dim).map(|a| self.step(&mut state, a)).sum();
        });
    }
}
