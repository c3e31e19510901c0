//! The thesis' positivity map \[x\]⊕ = log(1 + eˣ) + 1e-6 (6.4.3) and its inverse: variances are optimized as
//! unconstrained raw values and stored as variances.

use burn::tensor::Tensor;

/// Smallest variance \[·\]⊕ can produce.
pub const FLOOR: f64 = 1e-6;

/// Variances at (or, from hand-edited files, below) the floor have no finite preimage; Table C.2 lists several
/// at exactly 1.00e-6. They map to the raw value whose image lies this far above the floor, ≈ −27.6.
const MIN_EXCESS: f64 = 1e-12;

pub fn softplus(raw: f64) -> f64 {
    raw.exp().ln_1p() + FLOOR
}

pub fn inverse_softplus(variance: f64) -> f64 {
    (variance - FLOOR).max(MIN_EXCESS).exp_m1().ln()
}

/// Raw values here stay far below the ≈ 709 where eˣ overflows f64, so the plain formula is exact enough and
/// matches [`softplus`] operation for operation.
pub fn softplus_tensor<const D: usize>(raw: Tensor<D>) -> Tensor<D> {
    raw.exp().log1p().add_scalar(FLOOR)
}
