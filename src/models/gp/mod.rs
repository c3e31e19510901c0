//! Exact Gaussian processes in f64 (DLGPD's latent dynamics and reward models, thesis chapter 3): the
//! SE-ARD kernel, GPyTorch's constrained hyperparameters and priors, conditioning with a cached Cholesky
//! factor, and the negative log marginal likelihood with its gradients for the inputs the encoder produces.

pub mod constraint;
pub mod exact;
pub mod hypers;
pub mod kernel;
#[cfg(test)]
mod tests;

pub use constraint::{GammaPrior, GreaterThan};
pub use exact::{ConditionedGp, NllGradients, Prediction};
pub use hypers::{GpHypers, HyperInit, ObjectiveGradients};
pub use kernel::SeArd;
