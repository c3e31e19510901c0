//! Gray-box model of a table-tennis ball for the EKF of chapter 6: Euler-discretized flight with drag and Magnus
//! effect (eq. 6.21), a linear table-impact map placed at the time of impact within the step (6.4.2, eq. 6.22), its
//! analytic Jacobian (appendix C.2), and the filter's initialization from the first two measurements (6.4.3).
//!
//! State z = (p, v, ω, a_d, a_m) ∈ ℝ¹¹ (eq. 6.20); only the position is measured.
//!
//! ```
//! use mbrl::filtering::{filter_belief, forecast};
//! use mbrl::models::ball::{initial_belief, BallModel, BallModelParams, SpinPrior};
//!
//! let model = BallModel::new(BallModelParams::thesis_learned()).unwrap();
//! // First two measurements, one camera frame apart, before the bounce, no launcher information.
//! let start = initial_belief(model.params(), [0.1, 2.8, 0.1], [0.102, 2.775, 0.105], 1, false, &SpinPrior::Uninformed)
//!     .unwrap();
//! // One slot per later camera frame; None is a dropout.
//! let slots = [Some([0.104, 2.75, 0.11]), None, Some([0.108, 2.70, 0.12])];
//! let out = filter_belief(&model, &start, &slots).unwrap();
//! let next_second = forecast(&model, &out.last_belief().unwrap(), 180);
//! assert_eq!(next_second.len(), 180);
//! ```

pub mod baseline;
pub mod checkpoint;
mod error;
mod flight;
mod impact;
mod init;
pub mod learn;
mod model;
mod params;
mod state;
pub mod track;

pub use error::BallModelError;
pub use init::{initial_belief, SpinPrior};
pub use model::BallModel;
pub use params::{BallModelParams, BallPhysics};
pub use state::{BallBelief, BallState, Phase, AD, AM, MEAS_DIM, P, STATE_DIM, V, W};

#[cfg(test)]
mod tests;
