//! Forward and backward passes written out by hand over plain f32 buffers in torch's layout (weight
//! [out, in], bias [out]), for networks whose training step is many small tensors: there burn's autodiff spends
//! more on bookkeeping, copies and fresh allocations than on arithmetic. A model that trains here keeps burn as
//! its reference: a test holds every gradient to burn's.

use std::borrow::Cow;

use faer::{Accum, MatMut, MatRef, Par};

use super::params::ParamSet;
use crate::error::{Error, Result};

/// Below this many multiply-adds a GEMM stays on one thread: splitting costs more than it saves.
const PARALLEL_WORK: usize = 1 << 19;

/// dst (m × n) = [dst +] a (m × k) · b (k × n). Large products are split over the rayon pool, by rows of
/// `dst`, or by columns where `dst` is at least four times wider than tall: each piece packs the whole of the
/// operand the pieces share, and there `a` is much the smaller one (a convolution's weight gradient against
/// its im2col matrix). Every element is still summed by one thread in one order, so the bytes do not depend
/// on the split.
pub fn matmul(dst: MatMut<'_, f32>, accum: Accum, a: MatRef<'_, f32>, b: MatRef<'_, f32>) {
    let pieces = if dst.nrows() * dst.ncols() * a.ncols() >= PARALLEL_WORK { rayon::current_num_threads() } else { 1 };
    if dst.ncols() >= 4 * dst.nrows() {
        split_cols(dst, accum, a, b, pieces);
    } else {
        split_rows(dst, accum, a, b, pieces);
    }
}

fn split_rows(dst: MatMut<'_, f32>, accum: Accum, a: MatRef<'_, f32>, b: MatRef<'_, f32>, pieces: usize) {
    let m = dst.nrows();
    if pieces <= 1 || m < 16 {
        faer::linalg::matmul::matmul(dst, accum, a, b, 1.0f32, Par::Seq);
        return;
    }
    let half = pieces / 2;
    let mid = m * half / pieces;
    let (top, bottom) = dst.split_at_row_mut(mid);
    let (a_top, a_bottom) = a.split_at_row(mid);
    rayon::join(|| split_rows(top, accum, a_top, b, half), || split_rows(bottom, accum, a_bottom, b, pieces - half));
}

fn split_cols(dst: MatMut<'_, f32>, accum: Accum, a: MatRef<'_, f32>, b: MatRef<'_, f32>, pieces: usize) {
    let n = dst.ncols();
    if pieces <= 1 || n < 16 {
        faer::linalg::matmul::matmul(dst, accum, a, b, 1.0f32, Par::Seq);
        return;
    }
    let half = pieces / 2;
    let mid = n * half / pieces;
    let (left, right) = dst.split_at_col_mut(mid);
    let (b_left, b_right) = b.split_at_col(mid);
    rayon::join(|| split_cols(left, accum, a, b_left, half), || split_cols(right, accum, a, b_right, pieces - half));
}

/// Row-major `rows × cols` view of a buffer.
pub fn view(values: &[f32], rows: usize, cols: usize) -> MatRef<'_, f32> {
    MatRef::from_row_major_slice(values, rows, cols)
}

pub fn view_mut(values: &mut [f32], rows: usize, cols: usize) -> MatMut<'_, f32> {
    MatMut::from_row_major_slice_mut(values, rows, cols)
}

/// The index of a named tensor of `params` with the expected shape.
pub fn tensor_index(params: &ParamSet, name: &str, shape: &[usize]) -> Result<usize> {
    let index = params
        .tensors
        .iter()
        .position(|t| t.name == name)
        .ok_or_else(|| Error::config(format!("network lacks the tensor '{name}'")))?;
    let t = &params.tensors[index];
    if t.shape != shape || t.values.len() != shape.iter().product::<usize>() {
        return Err(Error::bad_shape(format!("the shape of '{name}'"), format!("{:?}", t.shape), format!("{shape:?}")));
    }
    Ok(index)
}

