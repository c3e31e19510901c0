//! Strided, unpadded 2-d convolutions and their transposes written out over flat f32 buffers, with their
//! backward passes, for training steps where burn's autodiff convolutions cost more than the arithmetic (DLGPD's
//! image VAE). Activations are channels-last (NHWC: image, row, column, channel), so that one kernel row of one
//! output position reads `kernel × channels` consecutive floats; every product is then one faer GEMM between an
//! im2col matrix and the weight, whose layout is permuted once per call. Weights and gradients stay in torch's
//! layout (Conv2d [out, in, k, k], ConvTranspose2d [in, out, k, k]), so checkpoints do not change.
//!
//! A convolution and its transpose are adjoints over the same pair of grids: the "big" grid (a convolution's
//! input, a transposed convolution's output) and the "small" one, with big side ≥ (small side − 1) · stride +
//! kernel. Both torch layouts are [small channels, big channels, k, k], so one permuted weight
//! W̃ [small channels, k · k · big channels] serves both directions:
//!
//! - convolution: y_small = im2col(x_big) · W̃ᵀ; its input gradient is col2im(dy · W̃);
//! - transposed convolution: y_big = col2im(x_small · W̃); its input gradient is im2col(dy) · W̃ᵀ.
//!
//! The images are taken in chunks whose im2col buffer stays in a core's cache. A layer with enough chunks runs
//! them as parallel tasks of whole chunks, each on one thread, and adds the tasks' weight gradients in order;
//! one with few (a 1 × 1 grid, a small batch) runs them in turn, splitting each chunk's gathers by image and
//! its GEMMs over the pool. Which of the two, and the chunk size, depend on the layer and the batch alone, and each
//! image is gathered and scattered by one thread: the bytes do not depend on the thread count.

use faer::{Accum, MatMut, MatRef};
use rayon::prelude::*;

use std::mem::MaybeUninit;
use std::sync::OnceLock;

use super::backprop::{
    add_column_sums, add_into, assume_written, fill_with_row, matmul, relu_backward, relu_in_place, slots,
    tensor_index, unwritten, view, view_mut,
};
use super::gemm::{packed_offset, Finish, Kernel, PackedRight, Start, PACKED_PANEL};
use super::params::ParamSet;
use crate::error::{Error, Result};
use crate::util::wide::widest_fn;

/// The im2col buffer of one chunk of images stays near this size, so that the GEMM reads it back from the
/// core's own cache: 16 MiB chunks made DLGPD's batch-256 step 6-8 % slower at one thread.
const COLUMN_BYTES: usize = 256 << 10;
/// ... unless a chunk would then have fewer GEMM rows than this (a 1 × 1 grid has one row per image).
const MIN_ROWS: usize = 256;
/// Layers with at least this many chunks run their chunks as parallel tasks, each on one thread; with fewer,
/// the chunks run in turn and each one's gathers and GEMMs are split over the pool.
const MIN_CHUNKS_FOR_TASKS: usize = 4;
/// The tasks a layer's chunks are grouped into: each task sums its own weight gradient, and the tasks' sums
/// are added in order, so a layer keeps this many partial gradients at most.
const TASKS: usize = 16;

/// Which way a layer maps between its two grids.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// Conv2d: big grid in, small grid out.
    Down,
    /// ConvTranspose2d: small grid in, big grid out.
    Up,
}

/// The input gradient a layer's backward pass returns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputGradient {
    /// None (an empty vector).
    Skip,
    /// The gradient at the layer's input.
    AtInput,
    /// The input being a ReLU's output, the gradient at that ReLU's input: zero where the input is not
    /// positive. Masked chunk by chunk while the chunk and its input are in cache; the layer below would mask
    /// it in a pass of its own, reading its output back from memory.
    BelowRelu,
}

/// The two square grids a layer maps between.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Grids {
    pub big_side: usize,
    pub big_channels: usize,
    pub small_side: usize,
    pub small_channels: usize,
    pub kernel: usize,
    pub stride: usize,
}

impl Grids {
    /// A convolution of `side`² × `channels_in` input without padding.
    pub fn conv(side: usize, channels_in: usize, channels_out: usize, kernel: usize, stride: usize) -> Grids {
        let small_side = if side >= kernel && stride > 0 { (side - kernel) / stride + 1 } else { 0 };
        Grids { big_side: side, big_channels: channels_in, small_side, small_channels: channels_out, kernel, stride }
    }

    /// A transposed convolution of `side`² × `channels_in` input without padding: output side (side − 1)·s + k.
    pub fn conv_transpose(side: usize, channels_in: usize, channels_out: usize, kernel: usize, stride: usize) -> Grids {
        let big_side = side.saturating_sub(1) * stride + kernel;
        Grids { big_side, big_channels: channels_out, small_side: side, small_channels: channels_in, kernel, stride }
    }

    pub fn big_len(&self) -> usize {
        self.big_side * self.big_side * self.big_channels
    }

    pub fn small_len(&self) -> usize {
        self.small_side * self.small_side * self.small_channels
    }

    fn positions(&self) -> usize {
        self.small_side * self.small_side
    }

    /// Columns of the im2col matrix: one kernel window over the big grid's channels.
    fn window(&self) -> usize {
        self.kernel * self.kernel * self.big_channels
    }

    fn chunk_images(&self) -> usize {
        let by_bytes = COLUMN_BYTES / (self.positions() * self.window() * 4).max(1);
        by_bytes.max(MIN_ROWS.div_ceil(self.positions().max(1))).max(1)
    }

