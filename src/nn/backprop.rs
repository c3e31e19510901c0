//! Forward and backward passes written out by hand over plain f32 buffers in torch's layout (weight
//! [out, in], bias [out]), for networks whose training step is many small tensors: there burn's autodiff spends
//! more on bookkeeping, copies and fresh allocations than on arithmetic. A model that trains here keeps burn as
//! its reference: a test holds every gradient to burn's.

use std::borrow::Cow;

use faer::{Accum, MatMut, MatRef};
use rayon::prelude::*;

use super::gemm::{Finish, Kernel, Start};
use super::params::ParamSet;
use super::sparse::SparseColumns;
use crate::error::{Error, Result};
use crate::util::wide::widest_fn;

/// Below this many multiply-adds a GEMM stays on one thread: splitting costs more than it saves.
const PARALLEL_WORK: usize = 1 << 19;

/// Values per task of an element-wise pass. A buffer under two blocks stays on one thread: waking another
/// costs more than a pass over it (SAC's and PETS' layers), while the context model's 75 000-row decoder
/// passes are tens of milliseconds each and would otherwise leave the second core idle.
const ELEMENTWISE_BLOCK: usize = 1 << 15;

/// dst (m × n) = [dst +] a (m × k) · b (k × n). Large products are split over the rayon pool, by rows of
/// `dst`, or by columns where `dst` is at least four times wider than tall: each piece packs the whole of the
/// operand the pieces share, and there `a` is much the smaller one (a convolution's weight gradient against
/// its im2col matrix). Every element is still summed by one thread in one order, so the bytes do not depend
/// on the split.
pub fn matmul(dst: MatMut<'_, f32>, accum: Accum, a: MatRef<'_, f32>, b: MatRef<'_, f32>) {
    if is_tall_weight_gradient(&dst, &a, &b) {
        transposed_product(dst, accum, a, b);
        return;
    }
    let kernel = Kernel::for_product(&dst, &a, &b);
    matmul_by(kernel, dst, Start::of(accum), a, b, Finish::Store, None);
}

/// dst = finish(start + a · b) (see [`gemm::Kernel::fused`]), split over the pool as [`matmul`] splits, on
/// `kernel`, which must be `Kernel::for_product` of this product; with `row_sums` also row_sums[i] +=
/// Σ_k a[i, k] (see [`Kernel::fused_summing`]): each row's sum is one piece's, in order of k, whatever the split.
pub fn matmul_by(
    kernel: Kernel,
    dst: MatMut<'_, f32>,
    start: Start<'_>,
    a: MatRef<'_, f32>,
    b: MatRef<'_, f32>,
    finish: Finish<'_>,
    row_sums: Option<&mut [f32]>,
) {
    let pieces = if dst.nrows() * dst.ncols() * a.ncols() >= PARALLEL_WORK { rayon::current_num_threads() } else { 1 };
    let product = Product { kernel, start, finish };
    if dst.ncols() >= 4 * dst.nrows() || packs_less_by_columns(&dst, &a) {
        split_cols(dst, a, b, product, pieces, row_sums);
    } else {
        split_rows(dst, a, b, product, pieces, row_sums);
    }
}

/// Whether a weight gradient (`a` stored by columns over a long inner dimension, as Xᵀ is) wider than tall
/// packs less split by columns: split by rows, every piece packs the whole of `b` (k × n); split by columns,
/// the whole of `a` (m × k), the smaller where n > m. A GRU's [in, 3·hidden] gradient over the context model's
/// tapes packed 600 columns twice on two threads, where 200 would do.
fn packs_less_by_columns(dst: &MatMut<'_, f32>, a: &MatRef<'_, f32>) -> bool {
    let (m, n, k) = (dst.nrows(), dst.ncols(), a.ncols());
    a.row_stride() == 1 && a.col_stride() != 1 && k >= 4 * m.max(n) && n > m
}

/// What every piece of a split product does besides its share of the multiply-adds.
#[derive(Clone, Copy)]
struct Product<'a> {
    kernel: Kernel,
    start: Start<'a>,
    finish: Finish<'a>,
}

