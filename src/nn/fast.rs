//! The planning-time inference path of an ensemble MLP: weights in plain f32 buffers, one dense GEMM per layer
//! and member (faer), no autodiff bookkeeping and no allocation per call beyond the caller's scratch. CEM and
//! information-gain planners push hundreds of thousands of rows through a trained model per decision; this path
//! is held to the burn forward pass by a test.

use faer::{Accum, MatMut, MatRef};

use super::activation::Activation;
use super::gemm::faer_product;
use super::params::NamedTensor;
use crate::error::{Error, Result};

#[derive(Clone, Debug)]
struct FastLayer {
    d_in: usize,
    d_out: usize,
    /// [members][in][out], row-major per member.
    weight: Vec<f32>,
    /// [members][out].
    bias: Vec<f32>,
}

#[derive(Clone, Debug)]
pub struct FastEnsembleMlp {
    members: usize,
    layers: Vec<FastLayer>,
    activation: Activation,
}

/// Reusable buffers for [`FastEnsembleMlp::forward`], so a planner thread allocates once.
#[derive(Default)]
pub struct Scratch {
    a: Vec<f32>,
    b: Vec<f32>,
}

impl FastEnsembleMlp {
    /// From (weight [E, in, out], bias [E, 1, out]) pairs in layer order; the activation follows every layer but
    /// the last.
    pub fn from_tensors(tensors: &[&NamedTensor], activation: Activation) -> Result<Self> {
        if tensors.is_empty() || tensors.len() % 2 != 0 {
            return Err(Error::config("ensemble MLP: expected (weight, bias) pairs of tensors"));
        }
        let members = tensors[0].shape.first().copied().unwrap_or(0);
        let mut layers = Vec::new();
        for pair in tensors.chunks(2) {
            let (w, b) = (pair[0], pair[1]);
            let ok = w.shape.len() == 3
                && w.shape[0] == members
                && b.shape == [members, 1, w.shape[2]]
                && w.values.len() == w.shape.iter().product::<usize>()
                && b.values.len() == members * w.shape[2];
            if !ok || members == 0 {
                return Err(Error::config(format!(
                    "ensemble MLP: '{}' {:?} and '{}' {:?} are not a [E, in, out] weight with its [E, 1, out] bias",
                    w.name, w.shape, b.name, b.shape
                )));
            }
            if let Some(prev) = layers.last() {
                let prev: &FastLayer = prev;
                if prev.d_out != w.shape[1] {
                    return Err(Error::config(format!(
                        "ensemble MLP: '{}' takes {} inputs, the layer before gives {}",
                        w.name, w.shape[1], prev.d_out
                    )));
                }
            }
            layers.push(FastLayer {
                d_in: w.shape[1],
                d_out: w.shape[2],
                weight: w.values.clone(),
                bias: b.values.clone(),
            });
        }
        Ok(FastEnsembleMlp { members, layers, activation })
    }

    pub fn members(&self) -> usize {
        self.members
    }

    pub fn d_input(&self) -> usize {
        self.layers[0].d_in
    }

    pub fn d_output(&self) -> usize {
        self.layers[self.layers.len() - 1].d_out
    }

    /// Multiply-adds per input row (for throughput figures).
    pub fn flops_per_row(&self) -> usize {
        self.layers.iter().map(|l| 2 * l.d_in * l.d_out).sum()
    }

    /// Member `member`'s output for `rows` inputs (row-major `rows × d_input`), written to `out`
    /// (`rows × d_output`).
    pub fn forward(&self, member: usize, input: &[f32], rows: usize, out: &mut [f32], scratch: &mut Scratch) {
        debug_assert!(member < self.members);
        debug_assert_eq!(input.len(), rows * self.d_input());
        debug_assert_eq!(out.len(), rows * self.d_output());
        let last = self.layers.len() - 1;
        let Scratch { a, b } = scratch;
        for (k, layer) in self.layers.iter().enumerate() {
            let src: &[f32] = if k == 0 { input } else { &a[..rows * layer.d_in] };
            let dst: &mut [f32] = if k == last {
                &mut out[..]
            } else {
                b.resize(rows * layer.d_out, 0.0);
                &mut b[..rows * layer.d_out]
            };
            let bias = &layer.bias[member * layer.d_out..(member + 1) * layer.d_out];
            for row in dst.chunks_mut(layer.d_out) {
                row.copy_from_slice(bias);
            }
            let w = &layer.weight[member * layer.d_in * layer.d_out..(member + 1) * layer.d_in * layer.d_out];
            faer_product(
                MatMut::from_row_major_slice_mut(dst, rows, layer.d_out),
                Accum::Add,
                MatRef::from_row_major_slice(src, rows, layer.d_in),
                MatRef::from_row_major_slice(w, layer.d_in, layer.d_out),
            );
            if k != last {
                self.activation.apply_in_place(dst);
                std::mem::swap(a, b);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::nn::ensemble::EnsembleMlpConfig;
    use crate::nn::params::ParamSet;
    use crate::nn::tensor::{inference_device, tensor, values};

    #[test]
    fn matches_the_burn_forward_pass() {
        let device = inference_device();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for activation in [Activation::Silu, Activation::Relu, Activation::Tanh] {
            let (members, d_in, d_out, rows) = (3, 5, 4, 37);
            let mlp = EnsembleMlpConfig::new(members, d_in, d_out, 2, 16, activation).init(&device, &mut rng);
            // Random weights of a trained-looking scale, not the small initial ones.
            let mut params = ParamSet::<f32>::from_module(&mlp, |p| p.to_string());
            params.tensors.iter_mut().flat_map(|t| t.values.iter_mut()).for_each(|v| *v = rng.random_range(-1.0..1.0));
            let mlp = params.load_into(mlp, &device).unwrap();
            let input: Vec<f32> = (0..members * rows * d_in).map(|_| rng.random_range(-2.0..2.0)).collect();
            let expected = values(&mlp.forward(tensor(input.clone(), [members, rows, d_in], &device)));

            let refs: Vec<&NamedTensor> = params.tensors.iter().collect();
            let fast = FastEnsembleMlp::from_tensors(&refs, activation).unwrap();
            let mut scratch = Scratch::default();
            for m in 0..members {
                let mut out = vec![0.0; rows * d_out];
                fast.forward(m, &input[m * rows * d_in..(m + 1) * rows * d_in], rows, &mut out, &mut scratch);
                for (i, (a, b)) in out.iter().zip(&expected[m * rows * d_out..]).enumerate() {
                    let tol = 1e-4 * b.abs().max(1.0);
                    assert!((a - b).abs() <= tol, "{activation:?} member {m} value {i}: fast {a} burn {b}");
                }
            }
        }
    }

    #[test]
    fn mismatched_layers_are_rejected() {
        let w = NamedTensor { name: "w".into(), shape: vec![2, 3, 4], values: vec![0.0; 24] };
        let b = NamedTensor { name: "b".into(), shape: vec![2, 1, 5], values: vec![0.0; 10] };
        assert!(FastEnsembleMlp::from_tensors(&[&w, &b], Activation::Relu).is_err());
    }
}
