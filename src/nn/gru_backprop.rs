//! A GRU cell (torch.nn.GRUCell's equations, gates stacked r, z, n) written out by hand over plain f32 buffers
//! for training through time: a step forward with its tape, a step back, and the weight gradients taken once
//! over all steps (one W_hh GEMM over every step's hidden-gate gradients rather than one per step). Its input is
//! `inputs` blocks of the hidden width side by side (the context model's context, action and terrain
//! embeddings), so each block's gates and gradients are one GEMM against its columns of W_ih.
//!
//! The models that train through it keep burn's `GruCell` (`nn::gru`) as their reference: the context model's
//! test holds every gradient to burn's autodiff.

use std::mem::MaybeUninit;

use faer::Accum;
use rayon::prelude::*;

use super::activation::{fast_sigmoid as sigmoid, fast_tanh as tanh};
use super::backprop::{
    add_column_sums, affine, assume_written, block_rows, matmul, new_product, product_from, slots, tensor_index,
    unwritten, view, view_mut,
};
use super::gemm::Finish;
use super::params::ParamSet;
use crate::error::Result;
use crate::util::wide::widest_fn;

/// The cell's weights as views of a parameter set (torch's layout: W_ih [3E, blocks·E], W_hh [3E, E]).
pub struct Gru<'a> {
    e: usize,
    inputs: usize,
    weight_ih: &'a [f32],
    weight_hh: &'a [f32],
    bias_ih: &'a [f32],
    bias_hh: &'a [f32],
    index: [usize; 4],
}

/// What one GRU step keeps for its backward pass (rows × E each).
pub struct GruTape {
    r: Vec<f32>,
    z: Vec<f32>,
    n: Vec<f32>,
    /// The hidden gates W_hh h + b_hh (rows × 3E): the backward pass needs their third block, W_hn h + b_hn,
    /// which the reset gate scales. Keeping the product spares a pass that copied it, at 2E more values per
    /// row held until the step back (a tape holds 6E per row instead of 4E).
    gh: Vec<f32>,
}

impl<'a> Gru<'a> {
    /// The cell `prefix` of `params` with hidden width `e` and `inputs` input blocks of width `e`.
    pub fn new(params: &'a ParamSet, prefix: &str, e: usize, inputs: usize) -> Result<Self> {
        let ix = [
            tensor_index(params, &format!("{prefix}.weight_ih"), &[3 * e, inputs * e])?,
            tensor_index(params, &format!("{prefix}.weight_hh"), &[3 * e, e])?,
            tensor_index(params, &format!("{prefix}.bias_ih"), &[3 * e])?,
            tensor_index(params, &format!("{prefix}.bias_hh"), &[3 * e])?,
        ];
        let v = |k: usize| params.tensors[ix[k]].values.as_slice();
        Ok(Gru { e, inputs, weight_ih: v(0), weight_hh: v(1), bias_ih: v(2), bias_hh: v(3), index: ix })
    }

    /// Where b_ih's gradient goes: the column sums of the input-gate gradients.
    pub fn bias_ih_index(&self) -> usize {
        self.index[2]
    }

    /// b_ih + x · W_ih[:, block]ᵀ (rows × 3E): the input gates of block `block`, with the bias.
    pub fn input_gates(&self, x: &[f32], rows: usize, block: usize) -> Vec<f32> {
        let (e, g) = (self.e, 3 * self.e);
        let weight = view(self.weight_ih, g, self.inputs * e).subcols(block * e, e).transpose();
        affine(view(x, rows, e), weight, self.bias_ih, Finish::Store)
    }

    /// gates + x · W_ih[:, block]ᵀ as a new buffer (rows × 3E), leaving `gates` as they are.
    pub fn input_gates_from(&self, gates: &[f32], x: &[f32], rows: usize, block: usize) -> Vec<f32> {
        let (e, g) = (self.e, 3 * self.e);
        let weight = view(self.weight_ih, g, self.inputs * e).subcols(block * e, e).transpose();
        product_from(gates, view(x, rows, e), weight)
    }

