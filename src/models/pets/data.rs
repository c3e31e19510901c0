//! Transitions of a rollout dataset as network inputs and targets: angles as (cos, sin), then the action; the
//! target is the state change (and the reward, when it is learned).

use rand::seq::SliceRandom;

use super::config::RewardSource;
use crate::data::Dataset;
use crate::error::{Error, Result};
use crate::nn::features::{feature_dim, features};
use crate::util::seeding::rng_for;

/// Row-major inputs and targets.
#[derive(Clone, Debug, Default)]
pub struct Transitions {
    pub inputs: Vec<f32>,
    pub targets: Vec<f32>,
    pub input_dim: usize,
    pub target_dim: usize,
}

impl Transitions {
    pub fn len(&self) -> usize {
        self.inputs.len().checked_div(self.input_dim).unwrap_or(0)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

pub struct Split {
    pub train: Transitions,
    pub valid: Transitions,
    pub train_rollouts: usize,
    pub valid_rollouts: usize,
}

/// Splits by whole rollouts (a seeded shuffle) and converts each part.
pub fn split_dataset(
    dataset: &Dataset,
    angular: &[bool],
    reward: RewardSource,
    validation_fraction: f64,
    seed: u64,
) -> Result<Split> {
    let meta = &dataset.meta;
    if meta.action_dim == 0 {
        return Err(Error::data(format!(
            "dataset of '{}' has no actions (action_dim 0); a dynamics model needs (state, action, next state) rows",
            meta.env
        )));
    }
    if meta.state_names.len() != angular.len() {
        return Err(Error::data(format!(
            "dataset states have {} dimensions ({}); env '{}' has {}",
            meta.state_names.len(),
            meta.state_names.join(", "),
            meta.env,
            angular.len()
        )));
    }
    let mut rollouts: Vec<u32> = dataset.steps.iter().map(|s| s.rollout).collect();
    rollouts.sort_unstable();
    rollouts.dedup();
    if rollouts.is_empty() {
        return Err(Error::data("dataset has no transitions"));
    }
    let mut order = rollouts.clone();
    order.shuffle(&mut rng_for(seed, &[VALIDATION_SPLIT_STREAM]));
    let held_out = if validation_fraction > 0.0 && rollouts.len() >= 2 {
        ((rollouts.len() as f64 * validation_fraction).round() as usize).clamp(1, rollouts.len() - 1)
    } else {
        0
    };
    let mut valid_ids: Vec<u32> = order[..held_out].to_vec();
    valid_ids.sort_unstable();
    let input_dim = feature_dim(angular, meta.action_dim);
    let target_dim = angular.len() + usize::from(reward == RewardSource::Learned);
    let empty = || Transitions { input_dim, target_dim, ..Default::default() };
    let (mut train, mut valid) = (empty(), empty());
    for step in &dataset.steps {
        let part = if valid_ids.binary_search(&step.rollout).is_ok() { &mut valid } else { &mut train };
        features(&step.state, &step.action, angular, &mut part.inputs);
        part.targets.extend(step.next_state.iter().zip(&step.state).map(|(n, s)| (n - s) as f32));
        if reward == RewardSource::Learned {
            part.targets.push(step.reward as f32);
        }
    }
    if train.inputs.iter().chain(&train.targets).chain(&valid.inputs).chain(&valid.targets).any(|x| !x.is_finite()) {
        return Err(Error::data("dataset values overflow 32-bit floats; rescale the data"));
    }
    Ok(Split { train, valid, train_rollouts: rollouts.len() - held_out, valid_rollouts: held_out })
}

pub const VALIDATION_SPLIT_STREAM: u64 = 10;
