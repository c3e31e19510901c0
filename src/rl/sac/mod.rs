//! Soft Actor-Critic (Haarnoja et al. 2018) as the SEADS code runs it: tanh-Gaussian actor, twin Q critics
//! with Polyak-averaged targets, fixed temperature α, Adam for both.
//!
//! As in the authors' code, the actor's tanh output in [−1, 1] is rescaled to the env bounds, the critics take
//! actions in env units (as the replay memory stores them), and log-probs are densities over env units: the
//! rescaling's Jacobian is part of them, which decides how much a step's entropy is worth.
//!
//! Training uses burn's autodiff for the two gradient passes; acting and the critic target go through the
//! plain-buffer fast path (`inference`), rebuilt from the parameters after every update.

pub mod agent;
pub mod batch;
pub mod config;
pub mod grad;
pub mod inference;
pub mod networks;
mod state;

pub use agent::Sac;
pub use batch::{SacLosses, TransitionBatch};
pub use config::SacConfig;

#[cfg(test)]
mod tests;
