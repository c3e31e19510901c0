//! Why a filter step can fail.

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FilterError {
    /// The Kalman gain needs S⁻¹; a non-positive-definite S means the covariances have broken down (or R is not
    /// a covariance), and continuing would silently produce garbage beliefs.
    #[error("innovation covariance S = H P Hᵀ + R is not positive definite")]
    InnovationNotPositiveDefinite,

    #[error("measurement has a non-finite component")]
    NonFiniteMeasurement,

    /// Position of the failure inside a measurement sequence, so a caller can name the offending sample.
    #[error("measurement {index}: {source}")]
    AtMeasurement {
        index: usize,
        #[source]
        source: Box<FilterError>,
    },
}

impl FilterError {
    pub(crate) fn at(self, index: usize) -> Self {
        FilterError::AtMeasurement { index, source: Box::new(self) }
    }
}