fn split_rows(
    dst: MatMut<'_, f32>,
    a: MatRef<'_, f32>,
    b: MatRef<'_, f32>,
    product: Product<'_>,
    pieces: usize,
    row_sums: Option<&mut [f32]>,
) {
    let m = dst.nrows();
    if pieces <= 1 || m < 16 {
        product.kernel.fused_summing(dst, product.start, a, b, product.finish, row_sums);
        return;
    }
    let half = pieces / 2;
    let mid = m * half / pieces;
    let (top, bottom) = dst.split_at_row_mut(mid);
    let (a_top, a_bottom) = a.split_at_row(mid);
    let upper = Product { start: product.start.rows(0, mid), finish: product.finish.rows(0, mid), ..product };
    let lower =
        Product { start: product.start.rows(mid, m - mid), finish: product.finish.rows(mid, m - mid), ..product };
    let (sums_top, sums_bottom) = match row_sums {
        Some(sums) => {
            let (top, bottom) = sums.split_at_mut(mid);
            (Some(top), Some(bottom))
        }
        None => (None, None),
    };
    rayon::join(
        || split_rows(top, a_top, b, upper, half, sums_top),
        || split_rows(bottom, a_bottom, b, lower, pieces - half, sums_bottom),
    );
}

/// Every piece reads all of `a`'s rows: the first one (from column 0) adds the row sums.
fn split_cols(
    dst: MatMut<'_, f32>,
    a: MatRef<'_, f32>,
    b: MatRef<'_, f32>,
    product: Product<'_>,
    pieces: usize,
    row_sums: Option<&mut [f32]>,
) {
    let n = dst.ncols();
    if pieces <= 1 || n < 16 {
        product.kernel.fused_summing(dst, product.start, a, b, product.finish, row_sums);
        return;
    }
    let half = pieces / 2;
    let mid = n * half / pieces;
    let (left, right) = dst.split_at_col_mut(mid);
    let (b_left, b_right) = b.split_at_col(mid);
    let left_part = Product { start: product.start.cols(0, mid), finish: product.finish.cols(0, mid), ..product };
    let right_part =
        Product { start: product.start.cols(mid, n - mid), finish: product.finish.cols(mid, n - mid), ..product };
    rayon::join(
        || split_cols(left, a, b_left, left_part, half, row_sums),
        || split_cols(right, a, b_right, right_part, pieces - half, None),
    );
}

/// A weight gradient dYᵀ·X over many rows into a row-major destination at least twice as tall as wide (a
/// GRU's [3·hidden, in] weights): faer's kernels run such a product 15-35 % slower than its transpose Xᵀ·dY
/// into a row-major buffer, whose rows are then the destination's columns.
fn is_tall_weight_gradient(dst: &MatMut<'_, f32>, a: &MatRef<'_, f32>, b: &MatRef<'_, f32>) -> bool {
    let (m, n, k) = (dst.nrows(), dst.ncols(), a.ncols());
    dst.col_stride() == 1 && a.row_stride() == 1 && b.col_stride() == 1 && m >= 2 * n && k >= 4 * m && n > 0
}

/// dst = [dst +] a · b computed as (bᵀ · aᵀ)ᵀ: the product into a row-major n × m buffer (split over the pool
/// as any other), then added to `dst` transposed.
fn transposed_product(mut dst: MatMut<'_, f32>, accum: Accum, a: MatRef<'_, f32>, b: MatRef<'_, f32>) {
    let (m, n) = (dst.nrows(), dst.ncols());
    let mut product = vec![0.0f32; n * m];
    matmul(view_mut(&mut product, n, m), Accum::Replace, b.transpose(), a.transpose());
    let product = view(&product, n, m).transpose();
    match accum {
        Accum::Add => dst += product,
        Accum::Replace => dst.copy_from(product),
    }
}

