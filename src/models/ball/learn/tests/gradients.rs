//! burn's autodiff gradients of the batched loss against central differences of the nalgebra loss.
