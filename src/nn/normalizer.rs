//! Per-dimension standardization fitted on training data and saved with the model.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Standard deviations below this count as constant dimensions and are left unscaled (as mbrl-lib does), so a
/// feature that never varies in the data does not blow up to ±∞ at planning time.
const MIN_STD: f64 = 1e-6;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Normalizer {
    pub mean: Vec<f32>,
    pub std: Vec<f32>,
}

impl Normalizer {
    pub fn identity(dim: usize) -> Self {
        Normalizer { mean: vec![0.0; dim], std: vec![1.0; dim] }
    }

    /// Fits on `rows` (each `dim` long, row-major), in f64 so large datasets do not lose precision.
    pub fn fit(rows: &[f32], dim: usize) -> Result<Self> {
        if dim == 0 || rows.is_empty() || !rows.len().is_multiple_of(dim) {
            return Err(Error::data(format!("normalizer: {} values do not form rows of {dim}", rows.len())));
        }
        let n = (rows.len() / dim) as f64;
        let mut mean = vec![0.0f64; dim];
        for row in rows.chunks(dim) {
            row.iter().zip(&mut mean).for_each(|(x, m)| *m += *x as f64);
        }
        mean.iter_mut().for_each(|m| *m /= n);
        let mut var = vec![0.0f64; dim];
        for row in rows.chunks(dim) {
            row.iter().zip(&mean).zip(&mut var).for_each(|((x, m), v)| *v += (*x as f64 - m).powi(2));
        }
        let std = var.iter().map(|v| (v / n).sqrt()).map(|s| if s < MIN_STD { 1.0 } else { s as f32 }).collect();
        Ok(Normalizer { mean: mean.iter().map(|m| *m as f32).collect(), std })
    }

    pub fn dim(&self) -> usize {
        self.mean.len()
    }

    /// Standardizes rows in place.
    pub fn apply(&self, rows: &mut [f32]) {
        let d = self.dim();
        for row in rows.chunks_mut(d) {
            for ((x, m), s) in row.iter_mut().zip(&self.mean).zip(&self.std) {
                *x = (*x - m) / s;
            }
        }
    }

    pub fn validate(&self) -> Result<()> {
        let ok = self.mean.len() == self.std.len()
            && self.mean.iter().all(|m| m.is_finite())
            && self.std.iter().all(|s| s.is_finite() && *s > 0.0);
        if ok {
            Ok(())
        } else {
            Err(Error::data("normalizer: mean and std must have equal length, be finite, and std > 0"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standardizes_and_leaves_constant_dimensions_unscaled() {
        let rows = vec![1.0, 5.0, 3.0, 5.0];
        let norm = Normalizer::fit(&rows, 2).unwrap();
        assert_eq!(norm.mean, vec![2.0, 5.0]);
        assert_eq!(norm.std, vec![1.0, 1.0]);
        let mut x = vec![3.0, 6.0];
        norm.apply(&mut x);
        assert_eq!(x, vec![1.0, 1.0]);
    }

    #[test]
    fn ragged_rows_are_an_error() {
        assert!(Normalizer::fit(&[1.0, 2.0, 3.0], 2).is_err());
    }
}