/// Two distinct buffers of `buffers`, both writable.
fn two_mut(buffers: &mut [Vec<f32>], first: usize, second: usize) -> (&mut Vec<f32>, &mut Vec<f32>) {
    assert_ne!(first, second, "two_mut: one buffer twice");
    if first < second {
        let (head, tail) = buffers.split_at_mut(second);
        (&mut head[first], &mut tail[0])
    } else {
        let (head, tail) = buffers.split_at_mut(first);
        (&mut tail[0], &mut head[second])
    }
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
        self.forward_then(x, rows, Finish::Store)
    }

    /// The outputs through a ReLU.
    pub fn forward_relu(&self, x: &[f32], rows: usize) -> Vec<f32> {
        self.forward_then(x, rows, Finish::Relu)
    }

    fn forward_then(&self, x: &[f32], rows: usize, finish: Finish<'_>) -> Vec<f32> {
        debug_assert_eq!(x.len(), rows * self.d_in);
        let weight = view(&self.weight, self.d_out, self.d_in).transpose();
        affine(view(x, rows, self.d_in), weight, self.bias, finish)
    }

    /// Adds this layer's weight and bias gradients for output gradients `dy` at inputs `x` to `grads`, and
    /// returns the input gradients when asked for.
    pub fn backward(&self, x: &[f32], dy: &[f32], rows: usize, grads: &mut [Vec<f32>], want_dx: bool) -> Vec<f32> {
        debug_assert_eq!(dy.len(), rows * self.d_out);
        let (o, i) = (self.d_out, self.d_in);
        let (weight_grad, bias_grad) = two_mut(grads, self.weight_index, self.bias_index);
        if self.non_negative {
            let mut acting = vec![0.0; o * i];
            matmul(view_mut(&mut acting, o, i), Accum::Replace, view(dy, rows, o).transpose(), view(x, rows, i));
            self.add_acting(weight_grad, &acting);
            add_column_sums(bias_grad, dy);
        } else {
            let (dst, a, b) = (view_mut(weight_grad, o, i), view(dy, rows, o).transpose(), view(x, rows, i));
            let kernel = Kernel::for_product(&dst, &a, &b);
            if kernel != Kernel::Faer && !is_tall_weight_gradient(&dst, &a, &b) {
                // The bias gradient, dY's column sums, added up as the kernel packs dYᵀ.
                matmul_by(kernel, dst, Start::Dst, a, b, Finish::Store, Some(&mut bias_grad[..]));
            } else {
                matmul(dst, Accum::Add, a, b);
                add_column_sums(bias_grad, dy);
            }
        }
        if !want_dx {
            return Vec::new();
        }
        self.backward_input(dy, rows)
    }

    /// Adds a monotone layer's weight gradient where its raw weight acts: only the positive raw weights do,
    /// so only they receive gradient (burn's ReLU backward).
    fn add_acting(&self, weight_grad: &mut [f32], acting: &[f32]) {
        for ((g, a), w) in weight_grad.iter_mut().zip(acting).zip(self.weight.iter()) {
            if *w > 0.0 {
                *g += a;
            }
        }
    }

    /// [`Dense::backward_through_relu`] for output gradients that are zero but at `dy`'s entries.
    pub fn sparse_backward_through_relu(&self, x: &[f32], dy: &SparseColumns, grads: &mut [Vec<f32>]) -> Vec<f32> {
        let (o, i) = (self.d_out, self.d_in);
        assert_eq!((dy.rows() * i, dy.width()), (x.len(), o), "sparse backward: the gradients do not fit the layer");
        let (weight_grad, bias_grad) = two_mut(grads, self.weight_index, self.bias_index);
        if self.non_negative {
            let mut acting = vec![0.0; o * i];
            dy.add_transposed_product(x, i, &mut acting);
            self.add_acting(weight_grad, &acting);
        } else {
            dy.add_transposed_product(x, i, weight_grad);
        }
        dy.add_column_sums(bias_grad);
        dy.product(&self.weight, i, Some(x))
    }

    /// [`Dense::backward`] with the input gradients taken on through the ReLU whose output `x` is: zero
    /// where x ≤ 0, as [`relu_backward`] leaves them.
    pub fn backward_through_relu(&self, x: &[f32], dy: &[f32], rows: usize, grads: &mut [Vec<f32>]) -> Vec<f32> {
        self.backward(x, dy, rows, grads, false);
        self.input_gradient(dy, rows, Finish::ReluGrad(view(x, rows, self.d_in)))
    }
}

impl Dense<'_> {
    /// The input gradients for output gradients `dy`, leaving the weights' gradients alone: for a network held
    /// fixed while something upstream of it learns (SAC's critics under the actor's loss).
    pub fn backward_input(&self, dy: &[f32], rows: usize) -> Vec<f32> {
        self.input_gradient(dy, rows, Finish::Store)
    }

    fn input_gradient(&self, dy: &[f32], rows: usize, finish: Finish<'_>) -> Vec<f32> {
        debug_assert_eq!(dy.len(), rows * self.d_out);
        let (o, i) = (self.d_out, self.d_in);
        new_product(view(dy, rows, o), view(&self.weight, o, i), finish)
    }
}