    /// The images of one window gathered into `col` (positions × window).
    fn gather_image(&self, big: &[f32], col: &mut [f32]) {
        let span = self.kernel * self.big_channels;
        for (col_at, big_at) in self.window_rows() {
            col[col_at..col_at + span].copy_from_slice(&big[big_at..big_at + span]);
        }
    }

    /// Where the pieces of one image's im2col rows lie: for each output position and kernel row, the offset of
    /// its `kernel · big channels` values in the rows and in the big grid.
    #[inline(always)]
    fn window_rows(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        let (k, s, c, side) = (self.kernel, self.stride, self.big_channels, self.big_side);
        (0..self.positions()).flat_map(move |position| {
            let (y, x) = (position / self.small_side, position % self.small_side);
            (0..k).map(move |ky| ((position * k + ky) * k * c, ((y * s + ky) * side + x * s) * c))
        })
    }

    /// Whether a kernel row's values are whole panels of a packed right operand, so that windows can be
    /// gathered straight into the kernel's packed layout.
    fn windows_pack(&self) -> bool {
        (self.kernel * self.big_channels).is_multiple_of(PACKED_PANEL)
    }

    /// im2col of `images` big-grid images, as [`Grids::gather`] lays it out but written where the GEMM kernel's
    /// packing would put it ([`packed_offset`]), on this thread: the weight gradient then reads it without
    /// copying it again. Only where [`Grids::windows_pack`].
    fn gather_packed(&self, big: &[f32], packed: &mut [f32]) {
        let (window, span) = (self.window(), self.kernel * self.big_channels);
        let rows = packed.len() / window;
        for (image, big) in big.chunks(self.big_len()).enumerate() {
            for (col_at, big_at) in self.window_rows() {
                let (row, first_col) = (image * self.positions() + col_at / window, col_at % window);
                for piece in (0..span).step_by(PACKED_PANEL) {
                    let to = packed_offset(rows, window, row, first_col + piece);
                    packed[to..to + PACKED_PANEL].copy_from_slice(&big[big_at + piece..][..PACKED_PANEL]);
                }
            }
        }
    }

    /// The adjoint of [`Grids::gather_image`] for one image.
    fn scatter_add_image(&self, col: &[f32], big: &mut [f32]) {
        scatter_add_image_widest(self, col, big);
    }

    /// im2col of `images` big-grid images: row (image, y, x) of `col` holds the window whose corner is at
    /// (y · stride, x · stride), ordered (ky, kx, channel). Split over the pool by image when `split`.
    fn gather(&self, big: &[f32], col: &mut [f32], split: bool) {
        let per_image = self.positions() * self.window();
        if split {
            col.par_chunks_mut(per_image)
                .zip(big.par_chunks(self.big_len()))
                .for_each(|(c, b)| self.gather_image(b, c));
        } else {
            col.chunks_mut(per_image).zip(big.chunks(self.big_len())).for_each(|(c, b)| self.gather_image(b, c));
        }
    }

    /// The adjoint of [`Grids::gather`]: adds every window of `col` back onto the big grid.
    fn scatter_add(&self, col: &[f32], big: &mut [f32], split: bool) {
        let per_image = self.positions() * self.window();
        if split {
            big.par_chunks_mut(self.big_len())
                .zip(col.par_chunks(per_image))
                .for_each(|(b, c)| self.scatter_add_image(c, b));
        } else {
            big.chunks_mut(self.big_len()).zip(col.chunks(per_image)).for_each(|(b, c)| self.scatter_add_image(c, b));
        }
    }
}

widest_fn! {
    fn scatter_add_image_widest(grids: &Grids, col: &[f32], big: &mut [f32]) {
        let span = grids.kernel * grids.big_channels;
        for (col_at, big_at) in grids.window_rows() {
            big[big_at..big_at + span].iter_mut().zip(&col[col_at..col_at + span]).for_each(|(b, p)| *b += p);
        }
    }
}

/// dst [+]= a · b: split over the pool (as [`matmul`] splits it) or on this thread, where on this thread
/// `packed` (b packed once for the kernel) is read instead of packing b again.
fn product(
    dst: MatMut<'_, f32>,
    accum: Accum,
    a: MatRef<'_, f32>,
    b: MatRef<'_, f32>,
    packed: Option<&PackedRight>,
    split: bool,
) {
    if split {
        matmul(dst, accum, a, b);
    } else {
        let mut dst = dst;
        let done = packed.and_then(|packed| packed.fused_product(dst.as_mut(), Start::of(accum), a, Finish::Store));
        if done.is_none() {
            Kernel::for_product(&dst, &a, &b).product(dst, accum, a, b);
        }
    }
}

/// One convolution or transposed convolution of a parameter set, ready to run forward and backward.
pub struct StridedConv {
    pub grids: Grids,
    pub direction: Direction,
    /// W̃ [small channels, k · k · big channels].
    weight: Vec<f32>,
    bias: Vec<f32>,
    weight_index: usize,
    bias_index: usize,
    /// Images per im2col buffer.
    chunk: usize,
    /// W̃ and W̃ᵀ packed for the products that run chunk by chunk on one thread (`None` inside where the
    /// kernel does not run), each on first use: a layer whose chunks run in turn, split over the pool, never
    /// reads them, and packing the decoder's first layer (3.3 M values each way) on one thread cost a step at
    /// two threads 2 %.
    packed: [OnceLock<Option<PackedRight>>; 2],
}

