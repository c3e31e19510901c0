//! The thin layer over burn that every learned model stands on: layers written as small burn modules
//! (`XConfig::new(..).init(&device, &mut rng)`), parameters as plain named buffers for our optimizer,
//! checkpoints and the fast inference path, and the f32 tensor helpers they share.
//!
//! Networks train in f32 on burn's flex CPU device with autodiff. Initial weights come from our own seeded
//! RNG, not burn's, so that the same seed gives the same network on every machine and thread count.

pub mod activation;
pub mod adam;
pub mod backprop;
pub mod blocked_conv;
pub mod conv;
pub mod conv_backprop;
pub mod dense;
pub mod ensemble;
pub mod fast;
pub mod features;
pub mod gaussian;
pub mod gemm;
pub mod gru;
pub mod gru_backprop;
pub mod init;
pub mod linear;
pub mod normalizer;
pub mod params;
pub mod pool;
pub mod sparse;
pub mod tensor;

pub use activation::Activation;
pub use adam::{Adam, AdamConfig};
pub use ensemble::{EnsembleLinear, EnsembleLinearConfig, EnsembleMlp, EnsembleMlpConfig};
pub use gaussian::{gaussian_nll, LogVarBounds};
pub use gru::{GruCell, GruCellConfig};
pub use linear::{Linear, LinearConfig, NonNegLinear};
pub use normalizer::Normalizer;
pub use params::{NamedTensor, ParamSet};
pub use pool::max_pool_sets;

#[cfg(test)]
mod tests;
