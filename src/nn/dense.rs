//! The planning-time path of single (non-ensemble) networks stored in torch layout: dense layers and a GRU cell
//! over plain f32 buffers, one faer GEMM per layer. Calibration by information gain pushes 10⁵–10⁶ rows per
//! decision through the context model; this path is held to the burn forward pass by tests.

use faer::{Accum, MatMut, MatRef};

use super::activation::{fast_sigmoid as sigmoid, fast_tanh as tanh, Activation};
use super::gemm::faer_product;
use super::params::{NamedTensor, ParamSet};
use crate::error::{Error, Result};

/// y = act(x W + b), W stored [in, out] (the transpose of torch's [out, in]) so a row batch is one GEMM.
#[derive(Clone, Debug)]
pub struct DenseLayer {
    pub d_in: usize,
    pub d_out: usize,
    weight: Vec<f32>,
    bias: Vec<f32>,
    /// ReLU(W) instead of W: the context encoder's monotone variance head (thesis eq. 4.27).
    pub activation: Activation,
}

fn find<'a>(params: &'a ParamSet, name: &str) -> Result<&'a NamedTensor> {
    params.get(name).ok_or_else(|| Error::config(format!("network lacks the tensor '{name}'")))
}

fn transpose(values: &[f32], rows: usize, cols: usize) -> Vec<f32> {
    let mut out = vec![0.0; values.len()];
    MatMut::from_row_major_slice_mut(&mut out, cols, rows)
        .copy_from(MatRef::from_row_major_slice(values, rows, cols).transpose());
    out
}

/// out = bias (per row) + src · w, with `w` row-major [d_in, d_out].
fn affine(src: &[f32], rows: usize, d_in: usize, w: &[f32], bias: &[f32], dst: &mut [f32]) {
    let d_out = bias.len();
    for row in dst.chunks_mut(d_out) {
        row.copy_from_slice(bias);
    }
    faer_product(
        MatMut::from_row_major_slice_mut(dst, rows, d_out),
        Accum::Add,
        MatRef::from_row_major_slice(src, rows, d_in),
        MatRef::from_row_major_slice(w, d_in, d_out),
    );
}

impl DenseLayer {
    /// The layer `prefix` (`prefix.weight` [out, in], `prefix.bias` [out]) of `params`.
    pub fn from_params(params: &ParamSet, prefix: &str, activation: Activation, non_negative: bool) -> Result<Self> {
        let w = find(params, &format!("{prefix}.weight"))?;
        let b = find(params, &format!("{prefix}.bias"))?;
        let [d_out, d_in] = w.shape[..] else {
            return Err(Error::bad_shape(format!("the shape of '{}'", w.name), format!("{:?}", w.shape), "[out, in]"));
        };
        if b.shape != [d_out] || w.values.len() != d_out * d_in || b.values.len() != d_out {
            return Err(Error::config(format!("'{}' {:?} does not fit its weight {:?}", b.name, b.shape, w.shape)));
        }
        let mut weight = transpose(&w.values, d_out, d_in);
        if non_negative {
            weight.iter_mut().for_each(|x| *x = x.max(0.0));
        }
        Ok(DenseLayer { d_in, d_out, weight, bias: b.values.clone(), activation })
    }

    /// `rows` inputs (row-major `rows × d_in`) → `dst` (`rows × d_out`).
    pub fn forward(&self, src: &[f32], rows: usize, dst: &mut [f32]) {
        debug_assert_eq!(src.len(), rows * self.d_in);
        debug_assert_eq!(dst.len(), rows * self.d_out);
        affine(src, rows, self.d_in, &self.weight, &self.bias, dst);
        self.activation.apply_in_place(dst);
    }

    /// Multiply-adds per row, for throughput figures.
    pub fn flops_per_row(&self) -> usize {
        2 * self.d_in * self.d_out
    }
}

/// Buffers a [`DenseStack`] reuses between calls.
#[derive(Default)]
pub struct StackScratch {
    a: Vec<f32>,
    b: Vec<f32>,
}

/// Layers applied in order.
#[derive(Clone, Debug)]
pub struct DenseStack {
    pub layers: Vec<DenseLayer>,
}

impl DenseStack {
    pub fn new(layers: Vec<DenseLayer>) -> Result<Self> {
        if layers.is_empty() {
            return Err(Error::config("a dense stack needs at least one layer"));
        }
        for pair in layers.windows(2) {
            if pair[0].d_out != pair[1].d_in {
                return Err(Error::config(format!(
                    "dense stack: a layer gives {} outputs, the next takes {}",
                    pair[0].d_out, pair[1].d_in
                )));
            }
        }
        Ok(DenseStack { layers })
    }