impl StridedConv {
    /// The layer `prefix` (`prefix.weight` in torch's layout, `prefix.bias`) of `params`.
    pub fn new(params: &ParamSet, prefix: &str, grids: Grids, direction: Direction) -> Result<Self> {
        let (k, big, small) = (grids.kernel, grids.big_channels, grids.small_channels);
        if grids.small_side == 0 || grids.stride == 0 || grids.big_side < (grids.small_side - 1) * grids.stride + k {
            return Err(Error::config(format!("'{prefix}': {grids:?} is not a valid strided convolution")));
        }
        let weight_index = tensor_index(params, &format!("{prefix}.weight"), &[small, big, k, k])?;
        let out_channels = match direction {
            Direction::Down => small,
            Direction::Up => big,
        };
        let bias_index = tensor_index(params, &format!("{prefix}.bias"), &[out_channels])?;
        Ok(StridedConv {
            grids,
            direction,
            // torch's [small, big, k, k] → W̃ [small, k, k, big]: each row a channels-first k × k "image" of the
            // big channels, permuted on the pool (one element at a time on one thread, this cost DLGPD's step 3 ms).
            weight: to_channels_last(&params.tensors[weight_index].values, big, k),
            packed: [OnceLock::new(), OnceLock::new()],
            bias: params.tensors[bias_index].values.clone(),
            weight_index,
            bias_index,
            chunk: grids.chunk_images(),
        })
    }

    /// W̃ (`transposed` false) or W̃ᵀ, packed for the kernel, or `None` where it does not run.
    fn packed_weight(&self, transposed: bool) -> Option<&PackedRight> {
        let (small, window) = (self.grids.small_channels, self.grids.window());
        let packed = self.packed[transposed as usize].get_or_init(|| {
            let weight = view(&self.weight, small, window);
            PackedRight::new(if transposed { weight.transpose() } else { weight })
        });
        packed.as_ref()
    }

    pub fn input_len(&self) -> usize {
        match self.direction {
            Direction::Down => self.grids.big_len(),
            Direction::Up => self.grids.small_len(),
        }
    }

    pub fn output_len(&self) -> usize {
        match self.direction {
            Direction::Down => self.grids.small_len(),
            Direction::Up => self.grids.big_len(),
        }
    }

    /// Images per task, or `None` where the layer's chunks run in turn, each split over the pool. It depends on
    /// the layer and the batch alone, so the bytes do not depend on the thread count.
    fn task_images(&self, images: usize) -> Option<usize> {
        let chunks = images.div_ceil(self.chunk);
        (chunks >= MIN_CHUNKS_FOR_TASKS).then(|| chunks.div_ceil(TASKS) * self.chunk)
    }

