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
