//! Kalman filtering over fixed-size states (thesis 6.3.2-6.3.6).
//!
//! The filter is generic over the state size `N` and measurement size `M` and works on nalgebra's stack-allocated
//! matrices, so one predict/update step allocates nothing. A model supplies its transition with Jacobian, its
//! measurement function with Jacobian and its noise covariances through [`EkfModel`]; a linear model with constant
//! Jacobians makes this the ordinary Kalman filter.

mod ekf;
mod error;
mod sequence;

pub use ekf::{predict, update, Belief, EkfModel, Mat, Vector};
pub use error::FilterError;
pub use sequence::{filter, filter_belief, forecast, forecast_means, FilterOutput};

#[cfg(test)]
mod tests;