    /// Runs `work` with an im2col buffer for a run of `images` images: this thread's own, kept from call to call
    /// (zeroing a fresh one for every task and layer was 2 % of DLGPD's step), or a fresh one where this thread
    /// already lends its buffer out (a task started while another waits on the pool).
    fn with_scratch<R>(&self, images: usize, work: impl FnOnce(&mut [f32]) -> R) -> R {
        thread_local! {
            static COLUMNS: std::cell::RefCell<Vec<f32>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let len = self.chunk.min(images) * self.grids.positions() * self.grids.window();
        COLUMNS.with(|columns| match columns.try_borrow_mut() {
            Ok(mut columns) => {
                if columns.len() < len {
                    columns.resize(len, 0.0);
                }
                work(&mut columns[..len])
            }
            Err(_) => work(&mut vec![0.0; len]),
        })
    }

    /// `x`: `images` inputs (NHWC) → their outputs (NHWC), through a ReLU when `relu`. Each chunk's outputs
    /// start from the bias and go through the ReLU while they are in cache, not in passes of their own over
    /// the whole batch.
    pub fn forward(&self, x: &[f32], images: usize, relu: bool) -> Vec<f32> {
        debug_assert_eq!(x.len(), images * self.input_len());
        let (input_len, output_len) = (self.input_len(), self.output_len());
        let len = images * output_len;
        let mut y = unwritten(len);
        let run = |x: &[f32], y: &mut [MaybeUninit<f32>], split: bool| {
            self.with_scratch(x.len() / input_len.max(1), |col| {
                for (x, y) in x.chunks(self.chunk * input_len).zip(y.chunks_mut(self.chunk * output_len)) {
                    let y = fill_with_row(y, &self.bias);
                    match self.direction {
                        Direction::Down => self.windows_times_weight(x, col, y, Accum::Add, split),
                        Direction::Up => self.spread_onto_windows(x, col, y, split),
                    }
                    if relu {
                        relu_in_place(y);
                    }
                }
            })
        };
        let y_slots = slots(&mut y, len);
        match self.task_images(images) {
            Some(task) => y_slots
                .par_chunks_mut(task * output_len)
                .zip(x.par_chunks(task * input_len))
                .for_each(|(y, x)| run(x, y, false)),
            None => run(x, y_slots, true),
        }
        // SAFETY: the chunks cover the output, and fill_with_row wrote each of them before the products.
        unsafe { assume_written(&mut y, len) };
        y
    }

    /// small (rows × small channels) [+]= im2col(big) · W̃ᵀ: a convolution, and a transposed convolution's
    /// input gradient. `col` is scratch of at least rows × window.
    fn windows_times_weight(&self, big: &[f32], col: &mut [f32], small: &mut [f32], accum: Accum, split: bool) {
        let rows = small.len() / self.grids.small_channels;
        let col = &mut col[..rows * self.grids.window()];
        self.grids.gather(big, col, split);
        self.columns_times_weight(col, small, accum, split);
    }

    /// small [+]= col · W̃ᵀ for windows already gathered into `col` (rows × window).
    fn columns_times_weight(&self, col: &[f32], small: &mut [f32], accum: Accum, split: bool) {
        let (window, channels) = (self.grids.window(), self.grids.small_channels);
        let rows = small.len() / channels;
        // On one thread, the weight as packed once per step (split over the pool, each piece packs its own).
        let packed = if split { None } else { self.packed_weight(true) };
        product(
            view_mut(small, rows, channels),
            accum,
            view(col, rows, window),
            view(&self.weight, channels, window).transpose(),
            packed,
            split,
        );
    }

    /// big += col2im(small · W̃), the adjoint of [`Self::windows_times_weight`]: a transposed convolution, and
    /// a convolution's input gradient.
    fn spread_onto_windows(&self, small: &[f32], col: &mut [f32], big: &mut [f32], split: bool) {
        let (window, channels) = (self.grids.window(), self.grids.small_channels);
        let rows = small.len() / channels;
        let col = &mut col[..rows * window];
        let packed = if split { None } else { self.packed_weight(false) };
        let (a, b) = (view(small, rows, channels), view(&self.weight, channels, window));
        product(view_mut(col, rows, window), Accum::Replace, a, b, packed, split);
        self.grids.scatter_add(col, big, split);
    }

    /// The weight gradient (W̃'s layout) and the bias gradient of one run of chunks, with their input gradients
    /// written to `dx` when it is not empty (masked by the input where `below_relu`). Each chunk of `dy` is
    /// first masked by the ReLU where there is one.
    fn backward_chunks(
        &self,
        x: &[f32],
        dy: &mut [f32],
        relu_output: Option<&[f32]>,
        dx: &mut [MaybeUninit<f32>],
        below_relu: bool,
        split: bool,
    ) -> (Vec<f32>, Vec<f32>) {
        let g = &self.grids;
        let (window, small) = (g.window(), g.small_channels);
        let (input_len, output_len) = (self.input_len(), self.output_len());
        let mut weight_grad = vec![0.0f32; small * window];
        let mut bias_grad = vec![0.0f32; self.bias.len()];
        self.with_scratch(x.len() / input_len.max(1), |col| {
            let chunks = x.chunks(self.chunk * input_len).zip(dy.chunks_mut(self.chunk * output_len));
            for (index, (x_part, dy_part)) in chunks.enumerate() {
                if let Some(y) = relu_output {
                    relu_backward(dy_part, &y[index * self.chunk * output_len..][..dy_part.len()]);
                }
                add_column_sums(&mut bias_grad, dy_part);
                let dy_part = &*dy_part;
                let (small_part, big_part) = match self.direction {
                    Direction::Down => (dy_part, x_part),
                    Direction::Up => (x_part, dy_part),
                };
                let rows = small_part.len() / small;
                let col = &mut col[..rows * window];
                // The small grid's values times the big grid's windows: the weight gradient in both directions.
                // A convolution's windows serve only this product, so on one thread they are gathered straight
                // into the kernel's packed layout; a transposed one's feed its input gradient too, by rows.
                let mut packed_done = false;
                if !split && self.direction == Direction::Down && g.windows_pack() {
                    g.gather_packed(big_part, col);
                    if let Some(windows) = PackedRight::from_packed(col, rows, window) {
                        let dst = view_mut(&mut weight_grad, small, window);
                        let a = view(small_part, rows, small).transpose();
                        packed_done = windows.fused_product(dst, Start::Dst, a, Finish::Store).is_some();
                    }
                }
                if !packed_done {
                    g.gather(big_part, col, split);
                    product(
                        view_mut(&mut weight_grad, small, window),
                        Accum::Add,
                        view(small_part, rows, small).transpose(),
                        view(col, rows, window),
                        None,
                        split,
                    );
                }
                if dx.is_empty() {
                    continue;
                }
                // Zeroed chunk by chunk, just before it is added to, while it stays in cache.
                let dx = fill_with_row(&mut dx[index * self.chunk * input_len..][..x_part.len()], &[0.0]);
                match self.direction {
                    Direction::Down => self.spread_onto_windows(small_part, col, dx, split),
                    // `col` holds this chunk's windows of dy already, gathered for the weight gradient.
                    Direction::Up => self.columns_times_weight(col, dx, Accum::Replace, split),
                }
                if below_relu {
                    relu_backward(dx, x_part);
                }
            }
        });
        (weight_grad, bias_grad)
    }

    /// Adds the weight and bias gradients for output gradients `dy` at inputs `x` to `grads` (torch's layout)
    /// and returns the input gradients `dx` asks for. With `relu_output` (this layer's output, through a
    /// ReLU), `dy` is the gradient at the ReLU's output and is masked in place, chunk by chunk, first.
    pub fn backward(
        &self,
        x: &[f32],
        dy: &mut [f32],
        relu_output: Option<&[f32]>,
        images: usize,
        grads: &mut [Vec<f32>],
        dx: InputGradient,
    ) -> Vec<f32> {
        let (want_dx, below_relu) = (dx != InputGradient::Skip, dx == InputGradient::BelowRelu);
        debug_assert_eq!(x.len(), images * self.input_len());
        debug_assert_eq!(dy.len(), images * self.output_len());
        debug_assert!(relu_output.is_none_or(|y| y.len() == dy.len()));
        let g = &self.grids;
        let (input_len, output_len) = (self.input_len(), self.output_len());
        let dx_len = if want_dx { x.len() } else { 0 };
        let mut dx = unwritten(dx_len);
        let dx_slots = slots(&mut dx, dx_len);
        let sums = match self.task_images(images) {
            None => vec![self.backward_chunks(x, dy, relu_output, dx_slots, below_relu, true)],
            Some(task) => {
                let tasks = images.div_ceil(task);
                let dx_parts: Vec<&mut [MaybeUninit<f32>]> = match want_dx {
                    true => dx_slots.chunks_mut(task * input_len).collect(),
                    false => (0..tasks).map(|_| <&mut [MaybeUninit<f32>]>::default()).collect(),
                };
                let relu_parts: Vec<Option<&[f32]>> = match relu_output {
                    Some(y) => y.chunks(task * output_len).map(Some).collect(),
                    None => vec![None; tasks],
                };
                dx_parts
                    .into_par_iter()
                    .zip(x.par_chunks(task * input_len))
                    .zip(dy.par_chunks_mut(task * output_len))
                    .zip(relu_parts)
                    .map(|(((dx, x), dy), relu)| self.backward_chunks(x, dy, relu, dx, below_relu, false))
                    .collect()
            }
        };
        // SAFETY: with `want_dx`, each task's chunks wrote the whole of its part of dx, and the parts cover it.
        unsafe { assume_written(&mut dx, dx_len) };
        let mut sums = sums.into_iter();
        if let Some((mut weight_grad, mut bias_grad)) = sums.next() {
            sums.for_each(|(weight, bias)| {
                add_into(&mut weight_grad, &weight);
                add_into(&mut bias_grad, &bias);
            });
            let torch_grad = &mut grads[self.weight_index];
            add_torch_layout(torch_grad, &weight_grad, g.big_channels, g.kernel * g.kernel);
            add_into(&mut grads[self.bias_index], &bias_grad);
        }
        dx
    }
}

/// Values of the weight gradient above which [`add_torch_layout`] runs on the pool.
const PARALLEL_LAYOUT: usize = 1 << 16;

/// dst [rows, channels, taps] += src [rows, taps, channels]: a gradient in W̃'s layout added to torch's.
fn add_torch_layout(dst: &mut [f32], src: &[f32], channels: usize, taps: usize) {
    let row_len = (channels * taps).max(1);
    let add_row = |(dst, src): (&mut [f32], &[f32])| {
        for (c, dst) in dst.chunks_exact_mut(taps.max(1)).enumerate() {
            dst.iter_mut().zip(src[c..].iter().step_by(channels)).for_each(|(d, s)| *d += s);
        }
    };
    if dst.len() >= PARALLEL_LAYOUT {
        dst.par_chunks_mut(row_len).zip(src.par_chunks(row_len)).for_each(add_row);
    } else {
        dst.chunks_mut(row_len).zip(src.chunks(row_len)).for_each(add_row);
    }
}

/// `images` images [channels, side, side] → [side, side, channels].
pub fn to_channels_last(x: &[f32], channels: usize, side: usize) -> Vec<f32> {
    let plane = side * side;
    // Each pixel's channels written together, from one place in each channel's plane.
    permuted(x, channels * plane, |x, out| {
        for (p, pixel) in out.chunks_exact_mut(channels.max(1)).enumerate() {
            pixel.iter_mut().zip(x[p..].iter().step_by(plane)).for_each(|(slot, v)| _ = slot.write(*v));
        }
    })
}

/// The inverse of [`to_channels_last`].
pub fn to_channels_first(x: &[f32], channels: usize, side: usize) -> Vec<f32> {
    let plane = side * side;
    permuted(x, channels * plane, |x, out| {
        for (c, channel) in out.chunks_exact_mut(plane.max(1)).enumerate() {
            channel.iter_mut().zip(x[c..].iter().step_by(channels)).for_each(|(slot, v)| _ = slot.write(*v));
        }
    })
}

/// A new buffer of `x`'s length whose images (`image_len` values each) `permute` writes in full, one task
/// per image, without zeroing it first.
fn permuted(x: &[f32], image_len: usize, permute: impl Fn(&[f32], &mut [MaybeUninit<f32>]) + Sync) -> Vec<f32> {
    assert!(image_len > 0 && x.len().is_multiple_of(image_len), "permuted: {} values are not whole images", x.len());
    let mut out = unwritten(x.len());
    {
        let images = slots(&mut out, x.len()).par_chunks_mut(image_len).zip(x.par_chunks(image_len));
        images.for_each(|(out, x)| permute(x, out));
    }
    // SAFETY: each image's permutation writes every slot of its image once (a pixel's channels, or a channel's
    // pixels, cover the image), and the images, all whole, cover the buffer.
    unsafe { assume_written(&mut out, x.len()) };
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use burn::module::Module;
    use burn::tensor::Tensor;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::nn::backprop::zero_gradients;
    use crate::nn::conv::Conv2dConfig;
    use crate::nn::tensor::{tensor, training_device, values};

    /// Asserts `ours` equals `theirs` to 1e-5 of the largest |value| of `theirs`.
    pub(crate) fn close(ours: &[f32], theirs: &[f32], what: &str) {
        assert_eq!(ours.len(), theirs.len(), "{what}");
        let scale = theirs.iter().fold(0.0f32, |m, x| m.max(x.abs())).max(1e-3);
        let worst = ours.iter().zip(theirs).fold(0.0f32, |m, (x, y)| m.max((x - y).abs()));
        assert!(worst <= 1e-5 * scale, "{what}: differs by {worst} at scale {scale}");
    }

    /// Output, input gradient and parameter gradients of one layer against burn's, for the loss Σ y ⊙ R.
    fn check<M: Module>(layer: M, forward: impl Fn(&M, Tensor<4>) -> Tensor<4>, grids: Grids, direction: Direction) {
        let device = training_device();
        let mut rng = ChaCha8Rng::seed_from_u64(grids.big_side as u64);
        let images = 3;
        let (in_channels, in_side, out_channels, out_side) = match direction {
            Direction::Down => (grids.big_channels, grids.big_side, grids.small_channels, grids.small_side),
            Direction::Up => (grids.small_channels, grids.small_side, grids.big_channels, grids.big_side),
        };
        let x: Vec<f32> = (0..images * in_channels * in_side * in_side).map(|_| rng.random_range(-1.0..1.0)).collect();
        let r: Vec<f32> =
            (0..images * out_channels * out_side * out_side).map(|_| rng.random_range(-1.0..1.0)).collect();
        let xt = tensor(x.clone(), [images, in_channels, in_side, in_side], &device).require_grad();
        let y = forward(&layer, xt.clone());
        let burn_grads = (y.clone() * tensor(r.clone(), y.dims(), &device)).sum().backward();
        let params = ParamSet::<f32>::from_module(&layer, |n: &str| format!("layer.{n}"));
        let ours = StridedConv::new(&params, "layer", grids, direction).unwrap();
        let x_last = to_channels_last(&x, in_channels, in_side);
        let y_ours = ours.forward(&x_last, images, false);
        close(&to_channels_first(&y_ours, out_channels, out_side), &values(&y), "output");
        let mut grads = zero_gradients(&params);
        let dx = ours.backward(
            &x_last,
            &mut to_channels_last(&r, out_channels, out_side),
            None,
            images,
            &mut grads,
            InputGradient::AtInput,
        );
        close(&to_channels_first(&dx, in_channels, in_side), &values(&xt.grad(&burn_grads).unwrap()), "dx");
        for ((t, g), theirs) in params.tensors.iter().zip(&grads).zip(ParamSet::<f32>::gradients(&layer, &burn_grads)) {
            close(g, &theirs, &t.name);
        }
    }

    /// Both directions, with sides that leave a convolution's last row unread and kernels wider than the stride.
    #[test]
    fn both_directions_match_burn_forward_and_backward() {
        let device = training_device();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for (side, cin, cout, k, s) in [(9, 2, 3, 3, 2), (7, 4, 5, 4, 3), (6, 3, 2, 4, 2)] {
            let conv = Conv2dConfig::new(cin, cout, k, s).init(&device, &mut rng);
            check(conv, |l, x| l.forward(x), Grids::conv(side, cin, cout, k, s), Direction::Down);
        }
        for (side, cin, cout, k, s) in [(4, 3, 2, 3, 2), (1, 5, 3, 5, 2), (3, 2, 4, 6, 2)] {
            let deconv = Conv2dConfig::new(cin, cout, k, s).init_transposed(&device, &mut rng);
            check(deconv, |l, x| l.forward(x), Grids::conv_transpose(side, cin, cout, k, s), Direction::Up);
        }
    }

    /// Random inputs and output gradients for `images` images of `layer`, drawn in that order.
    fn random_batch(layer: &StridedConv, images: usize, rng: &mut ChaCha8Rng) -> (Vec<f32>, Vec<f32>) {
        let x = (0..images * layer.input_len()).map(|_| rng.random_range(-1.0..1.0)).collect();
        let dy = (0..images * layer.output_len()).map(|_| rng.random_range(-1.0..1.0)).collect();
        (x, dy)
    }

    /// Asserts `layer` gives `reference`'s input gradient (empty without `want_dx`) and parameter gradients.
    fn assert_same_gradients(
        layer: &StridedConv,
        reference: &StridedConv,
        params: &ParamSet,
        batch: (&[f32], &[f32], usize),
        want_dx: InputGradient,
    ) {
        let (x, dy, images) = batch;
        let (mut reference_grads, mut grads) = (zero_gradients(params), zero_gradients(params));
        let dx_reference = reference.backward(x, &mut dy.to_vec(), None, images, &mut reference_grads, want_dx);
        let dx = layer.backward(x, &mut dy.to_vec(), None, images, &mut grads, want_dx);
        assert_eq!(dx.len(), if want_dx == InputGradient::Skip { 0 } else { x.len() });
        close(&dx, &dx_reference, "dx");
        for (ours, theirs) in grads.iter().zip(&reference_grads) {
            close(ours, theirs, "parameter gradient");
        }
    }

    /// `work` run on a pool of `threads` threads.
    fn on_pool<R: Send>(threads: usize, work: impl FnOnce() -> R + Send) -> R {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(work)
    }

    /// A convolution of 10 × 10 × 3 images to 4 channels and a transposed convolution of 4 × 4 × 4 to 3
    /// channels, both kernel 4, stride 2.
    fn small_layers(rng: &mut ChaCha8Rng) -> [(ParamSet, Grids, Direction); 2] {
        let device = training_device();
        let named = |n: &str| format!("layer.{n}");
        let down = ParamSet::<f32>::from_module(&Conv2dConfig::new(3, 4, 4, 2).init(&device, rng), named);
        let up = ParamSet::<f32>::from_module(&Conv2dConfig::new(4, 3, 4, 2).init_transposed(&device, rng), named);
        [
            (down, Grids::conv(10, 3, 4, 4, 2), Direction::Down),
            (up, Grids::conv_transpose(4, 4, 3, 4, 2), Direction::Up),
        ]
    }

    /// A batch split over several im2col buffers gives what one buffer gives, in both directions, whether the
    /// chunks run in turn (two-image chunks) or as parallel tasks (one-image chunks, one task each);
    /// and the tasks give the same bytes on any number of threads.
    #[test]
    fn chunked_batches_match_one_chunk() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let images = 5;
        for (params, grids, direction) in small_layers(&mut rng) {
            let whole = StridedConv::new(&params, "layer", grids, direction).unwrap();
            assert!(whole.chunk >= images && whole.task_images(images).is_none());
            let (x, dy) = random_batch(&whole, images, &mut rng);
            let (mut whole_grads, mut chunked_grads) = (zero_gradients(&params), zero_gradients(&params));
            let dx_whole = whole.backward(&x, &mut dy.clone(), None, images, &mut whole_grads, InputGradient::AtInput);
            for (chunk, tasks) in [(2, false), (1, true)] {
                let mut chunked = StridedConv::new(&params, "layer", grids, direction).unwrap();
                chunked.chunk = chunk;
                assert_eq!(chunked.task_images(images).is_some(), tasks);
                close(&chunked.forward(&x, images, false), &whole.forward(&x, images, false), "output");
                chunked_grads.iter_mut().for_each(|g| g.fill(0.0));
                close(
                    &chunked.backward(&x, &mut dy.clone(), None, images, &mut chunked_grads, InputGradient::AtInput),
                    &dx_whole,
                    "dx",
                );
                for (ours, theirs) in chunked_grads.iter().zip(&whole_grads) {
                    close(ours, theirs, "parameter gradient");
                }
                let on_threads = |threads| {
                    on_pool(threads, || {
                        let mut grads = zero_gradients(&params);
                        let dx =
                            chunked.backward(&x, &mut dy.clone(), None, images, &mut grads, InputGradient::AtInput);
                        (chunked.forward(&x, images, false), dx, grads)
                    })
                };
                let one = on_threads(1);
                assert!(on_threads(2) == one && on_threads(3) == one, "chunk {chunk}: bytes depend on the threads");
            }
        }
    }

