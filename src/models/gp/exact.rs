//! Exact GP regression in f64: the Cholesky factor of K + σ_n²I is computed once per conditioning and kept, so
//! that predictive means cost O(n) and variances O(n²) per query. The negative log marginal likelihood comes
//! with its gradients with respect to every hyperparameter, every input and every target, which is how the
//! encoder that produced the inputs learns through the GP (thesis eq. 3.16).

use faer::linalg::solvers::{DenseSolveCore, Llt, SolveCore};
use faer::{Mat, Side};

use super::kernel::SeArd;
use crate::error::{Error, Result};
use crate::util::fast_exp::scaled_exp_in_place;
use crate::util::wide::{clean_upper_state, widest_fn};

const LN_2PI: f64 = 1.837_877_066_409_345_5;
/// Jitter added to the diagonal when the factorization fails, relative to the mean diagonal, tried in turn.
const JITTERS: [f64; 7] = [1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4];

/// A GP conditioned on training data: inputs (rows × dims, row-major), targets and the prior mean at each
/// input. The mean function is the caller's: the transition GPs use the current value of their latent
/// dimension, the reward GP a constant.
#[derive(Clone, Debug)]
pub struct ConditionedGp {
    inputs: Vec<f64>,
    /// The inputs divided by their lengthscales, one contiguous column per dimension: the layout in which
    /// the cross-covariances of a query against every point are computed in one vectorized sweep.
    scaled_columns: Vec<Vec<f64>>,
    kernel: SeArd,
    noise: f64,
    jitter: f64,
    factor: Llt<f64>,
    residual: Vec<f64>,
    alpha: Vec<f64>,
}

/// Gradients of the negative log marginal likelihood.
#[derive(Clone, Debug, PartialEq)]
pub struct NllGradients {
    /// Row-major like the inputs.
    pub inputs: Vec<f64>,
    pub targets: Vec<f64>,
    pub prior_mean: Vec<f64>,
    pub lengthscales: Vec<f64>,
    pub outputscale: f64,
    pub noise: f64,
}

/// Predictive mean and variance of the latent function (without observation noise) at query points.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    pub mean: Vec<f64>,
    /// Empty unless asked for.
    pub variance: Vec<f64>,
}

fn check_finite(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(Error::data(format!("GP {what}: value {i} is {}, expected a finite number", values[i]))),
        None => Ok(()),
    }
}

widest_fn! {
    /// `column[j] = outputscale · exp(−½ Σ_c (points_c[j] − query_c)²)`, in one sweep per dimension, at the
    /// CPU's widest vector width (`util::wide`: the same bits on every width).
    fn cross_column(points: &[Vec<f64>], query: &[f64], outputscale: f64, column: &mut [f64]) {
        cross_column_portable(points, query, outputscale, column)
    }
}

#[inline(always)]
fn cross_column_portable(points: &[Vec<f64>], query: &[f64], outputscale: f64, column: &mut [f64]) {
    column.iter_mut().for_each(|k| *k = 0.0);
    for (dimension, x) in points.iter().zip(query) {
        for (k, p) in column.iter_mut().zip(dimension) {
            *k += (p - x) * (p - x);
        }
    }
    column.iter_mut().for_each(|k| *k *= -0.5);
    scaled_exp_in_place(column, outputscale);
}

impl ConditionedGp {
    /// Conditions on the data. `noise` is σ_n² (a variance). When K + σ_n²I is not numerically positive
    /// definite, jitter up to 1e-4 × the mean diagonal is added (see [`ConditionedGp::jitter`]); beyond
    /// that the data are an error.
    pub fn condition(inputs: &[f64], targets: &[f64], prior_mean: &[f64], kernel: SeArd, noise: f64) -> Result<Self> {
        let d = kernel.dims();
        let n = targets.len();
        if d == 0 || inputs.len() != n * d || prior_mean.len() != n {
            return Err(Error::data(format!(
                "GP data: {} input values, {n} targets and {} prior means; expected {n} rows of {d} inputs each",
                inputs.len(),
                prior_mean.len()
            )));
        }
        if n == 0 {
            return Err(Error::data("GP data: no training points"));
        }
        check_finite("inputs", inputs)?;
        check_finite("targets", targets)?;
        check_finite("prior mean", prior_mean)?;
        let hypers_ok = kernel.lengthscales.iter().all(|l| l.is_finite() && *l > 0.0)
            && kernel.outputscale.is_finite()
            && kernel.outputscale > 0.0
            && noise.is_finite()
            && noise >= 0.0;
        if !hypers_ok {
            return Err(Error::data(format!(
                "GP hyperparameters: lengthscales {:?}, outputscale {}, noise {noise}; expected positive finite values",
                kernel.lengthscales, kernel.outputscale
            )));
        }
        let k = kernel.matrix(inputs, inputs);
        let mean_diag = kernel.outputscale + noise;
        let mut jitter = 0.0;
        let factor = loop {
            let ky = Mat::from_fn(n, n, |i, j| k[(i, j)] + if i == j { noise + jitter } else { 0.0 });
            match ky.llt(Side::Lower) {
                Ok(f) => break f,
                Err(_) => match JITTERS.iter().map(|j| j * mean_diag).find(|&j| j > jitter) {
                    Some(next) => jitter = next,
                    None => {
                        return Err(Error::data(format!(
                            "GP kernel matrix of {n} points is not positive definite even with jitter {jitter:e} \
                             (outputscale {}, noise {noise}): the inputs are degenerate",
                            kernel.outputscale
                        )))
                    }
                },
            }
        };
        let residual: Vec<f64> = targets.iter().zip(prior_mean).map(|(y, m)| y - m).collect();
        let mut alpha = Mat::from_fn(n, 1, |i, _| residual[i]);
        factor.solve_in_place_with_conj(faer::Conj::No, alpha.as_mut());
        // faer's factorization and solve leave the vector registers dirty for the scalar loops below.
        clean_upper_state();
        let alpha = (0..n).map(|i| alpha[(i, 0)]).collect();
        let scaled_columns =
            (0..d).map(|c| (0..n).map(|j| inputs[j * d + c] / kernel.lengthscales[c]).collect()).collect();
        Ok(ConditionedGp { inputs: inputs.to_vec(), scaled_columns, kernel, noise, jitter, factor, residual, alpha })
    }

