//! The batched EKF correction with H = \[I₃, 0\] and the innovation log-likelihood log N(m | Hμ, S), the summand
//! of eq. 6.24.

use burn::tensor::Tensor;

use super::linalg::{inverse_3x3, symmetrize};

/// Corrects every sample with its measurement m \[B, 3\]; `r` is diag(R) as \[1, 3, 3\]. Returns the corrected
/// belief and log N(m | Hμ, S) \[B\]. As in the reference filter, the covariance update is (I − K H) Σ followed by
/// symmetrization.
pub fn update(mean: Tensor<2>, cov: Tensor<3>, m: Tensor<2>, r: &Tensor<3>) -> (Tensor<2>, Tensor<3>, Tensor<1>) {
    let [b, n] = mean.dims();
    // H Σ is the first three rows of Σ; it serves both S and the gain.
    let hp = cov.clone().slice([0..b, 0..3, 0..n]);
    let s = hp.clone().slice([0..b, 0..3, 0..3]) + r.clone();
    let (s_inv, det) = inverse_3x3(s);
    let innovation = (m - mean.clone().slice([0..b, 0..3])).unsqueeze_dim::<3>(1);
    // Kᵀ = S⁻¹ H Σ.
    let gain_t = s_inv.clone().matmul(hp.clone());
    let mean = mean + innovation.clone().matmul(gain_t.clone()).reshape([b, n]);
    let cov = symmetrize(cov - hp.swap_dims(1, 2).matmul(gain_t));
    let mahalanobis = innovation.clone().matmul(s_inv).matmul(innovation.swap_dims(1, 2)).reshape([b]);
    let log_likelihood =
        (mahalanobis + det.log().reshape([b])).add_scalar(3.0 * (2.0 * std::f64::consts::PI).ln()).mul_scalar(-0.5);
    (mean, cov, log_likelihood)
}
