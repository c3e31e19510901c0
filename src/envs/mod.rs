//! Simulators. Every environment is an [`Env`] for stepping one instance, and exposes its ground-truth
//! dynamics as a pure [`Dynamics`] so planners can use the simulator itself as a reference model.

pub mod ball;
pub mod boards;
pub mod embodiments;
pub mod pendulum;
pub mod registry;

use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

pub use registry::{parse_env, EnvName};

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