    pub fn len(&self) -> usize {
        self.alpha.len()
    }

    pub fn is_empty(&self) -> bool {
        self.alpha.is_empty()
    }

    pub fn kernel(&self) -> &SeArd {
        &self.kernel
    }

    pub fn noise(&self) -> f64 {
        self.noise
    }

    /// Diagonal jitter the factorization needed (0 when none); callers warn when it is not 0.
    pub fn jitter(&self) -> f64 {
        self.jitter
    }

    /// −log N(y | m, K + σ_n²I), summed over the points (GPyTorch's ExactMarginalLogLikelihood divides by n).
    pub fn neg_log_likelihood(&self) -> f64 {
        let l = self.factor.L();
        let log_det: f64 = (0..self.len()).map(|i| l[(i, i)].ln()).sum::<f64>() * 2.0;
        let fit: f64 = self.residual.iter().zip(&self.alpha).map(|(r, a)| r * a).sum();
        0.5 * (fit + log_det + self.len() as f64 * LN_2PI)
    }

    /// Gradients of [`ConditionedGp::neg_log_likelihood`]. With W = ½(K_y⁻¹ − ααᵀ), the derivative along any
    /// parameter θ of the kernel matrix is Σ_ij W_ij ∂K_ij/∂θ; the jitter counts as a constant. O(n³) for the
    /// explicit inverse.
    pub fn gradients(&self) -> NllGradients {
        let (n, d) = (self.len(), self.kernel.dims());
        let inverse = self.factor.inverse();
        clean_upper_state();
        let w = Mat::from_fn(n, n, |i, j| 0.5 * (inverse[(i, j)] - self.alpha[i] * self.alpha[j]));
        let k = self.kernel.matrix(&self.inputs, &self.inputs);
        let inv_sq: Vec<f64> = self.kernel.lengthscales.iter().map(|l| 1.0 / (l * l)).collect();
        let mut d_inputs = vec![0.0; n * d];
        let mut d_lengthscales = vec![0.0; d];
        let mut d_outputscale = 0.0;
        for i in 0..n {
            let xi = &self.inputs[i * d..(i + 1) * d];
            for j in 0..n {
                let wk = w[(i, j)] * k[(i, j)];
                d_outputscale += wk;
                if i == j {
                    continue;
                }
                let xj = &self.inputs[j * d..(j + 1) * d];
                for c in 0..d {
                    let diff = xi[c] - xj[c];
                    // ∂K_ij/∂ℓ_c = K_ij diff²/ℓ_c³; ∂K_ij/∂x_ic = −K_ij diff/ℓ_c², and K_ji contributes the same.
                    d_lengthscales[c] += wk * diff * diff * inv_sq[c] / self.kernel.lengthscales[c];
                    d_inputs[i * d + c] -= 2.0 * wk * diff * inv_sq[c];
                }
            }
        }
        NllGradients {
            inputs: d_inputs,
            targets: self.alpha.clone(),
            prior_mean: self.alpha.iter().map(|a| -a).collect(),
            lengthscales: d_lengthscales,
            outputscale: d_outputscale / self.kernel.outputscale,
            noise: (0..n).map(|i| w[(i, i)]).sum(),
        }
    }

    /// The posterior at `queries` (rows × dims) with the prior mean there; variances only when asked for.
    pub fn predict(&self, queries: &[f64], prior_mean: &[f64], with_variance: bool) -> Result<Prediction> {
        let d = self.kernel.dims();
        let q = prior_mean.len();
        if queries.len() != q * d {
            return Err(Error::data(format!(
                "GP query: {} input values for {q} prior means; expected {q} rows of {d}",
                queries.len()
            )));
        }
        check_finite("query inputs", queries)?;
        check_finite("query prior mean", prior_mean)?;
        // K(X, queries), N × q column-major: column i is query i against every point, contiguous.
        let n = self.len();
        let mut cross = vec![0.0; n * q];
        let mut scaled_query = vec![0.0; d];
        for (i, column) in cross.chunks_mut(n.max(1)).enumerate().take(q) {
            for (c, x) in scaled_query.iter_mut().enumerate() {
                *x = queries[i * d + c] / self.kernel.lengthscales[c];
            }
            cross_column(&self.scaled_columns, &scaled_query, self.kernel.outputscale, column);
        }
        let mean = (0..q)
            .map(|i| prior_mean[i] + cross[i * n..(i + 1) * n].iter().zip(&self.alpha).map(|(k, a)| k * a).sum::<f64>())
            .collect();
        let variance = if with_variance && n > 0 {
            let mut v = faer::MatMut::from_column_major_slice_mut(&mut cross, n, q);
            self.factor.L().solve_lower_triangular_in_place(v.as_mut());
            clean_upper_state();
            (0..q)
                .map(|i| {
                    let explained: f64 = (0..n).map(|j| v[(j, i)] * v[(j, i)]).sum();
                    (self.kernel.outputscale - explained).max(0.0)
                })
                .collect()
        } else {
            Vec::new()
        };
        Ok(Prediction { mean, variance })
    }
}