    /// Tasks of several chunks each, the last task and its last chunk partial, with and without the input
    /// gradient: the same values as one chunk, and the same bytes on one thread and two.
    #[test]
    fn tasks_of_several_chunks_match_one_chunk() {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let images = 35;
        for (params, grids, direction) in small_layers(&mut rng) {
            let mut whole = StridedConv::new(&params, "layer", grids, direction).unwrap();
            whole.chunk = images;
            let mut chunked = StridedConv::new(&params, "layer", grids, direction).unwrap();
            chunked.chunk = 2;
            assert_eq!(chunked.task_images(images), Some(4), "18 chunks in 16 tasks: 2 chunks per task");
            let (x, dy) = random_batch(&whole, images, &mut rng);
            close(&chunked.forward(&x, images, false), &whole.forward(&x, images, false), "output");
            for want_dx in [InputGradient::AtInput, InputGradient::Skip] {
                assert_same_gradients(&chunked, &whole, &params, (&x, &dy, images), want_dx);
                let on_threads = |threads| {
                    on_pool(threads, || {
                        let mut grads = zero_gradients(&params);
                        (chunked.backward(&x, &mut dy.clone(), None, images, &mut grads, want_dx), grads)
                    })
                };
                assert!(on_threads(1) == on_threads(2), "bytes depend on the threads");
            }
        }
    }