/// finish(bias + x · weight) as a new row-major buffer: a layer's output, the bias row repeated down the rows.
pub fn affine(x: MatRef<'_, f32>, weight: MatRef<'_, f32>, bias: &[f32], finish: Finish<'_>) -> Vec<f32> {
    fresh_product(x, weight, Start::Row(bias), finish)
}

/// finish(a · b) as a new row-major buffer.
pub fn new_product(a: MatRef<'_, f32>, b: MatRef<'_, f32>, finish: Finish<'_>) -> Vec<f32> {
    fresh_product(a, b, Start::Zero, finish)
}

/// start + a · b as a new row-major buffer, for a `start` (rows × b's columns, row-major) the caller keeps:
/// on the AVX-512 kernel it is read tile by tile, with no copy of its own.
pub fn product_from(start: &[f32], a: MatRef<'_, f32>, b: MatRef<'_, f32>) -> Vec<f32> {
    fresh_product(a, b, Start::Matrix(view(start, a.nrows(), b.ncols())), Finish::Store)
}

/// Nothing in the new buffer can be read, so a `Dst` start is taken as `Zero`.
fn fresh_product(a: MatRef<'_, f32>, b: MatRef<'_, f32>, start: Start<'_>, finish: Finish<'_>) -> Vec<f32> {
    let (rows, width) = (a.nrows(), b.ncols());
    let n = rows * width;
    let mut out = unwritten(n);
    // SAFETY: the view covers out's capacity, row-major; the AVX-512 kernel only stores into it, and the faer
    // branch below does not use it.
    let dst = unsafe { MatMut::from_raw_parts_mut(out.as_mut_ptr(), rows, width, width as isize, 1) };
    let kernel = Kernel::for_product(&dst, &a, &b);
    if kernel != Kernel::Faer && !matches!(start, Start::Dst) {
        // The kernel starts every element from zero, the bias row or the start matrix and stores it: nothing
        // of `out` is read.
        matmul_by(kernel, dst, start, a, b, finish, None);
        // SAFETY: the kernel stored every element of the rows × width output.
        unsafe { assume_written(&mut out, n) };
        return out;
    }
    // faer adds to the start, written first; with none it overwrites zeros.
    let (mut out, start) = match start {
        Start::Row(bias) => (repeat_row(bias, rows), Start::Dst),
        Start::Matrix(start) => (row_major_copy(start), Start::Dst),
        Start::Zero | Start::Dst => (zeros(n), Start::Zero),
    };
    matmul_by(kernel, view_mut(&mut out, rows, width), start, a, b, finish, None);
    out
}

/// The values of `m` by rows, copied in parallel blocks where they are one row-major run already.
fn row_major_copy(m: MatRef<'_, f32>) -> Vec<f32> {
    let (rows, cols) = (m.nrows(), m.ncols());
    if m.col_stride() == 1 && m.row_stride() == cols as isize {
        // SAFETY: a row-major view with rows exactly `cols` apart is rows · cols consecutive values.
        copy_of(unsafe { std::slice::from_raw_parts(m.as_ptr(), rows * cols) })
    } else {
        (0..rows).flat_map(|i| m.row(i).iter().copied()).collect()
    }
}

/// sums[j] += Σ_rows m[row, j] for a row-major matrix with `sums.len()` columns. A large matrix is summed in
/// blocks of rows of a size set by its width alone, whose partial sums are then added in block order: the
/// bytes do not depend on the threads.
pub fn add_column_sums(sums: &mut [f32], m: &[f32]) {
    let width = sums.len();
    if width == 0 || m.len() < 2 * ELEMENTWISE_BLOCK {
        add_rows_widest(sums, m, width);
        return;
    }
    let block = ELEMENTWISE_BLOCK.div_ceil(width) * width;
    let partials: Vec<Vec<f32>> = m
        .par_chunks(block)
        .map(|rows| {
            let mut partial = vec![0.0; width];
            add_rows_widest(&mut partial, rows, width);
            partial
        })
        .collect();
    for partial in &partials {
        sums.iter_mut().zip(partial).for_each(|(s, x)| *s += x);
    }
}

