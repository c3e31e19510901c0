//! f32 tensors on the flex CPU device. Tensors are created with an explicit dtype because the ball EKF
//! trains in f64 on the same process-wide device: the device's default float must not decide a network's
//! precision.

use burn::tensor::{Bool, DType, Device, Tensor, TensorData};

/// The CPU device networks train on (flex backend with autodiff).
pub fn training_device() -> Device {
    crate::util::alloc::keep_freed_memory();
    Device::flex().autodiff()
}

/// The same device without autodiff, for inference that needs no gradients.
pub fn inference_device() -> Device {
    crate::util::alloc::keep_freed_memory();
    Device::flex()
}

/// An f32 tensor from row-major values.
pub fn tensor<const D: usize>(values: Vec<f32>, shape: [usize; D], device: &Device) -> Tensor<D> {
    Tensor::from_data(TensorData::new(values, shape), (device, DType::F32))
}

pub fn zeros<const D: usize>(shape: [usize; D], device: &Device) -> Tensor<D> {
    tensor(vec![0.0; shape.iter().product()], shape, device)
}

pub fn mask<const D: usize>(values: Vec<bool>, shape: [usize; D], device: &Device) -> Tensor<D, Bool> {
    Tensor::from_data(TensorData::new(values, shape), device)
}

/// The tensor's values as f32, row-major.
pub fn values<const D: usize>(t: &Tensor<D>) -> Vec<f32> {
    t.to_data().convert::<f32>().try_to_vec::<f32>().expect("float tensor data converts to f32")
}

/// A scalar tensor's value.
pub fn scalar(t: &Tensor<1>) -> f64 {
    values(t).first().copied().unwrap_or(f32::NAN) as f64
}