    pub fn d_in(&self) -> usize {
        self.layers[0].d_in
    }

    pub fn d_out(&self) -> usize {
        self.layers[self.layers.len() - 1].d_out
    }

    /// Resizes `dst` to `rows × d_out` and fills it; `scratch` holds the hidden layers between calls.
    pub fn forward(&self, src: &[f32], rows: usize, dst: &mut Vec<f32>, scratch: &mut StackScratch) {
        let last = self.layers.len() - 1;
        let StackScratch { a, b } = scratch;
        for (k, layer) in self.layers.iter().enumerate() {
            let from: &[f32] = if k == 0 { src } else { &a[..rows * layer.d_in] };
            if k == last {
                dst.resize(rows * layer.d_out, 0.0);
                layer.forward(from, rows, dst);
            } else {
                b.resize(rows * layer.d_out, 0.0);
                layer.forward(from, rows, &mut b[..rows * layer.d_out]);
                std::mem::swap(a, b);
            }
        }
    }

    pub fn flops_per_row(&self) -> usize {
        self.layers.iter().map(DenseLayer::flops_per_row).sum()
    }
}

/// torch.nn.GRUCell's step over plain buffers. Input gates can be split by input block: a rollout's
/// context embedding is the same at every step, so its part of W_ih is applied once per rollout.
#[derive(Clone, Debug)]
pub struct DenseGru {
    pub d_input: usize,
    pub d_hidden: usize,
    /// W_ih as [in, 3H] and W_hh as [H, 3H].
    weight_ih: Vec<f32>,
    weight_hh: Vec<f32>,
    bias_ih: Vec<f32>,
    bias_hh: Vec<f32>,
}

impl DenseGru {
    pub fn from_params(params: &ParamSet, prefix: &str) -> Result<Self> {
        let w_ih = find(params, &format!("{prefix}.weight_ih"))?;
        let w_hh = find(params, &format!("{prefix}.weight_hh"))?;
        let b_ih = find(params, &format!("{prefix}.bias_ih"))?;
        let b_hh = find(params, &format!("{prefix}.bias_hh"))?;
        let [three_h, d_input] = w_ih.shape[..] else {
            let found = format!("{:?}", w_ih.shape);
            return Err(Error::bad_shape(format!("the shape of '{}'", w_ih.name), found, "[3H, in]"));
        };
        let h = three_h / 3;
        let ok = three_h % 3 == 0
            && w_hh.shape == [three_h, h]
            && b_ih.shape == [three_h]
            && b_hh.shape == [three_h]
            && w_ih.values.len() == three_h * d_input
            && w_hh.values.len() == three_h * h
            && b_ih.values.len() == three_h
            && b_hh.values.len() == three_h;
        if !ok {
            return Err(Error::config(format!("GRU '{prefix}': tensor shapes do not form a GRU cell")));
        }
        Ok(DenseGru {
            d_input,
            d_hidden: h,
            weight_ih: transpose(&w_ih.values, three_h, d_input),
            weight_hh: transpose(&w_hh.values, three_h, h),
            bias_ih: b_ih.values.clone(),
            bias_hh: b_hh.values.clone(),
        })
    }

    /// Input gates of the input columns `cols` alone: `x` is `rows × cols.len()`; `with_bias` adds b_ih (give it
    /// to exactly one block). Returns `rows × 3H`.
    pub fn input_gates_block(&self, x: &[f32], rows: usize, cols: std::ops::Range<usize>, with_bias: bool) -> Vec<f32> {
        let g = 3 * self.d_hidden;
        let w = &self.weight_ih[cols.start * g..cols.end * g];
        let zero = vec![0.0; g];
        let bias = if with_bias { &self.bias_ih } else { &zero };
        let mut out = vec![0.0; rows * g];
        affine(x, rows, cols.len(), w, bias, &mut out);
        out
    }

    /// Adds x·W_ih[cols] to `gates` (`rows × 3H`).
    pub fn add_input_gates(&self, x: &[f32], rows: usize, cols: std::ops::Range<usize>, gates: &mut [f32]) {
        let g = 3 * self.d_hidden;
        faer_product(
            MatMut::from_row_major_slice_mut(gates, rows, g),
            Accum::Add,
            MatRef::from_row_major_slice(x, rows, cols.len()),
            MatRef::from_row_major_slice(&self.weight_ih[cols.start * g..cols.end * g], cols.len(), g),
        );
    }