/// Rows per parallel task of an element-wise pass over `rows × width` values: one task below a block of
/// values, where splitting costs more than it saves (a batch-512 GRU step through time is three blocks).
pub fn block_rows(rows: usize, width: usize) -> usize {
    let tasks = (rows * width / ELEMENTWISE_BLOCK).clamp(1, rayon::current_num_threads().max(1));
    rows.div_ceil(tasks).max(1)
}

/// Applies `f` to every value, in parallel blocks when the buffer is large.
pub fn for_each_value(xs: &mut [f32], f: impl Fn(&mut f32) + Sync) {
    if xs.len() < 2 * ELEMENTWISE_BLOCK {
        for_each_widest(xs, &f);
    } else {
        xs.par_chunks_mut(ELEMENTWISE_BLOCK).for_each(|block| for_each_widest(block, &f));
    }
}

/// Applies `f` to every pair of `dst` and `src` values, in parallel blocks when the buffers are large.
pub fn zip_values(dst: &mut [f32], src: &[f32], f: impl Fn(&mut f32, f32) + Sync) {
    debug_assert_eq!(dst.len(), src.len());
    if dst.len() < 2 * ELEMENTWISE_BLOCK {
        zip_widest(dst, src, &f);
    } else {
        dst.par_chunks_mut(ELEMENTWISE_BLOCK)
            .zip(src.par_chunks(ELEMENTWISE_BLOCK))
            .for_each(|(d, s)| zip_widest(d, s, &f));
    }
}

widest_fn! {
    fn for_each_widest[F: Fn(&mut f32)](xs: &mut [f32], f: &F) {
        xs.iter_mut().for_each(f)
    }
}

widest_fn! {
    fn zip_widest[F: Fn(&mut f32, f32)](dst: &mut [f32], src: &[f32], f: &F) {
        dst.iter_mut().zip(src).for_each(|(d, s)| f(d, *s))
    }
}

widest_fn! {
    fn add_rows_widest(sums: &mut [f32], block: &[f32], width: usize) {
        for row in block.chunks(width) {
            sums.iter_mut().zip(row).for_each(|(s, x)| *s += x);
        }
    }
}

/// A new buffer of `n` values, each written by `fill` from its block's offset, in parallel blocks when large:
/// a fresh multi-megabyte buffer written by one thread (memset, memcpy) leaves the other core idle.
fn filled(n: usize, block: usize, fill: impl Fn(usize, &mut [std::mem::MaybeUninit<f32>]) + Sync) -> Vec<f32> {
    let mut out = Vec::with_capacity(n);
    let slots = &mut out.spare_capacity_mut()[..n];
    if n < 2 * ELEMENTWISE_BLOCK {
        fill(0, slots);
    } else {
        slots.par_chunks_mut(block).enumerate().for_each(|(k, chunk)| fill(k * block, chunk));
    }
    // SAFETY: `fill` wrote every one of the first n slots (each caller writes its whole chunk).
    unsafe { out.set_len(n) };
    out
}

/// `n` uninitialized slots for a pass that writes every one of them (see [`assume_written`]): a buffer a
/// training step fills in full need not be zeroed first, and zeroing the context model's step buffers was
/// about 5 % of its time.
pub fn unwritten(n: usize) -> Vec<f32> {
    Vec::with_capacity(n)
}

/// The spare capacity of `buffer` (from [`unwritten`]), `n` slots, for a pass to write.
pub fn slots(buffer: &mut Vec<f32>, n: usize) -> &mut [std::mem::MaybeUninit<f32>] {
    debug_assert!(buffer.is_empty(), "slots of a buffer that already holds values");
    &mut buffer.spare_capacity_mut()[..n]
}

/// Marks the first `n` slots of `buffer` written.
///
/// # Safety
/// Every one of the first `n` slots of `buffer`'s spare capacity must have been written since it came from
/// [`unwritten`].
pub unsafe fn assume_written(buffer: &mut Vec<f32>, n: usize) {
    debug_assert!(buffer.is_empty() && n <= buffer.capacity());
    // SAFETY: the caller wrote all n slots.
    unsafe { buffer.set_len(n) };
}