/// Gradients shaped like a parameter set, in its order.
pub fn zero_gradients(params: &ParamSet) -> Vec<Vec<f32>> {
    params.tensors.iter().map(|t| vec![0.0; t.values.len()]).collect()
}

/// y = x Wᵀ + b over row batches, with W's positive part instead of W for the monotone layers (eq. 4.27).
pub struct Dense<'a> {
    pub d_in: usize,
    pub d_out: usize,
    /// The weight that acts: the raw one, or its positive part.
    weight: Cow<'a, [f32]>,
    bias: &'a [f32],
    weight_index: usize,
    bias_index: usize,
    non_negative: bool,
}

impl<'a> Dense<'a> {
    /// The layer `prefix` (`prefix.weight` [d_out, d_in], `prefix.bias` [d_out]) of `params`.
    pub fn new(params: &'a ParamSet, prefix: &str, d_in: usize, d_out: usize, non_negative: bool) -> Result<Self> {
        let weight_index = tensor_index(params, &format!("{prefix}.weight"), &[d_out, d_in])?;
        let bias_index = tensor_index(params, &format!("{prefix}.bias"), &[d_out])?;
        let raw = &params.tensors[weight_index].values;
        let weight = if non_negative {
            Cow::Owned(raw.iter().map(|w| w.max(0.0)).collect())
        } else {
            Cow::Borrowed(raw.as_slice())
        };
        let bias = &params.tensors[bias_index].values;
        Ok(Dense { d_in, d_out, weight, bias, weight_index, bias_index, non_negative })
    }

    /// `rows` inputs → `rows × d_out` outputs.
    pub fn forward(&self, x: &[f32], rows: usize) -> Vec<f32> {
        debug_assert_eq!(x.len(), rows * self.d_in);
        let mut y = self.bias.repeat(rows);
        matmul(
            view_mut(&mut y, rows, self.d_out),
            Accum::Add,
            view(x, rows, self.d_in),
            view(&self.weight, self.d_out, self.d_in).transpose(),
        );
        y
    }

    /// Adds this layer's weight and bias gradients for output gradients `dy` at inputs `x` to `grads`, and
    /// returns the input gradients when asked for.
    pub fn backward(&self, x: &[f32], dy: &[f32], rows: usize, grads: &mut [Vec<f32>], want_dx: bool) -> Vec<f32> {
        debug_assert_eq!(dy.len(), rows * self.d_out);
        let (o, i) = (self.d_out, self.d_in);
        let weight_grad = &mut grads[self.weight_index];
        if self.non_negative {
            // Only the positive raw weights act, so only they receive gradient (burn's ReLU backward).
            let mut acting = vec![0.0; o * i];
            matmul(view_mut(&mut acting, o, i), Accum::Replace, view(dy, rows, o).transpose(), view(x, rows, i));
            for ((g, a), w) in weight_grad.iter_mut().zip(&acting).zip(self.weight.iter()) {
                if *w > 0.0 {
                    *g += a;
                }
            }
        } else {
            matmul(view_mut(weight_grad, o, i), Accum::Add, view(dy, rows, o).transpose(), view(x, rows, i));
        }
        add_column_sums(&mut grads[self.bias_index], dy);
        if !want_dx {
            return Vec::new();
        }
        self.backward_input(dy, rows)
    }
}

impl Dense<'_> {
    /// The input gradients for output gradients `dy`, leaving the weights' gradients alone: for a network held
    /// fixed while something upstream of it learns (SAC's critics under the actor's loss).
    pub fn backward_input(&self, dy: &[f32], rows: usize) -> Vec<f32> {
        debug_assert_eq!(dy.len(), rows * self.d_out);
        let (o, i) = (self.d_out, self.d_in);
        let mut dx = vec![0.0; rows * i];
        matmul(view_mut(&mut dx, rows, i), Accum::Replace, view(dy, rows, o), view(&self.weight, o, i));
        dx
    }
}