    /// gates (rows × 3E) += x · W_ih[:, block]ᵀ for input block `block` (0 context, 1 action, 2 terrain).
    pub fn add_input_gates(&self, x: &[f32], rows: usize, block: usize, gates: &mut [f32]) {
        let (e, g) = (self.e, 3 * self.e);
        matmul(
            view_mut(gates, rows, g),
            Accum::Add,
            view(x, rows, e),
            view(self.weight_ih, g, self.inputs * e).subcols(block * e, e).transpose(),
        );
    }

    /// The input-gate gradients `d_gates` (rows × 3E) of block `block`'s input `x`, a ReLU's output: adds to
    /// W_ih's gradient and returns the gradient at the ReLU's input (zero where x ≤ 0).
    pub fn input_backward_through_relu(
        &self,
        x: &[f32],
        d_gates: &[f32],
        rows: usize,
        block: usize,
        grads: &mut [Vec<f32>],
    ) -> Vec<f32> {
        let (e, g, width) = (self.e, 3 * self.e, self.inputs * self.e);
        matmul(
            view_mut(&mut grads[self.index[0]], g, width).subcols_mut(block * e, e),
            Accum::Add,
            view(d_gates, rows, g).transpose(),
            view(x, rows, e),
        );
        let weight = view(self.weight_ih, g, width).subcols(block * e, e);
        new_product(view(d_gates, rows, g), weight, Finish::ReluGrad(view(x, rows, e)))
    }

    /// h ← GRU(h) from complete input gates `gi` (rows × 3E, b_ih included).
    pub fn step(&self, gi: &[f32], h: &mut [f32], rows: usize) -> GruTape {
        let (e, g) = (self.e, 3 * self.e);
        let gh = affine(view(h, rows, e), view(self.weight_hh, g, e).transpose(), self.bias_hh, Finish::Store);
        let size = rows * e;
        // The blocks below write every slot of the tapes only when the inputs have these sizes.
        assert!(h.len() == size && gi.len() == rows * g, "GRU step: h or gi does not hold {rows} rows");
        let (mut r, mut z, mut n) = (unwritten(size), unwritten(size), unwritten(size));
        let (he, hg) = (block_rows(rows, e) * e, block_rows(rows, e) * g);
        h.par_chunks_mut(he)
            .zip(slots(&mut r, size).par_chunks_mut(he).zip(slots(&mut z, size).par_chunks_mut(he)))
            .zip(slots(&mut n, size).par_chunks_mut(he))
            .zip(gi.par_chunks(hg).zip(gh.par_chunks(hg)))
            .for_each(|(((h, (r, z)), n), (gi, gh))| gates_forward(h, r, z, n, gi, gh, e));
        // SAFETY: the blocks of h cover all `size` values, and each wrote its rows of all three tapes.
        unsafe {
            for buffer in [&mut r, &mut z, &mut n] {
                assume_written(buffer, size);
            }
        }
        GruTape { r, z, n, gh }
    }

    /// Backward of one step: from dh' (rows × E) and the previous state, dh and the input-gate gradients
    /// (returned, in that order), and the hidden-gate gradients written to every slot of `d_gh` (for one W_hh
    /// GEMM over all steps later, so the caller's buffer for all steps is never zeroed).
    pub fn step_backward(
        &self,
        tape: &GruTape,
        h_prev: &[f32],
        dh_next: &[f32],
        rows: usize,
        d_gh: &mut [MaybeUninit<f32>],
    ) -> (Vec<f32>, Vec<f32>) {
        let (e, g) = (self.e, 3 * self.e);
        let size = rows * e;
        let sizes = [tape.r.len(), tape.z.len(), tape.n.len(), h_prev.len(), dh_next.len()];
        let gate_sizes = [tape.gh.len(), d_gh.len()];
        assert!(
            sizes.iter().all(|&n| n == size) && gate_sizes.iter().all(|&n| n == rows * g),
            "GRU step back: buffers of another size"
        );
        let (mut dh, mut d_gi) = (unwritten(size), unwritten(rows * g));
        let (he, hg) = (block_rows(rows, e) * e, block_rows(rows, e) * g);
        slots(&mut dh, size)
            .par_chunks_mut(he)
            .zip(slots(&mut d_gi, rows * g).par_chunks_mut(hg).zip(d_gh.par_chunks_mut(hg)))
            .zip(tape.r.par_chunks(he).zip(tape.z.par_chunks(he)))
            .zip(tape.n.par_chunks(he).zip(tape.gh.par_chunks(hg)))
            .zip(h_prev.par_chunks(he).zip(dh_next.par_chunks(he)))
            .for_each(|((((dh, (d_gi, d_gh)), (r, z)), (n, gh)), (h_prev, dh_next))| {
                gates_backward(GateGradients { dh, d_gi, d_gh }, GateTape { r, z, n, gh }, h_prev, dh_next, e)
            });
        // SAFETY: the row blocks cover all rows, and each row wrote its E values of dh and 3E of d_gi and d_gh.
        let d_gh = unsafe {
            assume_written(&mut dh, size);
            assume_written(&mut d_gi, rows * g);
            std::slice::from_raw_parts(d_gh.as_ptr().cast::<f32>(), d_gh.len())
        };
        matmul(view_mut(&mut dh, rows, e), Accum::Add, view(d_gh, rows, g), view(self.weight_hh, g, e));
        (dh, d_gi)
    }

