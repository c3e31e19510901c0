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

pub use registry::{instance_env, parse_env, EnvName, ENV_NAMES, INSTANCE_STREAM};

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

/// A simulator's equations as a pure function: the same state and action always give the same result, so a
/// planner can use the simulator itself as its model (see `control::BatchDynamics`).
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
