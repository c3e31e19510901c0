//! The control seam: what a controller sees of a world and of a model. Below models and planning, above the
//! simulators, so a learned model implements [`BatchDynamics`] without importing any simulator, a planner
//! optimizes an [`Objective`] without knowing the model inside it, and every controller (CEM MPC, EIG
//! calibration, DLGPD image control, TRADYN navigation, SEADS skills) runs in an env through one
//! [`run_episode`].

pub mod dynamics;
pub mod episode;
pub mod objective;
pub mod reward;

pub use dynamics::{par_candidate_blocks, BatchDynamics};
pub use episode::{run_episode, Agent, Transition};
pub use objective::{Objective, ReturnObjective};
pub use reward::{known_reward, RewardFn};