    /// W_hh's and b_hh's gradients from all steps' hidden-gate gradients and previous states at once.
    pub fn hidden_weight_backward(&self, h_prev: &[f32], d_gh: &[f32], rows: usize, grads: &mut [Vec<f32>]) {
        let (e, g) = (self.e, 3 * self.e);
        matmul(
            view_mut(&mut grads[self.index[1]], g, e),
            Accum::Add,
            view(d_gh, rows, g).transpose(),
            view(h_prev, rows, e),
        );
        add_column_sums(&mut grads[self.index[3]], d_gh);
    }
}

widest_fn! {
    /// Rows of a step forward: the gates from their input and hidden parts, the new state over the old.
    fn gates_forward(
        h: &mut [f32],
        r: &mut [MaybeUninit<f32>],
        z: &mut [MaybeUninit<f32>],
        n: &mut [MaybeUninit<f32>],
        gi: &[f32],
        gh: &[f32],
        e: usize,
    ) {
        let g = 3 * e;
        for row in 0..h.len() / e {
            let (gi, gh) = (&gi[row * g..(row + 1) * g], &gh[row * g..(row + 1) * g]);
            for k in 0..e {
                let at = row * e + k;
                let reset = sigmoid(gi[k] + gh[k]);
                let update = sigmoid(gi[e + k] + gh[e + k]);
                let new = tanh(gi[2 * e + k] + reset * gh[2 * e + k]);
                r[at].write(reset);
                z[at].write(update);
                n[at].write(new);
                h[at] = (1.0 - update) * new + update * h[at];
            }
        }
    }
}

/// A block of rows' outputs of a step back.
struct GateGradients<'a> {
    dh: &'a mut [MaybeUninit<f32>],
    d_gi: &'a mut [MaybeUninit<f32>],
    d_gh: &'a mut [MaybeUninit<f32>],
}

/// A block of rows of a step's tape.
struct GateTape<'a> {
    r: &'a [f32],
    z: &'a [f32],
    n: &'a [f32],
    gh: &'a [f32],
}

widest_fn! {
    /// Rows of a step back: dh without its W_hh term, and the input- and hidden-gate gradients.
    fn gates_backward(out: GateGradients<'_>, tape: GateTape<'_>, h_prev: &[f32], dh_next: &[f32], e: usize) {
        let g = 3 * e;
        let GateGradients { dh, d_gi, d_gh } = out;
        for row in 0..dh.len() / e {
            let (d_gi, d_gh) = (&mut d_gi[row * g..(row + 1) * g], &mut d_gh[row * g..(row + 1) * g]);
            let hn = &tape.gh[row * g + 2 * e..(row + 1) * g];
            for k in 0..e {
                let at = row * e + k;
                let (r, z, n, hn) = (tape.r[at], tape.z[at], tape.n[at], hn[k]);
                let d = dh_next[at];
                let dn = d * (1.0 - z) * (1.0 - n * n);
                let dz = d * (h_prev[at] - n) * z * (1.0 - z);
                let dr = dn * hn * r * (1.0 - r);
                d_gi[k].write(dr);
                d_gi[e + k].write(dz);
                d_gi[2 * e + k].write(dn);
                d_gh[k].write(dr);
                d_gh[e + k].write(dz);
                d_gh[2 * e + k].write(dn * r);
                dh[at].write(d * z);
            }
        }
    }
}
