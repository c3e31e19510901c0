//! f32 matrix products for the hand-written training paths, on one thread (`backprop::matmul` splits work over
//! the pool and calls this per piece).
//!
//! faer's kernels reach 150-170 GFLOP/s on cache-sized products here, but 110-135 on the training paths' tall
//! ones (25 000-75 000 rows by 200 inner by 200-600 out): they start each output tile with a load that misses
//! every cache level and wait for it. On AVX-512 machines those products run through the kernel below, which
//! prefetches the next output tile and the next rows of the left operand while it works on the current ones,
//! and which starts each tile from a bias row and ends it with a ReLU (or a ReLU's gradient mask) in cache:
//! the passes that wrote the bias rows and applied the activation over every layer's output cost the context
//! model's step as much again as the kernel saves. Elsewhere, and for products small enough to stay in cache,
//! faer does the work, with the start and the finish as passes of their own.
//!
//! On either kernel every output element is one thread's sum in one order (on this one: its start, then
//! k = 0, 1, … by fused multiply-adds), whatever the split of rows or columns around it, and the kernel is
//! chosen from the whole product's shape: the bytes do not depend on the thread count.

use faer::{Accum, MatMut, MatRef, Par};

/// Products whose three operands hold fewer values than this (2 MiB, a core's L2) are left to faer: they sit
/// in cache, where faer's kernels are at least as fast.
const MIN_VALUES: usize = 1 << 19;

/// Outputs narrower than one vector are left to faer: the kernel would spend a 16-lane multiply-add on each
/// of them (a VAE's 3-wide latent head).
const MIN_COLS: usize = 16;

/// What each output element starts from before the products are added.
#[derive(Clone, Copy, Debug)]
pub enum Start<'a> {
    Zero,
    /// The value `dst` holds.
    Dst,
    /// The row vector (a layer's bias), the same for every row: `n` values.
    Row(&'a [f32]),
}

/// What happens to each finished output element before it is stored.
#[derive(Clone, Copy, Debug)]
pub enum Finish<'a> {
    Store,
    /// max(x, 0): a ReLU layer's output.
    Relu,
    /// Zero where the matrix of the output's shape is not positive: the gradient through a ReLU whose output
    /// that matrix is.
    ReluGrad(MatRef<'a, f32>),
}

impl<'a> Start<'a> {
    pub fn of(accum: Accum) -> Start<'a> {
        match accum {
            Accum::Add => Start::Dst,
            Accum::Replace => Start::Zero,
        }
    }

    /// The start of the output's columns `from..from + count`.
    pub fn cols(self, from: usize, count: usize) -> Start<'a> {
        match self {
            Start::Row(row) => Start::Row(&row[from..from + count]),
            other => other,
        }
    }
}

impl<'a> Finish<'a> {
    /// The finish of the output's rows `from..from + count`.
    pub fn rows(self, from: usize, count: usize) -> Finish<'a> {
        match self {
            Finish::ReluGrad(y) => Finish::ReluGrad(y.subrows(from, count)),
            other => other,
        }
    }

    /// The finish of the output's columns `from..from + count`.
    pub fn cols(self, from: usize, count: usize) -> Finish<'a> {
        match self {
            Finish::ReluGrad(y) => Finish::ReluGrad(y.subcols(from, count)),
            other => other,
        }
    }
}

/// Which kernel runs a product. It is chosen once for the whole product, before any split over threads, so
/// that every piece runs the same one and the bytes do not depend on the split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    Faer,
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

impl Kernel {
    pub fn for_product(dst: &MatMut<'_, f32>, a: &MatRef<'_, f32>, b: &MatRef<'_, f32>) -> Kernel {
        let (m, n, k) = (dst.nrows(), dst.ncols(), a.ncols());
        #[cfg(target_arch = "x86_64")]
        if n >= MIN_COLS && m * k + k * n + m * n >= MIN_VALUES && avx512::fits(dst, a, b) {
            return Kernel::Avx512;
        }
        let _ = (m, n, k);
        Kernel::Faer
    }

