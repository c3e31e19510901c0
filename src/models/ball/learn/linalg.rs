//! Small batched linear algebra burn lacks: a 3×3 inverse with its determinant, cross-product matrices,
//! diagonal embedding.

use burn::tensor::{Device, Tensor};

use super::device::{eye, indices, tensor};

/// Row-major positions of the two products whose difference is each cofactor, listed for the adjugate
/// (adj = cofactorᵀ): adj_ij = s\[A\] s\[B\] − s\[C\] s\[D\] with indices into the flattened matrix.
const ADJ_A: [i64; 9] = [4, 2, 1, 5, 0, 2, 3, 1, 0];
const ADJ_B: [i64; 9] = [8, 7, 5, 6, 8, 3, 7, 6, 4];
const ADJ_C: [i64; 9] = [5, 1, 2, 3, 2, 0, 4, 0, 1];
const ADJ_D: [i64; 9] = [7, 8, 4, 8, 6, 5, 6, 7, 3];

/// S⁻¹ \[B, 3, 3\] and det S \[B, 1\] by the adjugate formula: one pass of gathers and products, differentiable
/// everywhere det S ≠ 0. For the innovation covariance (symmetric positive definite, condition numbers far
/// below 1e8 here) it agrees with a Cholesky solve to rounding.
pub fn inverse_3x3(s: Tensor<3>) -> (Tensor<3>, Tensor<2>) {
    let b = s.dims()[0];
    let device = s.device();
    let flat = s.reshape([b, 9]);
    let pick = |idx: [i64; 9]| flat.clone().select(1, indices(idx.to_vec(), &device));
    let adj = pick(ADJ_A) * pick(ADJ_B) - pick(ADJ_C) * pick(ADJ_D);
    // det = Σ_j s_0j cof_0j, and cof_0j = adj_j0 sits at flat positions 0, 3, 6 of the adjugate.
    let first_column = adj.clone().select(1, indices(vec![0, 3, 6], &device));
    let det = (flat.slice([0..b, 0..3]) * first_column).sum_dim(1);
    ((adj / det.clone()).reshape([b, 3, 3]), det)
}

/// Constant \[3, 9\] map from a vector u to its cross-product matrix \[u\]ₓ (flattened), \[u\]ₓ x = u × x.
pub fn cross_matrix_map(device: &Device) -> Tensor<2> {
    let mut m = vec![0.0; 27];
    for (k, idx, sign) in [(2, 1, -1.0), (1, 2, 1.0), (2, 3, 1.0), (0, 5, -1.0), (1, 6, -1.0), (0, 7, 1.0)] {
        m[9 * k + idx] = sign;
    }
    tensor(m, [3, 9], device)
}

/// \[u\]ₓ \[B, 3, 3\] for u \[B, 3\].
pub fn cross_matrix(u: Tensor<2>, map: &Tensor<2>) -> Tensor<3> {
    let b = u.dims()[0];
    u.matmul(map.clone()).reshape([b, 3, 3])
}

/// diag(v) \[B, n, n\] for v \[B, n\].
pub fn diag_embed(v: Tensor<2>) -> Tensor<3> {
    let n = v.dims()[1];
    let device = v.device();
    v.unsqueeze_dim::<3>(2) * eye(n, &device).unsqueeze::<3>()
}

/// (P + Pᵀ) / 2: rounding in F P Fᵀ and P − K H P leaves covariances slightly asymmetric.
pub fn symmetrize(p: Tensor<3>) -> Tensor<3> {
    (p.clone() + p.swap_dims(1, 2)).mul_scalar(0.5)
}