/// Writes `row` over `slots` again and again (`slots` holds whole rows; a one-value row fills them with that
/// value) and returns them as values: a layer's chunk of outputs starting from its bias.
pub fn fill_with_row<'a>(slots: &'a mut [std::mem::MaybeUninit<f32>], row: &[f32]) -> &'a mut [f32] {
    assert!(!row.is_empty() && slots.len().is_multiple_of(row.len()), "fill_with_row: slots of whole rows");
    for chunk in slots.chunks_exact_mut(row.len()) {
        chunk.iter_mut().zip(row).for_each(|(slot, x)| _ = slot.write(*x));
    }
    // SAFETY: every slot was written just above (the chunks cover them all, the rows being whole), and
    // MaybeUninit<f32> has f32's layout.
    unsafe { &mut *(slots as *mut [std::mem::MaybeUninit<f32>] as *mut [f32]) }
}

/// `n` zeros.
pub fn zeros(n: usize) -> Vec<f32> {
    filled(n, ELEMENTWISE_BLOCK, |_, chunk| chunk.iter_mut().for_each(|slot| _ = slot.write(0.0)))
}

/// A copy of `src`.
pub fn copy_of(src: &[f32]) -> Vec<f32> {
    filled(src.len(), ELEMENTWISE_BLOCK, |start, chunk| {
        chunk.iter_mut().zip(&src[start..]).for_each(|(slot, x)| _ = slot.write(*x));
    })
}

/// The buffers one after another.
pub fn concat(parts: &[&[f32]]) -> Vec<f32> {
    let mut out = Vec::with_capacity(parts.iter().map(|p| p.len()).sum());
    for part in parts {
        let start = out.len();
        let slots = &mut out.spare_capacity_mut()[..part.len()];
        slots.par_chunks_mut(ELEMENTWISE_BLOCK).zip(part.par_chunks(ELEMENTWISE_BLOCK)).for_each(|(s, p)| {
            s.iter_mut().zip(p).for_each(|(slot, x)| _ = slot.write(*x));
        });
        // SAFETY: the part's slots were all written just above.
        unsafe { out.set_len(start + part.len()) };
    }
    out
}

/// `row` repeated `rows` times (a bias broadcast over a batch).
pub fn repeat_row(row: &[f32], rows: usize) -> Vec<f32> {
    if row.is_empty() {
        return Vec::new();
    }
    let block = ELEMENTWISE_BLOCK.div_ceil(row.len()) * row.len();
    filled(row.len() * rows, block, |_, chunk| {
        chunk.iter_mut().zip(row.iter().cycle()).for_each(|(slot, x)| _ = slot.write(*x));
    })
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
        let hidden = self.first.forward_relu(x, rows);
        let out = self.second.forward(&hidden, rows);
        (out, TwoLayerTape { hidden })
    }

    /// [`TwoLayer::forward`] with the output through a ReLU.
    pub fn forward_relu(&self, x: &[f32], rows: usize) -> (Vec<f32>, TwoLayerTape) {
        let hidden = self.first.forward_relu(x, rows);
        let out = self.second.forward_relu(&hidden, rows);
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
        let d_hidden = self.second.backward_through_relu(&tape.hidden, d_out, rows, grads);
        self.first.backward(x, &d_hidden, rows, grads, want_dx)
    }
}

impl TwoLayer<'_> {
    /// [`TwoLayer::backward`] for output gradients that are zero but at `d_out`'s entries (a max pool's).
    pub fn sparse_backward(
        &self,
        x: &[f32],
        tape: &TwoLayerTape,
        d_out: &SparseColumns,
        grads: &mut [Vec<f32>],
        want_dx: bool,
    ) -> Vec<f32> {
        let d_hidden = self.second.sparse_backward_through_relu(&tape.hidden, d_out, grads);
        self.first.backward(x, &d_hidden, d_out.rows(), grads, want_dx)
    }
}

/// dst[i] += src[i].
pub fn add_into(dst: &mut [f32], src: &[f32]) {
    zip_values(dst, src, |a, b| *a += b);
}

/// In place: ReLU, keeping the output as its own derivative mask.
pub fn relu_in_place(xs: &mut [f32]) {
    for_each_value(xs, |x| *x = x.max(0.0));
}