/// sums[j] += Σ_rows m[row, j] for a row-major matrix with `sums.len()` columns.
pub fn add_column_sums(sums: &mut [f32], m: &[f32]) {
    for row in m.chunks(sums.len()) {
        for (s, x) in sums.iter_mut().zip(row) {
            *s += x;
        }
    }
}

/// Linear → ReLU → Linear; the caller applies and differentiates what follows the second layer.
pub struct TwoLayer<'a> {
    pub first: Dense<'a>,
    pub second: Dense<'a>,
}

/// What a [`TwoLayer`] forward pass keeps for its backward pass.
pub struct TwoLayerTape {
    /// The ReLU'd hidden layer.
    hidden: Vec<f32>,
}

impl<'a> TwoLayer<'a> {
    pub fn new(
        params: &'a ParamSet,
        prefix: &str,
        d_in: usize,
        hidden: usize,
        d_out: usize,
        non_negative: bool,
    ) -> Result<Self> {
        Ok(TwoLayer {
            first: Dense::new(params, &format!("{prefix}.first"), d_in, hidden, non_negative)?,
            second: Dense::new(params, &format!("{prefix}.second"), hidden, d_out, non_negative)?,
        })
    }

    /// The second layer's output (before any activation of the caller's) and the tape.
    pub fn forward(&self, x: &[f32], rows: usize) -> (Vec<f32>, TwoLayerTape) {
        let mut hidden = self.first.forward(x, rows);
        hidden.iter_mut().for_each(|h| *h = h.max(0.0));
        let out = self.second.forward(&hidden, rows);
        (out, TwoLayerTape { hidden })
    }

    pub fn backward(
        &self,
        x: &[f32],
        tape: &TwoLayerTape,
        d_out: &[f32],
        rows: usize,
        grads: &mut [Vec<f32>],
        want_dx: bool,
    ) -> Vec<f32> {
        let mut d_hidden = self.second.backward(&tape.hidden, d_out, rows, grads, true);
        for (d, h) in d_hidden.iter_mut().zip(&tape.hidden) {
            if *h <= 0.0 {
                *d = 0.0;
            }
        }
        self.first.backward(x, &d_hidden, rows, grads, want_dx)
    }
}

/// dst[i] += src[i].
pub fn add_into(dst: &mut [f32], src: &[f32]) {
    dst.iter_mut().zip(src).for_each(|(a, b)| *a += b);
}

/// In place: ReLU, keeping the output as its own derivative mask.
pub fn relu_in_place(xs: &mut [f32]) {
    xs.iter_mut().for_each(|x| *x = x.max(0.0));
}

/// d ← d · 1[y > 0] for a ReLU output y.
pub fn relu_backward(d: &mut [f32], y: &[f32]) {
    for (d, y) in d.iter_mut().zip(y) {
        if *y <= 0.0 {
            *d = 0.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn split_matmul_gives_the_bytes_of_one_thread() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let (m, k, n) = (301, 97, 203);
        let a: Vec<f32> = (0..m * k).map(|_| rng.random_range(-1.0..1.0)).collect();
        let b: Vec<f32> = (0..k * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut one = vec![0.5; m * n];
        faer::linalg::matmul::matmul(
            view_mut(&mut one, m, n),
            Accum::Add,
            view(&a, m, k),
            view(&b, k, n),
            1.0,
            Par::Seq,
        );
        for pieces in [2, 3, 7] {
            let mut split = vec![0.5; m * n];
            split_rows(view_mut(&mut split, m, n), Accum::Add, view(&a, m, k), view(&b, k, n), pieces);
            assert_eq!(split, one, "{pieces} pieces of rows");
            let mut split = vec![0.5; m * n];
            split_cols(view_mut(&mut split, m, n), Accum::Add, view(&a, m, k), view(&b, k, n), pieces);
            assert_eq!(split, one, "{pieces} pieces of columns");
        }
    }
}
