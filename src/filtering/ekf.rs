//! The extended Kalman filter's two moves: predict (eq. 6.15) and update with one measurement (eq. 6.16).

use std::f64::consts::PI;

use nalgebra::{Cholesky, SMatrix, SVector};

use super::FilterError;

pub type Vector<const N: usize> = SVector<f64, N>;
pub type Mat<const R: usize, const C: usize> = SMatrix<f64, R, C>;

/// A state-space model with additive Gaussian noise, linearized by its Jacobians (eq. 6.9-6.14).
pub trait EkfModel<const N: usize, const M: usize> {
    /// The discrete part of a hybrid state, which the model advances deterministically and the filter carries along
    /// without a covariance (e.g. "the ball has already hit the table"). Continuous-only models use `()`.
    type Mode: Copy + Default + std::fmt::Debug + PartialEq;

    /// g(x) and its Jacobian ∂g/∂x at x; advances `mode` when the step changes it.
    fn predict(&self, x: &Vector<N>, mode: &mut Self::Mode) -> (Vector<N>, Mat<N, N>);

    /// h(x) and its Jacobian ∂h/∂x at x.
    fn measure(&self, x: &Vector<N>) -> (Vector<M>, Mat<M, N>);

    /// Covariance Q of the transition noise added after the step taken from x.
    fn process_noise(&self, x: &Vector<N>) -> Mat<N, N>;

    /// Covariance R of the measurement noise.
    fn measurement_noise(&self) -> Mat<M, M>;

    /// g(x) alone: long open-loop forecasts need no Jacobian, so a model may skip computing it.
    fn predict_mean(&self, x: &Vector<N>, mode: &mut Self::Mode) -> Vector<N> {
        self.predict(x, mode).0
    }

    /// One prediction of mean and covariance, P ← F P Fᵀ + Q. Override when F is sparse enough that a structured
    /// product beats the dense one; the result must equal the dense formula.
    fn predict_belief(&self, belief: &Belief<N, Self::Mode>) -> Belief<N, Self::Mode> {
        let mut mode = belief.mode;
        let (mean, f) = self.predict(&belief.mean, &mut mode);
        let cov = symmetrize(f * belief.cov * f.transpose() + self.process_noise(&belief.mean));
        Belief { mean, cov, mode }
    }
}

/// A Gaussian belief N(mean, cov) over the continuous state, plus the discrete mode it was reached in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Belief<const N: usize, D = ()> {
    pub mean: Vector<N>,
    pub cov: Mat<N, N>,
    pub mode: D,
}

impl<const N: usize, D: Default> Belief<N, D> {
    pub fn new(mean: Vector<N>, cov: Mat<N, N>) -> Self {
        Belief { mean, cov, mode: D::default() }
    }
}

/// Prediction step: mean ← g(mean), P ← F P Fᵀ + Q.
pub fn predict<Mo, const N: usize, const M: usize>(model: &Mo, belief: &Belief<N, Mo::Mode>) -> Belief<N, Mo::Mode>
where
    Mo: EkfModel<N, M>,
{
    model.predict_belief(belief)
}

/// Correction step with measurement `m`. Returns the filtered belief and the innovation log-likelihood
/// log N(m | h(x̂), S), the summand of the marginal likelihood (eq. 6.24).
///
/// The covariance update is (I − K H) P = P − K (H P) followed by symmetrization, not the Joseph form: it is the
/// update the thesis states (6.4.3) and fitted its parameters with, so likelihoods and beliefs match its model; it
/// costs one N×M×N product where the Joseph form needs two extra N×N×N ones; and with the gain from a Cholesky solve
/// of a well-conditioned S, loss of symmetry is the drift that shows in practice, which the symmetrization removes.
/// The Joseph form's guarantee (positive definiteness for any gain) buys nothing here: the gain is the optimal one.
pub fn update<Mo, const N: usize, const M: usize>(
    model: &Mo,
    prior: &Belief<N, Mo::Mode>,
    m: &Vector<M>,
) -> Result<(Belief<N, Mo::Mode>, f64), FilterError>
where
    Mo: EkfModel<N, M>,
{
    if m.iter().any(|v| !v.is_finite()) {
        return Err(FilterError::NonFiniteMeasurement);
    }
    let (predicted, h) = model.measure(&prior.mean);
    let innovation = m - predicted;
    // H P is (P Hᵀ)ᵀ because P is symmetric; it serves both S and the gain.
    let hp = h * prior.cov;
    let s = hp * h.transpose() + model.measurement_noise();
    let chol = Cholesky::new(s).ok_or(FilterError::InnovationNotPositiveDefinite)?;
    // Kᵀ = S⁻¹ H P: solving with the factor avoids forming S⁻¹ and fails loudly when S is not a covariance.
    let gain_t = chol.solve(&hp);
    let mean = prior.mean + gain_t.tr_mul(&innovation);
    let cov = symmetrize(prior.cov - gain_t.tr_mul(&hp));
    let log_likelihood = gaussian_log_density(&chol, &innovation);
    Ok((Belief { mean, cov, mode: prior.mode }, log_likelihood))
}

/// log N(r | 0, S) from the Cholesky factor of S.
fn gaussian_log_density<const M: usize>(chol: &Cholesky<f64, nalgebra::Const<M>>, r: &Vector<M>) -> f64 {
    let mahalanobis = r.dot(&chol.solve(r));
    -0.5 * (mahalanobis + chol.ln_determinant() + M as f64 * (2.0 * PI).ln())
}

fn symmetrize<const N: usize>(p: Mat<N, N>) -> Mat<N, N> {
    (p + p.transpose()) * 0.5
}