/// d ← d · 1[y > 0] for a ReLU output y.
pub fn relu_backward(d: &mut [f32], y: &[f32]) {
    // An unconditional store: the conditional one does not vectorize.
    zip_values(d, y, |d, y| *d = if y <= 0.0 { 0.0 } else { *d });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::params::NamedTensor;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn tall_weight_gradients_equal_the_direct_product_on_any_pool() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        // dYᵀ·X for a [3·40, 33] weight over 700 rows: the shape that takes the transposed route.
        let (rows, o, i) = (700, 120, 33);
        let dy: Vec<f32> = (0..rows * o).map(|_| rng.random_range(-1.0..1.0)).collect();
        let x: Vec<f32> = (0..rows * i).map(|_| rng.random_range(-1.0..1.0)).collect();
        let start: Vec<f32> = (0..o * i).map(|_| rng.random_range(-1.0..1.0)).collect();
        let (a, b) = (view(&dy, rows, o).transpose(), view(&x, rows, i));
        let mut probe = start.clone();
        assert!(is_tall_weight_gradient(&view_mut(&mut probe, o, i), &a, &b));
        let mut direct = start.clone();
        crate::nn::gemm::faer_product(view_mut(&mut direct, o, i), Accum::Add, a, b);
        let run = |threads: usize, accum: Accum| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut out = start.clone();
            pool.install(|| matmul(view_mut(&mut out, o, i), accum, a, b));
            out
        };
        let one = run(1, Accum::Add);
        for (ours, theirs) in one.iter().zip(&direct) {
            assert!((ours - theirs).abs() <= 1e-4 * (1.0 + theirs.abs()), "{ours} vs {theirs}");
        }
        assert_eq!(run(2, Accum::Add), one);
        assert_eq!(run(3, Accum::Add), one);
        let replaced = run(2, Accum::Replace);
        for ((r, added), s) in replaced.iter().zip(&one).zip(&start) {
            assert!((r + s - added).abs() <= 1e-4 * (1.0 + added.abs()));
        }
    }

    #[test]
    fn split_matmul_gives_the_bytes_of_one_thread() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let (m, k, n) = (301, 97, 203);
        let a: Vec<f32> = (0..m * k).map(|_| rng.random_range(-1.0..1.0)).collect();
        let b: Vec<f32> = (0..k * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let bias: Vec<f32> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let relu_out: Vec<f32> = (0..m * n).map(|_| rng.random_range(-1.0f32..1.0).max(0.0)).collect();
        let gates: Vec<f32> = (0..m * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        for kernel in crate::nn::gemm::available_kernels() {
            let cases = [
                (Start::Dst, Finish::Store),
                (Start::Row(&bias), Finish::Relu),
                (Start::Zero, Finish::ReluGrad(view(&relu_out, m, n))),
                (Start::Matrix(view(&gates, m, n)), Finish::Store),
            ];
            // `a` stored by rows and by columns (a weight gradient's dYᵀ), which the kernel reads differently.
            let a_by_columns: Vec<f32> = (0..m * k).map(|x| a[(x % m) * k + x / m]).collect();
            for (start, finish) in cases {
                for a_view in [view(&a, m, k), view(&a_by_columns, k, m).transpose()] {
                    let mut one = vec![0.5; m * n];
                    let mut one_sums = vec![0.25; m];
                    let dst = view_mut(&mut one, m, n);
                    kernel.fused_summing(dst, start, a_view, view(&b, k, n), finish, Some(&mut one_sums));
                    let product = Product { kernel, start, finish };
                    for pieces in [2, 3, 7] {
                        for by_rows in [true, false] {
                            let (mut split, mut sums) = (vec![0.5; m * n], vec![0.25; m]);
                            let dst = view_mut(&mut split, m, n);
                            let split_by = if by_rows { split_rows } else { split_cols };
                            split_by(dst, a_view, view(&b, k, n), product, pieces, Some(&mut sums));
                            let what = if by_rows { "rows" } else { "columns" };
                            assert_eq!(split, one, "{kernel:?} {start:?}: {pieces} pieces of {what}");
                            assert_eq!(sums, one_sums, "{kernel:?} {start:?}: row sums, {pieces} pieces of {what}");
                        }
                    }
                    for (i, sum) in one_sums.iter().enumerate() {
                        let want = 0.25 + (0..k).map(|kk| a[i * k + kk] as f64).sum::<f64>();
                        assert!((*sum as f64 - want).abs() <= 1e-4, "{kernel:?}: row {i} sums to {sum}, not {want}");
                    }
                }
            }
        }
    }

    /// A layer's gradients on a batch large enough for the AVX-512 kernel, which sums the bias gradient as it
    /// packs dYᵀ: the sums of an f64 reference, and the same bytes on any pool.
    #[test]
    fn a_large_layers_gradients_are_the_sums_on_any_pool() {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let (rows, d_in, d_out) = (3000, 150, 200);
        let mut random = |n: usize| (0..n).map(|_| rng.random_range(-1.0f32..1.0)).collect::<Vec<_>>();
        let params = ParamSet {
            tensors: vec![
                NamedTensor { name: "layer.weight".into(), shape: vec![d_out, d_in], values: random(d_out * d_in) },
                NamedTensor { name: "layer.bias".into(), shape: vec![d_out], values: random(d_out) },
            ],
        };
        let (x, dy) = (random(rows * d_in), random(rows * d_out));
        let layer = Dense::new(&params, "layer", d_in, d_out, false).unwrap();
        let mut probe = vec![0.0; d_out * d_in];
        let (dst, a, b) = (view_mut(&mut probe, d_out, d_in), view(&dy, rows, d_out).transpose(), view(&x, rows, d_in));
        assert!(!is_tall_weight_gradient(&dst, &a, &b));
        assert_eq!(Some(&Kernel::for_product(&dst, &a, &b)), crate::nn::gemm::available_kernels().last());
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut grads = vec![vec![0.5; d_out * d_in], vec![0.25; d_out]];
                let dx = layer.backward(&x, &dy, rows, &mut grads, true);
                (grads, dx)
            })
        };
        let (grads, dx) = run(1);
        for o in 0..d_out {
            let bias = 0.25 + (0..rows).map(|r| dy[r * d_out + o] as f64).sum::<f64>();
            assert!((grads[1][o] as f64 - bias).abs() <= 1e-3, "bias {o}: {} vs {bias}", grads[1][o]);
            for i in (0..d_in).step_by(7) {
                let weight = 0.5 + (0..rows).map(|r| dy[r * d_out + o] as f64 * x[r * d_in + i] as f64).sum::<f64>();
                let got = grads[0][o * d_in + i] as f64;
                assert!((got - weight).abs() <= 1e-3, "weight ({o}, {i}): {got} vs {weight}");
            }
        }
        let w = &params.tensors[0].values;
        for r in (0..rows).step_by(97) {
            let want = (0..d_out).map(|o| dy[r * d_out + o] as f64 * w[o * d_in] as f64).sum::<f64>();
            assert!((dx[r * d_in] as f64 - want).abs() <= 1e-3, "dx row {r}");
        }
        for threads in [2, 3] {
            assert_eq!(run(threads), (grads.clone(), dx.clone()), "{threads} threads");
        }
    }

    /// The passes that split large buffers over the pool: exact copies, and column sums whose bytes do not
    /// depend on the threads and whose value is the sum's.
    #[test]
    fn large_passes_give_the_same_bytes_on_any_pool() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let (rows, width) = (3001, 37);
        let m: Vec<f32> = (0..rows * width).map(|_| rng.random_range(-1.0..1.0)).collect();
        let bias: Vec<f32> = (0..width).map(|_| rng.random_range(-1.0..1.0)).collect();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut sums = vec![0.5; width];
                add_column_sums(&mut sums, &m);
                let copies = (copy_of(&m), concat(&[&m[..5], &m, &bias]), repeat_row(&bias, rows), zeros(m.len()));
                (sums, copies)
            })
        };
        let (sums, (copy, joined, repeated, zeroed)) = run(1);
        assert_eq!(copy, m);
        assert_eq!(joined, [&m[..5], &m, &bias].concat());
        assert_eq!(repeated, bias.repeat(rows));
        assert!(zeroed.iter().all(|z| *z == 0.0) && zeroed.len() == m.len());
        for (j, s) in sums.iter().enumerate() {
            let exact = 0.5 + m.iter().skip(j).step_by(width).map(|x| *x as f64).sum::<f64>();
            assert!((*s as f64 - exact).abs() < 1e-3, "column {j}: {s} vs {exact}");
        }
        for threads in [2, 3] {
            assert_eq!(run(threads), run(1), "{threads} threads");
        }
    }
}
