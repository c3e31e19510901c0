//! Learning the ball EKF's parameters Ψ (6.4.3, eq. 6.24; appendix C.1) with burn: a batched, differentiable
//! copy of the filter in `models::ball` runs over chunks of recordings in f64 on the flex CPU backend with
//! autodiff, and Adam maximizes the innovation log-likelihood. The result is a plain [`BallModelParams`] (plus the
//! launcher spin network's weights when it was learned) for the fast nalgebra filter.
//!
//! The batched filter repeats the reference model's equations step by step: Euler flight with drag and Magnus
//! effect, the impact placed at the gravity-only time of impact with the map C, the analytic Jacobian of C.2
//! including the impact branch, at most one impact per chunk (a per-sample phase decided on the host), the
//! correction with (I − KH)Σ, and missing measurements as prediction alone. Tests hold it to the nalgebra filter's
//! loss and to finite differences of that loss.
//!
//! burn 0.22's tensors carry no backend type parameter: the device, chosen at run time, is the backend. The
//! modules here are therefore plain structs; another backend is a different [`burn::tensor::Device`].
//!
//! [`BallModelParams`]: crate::models::ball::BallModelParams

mod batch;
mod chunks;
mod device;
mod filter;
mod flight;
mod impact;
mod init;
pub mod job;
mod linalg;
pub mod options;
mod params;
mod positive;
mod predict;
mod reference;
mod rotation;
mod spin_net;
mod train;
mod trainer;
mod update;

pub use batch::Batch;
pub use chunks::{cut_chunks, detect_impact_frame, Chunk};
pub use device::training_device;
pub use filter::{chunk_loss, log_likelihoods};
pub use params::BallParamsModule;
pub use positive::{inverse_softplus, softplus};
pub use reference::{chunk_nll, reference_loss};
pub use rotation::{launch_rotation, observed_side_info};
pub use spin_net::{SpinNet, SpinNetWeights};
pub use train::{train, TrainOutcome, TrainSettings};
pub use trainer::BallEkfTrainer;

#[cfg(test)]
mod tests;
