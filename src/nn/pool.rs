//! Max pooling over sets of different sizes (context sets), padded to a common size.

use burn::tensor::{Bool, Tensor};

/// features: [sets, max_size, F], present: [sets, max_size] (true where a row is a real member).
/// Returns [sets, F]: the element-wise maximum of 0 and each set's members. The zero start is what the authors'
/// encoder does (a zero-initialised output maxed with each member); it makes an empty set 0 rather than −∞.
pub fn max_pool_sets(features: Tensor<3>, present: Tensor<2, Bool>) -> Tensor<2> {
    let [sets, size, f] = features.dims();
    let absent = present.bool_not().unsqueeze_dim::<3>(2).expand([sets, size, f]);
    features.mask_fill(absent, 0.0).clamp_min(0.0).max_dim(1).reshape([sets, f])
}
