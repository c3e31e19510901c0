//! What a planner optimizes: a cost per candidate action sequence.

use std::sync::atomic::{AtomicU64, Ordering};

use super::BatchDynamics;
use crate::util::seeding::derive_seed;

/// Cost of a batch of open-loop action sequences (lower is better). `candidates` holds them back to back,
/// each `horizon × action_dim`.
pub trait Objective: Sync {
    fn costs(&self, candidates: &[f64], horizon: usize, costs: &mut [f64]);
}

/// Negative return of a model rolled out from a fixed start state. Each call keys the model's randomness with a
/// fresh seed derived from `seed` and the call count, so repeated CEM iterations see fresh particles while the
/// whole plan stays a function of the seed.
pub struct ReturnObjective<'a> {
    pub dynamics: &'a dyn BatchDynamics,
    pub init: &'a [f64],
    pub seed: u64,
    pub calls: AtomicU64,
}

impl<'a> ReturnObjective<'a> {
    pub fn new(dynamics: &'a dyn BatchDynamics, init: &'a [f64], seed: u64) -> Self {
        ReturnObjective { dynamics, init, seed, calls: AtomicU64::new(0) }
    }
}

impl Objective for ReturnObjective<'_> {
    fn costs(&self, candidates: &[f64], horizon: usize, costs: &mut [f64]) {
        let call = self.calls.fetch_add(1, Ordering::Relaxed);
        let seed = derive_seed(self.seed, &[call]);
        self.dynamics.rollout(self.init, candidates, horizon, seed, costs, None);
        for c in costs.iter_mut() {
            *c = -*c;
        }
    }
}
