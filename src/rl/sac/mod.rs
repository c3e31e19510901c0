//! Soft Actor-Critic (Haarnoja et al. 2018) as the SEADS code runs it: tanh-Gaussian actor, twin Q critics
//! with Polyak-averaged targets, fixed temperature α, Adam for both.
//!
//! The networks work in actions scaled to [−1, 1]: the actor's tanh output is rescaled to the env bounds for
//! acting, and batch actions (stored in env units) are mapped back before they enter the critics. Log-probs
//! are densities over that [−1, 1] space.
//!
//! Training uses burn's autodiff for the two gradient passes; acting and the critic target go through the
//! plain-buffer fast path (`inference`), rebuilt from the parameters after every update.

pub mod agent;
pub mod batch;
pub mod config;
pub mod inference;
pub mod networks;
mod state;

pub use agent::Sac;
pub use batch::{SacLosses, TransitionBatch};
pub use config::SacConfig;

#[cfg(test)]
mod tests;