    /// Windows of 1024 values (64 channels, kernel 4) in tasks of two one-image chunks of 289 rows (two blocks
    /// of the kernel's inner dimension), whose weight gradients go to the AVX-512 kernel where there is one: the
    /// values of one chunk split over the pool, in both directions, and the same bytes on one thread and two.
    #[test]
    fn wide_weight_gradients_in_tasks_match_one_chunk() {
        let device = training_device();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let named = |n: &str| format!("layer.{n}");
        let down = ParamSet::<f32>::from_module(&Conv2dConfig::new(64, 64, 4, 2).init(&device, &mut rng), named);
        let up =
            ParamSet::<f32>::from_module(&Conv2dConfig::new(64, 64, 4, 2).init_transposed(&device, &mut rng), named);
        let layers = [
            (down, Grids::conv(36, 64, 64, 4, 2), Direction::Down),
            (up, Grids::conv_transpose(17, 64, 64, 4, 2), Direction::Up),
        ];
        let images = 20;
        for (params, grids, direction) in layers {
            assert_eq!(grids.window(), 1024);
            let mut whole = StridedConv::new(&params, "layer", grids, direction).unwrap();
            whole.chunk = images;
            let mut tasks = StridedConv::new(&params, "layer", grids, direction).unwrap();
            tasks.chunk = 1;
            // Two chunks per task, so that each task's weight gradient sums two products.
            assert!(tasks.task_images(images) == Some(2) && whole.task_images(images).is_none());
            // The weight gradient's operands as a task lays them out: the kernel reads them where there is one.
            let rows = grids.small_side * grids.small_side;
            let mut weight_grad = vec![0.0f32; 64 * 1024];
            let (small_part, col) = (vec![0.0f32; rows * 64], vec![0.0f32; rows * 1024]);
            let dst = view_mut(&mut weight_grad, 64, 1024);
            let (a, b) = (view(&small_part, rows, 64).transpose(), view(&col, rows, 1024));
            #[cfg(target_arch = "x86_64")]
            if is_x86_feature_detected!("avx512f") {
                assert_ne!(
                    Kernel::for_product(&dst, &a, &b),
                    Kernel::Faer,
                    "the AVX-512 kernel reads a task's weight gradient"
                );
            }
            let _ = (dst, a, b);
            let (x, dy) = random_batch(&whole, images, &mut rng);
            assert_same_gradients(&tasks, &whole, &params, (&x, &dy, images), InputGradient::AtInput);
            let on_threads = |threads| {
                on_pool(threads, || {
                    let mut grads = zero_gradients(&params);
                    tasks.backward(&x, &mut dy.clone(), None, images, &mut grads, InputGradient::Skip);
                    grads
                })
            };
            assert!(on_threads(1) == on_threads(2), "{direction:?}: bytes depend on the threads");
        }
    }