    /// h ← GRU(h) given the complete input gates `gi` (`rows × 3H`); `gh` is scratch.
    pub fn step(&self, gi: &[f32], h: &mut [f32], rows: usize, gh: &mut Vec<f32>) {
        let hd = self.d_hidden;
        let g = 3 * hd;
        gh.resize(rows * g, 0.0);
        affine(h, rows, hd, &self.weight_hh, &self.bias_hh, gh);
        for ((h_row, gi_row), gh_row) in h.chunks_mut(hd).zip(gi.chunks(g)).zip(gh.chunks(g)) {
            for k in 0..hd {
                let r = sigmoid(gi_row[k] + gh_row[k]);
                let z = sigmoid(gi_row[hd + k] + gh_row[hd + k]);
                let n = tanh(gi_row[2 * hd + k] + r * gh_row[2 * hd + k]);
                h_row[k] = (1.0 - z) * n + z * h_row[k];
            }
        }
    }

    pub fn flops_per_row(&self) -> usize {
        2 * 3 * self.d_hidden * (self.d_input + self.d_hidden)
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::nn::tensor::{inference_device, tensor, values};
    use crate::nn::{GruCellConfig, LinearConfig};

    fn randomize(params: &mut ParamSet, rng: &mut ChaCha8Rng) {
        params.tensors.iter_mut().flat_map(|t| t.values.iter_mut()).for_each(|v| *v = rng.random_range(-1.0..1.0));
    }

    fn close(a: &[f32], b: &[f32]) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-4 * (1.0 + y.abs()), "{x} vs {y}");
        }
    }

    #[test]
    fn dense_layer_matches_burn_linear_including_non_negative_weights() {
        let device = inference_device();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let (d_in, d_out, rows) = (6, 5, 9);
        for non_negative in [false, true] {
            let linear = LinearConfig::new(d_in, d_out).init(&device, &mut rng);
            let mut params = ParamSet::<f32>::from_module(&linear, |p| format!("layer.{p}"));
            randomize(&mut params, &mut rng);
            let linear = params.load_into(linear, &device).unwrap();
            let x: Vec<f32> = (0..rows * d_in).map(|_| rng.random_range(-2.0..2.0)).collect();
            let reference = if non_negative {
                let nn = crate::nn::NonNegLinear { weight: linear.weight.clone(), bias: linear.bias.clone() };
                values(&nn.forward(tensor(x.clone(), [rows, d_in], &device)))
            } else {
                values(&linear.forward(tensor(x.clone(), [rows, d_in], &device)))
            };
            let layer = DenseLayer::from_params(&params, "layer", Activation::Identity, non_negative).unwrap();
            let mut out = vec![0.0; rows * d_out];
            layer.forward(&x, rows, &mut out);
            close(&out, &reference);
        }
    }

    #[test]
    fn dense_gru_matches_the_burn_cell_with_split_input_blocks() {
        let device = inference_device();
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let (d_in, hidden, rows) = (7, 5, 11);
        let cell = GruCellConfig::new(d_in, hidden).init(&device, &mut rng);
        let mut params = ParamSet::<f32>::from_module(&cell, |p| format!("gru.{p}"));
        randomize(&mut params, &mut rng);
        let cell = params.load_into(cell, &device).unwrap();
        let x: Vec<f32> = (0..rows * d_in).map(|_| rng.random_range(-2.0..2.0)).collect();
        let h: Vec<f32> = (0..rows * hidden).map(|_| rng.random_range(-1.0..1.0)).collect();
        let reference =
            values(&cell.forward(tensor(x.clone(), [rows, d_in], &device), tensor(h.clone(), [rows, hidden], &device)));
        let gru = DenseGru::from_params(&params, "gru").unwrap();
        let split = 3;
        let left: Vec<f32> = x.chunks(d_in).flat_map(|r| r[..split].to_vec()).collect();
        let right: Vec<f32> = x.chunks(d_in).flat_map(|r| r[split..].to_vec()).collect();
        let mut gates = gru.input_gates_block(&left, rows, 0..split, true);
        gru.add_input_gates(&right, rows, split..d_in, &mut gates);
        let mut state = h.clone();
        gru.step(&gates, &mut state, rows, &mut Vec::new());
        close(&state, &reference);
    }
}
