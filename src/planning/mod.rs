//! Planners. A planner optimizes an [`Objective`] over action sequences and knows nothing of the model
//! behind it.

pub mod bfs;
pub mod cem;
pub mod colored_noise;
pub mod mpc;
pub mod solve_board;

pub use cem::{Cem, CemConfig, CemIteration, NoiseKind};

/// Cost of a batch of open-loop action sequences (lower is better). `candidates` holds them back to back,
/// each `horizon × action_dim`.
pub trait Objective: Sync {
    fn costs(&self, candidates: &[f64], horizon: usize, costs: &mut [f64]);
}

/// Negative return of a [`Dynamics`](crate::envs::Dynamics) rolled out from a fixed start state.
pub struct ReturnObjective<'a> {
    pub dynamics: &'a dyn crate::envs::Dynamics,
    pub init: &'a [f64],
}

impl Objective for ReturnObjective<'_> {
    fn costs(&self, candidates: &[f64], horizon: usize, costs: &mut [f64]) {
        self.dynamics.rollout_returns(self.init, candidates, horizon, costs);
        for c in costs.iter_mut() {
            *c = -*c;
        }
    }
}
