//! What can be wrong with ball-model parameters or initial measurements.

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BallModelError {
    #[error("ball model parameter `{field}`: {message}")]
    InvalidParameter { field: &'static str, message: String },

    #[error("the first two measurements must be at least one frame apart (frame gap 0)")]
    ZeroFrameGap,

    #[error("initial {what} has a non-finite component")]
    NonFiniteInitialValue { what: &'static str },
}