    /// dst (m × n) = [dst +] a (m × k) · b (k × n), sequentially. `self` must be `for_product` of this product
    /// or of one it is a block of (rows or columns).
    pub fn product(self, dst: MatMut<'_, f32>, accum: Accum, a: MatRef<'_, f32>, b: MatRef<'_, f32>) {
        self.fused(dst, Start::of(accum), a, b, Finish::Store);
    }

    /// dst = finish(start + a · b), sequentially; a `Row` start has `n` values and a `ReluGrad` matrix is
    /// m × n. On faer the start and the finish are passes of their own; the AVX-512 kernel applies them to
    /// each tile in registers, which spares the training paths a pass over every layer's output.
    pub fn fused(
        self,
        mut dst: MatMut<'_, f32>,
        start: Start<'_>,
        a: MatRef<'_, f32>,
        b: MatRef<'_, f32>,
        finish: Finish<'_>,
    ) {
        let (m, n) = (dst.nrows(), dst.ncols());
        if let Start::Row(row) = start {
            assert_eq!(row.len(), n, "gemm: a start row needs one value per output column");
        }
        if let Finish::ReluGrad(y) = finish {
            assert!(y.nrows() == m && y.ncols() == n, "gemm: the ReLU output must have the output's shape");
        }
        match self {
            Kernel::Faer => {
                let accum = match start {
                    Start::Zero => Accum::Replace,
                    Start::Dst => Accum::Add,
                    Start::Row(row) => {
                        for i in 0..m {
                            dst.as_mut().row_mut(i).iter_mut().zip(row).for_each(|(x, value)| *x = *value);
                        }
                        Accum::Add
                    }
                };
                faer::linalg::matmul::matmul(dst.as_mut(), accum, a, b, 1.0f32, Par::Seq);
                finish_pass(dst, finish);
            }
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 => {
                assert!(avx512::fits(&dst, &a, &b), "gemm: the AVX-512 kernel was chosen for a layout it cannot read");
                let mask_by_rows = match finish {
                    Finish::ReluGrad(y) => y.col_stride() == 1 && y.row_stride() >= n as isize,
                    _ => true,
                };
                if mask_by_rows {
                    // SAFETY: `fits` checked that the CPU has AVX-512F and that the layouts are those the kernel
                    // reads; the start row and the ReLU output have the output's shape (asserted above), the
                    // ReLU output by rows.
                    unsafe { avx512::product(dst, start, a, b, finish) }
                } else {
                    // A ReLU output the tiles cannot read by rows: the mask as a pass of its own.
                    // SAFETY: as above, with no finish in the kernel.
                    unsafe { avx512::product(dst.as_mut(), start, a, b, Finish::Store) };
                    finish_pass(dst, finish);
                }
            }
        }
    }
}

/// The finish as a pass over `dst`, row by row.
fn finish_pass(mut dst: MatMut<'_, f32>, finish: Finish<'_>) {
    match finish {
        Finish::Store => {}
        Finish::Relu => {
            for i in 0..dst.nrows() {
                dst.as_mut().row_mut(i).iter_mut().for_each(|x| *x = x.max(0.0));
            }
        }
        Finish::ReluGrad(y) => {
            for i in 0..dst.nrows() {
                let zip = dst.as_mut().row_mut(i).iter_mut().zip(y.row(i).iter());
                zip.for_each(|(x, y)| *x = if *y <= 0.0 { 0.0 } else { *x });
            }
        }
    }
}