    /// Windows gathered straight into the kernel's packed layout hold each window's values where
    /// `packed_offset` puts them: 588 rows (two whole blocks of the kernel's inner dimension and a partial
    /// one), windows of four 128-value kernel rows.
    #[test]
    fn windows_gathered_packed_sit_where_the_kernel_packs_them() {
        let grids = Grids::conv(30, 32, 64, 4, 2);
        assert!(grids.windows_pack() && !Grids::conv(10, 3, 4, 4, 2).windows_pack());
        let (images, window) = (3, grids.window());
        let big: Vec<f32> = (0..images * grids.big_len()).map(|i| i as f32).collect();
        let rows = images * grids.positions();
        assert_eq!(rows, 588);
        let mut col = vec![0.0; rows * window];
        grids.gather(&big, &mut col, false);
        let mut packed = vec![f32::NAN; rows * window];
        grids.gather_packed(&big, &mut packed);
        for row in 0..rows {
            for first in (0..window).step_by(PACKED_PANEL) {
                let at = packed_offset(rows, window, row, first);
                assert_eq!(packed[at..at + PACKED_PANEL], col[row * window + first..][..PACKED_PANEL], "row {row}");
            }
        }
    }

    /// The ReLU applied chunk by chunk gives the bits of a pass over the whole output, and the gradient masked
    /// chunk by chunk gives what masking it first gives, on tasks of several chunks and on chunks in turn.
    #[test]
    fn fused_relu_matches_separate_passes() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let images = 13;
        for (params, grids, direction) in small_layers(&mut rng) {
            for chunk in [2, images] {
                let mut layer = StridedConv::new(&params, "layer", grids, direction).unwrap();
                layer.chunk = chunk;
                let x: Vec<f32> = (0..images * layer.input_len()).map(|_| rng.random_range(-1.0..1.0)).collect();
                let mut y = layer.forward(&x, images, false);
                crate::nn::backprop::relu_in_place(&mut y);
                let fused = layer.forward(&x, images, true);
                assert!(fused == y, "chunk {chunk}: the fused ReLU changed the output's bits");
                assert!(fused.contains(&0.0) && fused.iter().any(|&v| v > 0.0));
                let dy: Vec<f32> = (0..y.len()).map(|_| rng.random_range(-1.0..1.0)).collect();
                let mut masked = dy.clone();
                relu_backward(&mut masked, &y);
                let (mut separate, mut fused_grads) = (zero_gradients(&params), zero_gradients(&params));
                let dx = layer.backward(&x, &mut masked.clone(), None, images, &mut separate, InputGradient::AtInput);
                let mut dy_fused = dy.clone();
                let dx_fused =
                    layer.backward(&x, &mut dy_fused, Some(&y), images, &mut fused_grads, InputGradient::AtInput);
                assert!(dy_fused == masked, "the gradient is masked in place");
                close(&dx_fused, &dx, "dx");
                // Taken on below the ReLU whose output x is, chunk by chunk: the bits of masking dx after.
                let mut below = zero_gradients(&params);
                let dx_below =
                    layer.backward(&x, &mut masked.clone(), None, images, &mut below, InputGradient::BelowRelu);
                let mut dx_masked = dx.clone();
                relu_backward(&mut dx_masked, &x);
                assert!(dx_below == dx_masked, "chunk {chunk}: the input gradient's mask changed its bits");
                assert!(dx_below.contains(&0.0) && dx_below.iter().any(|&v| v != 0.0));
                assert!(below == separate, "the mask of dx changed the parameter gradients");
                for (ours, theirs) in fused_grads.iter().zip(&separate) {
                    close(ours, theirs, "parameter gradient");
                }
            }
        }
    }

    #[test]
    fn layouts_round_trip() {
        let x: Vec<f32> = (0..2 * 3 * 16).map(|i| i as f32).collect();
        assert_eq!(to_channels_first(&to_channels_last(&x, 3, 4), 3, 4), x);
        // Weights of 2 × 3 × 2 × 2, and of 48 × 64 × 5 × 5, which the pool permutes: element by element against
        // the layouts' definitions, and back.
        for (rows, channels, kernel) in [(2, 3, 2), (48, 64, 5)] {
            let taps = kernel * kernel;
            let w: Vec<f32> = (0..rows * channels * taps).map(|i| i as f32).collect();
            let last = to_channels_last(&w, channels, kernel);
            for (r, c, t) in (0..rows).flat_map(|r| (0..channels).flat_map(move |c| (0..taps).map(move |t| (r, c, t))))
            {
                assert_eq!(last[(r * taps + t) * channels + c], w[(r * channels + c) * taps + t]);
            }
            let mut back = vec![1.0; w.len()];
            add_torch_layout(&mut back, &last, channels, taps);
            assert!(back.iter().zip(&w).all(|(b, w)| *b == w + 1.0), "{rows} × {channels} × {taps}");
        }
    }
}
