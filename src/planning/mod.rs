//! Planners. A planner optimizes an [`Objective`] over action sequences and knows nothing of the model
//! behind it.

pub mod bfs;
pub mod board_view;
pub mod cem;
/// Lives in util so that data collection (below planning) can draw colored exploration noise too.
pub use crate::util::colored_noise;
pub mod mpc;
pub mod solve_board;

pub use cem::{Cem, CemConfig, CemIteration, NoiseKind};

/// Cost of a batch of open-loop action sequences (lower is better). `candidates` holds them back to back,
/// each `horizon × action_dim`.
pub trait Objective: Sync {
    fn costs(&self, candidates: &[f64], horizon: usize, costs: &mut [f64]);
}

/// Negative return of a model rolled out from a fixed start state. Each call keys the model's randomness with a
/// fresh seed derived from `seed` and the call count, so repeated CEM iterations see fresh particles while the
/// whole plan stays a function of the seed.
pub struct ReturnObjective<'a> {
    pub dynamics: &'a dyn crate::envs::BatchDynamics,
    pub init: &'a [f64],
    pub seed: u64,
    pub calls: std::sync::atomic::AtomicU64,
}

impl<'a> ReturnObjective<'a> {
    pub fn new(dynamics: &'a dyn crate::envs::BatchDynamics, init: &'a [f64], seed: u64) -> Self {
        ReturnObjective { dynamics, init, seed, calls: std::sync::atomic::AtomicU64::new(0) }
    }
}

impl Objective for ReturnObjective<'_> {
    fn costs(&self, candidates: &[f64], horizon: usize, costs: &mut [f64]) {
        let call = self.calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let seed = crate::util::seeding::derive_seed(self.seed, &[call]);
        self.dynamics.rollout(self.init, candidates, horizon, seed, costs, None);
        for c in costs.iter_mut() {
            *c = -*c;
        }
    }
}