/// Every kernel this machine runs, faer first: for tests that hold each of them to the same contract.
#[cfg(test)]
pub(crate) fn available_kernels() -> Vec<Kernel> {
    let mut kernels = vec![Kernel::Faer];
    #[cfg(target_arch = "x86_64")]
    if is_x86_feature_detected!("avx512f") {
        kernels.push(Kernel::Avx512);
    }
    kernels
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;
    use std::sync::OnceLock;

    use faer::{MatMut, MatRef};

    use super::{Finish, Start};

    /// Output columns per kernel call: two 16-lane vectors.
    const NR: usize = 32;
    /// Output rows per kernel call: 12 × 2 accumulators leave registers for the right operand's two vectors and
    /// the broadcast.
    const MR: usize = 12;
    /// Inner-dimension block: one block of the right operand, packed, stays in the core's L2.
    const KC: usize = 256;

    fn has_avx512() -> bool {
        static DETECTED: OnceLock<bool> = OnceLock::new();
        *DETECTED.get_or_init(|| is_x86_feature_detected!("avx512f"))
    }

    /// The layouts the kernel is fast on: `dst` written by rows (which its masked stores need), `a` read along
    /// either axis with a unit stride and positive strides throughout (which its packing needs only for speed).
    pub(super) fn fits(dst: &MatMut<'_, f32>, a: &MatRef<'_, f32>, b: &MatRef<'_, f32>) -> bool {
        let unit_a = a.row_stride() == 1 || a.col_stride() == 1;
        let rows_of_dst = dst.col_stride() == 1 && dst.row_stride() >= dst.ncols() as isize;
        let strides_positive = a.row_stride() > 0 && a.col_stride() > 0 && b.row_stride() > 0 && b.col_stride() > 0;
        has_avx512() && unit_a && rows_of_dst && strides_positive && dst.ncols() > 0 && a.ncols() > 0
    }

    /// # Safety
    /// The CPU supports AVX-512F and `fits(&dst, &a, &b)` holds; a `Row` start has n values, a `ReluGrad`
    /// matrix is m × n with unit column stride.
    pub(super) unsafe fn product(
        dst: MatMut<'_, f32>,
        start: Start<'_>,
        a: MatRef<'_, f32>,
        b: MatRef<'_, f32>,
        finish: Finish<'_>,
    ) {
        let (m, n, k) = (dst.nrows(), dst.ncols(), a.ncols());
        assert!(a.nrows() == m && b.nrows() == k && b.ncols() == n, "gemm: operand shapes do not fit");
        let ldc = dst.row_stride() as usize;
        let c = dst.as_ptr_mut();
        let (ars, aks) = (a.row_stride(), a.col_stride());
        let panels = n.div_ceil(NR);
        // Lanes of the last panel past the output's last column hold zeros or an earlier block's values: they
        // feed only accumulator lanes that the masked stores leave out.
        let mut packed = vec![0.0f32; panels * KC.min(k) * NR];
        // One row block of `a` at a time, [k][row]: the kernel's broadcasts then read consecutive values.
        let mut a_block = vec![0.0f32; KC.min(k) * MR];
        for k0 in (0..k).step_by(KC) {
            let kc = (k - k0).min(KC);
            pack(b, k0, kc, &mut packed);
            // The start applies to the first block of the inner dimension, the finish to the last.
            let (begin, row) = match start {
                _ if k0 > 0 => (Begin::Load, std::ptr::null()),
                Start::Zero => (Begin::Zero, std::ptr::null()),
                Start::Dst => (Begin::Load, std::ptr::null()),
                Start::Row(row) => (Begin::Row, row.as_ptr()),
            };
            let (end, relu_out, ldy) = match finish {
                _ if k0 + kc < k => (End::Store, std::ptr::null(), 0),
                Finish::Store => (End::Store, std::ptr::null(), 0),
                Finish::Relu => (End::Relu, std::ptr::null(), 0),
                Finish::ReluGrad(y) => (End::ReluGrad, y.as_ptr(), y.row_stride() as usize),
            };
            for i0 in (0..m).step_by(MR) {
                let rows = (m - i0).min(MR);
                pack_rows(a.subrows(i0, rows).subcols(k0, kc), &mut a_block);
                // Rows read along k stream from memory: the next block's are fetched while this one works.
                let (next_a, prefetch_rows) = if aks == 1 && i0 + MR < m {
                    // SAFETY: row i0 + MR < m, column k0 < k: inside `a`.
                    (unsafe { a.as_ptr().offset((i0 + MR) as isize * ars + k0 as isize) }, (m - i0 - MR).min(MR))
                } else {
                    (a.as_ptr(), 0)
                };
                for p in 0..panels {
                    let j0 = p * NR;
                    let cols = (n - j0).min(NR);
                    // SAFETY: (i0, j0) lies inside `dst`, and so does (i0 + MR, 0) where it is taken.
                    let tile = unsafe { c.add(i0 * ldc + j0) };
                    let next_tile = if p + 1 < panels {
                        unsafe { tile.add(NR) }
                    } else if i0 + MR < m {
                        unsafe { c.add((i0 + MR) * ldc) }
                    } else {
                        tile
                    };
                    let call = Call {
                        a: a_block.as_ptr(),
                        b: unsafe { packed.as_ptr().add(p * kc * NR) },
                        kc,
                        c: tile,
                        ldc,
                        masks: masks(cols),
                        begin,
                        // SAFETY: column j0 < n of the start row and (i0, j0) of the ReLU output exist.
                        row: if row.is_null() { row } else { unsafe { row.add(j0) } },
                        end,
                        relu_out: if relu_out.is_null() { relu_out } else { unsafe { relu_out.add(i0 * ldy + j0) } },
                        ldy,
                        next_c: next_tile,
                        next_a,
                        next_a_stride: ars,
                        prefetch_rows: if p == 0 { prefetch_rows } else { 0 },
                    };
                    // SAFETY: the tile's `rows` × `cols` values lie inside `dst` (masks cover the columns), the
                    // packed blocks hold kc steps, and the caller guarantees AVX-512F.
                    unsafe { dispatch(rows, cols > 16, &call) };
                }
            }
        }
    }

    /// A block of `a`'s rows as [k][MR] (slots past its last row are left as they were: a kernel for fewer
    /// rows never reads them).
    fn pack_rows(rows: MatRef<'_, f32>, out: &mut [f32]) {
        if rows.col_stride() == 1 {
            for r in 0..rows.nrows() {
                for (kk, value) in rows.row(r).iter().enumerate() {
                    out[kk * MR + r] = *value;
                }
            }
        } else {
            for kk in 0..rows.ncols() {
                for (r, value) in rows.col(kk).iter().enumerate() {
                    out[kk * MR + r] = *value;
                }
            }
        }
    }

    /// Lanes of each of a tile's two vectors that lie inside the output.
    fn masks(cols: usize) -> [__mmask16; 2] {
        let lanes = |count: usize| if count >= 16 { 0xffff } else { ((1u32 << count) - 1) as __mmask16 };
        [lanes(cols), lanes(cols.saturating_sub(16))]
    }

    /// Rows k0..k0 + kc of `b` as panels of 32 columns, [panel][k][32].
    fn pack(b: MatRef<'_, f32>, k0: usize, kc: usize, packed: &mut [f32]) {
        let n = b.ncols();
        for p in 0..n.div_ceil(NR) {
            let cols = (n - p * NR).min(NR);
            let panel = &mut packed[p * kc * NR..(p + 1) * kc * NR];
            if b.col_stride() == 1 {
                for (kk, row) in panel.chunks_exact_mut(NR).enumerate() {
                    let src = b.subrows(k0 + kk, 1).subcols(p * NR, cols);
                    // SAFETY: a 1 × cols view with unit column stride is `cols` contiguous values.
                    let src = unsafe { std::slice::from_raw_parts(src.as_ptr(), cols) };
                    row[..cols].copy_from_slice(src);
                }
            } else {
                for jj in 0..cols {
                    let column = b.col(p * NR + jj).subrows(k0, kc);
                    for (kk, value) in column.iter().enumerate() {
                        panel[kk * NR + jj] = *value;
                    }
                }
            }
        }
    }

    #[derive(Clone, Copy, PartialEq)]
    enum Begin {
        Zero,
        Load,
        Row,
    }

    #[derive(Clone, Copy, PartialEq)]
    enum End {
        Store,
        Relu,
        ReluGrad,
    }

    struct Call {
        /// The row block, [k][MR].
        a: *const f32,
        b: *const f32,
        kc: usize,
        c: *mut f32,
        ldc: usize,
        masks: [__mmask16; 2],
        begin: Begin,
        /// The start row at the tile's first column.
        row: *const f32,
        end: End,
        /// The ReLU output at the tile's first element, and its row stride.
        relu_out: *const f32,
        ldy: usize,
        next_c: *const f32,
        next_a: *const f32,
        next_a_stride: isize,
        prefetch_rows: usize,
    }

    macro_rules! by_rows {
        ($rows:expr, $v:literal, $call:expr) => {
            match $rows {
                12 => kernel::<12, $v>($call),
                11 => kernel::<11, $v>($call),
                10 => kernel::<10, $v>($call),
                9 => kernel::<9, $v>($call),
                8 => kernel::<8, $v>($call),
                7 => kernel::<7, $v>($call),
                6 => kernel::<6, $v>($call),
                5 => kernel::<5, $v>($call),
                4 => kernel::<4, $v>($call),
                3 => kernel::<3, $v>($call),
                2 => kernel::<2, $v>($call),
                _ => kernel::<1, $v>($call),
            }
        };
    }

    #[target_feature(enable = "avx512f")]
    unsafe fn dispatch(rows: usize, two_vectors: bool, call: &Call) {
        if two_vectors {
            by_rows!(rows, 2, call)
        } else {
            by_rows!(rows, 1, call)
        }
    }

    /// One R × 16·V tile of the output over kc steps of the inner dimension.
    #[target_feature(enable = "avx512f")]
    unsafe fn kernel<const R: usize, const V: usize>(call: &Call) {
        let &Call { a, b, kc, c, ldc, masks, begin, row, end, next_c, next_a, next_a_stride, prefetch_rows, .. } = call;
        unsafe {
            // Prefetch addresses may lie past the output's last row or column (a shorter next block): a
            // prefetch never faults, and wrapping arithmetic keeps the pointer computation defined.
            for r in 0..R {
                for v in 0..V {
                    _mm_prefetch::<_MM_HINT_T0>(next_c.wrapping_add(r * ldc + 16 * v) as *const i8);
                }
            }
            let mut acc = [[_mm512_setzero_ps(); V]; R];
            match begin {
                Begin::Zero => {}
                Begin::Load => {
                    for (r, values) in acc.iter_mut().enumerate() {
                        for (v, lane) in values.iter_mut().enumerate() {
                            *lane = _mm512_maskz_loadu_ps(masks[v], c.add(r * ldc + 16 * v));
                        }
                    }
                }
                Begin::Row => {
                    for values in acc.iter_mut() {
                        for (v, lane) in values.iter_mut().enumerate() {
                            *lane = _mm512_maskz_loadu_ps(masks[v], row.add(16 * v));
                        }
                    }
                }
            }
            // The next rows' kc values, one 16-value line per step, row by row.
            let lines_per_row = kc.div_ceil(16);
            let prefetch_steps = prefetch_rows * lines_per_row;
            for kk in 0..kc {
                if kk < prefetch_steps {
                    let (ahead, line) = (kk / lines_per_row, kk % lines_per_row);
                    _mm_prefetch::<_MM_HINT_T0>(
                        next_a.wrapping_offset(ahead as isize * next_a_stride + 16 * line as isize) as *const i8,
                    );
                }
                let mut bv = [_mm512_setzero_ps(); V];
                for (v, lane) in bv.iter_mut().enumerate() {
                    *lane = _mm512_loadu_ps(b.add(kk * NR + 16 * v));
                }
                let a_k = a.add(kk * MR);
                for (r, values) in acc.iter_mut().enumerate() {
                    let broadcast = _mm512_set1_ps(*a_k.add(r));
                    for (v, lane) in values.iter_mut().enumerate() {
                        *lane = _mm512_fmadd_ps(broadcast, bv[v], *lane);
                    }
                }
            }
            for (r, values) in acc.iter().enumerate() {
                for (v, lane) in values.iter().enumerate() {
                    _mm512_mask_storeu_ps(c.add(r * ldc + 16 * v), masks[v], *lane);
                }
            }
            if end != End::Store {
                finish_tile::<R, V>(call);
            }
        }
    }

    /// The finish applied to a tile the kernel just stored (still in L1). A pass of its own: inside the kernel
    /// it took registers the accumulators need, and they spilled.
    #[inline(never)]
    #[target_feature(enable = "avx512f")]
    unsafe fn finish_tile<const R: usize, const V: usize>(call: &Call) {
        let &Call { c, ldc, masks, end, relu_out, ldy, .. } = call;
        let zero = _mm512_setzero_ps();
        for r in 0..R {
            for (v, &mask) in masks.iter().enumerate().take(V) {
                unsafe {
                    let at = c.add(r * ldc + 16 * v);
                    let value = _mm512_maskz_loadu_ps(mask, at);
                    let value = match end {
                        End::Store => value,
                        // max_ps gives its second operand where the first is NaN: 0, as f32::max does.
                        End::Relu => _mm512_max_ps(value, zero),
                        End::ReluGrad => {
                            let y = _mm512_maskz_loadu_ps(mask, relu_out.add(r * ldy + 16 * v));
                            // Zero where y ≤ 0 (a NaN y keeps the gradient, as relu_backward does).
                            _mm512_mask_mov_ps(value, _mm512_cmp_ps_mask::<_CMP_LE_OQ>(y, zero), zero)
                        }
                    };
                    _mm512_mask_storeu_ps(at, mask, value);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use faer::Mat;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// The product in f64, element by element.
    fn reference(c0: &Mat<f32>, accum: Accum, a: MatRef<'_, f32>, b: MatRef<'_, f32>) -> Mat<f64> {
        Mat::from_fn(c0.nrows(), c0.ncols(), |i, j| {
            let start = if matches!(accum, Accum::Add) { c0[(i, j)] as f64 } else { 0.0 };
            start + (0..a.ncols()).map(|k| a[(i, k)] as f64 * b[(k, j)] as f64).sum::<f64>()
        })
    }

    fn random(rows: usize, cols: usize, rng: &mut ChaCha8Rng) -> Mat<f32> {
        Mat::from_fn(rows, cols, |_, _| rng.random_range(-1.0..1.0))
    }

    /// Row-major (a buffer's rows) or column-major storage of the same values.
    fn stored(values: &Mat<f32>, row_major: bool) -> Mat<f32> {
        if row_major {
            values.transpose().to_owned()
        } else {
            values.clone()
        }
    }

    #[test]
    fn matches_an_f64_product_for_every_layout_and_ragged_edge() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        // Operands past MIN_VALUES with a ragged last row block, columns with one- and two-vector tails, inner
        // sizes across the 256 block, and a weight gradient's shape (few rows, a long inner dimension).
        for &(m, n, k) in
            &[(2031, 300, 9), (1024, 600, 200), (1100, 257, 300), (1037, 280, 513), (2000, 270, 1), (40, 600, 9000)]
        {
            for accum in [Accum::Replace, Accum::Add] {
                for (a_rows, b_rows) in [(true, true), (false, true), (true, false), (false, false)] {
                    let (a, b, c0) = (random(m, k, &mut rng), random(k, n, &mut rng), random(m, n, &mut rng));
                    let a_stored = stored(&a, a_rows);
                    let a_view = if a_rows { a_stored.transpose() } else { a_stored.as_ref() };
                    let b_stored = stored(&b, b_rows);
                    let b_view = if b_rows { b_stored.transpose() } else { b_stored.as_ref() };
                    // dst as a row-major buffer, as the training paths hold it.
                    let mut buffer: Vec<f32> = (0..m * n).map(|x| c0[(x / n, x % n)]).collect();
                    let dst = MatMut::from_row_major_slice_mut(&mut buffer, m, n);
                    let kernel = Kernel::for_product(&dst, &a_view, &b_view);
                    #[cfg(target_arch = "x86_64")]
                    if is_x86_feature_detected!("avx512f") {
                        assert_eq!(kernel, Kernel::Avx512, "{m}×{n}×{k}");
                    }
                    kernel.product(dst, accum, a_view, b_view);
                    let expected = reference(&c0, accum, a.as_ref(), b.as_ref());
                    for (x, got) in buffer.iter().enumerate() {
                        let want = expected[(x / n, x % n)];
                        let tol = 1e-5 * (k as f64).sqrt() * 4.0;
                        assert!(
                            (*got as f64 - want).abs() <= tol,
                            "{m}×{n}×{k} {accum:?} a rows {a_rows} b rows {b_rows} at {x}: {got} vs {want}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_bias_start_and_a_relu_finish_are_applied_in_place() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for &(m, n, k) in &[(1031, 300, 9), (1030, 45, 600), (1100, 17, 260)] {
            let (a, b) = (random(m, k, &mut rng), random(k, n, &mut rng));
            let bias: Vec<f32> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            // A ReLU output with zeros, positives and a NaN, which keeps its gradient as relu_backward does.
            let mut relu_out: Vec<f32> = (0..m * n).map(|_| rng.random_range(-1.0f32..1.0).max(0.0)).collect();
            relu_out[7] = f32::NAN;
            let y = MatRef::from_row_major_slice(&relu_out, m, n);
            let plain = reference(&Mat::zeros(m, n), Accum::Replace, a.as_ref(), b.as_ref());
            for kernel in available_kernels() {
                let mut with_bias = vec![0.0f32; m * n];
                let dst = MatMut::from_row_major_slice_mut(&mut with_bias, m, n);
                kernel.fused(dst, Start::Row(&bias), a.as_ref(), b.as_ref(), Finish::Relu);
                let mut masked = vec![1.0f32; m * n];
                let dst = MatMut::from_row_major_slice_mut(&mut masked, m, n);
                kernel.fused(dst, Start::Zero, a.as_ref(), b.as_ref(), Finish::ReluGrad(y));
                let tol = 1e-5 * (k as f64).sqrt() * 4.0;
                for x in 0..m * n {
                    let (i, j) = (x / n, x % n);
                    let want_relu = (plain[(i, j)] + bias[j] as f64).max(0.0);
                    let want_grad = if relu_out[x] <= 0.0 { 0.0 } else { plain[(i, j)] };
                    assert!((with_bias[x] as f64 - want_relu).abs() <= tol, "{kernel:?} relu {m}×{n}×{k} at {x}");
                    assert!((masked[x] as f64 - want_grad).abs() <= tol, "{kernel:?} relu grad {m}×{n}×{k} at {x}");
                }
            }
        }
    }

    #[test]
    fn each_row_is_the_same_whatever_the_split() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let (m, n, k) = (1000, 270, 300);
        let (a, b) = (random(m, k, &mut rng), random(k, n, &mut rng));
        let mut whole = vec![0.0f32; m * n];
        let dst = MatMut::from_row_major_slice_mut(&mut whole, m, n);
        // Chosen once for the whole product, as backprop::matmul chooses; the pieces are too small to be
        // given the AVX-512 kernel on their own.
        let kernel = Kernel::for_product(&dst, &a.as_ref(), &b.as_ref());
        assert_eq!(available_kernels().last(), Some(&kernel));
        kernel.product(dst, Accum::Replace, a.as_ref(), b.as_ref());
        let mut pieces = vec![0.0f32; m * n];
        let mid = 437;
        let (top, bottom) = pieces.split_at_mut(mid * n);
        let top = MatMut::from_row_major_slice_mut(top, mid, n);
        kernel.product(top, Accum::Replace, a.subrows(0, mid), b.as_ref());
        let bottom = MatMut::from_row_major_slice_mut(bottom, m - mid, n);
        kernel.product(bottom, Accum::Replace, a.subrows(mid, m - mid), b.as_ref());
        assert!(whole.iter().zip(&pieces).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
}
