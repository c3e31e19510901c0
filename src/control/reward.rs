//! The reward seam: a reward known in closed form, so a learned dynamics model need not learn it. The
//! simulators define their rewards as plain functions; this is where they become something a model holds.

use crate::envs::pendulum::dynamics::{NominalPendulumReward, PendulumReward};
use crate::envs::EnvName;

pub trait RewardFn: Sync + Send {
    fn reward(&self, state: &[f64], action: &[f64], next_state: &[f64]) -> f64;
}

impl RewardFn for PendulumReward {
    fn reward(&self, state: &[f64], action: &[f64], _next_state: &[f64]) -> f64 {
        self.reward_of(state, action)
    }
}

impl RewardFn for NominalPendulumReward {
    fn reward(&self, state: &[f64], action: &[f64], _next_state: &[f64]) -> f64 {
        self.reward_of(state, action)
    }
}

/// The env's closed-form reward as a seam, where it has one (see [`EnvName::known_reward`]).
pub fn known_reward(env: &EnvName) -> Option<Box<dyn RewardFn>> {
    env.known_reward().map(|r| Box::new(r) as Box<dyn RewardFn>)
}
