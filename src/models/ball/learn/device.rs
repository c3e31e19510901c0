//! The device the ball EKF learns on (burn's flex CPU backend with autodiff) and f64 tensor constructors.

use burn::tensor::{Bool, DType, Device, Int, Tensor, TensorData};

/// Flex CPU device with autodiff. The filter subtracts nearly equal covariances (P − K H P) and takes logarithms
/// of 3×3 determinants around 1e-15, which f32 cannot resolve, so everything here is f64. burn 0.22 offers two
/// ways: `Device::configure(FloatDType::F64)`, which fixes the default float of the process-wide flex device once
/// and for all (a second call fails), or an explicit dtype at each tensor's creation, which later operations
/// inherit. This module does the latter and leaves the device's default alone: networks elsewhere in the same
/// process train on the same flex device in f32, and whichever module configured it first would otherwise decide
/// the precision of the other.
pub fn training_device() -> Device {
    crate::util::alloc::keep_freed_memory();
    Device::flex().autodiff()
}

/// An f64 tensor from row-major values.
pub fn tensor<const D: usize>(values: Vec<f64>, shape: [usize; D], device: &Device) -> Tensor<D> {
    Tensor::from_data(TensorData::new(values, shape), (device, DType::F64))
}

pub fn zeros<const D: usize>(shape: [usize; D], device: &Device) -> Tensor<D> {
    let n = shape.iter().product();
    tensor(vec![0.0; n], shape, device)
}

pub fn mask<const D: usize>(values: Vec<bool>, shape: [usize; D], device: &Device) -> Tensor<D, Bool> {
    Tensor::from_data(TensorData::new(values, shape), device)
}

/// A per-sample flag repeated along the trailing dimensions of `shape` (masks must match the masked tensor).
pub fn row_mask<const D: usize>(flags: &[bool], shape: [usize; D], device: &Device) -> Tensor<D, Bool> {
    let per_row: usize = shape[1..].iter().product();
    let values = flags.iter().flat_map(|&f| std::iter::repeat_n(f, per_row)).collect();
    mask(values, shape, device)
}

pub fn indices(values: Vec<i64>, device: &Device) -> Tensor<1, Int> {
    let n = values.len();
    Tensor::from_data(TensorData::new(values, [n]), device)
}

/// n×n identity (built from data: `Tensor::eye` would follow the device's default dtype).
pub fn eye(n: usize, device: &Device) -> Tensor<2> {
    tensor((0..n * n).map(|k| if k / n == k % n { 1.0 } else { 0.0 }).collect(), [n, n], device)
}

/// The tensor's values, row-major.
pub fn values<const D: usize>(t: &Tensor<D>) -> Vec<f64> {
    t.to_data().convert::<f64>().try_to_vec::<f64>().expect("f64 tensor data")
}
