//! f32 matrix products for the hand-written training paths, on one thread (`backprop::matmul` splits work over
//! the pool and calls this per piece).
//!
//! faer's kernels reach 150-170 GFLOP/s on cache-sized products here, but 110-135 on the training paths' tall
//! ones (25 000-75 000 rows by 200 inner by 200-600 out): they start each output tile with a load that misses
//! every cache level and wait for it. On AVX-512 machines those products run through the kernel below, which
//! prefetches the next output tile and the next rows of the left operand while it works on the current ones,
//! and which starts each tile from a bias row (or from a matrix the caller keeps) and ends it with a ReLU (or a
//! ReLU's gradient mask) in cache: the passes that wrote the bias rows and applied the activation over every
//! layer's output cost the context model's step as much again as the kernel saves.
//!
//! Products small enough to stay in cache went to faer until 2026-11-29: timed alone, with their operands hot,
//! the two kernels came within about 15 % of each other on SAC's and DLGPD's shapes, faer ahead on most, but
//! inside the training steps this one ran SAC's update 9-12 % faster and DLGPD's convolutions 1-7 % faster (interleaved A/B runs of the training-step
//! bench). So every product this kernel reads goes to it; faer does the rest (outputs narrower than a vector,
//! other layouts, machines without AVX-512), with the start and the finish as passes of their own.
//!
//! On either kernel every output element is one thread's sum in one order (on this one: its start, then
//! k = 0, 1, … by fused multiply-adds), whatever the split of rows or columns around it, and the kernel is
//! chosen from the whole product's shape: the bytes do not depend on the thread count.

use faer::{Accum, MatMut, MatRef, Par};

use crate::util::wide::clean_upper_state;

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
    /// The matrix of the output's shape (gates the caller summed so far, kept for another use).
    Matrix(MatRef<'a, f32>),
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
    /// Times the matrix of the output's shape, element by element: the gradient through an activation whose
    /// slopes that matrix holds.
    Scale(MatRef<'a, f32>),
}

impl<'a> Start<'a> {
    pub fn of(accum: Accum) -> Start<'a> {
        match accum {
            Accum::Add => Start::Dst,
            Accum::Replace => Start::Zero,
        }
    }

    /// The start of the output's rows `from..from + count`.
    pub fn rows(self, from: usize, count: usize) -> Start<'a> {
        match self {
            Start::Matrix(start) => Start::Matrix(start.subrows(from, count)),
            other => other,
        }
    }

    /// The start of the output's columns `from..from + count`.
    pub fn cols(self, from: usize, count: usize) -> Start<'a> {
        match self {
            Start::Row(row) => Start::Row(&row[from..from + count]),
            Start::Matrix(start) => Start::Matrix(start.subcols(from, count)),
            other => other,
        }
    }
}

impl<'a> Finish<'a> {
    /// The finish of the output's rows `from..from + count`.
    pub fn rows(self, from: usize, count: usize) -> Finish<'a> {
        match self {
            Finish::ReluGrad(y) => Finish::ReluGrad(y.subrows(from, count)),
            Finish::Scale(y) => Finish::Scale(y.subrows(from, count)),
            other => other,
        }
    }

    /// The finish of the output's columns `from..from + count`.
    pub fn cols(self, from: usize, count: usize) -> Finish<'a> {
        match self {
            Finish::ReluGrad(y) => Finish::ReluGrad(y.subcols(from, count)),
            Finish::Scale(y) => Finish::Scale(y.subcols(from, count)),
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
        #[cfg(target_arch = "x86_64")]
        if dst.ncols() >= MIN_COLS && avx512::fits(dst, a, b) {
            return Kernel::Avx512;
        }
        let _ = (dst, a, b);
        Kernel::Faer
    }

    /// dst (m × n) = [dst +] a (m × k) · b (k × n), sequentially. `self` must be `for_product` of this product
    /// or of one it is a block of (rows or columns).
    pub fn product(self, dst: MatMut<'_, f32>, accum: Accum, a: MatRef<'_, f32>, b: MatRef<'_, f32>) {
        self.fused(dst, Start::of(accum), a, b, Finish::Store);
    }

    /// dst = finish(start + a · b), sequentially; a `Row` start has `n` values and a `ReluGrad` or `Scale`
    /// matrix is m × n. On faer the start and the finish are passes of their own; the AVX-512 kernel applies them to
    /// each tile in registers, which spares the training paths a pass over every layer's output.
    pub fn fused(
        self,
        dst: MatMut<'_, f32>,
        start: Start<'_>,
        a: MatRef<'_, f32>,
        b: MatRef<'_, f32>,
        finish: Finish<'_>,
    ) {
        self.fused_summing(dst, start, a, b, finish, None);
    }

    /// [`Kernel::fused`], and with `row_sums` (m values) also row_sums[i] += Σ_k a[i, k], each summed in order
    /// of k: a layer's bias gradient beside its weight gradient dYᵀ·X, which the AVX-512 kernel adds up as it
    /// packs dYᵀ instead of in a pass of its own over dY.
    pub fn fused_summing(
        self,
        mut dst: MatMut<'_, f32>,
        start: Start<'_>,
        a: MatRef<'_, f32>,
        b: MatRef<'_, f32>,
        finish: Finish<'_>,
        row_sums: Option<&mut [f32]>,
    ) {
        let (m, n) = (dst.nrows(), dst.ncols());
        if let Some(sums) = &row_sums {
            assert_eq!(sums.len(), m, "gemm: row sums need one value per row of a");
        }
        match start {
            Start::Row(row) => assert_eq!(row.len(), n, "gemm: a start row needs one value per output column"),
            Start::Matrix(start) => {
                assert!(start.nrows() == m && start.ncols() == n, "gemm: the start matrix must have the output's shape")
            }
            Start::Zero | Start::Dst => {}
        }
        if let Finish::ReluGrad(y) | Finish::Scale(y) = finish {
            assert!(y.nrows() == m && y.ncols() == n, "gemm: a finish matrix must have the output's shape");
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
                    Start::Matrix(start) => {
                        dst.copy_from(start);
                        Accum::Add
                    }
                };
                faer_product(dst.as_mut(), accum, a, b);
                finish_pass(dst, finish);
                if let Some(sums) = row_sums {
                    add_row_sums(sums, a);
                }
            }
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 => {
                assert!(avx512::fits(&dst, &a, &b), "gemm: the AVX-512 kernel was chosen for a layout it cannot read");
                let mask_by_rows = match finish {
                    Finish::ReluGrad(y) | Finish::Scale(y) => y.col_stride() == 1 && y.row_stride() >= n as isize,
                    _ => true,
                };
                if let Start::Matrix(source) = start {
                    if source.col_stride() != 1 || source.row_stride() < 0 {
                        // A start the tiles cannot read by rows, forwards: copied into the output first.
                        dst.copy_from(source);
                        return Kernel::Avx512.fused_summing(dst, Start::Dst, a, b, finish, row_sums);
                    }
                }
                if mask_by_rows {
                    // SAFETY: `fits` checked that the CPU has AVX-512F and that the layouts are those the kernel
                    // reads; the start row and the ReLU output have the output's shape (asserted above), the
                    // ReLU output by rows.
                    unsafe { avx512::product(dst, start, a, avx512::Right::Matrix(b), finish, row_sums) }
                } else {
                    // A ReLU output the tiles cannot read by rows: the mask as a pass of its own.
                    // SAFETY: as above, with no finish in the kernel.
                    unsafe {
                        avx512::product(dst.as_mut(), start, a, avx512::Right::Matrix(b), Finish::Store, row_sums)
                    };
                    finish_pass(dst, finish);
                }
            }
        }
    }
}

/// dst = [dst +] a · b on faer's kernels, on the calling thread, with the vector registers cleared after them
/// for the baseline code that follows (see [`clean_upper_state`]). Every f32 product that goes to faer goes
/// through here (clippy.toml disallows calling faer's `matmul` directly).
#[allow(clippy::disallowed_methods)]
pub fn faer_product(dst: MatMut<'_, f32>, accum: Accum, a: MatRef<'_, f32>, b: MatRef<'_, f32>) {
    faer::linalg::matmul::matmul(dst, accum, a, b, 1.0f32, Par::Seq);
    clean_upper_state();
}

/// A right operand packed once for the AVX-512 kernel, for a product run many times over it (a convolution's
/// weight, chunk after chunk of images): packing the weight for every chunk was a third of the kernel's
/// packing in DLGPD's step.
pub struct PackedRight<V = Vec<f32>> {
    values: V,
    k: usize,
    n: usize,
}

/// Columns per panel of a packed right operand.
pub const PACKED_PANEL: usize = 32;
/// Rows per block of a packed right operand.
const PACKED_ROWS: usize = 256;

/// Where the values of row `row`, columns `col..col + PACKED_PANEL` (`col` a multiple of the panel), lie in a
/// k × n right operand packed as [`PackedRight`] holds it: blocks of 256 rows, each block by panels.
pub fn packed_offset(k: usize, n: usize, row: usize, col: usize) -> usize {
    debug_assert!(row < k && col < n && col.is_multiple_of(PACKED_PANEL));
    let (k0, panels) = (row - row % PACKED_ROWS, n.div_ceil(PACKED_PANEL));
    let kc = (k - k0).min(PACKED_ROWS);
    k0 * panels * PACKED_PANEL + (col / PACKED_PANEL) * kc * PACKED_PANEL + (row - k0) * PACKED_PANEL
}

impl PackedRight {
    /// `b` packed, or `None` where the AVX-512 kernel does not run (that product then goes to faer with `b`).
    pub fn new(b: MatRef<'_, f32>) -> Option<PackedRight> {
        #[cfg(target_arch = "x86_64")]
        if b.ncols() >= MIN_COLS && b.nrows() > 0 && b.row_stride() > 0 && b.col_stride() > 0 && avx512::has_avx512() {
            // SAFETY: the CPU has AVX-512F (checked just above).
            let values = unsafe { avx512::pack_whole(b) };
            return Some(PackedRight { values, k: b.nrows(), n: b.ncols() });
        }
        let _ = b;
        None
    }
}

impl<'a> PackedRight<&'a [f32]> {
    /// A k × n operand whose values the caller wrote where [`packed_offset`] puts them (n a whole number of
    /// panels), or `None` where the AVX-512 kernel does not run.
    pub fn from_packed(values: &'a [f32], k: usize, n: usize) -> Option<Self> {
        assert!(n.is_multiple_of(PACKED_PANEL) && values.len() == k * n, "gemm: packed values of another shape");
        #[cfg(target_arch = "x86_64")]
        if n >= MIN_COLS && k > 0 && avx512::has_avx512() {
            return Some(PackedRight { values, k, n });
        }
        None
    }
}

impl<V: AsRef<[f32]>> PackedRight<V> {
    /// dst = finish(start + a · self), sequentially on the AVX-512 kernel; `None` (nothing written) where the
    /// kernel does not read this output or left operand.
    pub fn fused_product(
        &self,
        dst: MatMut<'_, f32>,
        start: Start<'_>,
        a: MatRef<'_, f32>,
        finish: Finish<'_>,
    ) -> Option<()> {
        assert!(
            a.ncols() == self.k && dst.ncols() == self.n && dst.nrows() == a.nrows(),
            "gemm: operand shapes do not fit"
        );
        if let Start::Row(row) = start {
            assert_eq!(row.len(), self.n, "gemm: a start row needs one value per output column");
        }
        // The starts and finishes that need no matrix beside the output.
        let plain = matches!((start, finish), (Start::Zero | Start::Dst | Start::Row(_), Finish::Store | Finish::Relu));
        #[cfg(target_arch = "x86_64")]
        if plain && avx512::fits_left(&dst, &a) {
            let view = avx512::PackedView {
                values: self.values.as_ref(),
                panels: self.n.div_ceil(PACKED_PANEL),
                first_panel: 0,
                k: self.k,
                n: self.n,
            };
            // SAFETY: the kernel runs here and reads these layouts (checked above); the packed operand has the
            // product's shape and a start row n values (asserted).
            unsafe { avx512::product(dst, start, a, avx512::Right::Packed(view), finish, None) };
            return Some(());
        }
        let _ = (dst, start, a, finish);
        None
    }
}

/// sums[i] += Σ_k a[i, k], in order of k.
fn add_row_sums(sums: &mut [f32], a: MatRef<'_, f32>) {
    for (i, sum) in sums.iter_mut().enumerate() {
        *sum = a.row(i).iter().fold(*sum, |total, x| total + x);
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
        Finish::Scale(y) => {
            for i in 0..dst.nrows() {
                dst.as_mut().row_mut(i).iter_mut().zip(y.row(i).iter()).for_each(|(x, y)| *x *= *y);
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
    const NR: usize = super::PACKED_PANEL;
    /// Output rows per kernel call: 12 × 2 accumulators leave registers for the right operand's two vectors and
    /// the broadcast.
    const MR: usize = 12;
    /// Inner-dimension block: one block of the right operand, packed, stays in the core's L2.
    const KC: usize = super::PACKED_ROWS;
    /// Widest column block: a packed KC × NC block of the right operand (768 KiB) stays in L2 beside the
    /// rows of `a` it meets. Wider outputs (a transposed convolution's 3200 columns) are cut into equal
    /// blocks; streaming a 3 MiB block from L3 for every 12 rows cost those products a third of their speed.
    const NC: usize = 768;

    pub(super) fn has_avx512() -> bool {
        static DETECTED: OnceLock<bool> = OnceLock::new();
        *DETECTED.get_or_init(|| is_x86_feature_detected!("avx512f"))
    }

    /// The right operand of a product: a matrix the kernel packs block by block, or one packed before.
    #[derive(Clone, Copy)]
    pub(super) enum Right<'a> {
        Matrix(MatRef<'a, f32>),
        Packed(PackedView<'a>),
    }

    /// Columns `first_panel · NR..` (`n` of them) of a [`super::PackedRight`].
    #[derive(Clone, Copy)]
    pub(super) struct PackedView<'a> {
        pub values: &'a [f32],
        /// Panels of the whole operand: a block of k rows spans all of them.
        pub panels: usize,
        pub first_panel: usize,
        pub k: usize,
        pub n: usize,
    }

    impl Right<'_> {
        fn nrows(&self) -> usize {
            match self {
                Right::Matrix(b) => b.nrows(),
                Right::Packed(view) => view.k,
            }
        }

        fn ncols(&self) -> usize {
            match self {
                Right::Matrix(b) => b.ncols(),
                Right::Packed(view) => view.n,
            }
        }

        /// Columns j0..j0 + cols; a packed operand is cut at whole panels only.
        fn subcols(self, j0: usize, cols: usize) -> Self {
            match self {
                Right::Matrix(b) => Right::Matrix(b.subcols(j0, cols)),
                Right::Packed(view) => {
                    assert!(j0.is_multiple_of(NR) && j0 + cols <= view.n, "gemm: a packed operand cut inside a panel");
                    Right::Packed(PackedView { first_panel: view.first_panel + j0 / NR, n: cols, ..view })
                }
            }
        }
    }

    /// `b` as the kernel reads its blocks: [k block][panel][kc][NR], every block of KC rows but the last.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn pack_whole(b: MatRef<'_, f32>) -> Vec<f32> {
        let (k, panels) = (b.nrows(), b.ncols().div_ceil(NR));
        let mut values = vec![0.0; k * panels * NR];
        for k0 in (0..k).step_by(KC) {
            let kc = (k - k0).min(KC);
            // SAFETY: the caller guarantees AVX-512F; the block holds kc rows of every panel.
            unsafe { pack(b, k0, kc, &mut values[k0 * panels * NR..][..kc * panels * NR]) };
        }
        values
    }

    /// Whether the kernel reads a product with this output and left operand (its right operand packed).
    pub(super) fn fits_left(dst: &MatMut<'_, f32>, a: &MatRef<'_, f32>) -> bool {
        let unit_a = a.row_stride() == 1 || a.col_stride() == 1;
        let rows_of_dst = dst.col_stride() == 1 && dst.row_stride() >= dst.ncols() as isize;
        has_avx512()
            && unit_a
            && rows_of_dst
            && a.row_stride() > 0
            && a.col_stride() > 0
            && dst.ncols() > 0
            && a.ncols() > 0
    }

    /// The layouts the kernel reads: `dst` written by rows (which its masked stores need), `a` with a unit
    /// stride along one axis (it reads `a` by rows in place and packs it by columns), positive strides.
    pub(super) fn fits(dst: &MatMut<'_, f32>, a: &MatRef<'_, f32>, b: &MatRef<'_, f32>) -> bool {
        fits_left(dst, a) && b.row_stride() > 0 && b.col_stride() > 0
    }

    /// # Safety
    /// The CPU supports AVX-512F and `fits(&dst, &a, &b)` holds; a `Row` start has n values, a `Matrix` start
    /// and a `ReluGrad` or `Scale` matrix are m × n with unit column stride (the start also with a row stride ≥ 0),
    /// `row_sums` has m values. A tile's second vector may lie past a buffer's end where its mask is empty:
    /// masked loads and stores never touch those lanes, and its address is computed with wrapping arithmetic.
    pub(super) unsafe fn product(
        dst: MatMut<'_, f32>,
        start: Start<'_>,
        a: MatRef<'_, f32>,
        b: Right<'_>,
        finish: Finish<'_>,
        mut row_sums: Option<&mut [f32]>,
    ) {
        let (m, n, k) = (dst.nrows(), dst.ncols(), a.ncols());
        assert!(a.nrows() == m && b.nrows() == k && b.ncols() == n, "gemm: operand shapes do not fit");
        if let Right::Packed(packed) = b {
            assert!(packed.values.len() >= k * packed.panels * NR, "gemm: a packed operand shorter than its shape");
        }
        let column_blocks = n.div_ceil(NC);
        if column_blocks > 1 {
            // Every element still sums its start and then k in order, in the same KC blocks: cutting the
            // columns changes no bytes. The row sums are taken once, with the first block.
            let width = n.div_ceil(column_blocks).next_multiple_of(NR);
            let mut dst = dst;
            for j0 in (0..n).step_by(width) {
                let cols = width.min(n - j0);
                let block = dst.as_mut().subcols_mut(j0, cols);
                let (start, finish) = (start.cols(j0, cols), finish.cols(j0, cols));
                // SAFETY: a block of columns keeps the layouts `fits` checked and the caller's guarantees.
                unsafe { product(block, start, a, b.subcols(j0, cols), finish, row_sums.take()) };
            }
            return;
        }
        let ldc = dst.row_stride() as usize;
        let c = dst.as_ptr_mut();
        let (ars, aks) = (a.row_stride(), a.col_stride());
        let panels = n.div_ceil(NR);
        // Each thread keeps its packing buffers from product to product (zeroing a fresh 0.1-0.8 MiB one for
        // every conv chunk cost DLGPD's step 3 %); a product nested in another's use of them takes new ones.
        // Lanes of the last panel past the output's last column hold zeros or values of an earlier block or
        // product: they feed only accumulator lanes that the masked stores leave out.
        let (mut packed, mut a_block) = PACKING_BUFFERS.take();
        if let Right::Matrix(_) = b {
            grow(&mut packed, panels * KC.min(k) * NR);
        }
        // `a` stored by rows is read in place, its 12 rows' values consecutive along k. Stored by columns (a
        // weight gradient's dYᵀ), its row block is packed as [k][row]: read in place, each k's 12 values sit
        // on lines of their own, which crowd the right operand's panel out of L1 (8 % slower).
        let a_by_rows = aks == 1;
        let lda = if a_by_rows { ars as usize } else { MR };
        if !a_by_rows {
            grow(&mut a_block, KC.min(k) * MR);
        }
        for k0 in (0..k).step_by(KC) {
            let kc = (k - k0).min(KC);
            let b_block = match b {
                Right::Matrix(b) => {
                    // SAFETY: the caller guarantees AVX-512F.
                    unsafe { pack(b, k0, kc, &mut packed) };
                    packed.as_ptr()
                }
                // Blocks before k0 hold KC rows of every panel; this one kc rows of each.
                Right::Packed(right) => right.values[k0 * right.panels * NR + right.first_panel * kc * NR..].as_ptr(),
            };
            // The start applies to the first block of the inner dimension, the finish to the last.
            // A `Matrix` start is read as the output is on later blocks: from a tile of rows `lds` apart.
            let (begin, row, start_at, lds) = match start {
                _ if k0 > 0 => (Begin::Load, std::ptr::null(), c.cast_const(), ldc),
                Start::Zero => (Begin::Zero, std::ptr::null(), c.cast_const(), ldc),
                Start::Dst => (Begin::Load, std::ptr::null(), c.cast_const(), ldc),
                Start::Row(row) => (Begin::Row, row.as_ptr(), c.cast_const(), ldc),
                Start::Matrix(source) => (Begin::Load, std::ptr::null(), source.as_ptr(), source.row_stride() as usize),
            };
            let (end, finish_from, ldf) = match finish {
                _ if k0 + kc < k => (End::Store, std::ptr::null(), 0),
                Finish::Store => (End::Store, std::ptr::null(), 0),
                Finish::Relu => (End::Relu, std::ptr::null(), 0),
                Finish::ReluGrad(y) => (End::ReluGrad, y.as_ptr(), y.row_stride() as usize),
                Finish::Scale(y) => (End::Scale, y.as_ptr(), y.row_stride() as usize),
            };
            for i0 in (0..m).step_by(MR) {
                let rows = (m - i0).min(MR);
                let block = a.subrows(i0, rows).subcols(k0, kc);
                // Each row's sum goes on from the last block of k, so it is summed in order of k throughout.
                let sums = row_sums.as_deref_mut().map(|sums| &mut sums[i0..i0 + rows]);
                let a_rows = if a_by_rows {
                    if let Some(sums) = sums {
                        super::add_row_sums(sums, block);
                    }
                    // SAFETY: row i0 < m and column k0 < k lie inside `a`.
                    unsafe { a.as_ptr().offset(i0 as isize * ars + k0 as isize) }
                } else {
                    // SAFETY: as above; `a`'s row stride is 1, and the caller guarantees AVX-512F.
                    unsafe { pack_columns(block, &mut a_block, sums) };
                    a_block.as_ptr()
                };
                // Rows read along k stream from memory: the next block's are fetched while this one works.
                let (next_a, prefetch_rows) = if a_by_rows && i0 + MR < m {
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
                        a: a_rows,
                        lda,
                        b: unsafe { b_block.add(p * kc * NR) },
                        kc,
                        c: tile,
                        ldc,
                        masks: masks(cols),
                        begin,
                        // SAFETY: (i0, j0) lies inside the start matrix, which has the output's shape.
                        load_from: unsafe { start_at.add(i0 * lds + j0) },
                        lds,
                        // SAFETY: column j0 < n of the start row and (i0, j0) of the finish matrix exist.
                        row: if row.is_null() { row } else { unsafe { row.add(j0) } },
                        end,
                        finish_from: if finish_from.is_null() {
                            finish_from
                        } else {
                            unsafe { finish_from.add(i0 * ldf + j0) }
                        },
                        ldf,
                        next_c: next_tile,
                        next_a,
                        next_a_stride: ars,
                        prefetch_rows: if p == 0 { prefetch_rows } else { 0 },
                    };
                    // SAFETY: the tile's `rows` × `cols` values lie inside `dst` (masks cover the columns), the
                    // packed blocks hold kc steps, and the caller guarantees AVX-512F.
                    unsafe { dispatch(rows, cols > 16, a_by_rows, &call) };
                }
            }
        }
        PACKING_BUFFERS.set((packed, a_block));
    }

    thread_local! {
        static PACKING_BUFFERS: std::cell::Cell<(Vec<f32>, Vec<f32>)> = const { std::cell::Cell::new((Vec::new(), Vec::new())) };
    }

    fn grow(buffer: &mut Vec<f32>, len: usize) {
        if buffer.len() < len {
            buffer.resize(len, 0.0);
        }
    }

    /// A block of `a`'s rows, stored by columns, as [k][MR]: each k's values are consecutive, one masked
    /// vector copy (slots past the block's last row are left as they were: a kernel for fewer rows never reads
    /// them).
    /// With `sums` (one per row), adds each row's values to its sum in order of k.
    #[target_feature(enable = "avx512f")]
    unsafe fn pack_columns(rows: MatRef<'_, f32>, out: &mut [f32], sums: Option<&mut [f32]>) {
        let mask = ((1u32 << rows.nrows()) - 1) as __mmask16;
        assert!(rows.row_stride() == 1 && rows.nrows() <= MR && out.len() >= rows.ncols() * MR);
        assert!(sums.as_ref().is_none_or(|sums| sums.len() == rows.nrows()));
        // SAFETY: `sums` holds nrows values, which the mask covers.
        let mut total =
            sums.as_ref().map_or(_mm512_setzero_ps(), |sums| unsafe { _mm512_maskz_loadu_ps(mask, sums.as_ptr()) });
        for kk in 0..rows.ncols() {
            // SAFETY: column kk holds nrows consecutive values; out holds MR values at kk·MR.
            unsafe {
                let column = _mm512_maskz_loadu_ps(mask, rows.as_ptr().offset(kk as isize * rows.col_stride()));
                _mm512_mask_storeu_ps(out.as_mut_ptr().add(kk * MR), mask, column);
                total = _mm512_add_ps(total, column);
            }
        }
        if let Some(sums) = sums {
            // SAFETY: as above.
            unsafe { _mm512_mask_storeu_ps(sums.as_mut_ptr(), mask, total) };
        }
    }

    /// Lanes of each of a tile's two vectors that lie inside the output.
    fn masks(cols: usize) -> [__mmask16; 2] {
        let lanes = |count: usize| if count >= 16 { 0xffff } else { ((1u32 << count) - 1) as __mmask16 };
        [lanes(cols), lanes(cols.saturating_sub(16))]
    }

    /// The offsets of 16 consecutive columns of `b` from the first, where `b` is stored by columns and they fit
    /// a gather's 32-bit indices.
    fn gather_offsets(b: MatRef<'_, f32>) -> Option<__m512i> {
        let stride = i32::try_from(b.col_stride()).ok()?;
        if b.row_stride() != 1 || stride.checked_mul(15).is_none() {
            return None;
        }
        let offsets: [i32; 16] = std::array::from_fn(|j| j as i32 * stride);
        // SAFETY: an unaligned load of 16 i32 from an array of 16.
        Some(unsafe { _mm512_loadu_si512(offsets.as_ptr().cast()) })
    }

    /// Rows k0..k0 + kc of `b` as panels of 32 columns, [panel][k][32].
    #[target_feature(enable = "avx512f")]
    unsafe fn pack(b: MatRef<'_, f32>, k0: usize, kc: usize, packed: &mut [f32]) {
        let n = b.ncols();
        for p in 0..n.div_ceil(NR) {
            let cols = (n - p * NR).min(NR);
            let panel = &mut packed[p * kc * NR..(p + 1) * kc * NR];
            if b.col_stride() == 1 {
                // Two masked vector copies per row: a copy_from_slice of a run-time length is a memmove call
                // per 32 values, which cost the weight gradients' packing more than the copying.
                let masks = masks(cols);
                for (kk, row) in panel.chunks_exact_mut(NR).enumerate() {
                    // SAFETY: row k0 + kk < k and columns p·NR.. of `b` exist; the masks cover `cols` of them,
                    // and `row` holds NR values.
                    unsafe {
                        let src = b.as_ptr().offset((k0 + kk) as isize * b.row_stride() + (p * NR) as isize);
                        for (v, &mask) in masks.iter().enumerate() {
                            let values = _mm512_maskz_loadu_ps(mask, src.wrapping_add(16 * v));
                            _mm512_storeu_ps(row.as_mut_ptr().add(16 * v), values);
                        }
                    }
                }
            } else if let Some(offsets) = gather_offsets(b) {
                // `b` by columns (a weight's transpose): each row of the panel is gathered, 16 columns at a
                // time; element by element it cost PETS' step 3 %.
                let masks = masks(cols);
                for (kk, row) in panel.chunks_exact_mut(NR).enumerate() {
                    for (v, &mask) in masks.iter().enumerate() {
                        // SAFETY: row k0 + kk < k of `b` exists, and so do the columns the mask covers, whose
                        // offsets from column p·NR + 16v fit in i32 (`gather_offsets`); `row` holds NR values.
                        unsafe {
                            let first = (k0 + kk) as isize + (p * NR + 16 * v) as isize * b.col_stride();
                            let base = b.as_ptr().wrapping_offset(first);
                            let values = _mm512_mask_i32gather_ps::<4>(_mm512_setzero_ps(), mask, offsets, base.cast());
                            _mm512_storeu_ps(row.as_mut_ptr().add(16 * v), values);
                        }
                    }
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
        Scale,
    }

    struct Call {
        /// The tile's rows of `a` at the block's first k: in place by rows (`lda` values apart), or packed as
        /// [k][MR] (each k `lda` = MR values after the last).
        a: *const f32,
        lda: usize,
        b: *const f32,
        kc: usize,
        c: *mut f32,
        ldc: usize,
        masks: [__mmask16; 2],
        begin: Begin,
        /// Where a `Load` begin reads the tile (the output itself, or the start matrix), rows `lds` apart.
        load_from: *const f32,
        lds: usize,
        /// The start row at the tile's first column.
        row: *const f32,
        end: End,
        /// The finish's matrix (a ReLU output, or slopes to scale by) at the tile's first element, and its row
        /// stride.
        finish_from: *const f32,
        ldf: usize,
        next_c: *const f32,
        next_a: *const f32,
        next_a_stride: isize,
        prefetch_rows: usize,
    }

    macro_rules! by_rows {
        ($rows:expr, $v:literal, $direct:literal, $call:expr) => {
            match $rows {
                12 => kernel::<12, $v, $direct>($call),
                11 => kernel::<11, $v, $direct>($call),
                10 => kernel::<10, $v, $direct>($call),
                9 => kernel::<9, $v, $direct>($call),
                8 => kernel::<8, $v, $direct>($call),
                7 => kernel::<7, $v, $direct>($call),
                6 => kernel::<6, $v, $direct>($call),
                5 => kernel::<5, $v, $direct>($call),
                4 => kernel::<4, $v, $direct>($call),
                3 => kernel::<3, $v, $direct>($call),
                2 => kernel::<2, $v, $direct>($call),
                _ => kernel::<1, $v, $direct>($call),
            }
        };
    }

    #[target_feature(enable = "avx512f")]
    unsafe fn dispatch(rows: usize, two_vectors: bool, a_by_rows: bool, call: &Call) {
        match (two_vectors, a_by_rows) {
            (true, true) => by_rows!(rows, 2, true, call),
            (true, false) => by_rows!(rows, 2, false, call),
            (false, true) => by_rows!(rows, 1, true, call),
            (false, false) => by_rows!(rows, 1, false, call),
        }
    }

    /// One R × 16·V tile of the output over kc steps of the inner dimension.
    #[target_feature(enable = "avx512f")]
    unsafe fn kernel<const R: usize, const V: usize, const A_BY_ROWS: bool>(call: &Call) {
        let &Call {
            a,
            lda,
            b,
            kc,
            c,
            ldc,
            masks,
            begin,
            load_from,
            lds,
            row,
            end,
            finish_from,
            ldf,
            next_c,
            next_a,
            next_a_stride,
            prefetch_rows,
            ..
        } = call;
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
                            *lane = _mm512_maskz_loadu_ps(masks[v], load_from.wrapping_add(r * lds + 16 * v));
                        }
                    }
                }
                Begin::Row => {
                    for values in acc.iter_mut() {
                        for (v, lane) in values.iter_mut().enumerate() {
                            *lane = _mm512_maskz_loadu_ps(masks[v], row.wrapping_add(16 * v));
                        }
                    }
                }
            }
            macro_rules! step {
                ($kk:expr) => {{
                    let kk = $kk;
                    let mut bv = [_mm512_setzero_ps(); V];
                    for (v, lane) in bv.iter_mut().enumerate() {
                        *lane = _mm512_loadu_ps(b.add(kk * NR + 16 * v));
                    }
                    for (r, values) in acc.iter_mut().enumerate() {
                        let value = if A_BY_ROWS { *a.add(r * lda + kk) } else { *a.add(kk * lda + r) };
                        let broadcast = _mm512_set1_ps(value);
                        for (v, lane) in values.iter_mut().enumerate() {
                            *lane = _mm512_fmadd_ps(broadcast, bv[v], *lane);
                        }
                    }
                }};
            }
            // The first steps each fetch one 16-value line of the next rows' kc values, row by row; the steps
            // are split into loops over rows and lines so no step divides to find its line.
            let lines_per_row = kc.div_ceil(16);
            let mut kk = 0;
            'prefetching: for ahead in 0..prefetch_rows {
                let next_row = next_a.wrapping_offset(ahead as isize * next_a_stride);
                for line in 0..lines_per_row {
                    if kk == kc {
                        break 'prefetching;
                    }
                    _mm_prefetch::<_MM_HINT_T0>(next_row.wrapping_add(16 * line) as *const i8);
                    step!(kk);
                    kk += 1;
                }
            }
            while kk < kc {
                step!(kk);
                kk += 1;
            }
            match end {
                End::Store => {}
                // Applied in registers before the store: as a pass over the stored tile, each read waited on a
                // masked store (which does not forward to a later load), 3.6 % of the context step.
                // max_ps gives its second operand where the first is NaN: 0, as f32::max does.
                End::Relu => {
                    let zero = _mm512_setzero_ps();
                    for values in acc.iter_mut() {
                        for lane in values.iter_mut() {
                            *lane = _mm512_max_ps(*lane, zero);
                        }
                    }
                }
                // Zero where y ≤ 0 (a NaN y keeps the gradient, as relu_backward does).
                End::ReluGrad => {
                    let zero = _mm512_setzero_ps();
                    for (r, values) in acc.iter_mut().enumerate() {
                        for (v, lane) in values.iter_mut().enumerate() {
                            let y = _mm512_maskz_loadu_ps(masks[v], finish_from.wrapping_add(r * ldf + 16 * v));
                            *lane = _mm512_mask_mov_ps(*lane, _mm512_cmp_ps_mask::<_CMP_LE_OQ>(y, zero), zero);
                        }
                    }
                }
                End::Scale => {
                    for (r, values) in acc.iter_mut().enumerate() {
                        for (v, lane) in values.iter_mut().enumerate() {
                            let y = _mm512_maskz_loadu_ps(masks[v], finish_from.wrapping_add(r * ldf + 16 * v));
                            *lane = _mm512_mul_ps(*lane, y);
                        }
                    }
                }
            }
            for (r, values) in acc.iter().enumerate() {
                for (v, lane) in values.iter().enumerate() {
                    _mm512_mask_storeu_ps(c.wrapping_add(r * ldc + 16 * v), masks[v], *lane);
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
        // Operands with a ragged last row block, columns with one- and two-vector tails, inner
        // sizes across the 256 block, a weight gradient's shape (few rows, a long inner dimension), and an
        // output wide enough to be cut into column blocks.
        for &(m, n, k) in &[
            (2031, 300, 9),
            (1024, 600, 200),
            (1100, 257, 300),
            (1037, 280, 513),
            (2000, 270, 1),
            (40, 600, 9000),
            (100, 1601, 270),
        ] {
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
    fn starts_and_finishes_are_applied_in_place() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        // The last is cut into column blocks by the AVX-512 kernel.
        for &(m, n, k) in &[(1031, 300, 9), (1030, 45, 600), (1100, 17, 260), (40, 1601, 300)] {
            let (a, b) = (random(m, k, &mut rng), random(k, n, &mut rng));
            let bias: Vec<f32> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            // A ReLU output with zeros, positives and a NaN, which keeps its gradient as relu_backward does.
            let mut relu_out: Vec<f32> = (0..m * n).map(|_| rng.random_range(-1.0f32..1.0).max(0.0)).collect();
            relu_out[7] = f32::NAN;
            let y = MatRef::from_row_major_slice(&relu_out, m, n);
            let slope_values: Vec<f32> = (0..m * n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let slopes = MatRef::from_row_major_slice(&slope_values, m, n);
            let plain = reference(&Mat::zeros(m, n), Accum::Replace, a.as_ref(), b.as_ref());
            for kernel in available_kernels() {
                let mut with_bias = vec![0.0f32; m * n];
                let dst = MatMut::from_row_major_slice_mut(&mut with_bias, m, n);
                kernel.fused(dst, Start::Row(&bias), a.as_ref(), b.as_ref(), Finish::Relu);
                let mut masked = vec![1.0f32; m * n];
                let dst = MatMut::from_row_major_slice_mut(&mut masked, m, n);
                kernel.fused(dst, Start::Zero, a.as_ref(), b.as_ref(), Finish::ReluGrad(y));
                // Slopes to scale by, on a start of the output's own values: read by rows (in the AVX-512
                // kernel's tiles), and by columns (a pass of its own), to the same bytes.
                let mut scaled = vec![0.5f32; m * n];
                let dst = MatMut::from_row_major_slice_mut(&mut scaled, m, n);
                kernel.fused(dst, Start::Dst, a.as_ref(), b.as_ref(), Finish::Scale(slopes));
                let slopes_by_columns = slopes.to_owned();
                let mut scaled_by_columns = vec![0.5f32; m * n];
                let dst = MatMut::from_row_major_slice_mut(&mut scaled_by_columns, m, n);
                kernel.fused(dst, Start::Dst, a.as_ref(), b.as_ref(), Finish::Scale(slopes_by_columns.as_ref()));
                let same_bits = scaled.iter().zip(&scaled_by_columns).all(|(r, c)| r.to_bits() == c.to_bits());
                assert!(same_bits, "{kernel:?}: slopes by columns give the bytes of slopes by rows");
                // A start matrix read by rows, and one read by columns (the kernel copies it first).
                let mut from_rows = vec![f32::NAN; m * n];
                let dst = MatMut::from_row_major_slice_mut(&mut from_rows, m, n);
                kernel.fused(dst, Start::Matrix(y), a.as_ref(), b.as_ref(), Finish::Store);
                let y_by_columns = y.to_owned();
                let mut from_columns = vec![f32::NAN; m * n];
                let dst = MatMut::from_row_major_slice_mut(&mut from_columns, m, n);
                kernel.fused(dst, Start::Matrix(y_by_columns.as_ref()), a.as_ref(), b.as_ref(), Finish::Store);
                // And one whose rows run backwards (a negative row stride), which the kernel also copies first.
                let mut from_reversed = vec![f32::NAN; m * n];
                let dst = MatMut::from_row_major_slice_mut(&mut from_reversed, m, n);
                kernel.fused(dst, Start::Matrix(y.reverse_rows()), a.as_ref(), b.as_ref(), Finish::Store);
                let tol = 1e-5 * (k as f64).sqrt() * 4.0;
                for x in 0..m * n {
                    let (i, j) = (x / n, x % n);
                    let reversed = relu_out[(m - 1 - i) * n + j] as f64;
                    if !reversed.is_nan() {
                        let want = plain[(i, j)] + reversed;
                        assert!((from_reversed[x] as f64 - want).abs() <= tol, "{kernel:?} reversed start at {x}");
                    }
                    let want_relu = (plain[(i, j)] + bias[j] as f64).max(0.0);
                    let want_grad = if relu_out[x] <= 0.0 { 0.0 } else { plain[(i, j)] };
                    assert!((with_bias[x] as f64 - want_relu).abs() <= tol, "{kernel:?} relu {m}×{n}×{k} at {x}");
                    assert!((masked[x] as f64 - want_grad).abs() <= tol, "{kernel:?} relu grad {m}×{n}×{k} at {x}");
                    let want_scaled = (0.5 + plain[(i, j)]) * slope_values[x] as f64;
                    assert!((scaled[x] as f64 - want_scaled).abs() <= tol, "{kernel:?} scale {m}×{n}×{k} at {x}");
                    if x != 7 {
                        let want = plain[(i, j)] + relu_out[x] as f64;
                        assert!((from_rows[x] as f64 - want).abs() <= tol, "{kernel:?} start {m}×{n}×{k} at {x}");
                    }
                }
                assert!(from_rows[7].is_nan(), "{kernel:?}: the start matrix's NaN is kept");
                let same_bits = from_rows.iter().zip(&from_columns).all(|(r, c)| r.to_bits() == c.to_bits());
                assert!(same_bits, "{kernel:?}: a start by columns gives the bytes of one by rows");
            }
        }
    }

    #[test]
    fn packed_right_operands_give_the_bytes_of_the_kernels_own_packing() {
        let kernel = *available_kernels().last().unwrap();
        if kernel == Kernel::Faer {
            eprintln!("skipped: no AVX-512 here; packed operands exist only for that kernel");
            assert!(PackedRight::new(Mat::<f32>::zeros(4, 32).as_ref()).is_none());
            return;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        // Ragged rows, two blocks of k (256 + 44) and, at 1600 columns, a cut into column blocks.
        for (m, k, n) in [(37, 300, 64), (25, 40, 1600), (13, 256, 48)] {
            for a_rows in [true, false] {
                let (a, b) = (random(m, k, &mut rng), random(k, n, &mut rng));
                let a_stored = stored(&a, a_rows);
                let a_view = if a_rows { a_stored.transpose() } else { a_stored.as_ref() };
                let start: Vec<f32> = (0..m * n).map(|_| rng.random_range(-1.0..1.0)).collect();
                let mut expected = start.clone();
                let dst = MatMut::from_row_major_slice_mut(&mut expected, m, n);
                kernel.product(dst, Accum::Add, a_view, b.as_ref());
                let packed = PackedRight::new(b.as_ref()).expect("AVX-512 is here");
                let mut got = start.clone();
                let dst = MatMut::from_row_major_slice_mut(&mut got, m, n);
                packed.fused_product(dst, Start::Dst, a_view, Finish::Store).expect("the kernel reads these layouts");
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&got), bits(&expected), "{m}×{k}×{n}, a rows {a_rows}: packed once");
                if n.is_multiple_of(PACKED_PANEL) {
                    // The same operand written value by value where packed_offset puts it.
                    let mut values = vec![f32::NAN; k * n];
                    for row in 0..k {
                        for col in (0..n).step_by(PACKED_PANEL) {
                            let at = packed_offset(k, n, row, col);
                            (0..PACKED_PANEL).for_each(|t| values[at + t] = b[(row, col + t)]);
                        }
                    }
                    let written = PackedRight::from_packed(&values, k, n).expect("AVX-512 is here");
                    let mut got = start.clone();
                    let dst = MatMut::from_row_major_slice_mut(&mut got, m, n);
                    written.fused_product(dst, Start::Dst, a_view, Finish::Store).expect("the kernel reads these");
                    assert_eq!(bits(&got), bits(&expected), "{m}×{k}×{n}, a rows {a_rows}: packed by the caller");
                }
            }
        }
    }

    #[test]
    fn wide_outputs_are_cut_into_column_blocks_without_changing_bytes() {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        // 1601 columns: three blocks of 544, 544 and 513, each narrower than one block, so run uncut alone.
        let (m, n, k) = (300, 1601, 270);
        let kernel = *available_kernels().last().unwrap();
        if kernel == Kernel::Faer {
            eprintln!("skipped: no AVX-512 here; only that kernel cuts its columns");
            return;
        }
        for a_rows in [true, false] {
            let (a, b) = (random(m, k, &mut rng), random(k, n, &mut rng));
            let a_stored = stored(&a, a_rows);
            let a_view = if a_rows { a_stored.transpose() } else { a_stored.as_ref() };
            let bias: Vec<f32> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let mut whole = vec![0.0f32; m * n];
            let mut whole_sums = vec![0.5f32; m];
            let dst = MatMut::from_row_major_slice_mut(&mut whole, m, n);
            kernel.fused_summing(dst, Start::Row(&bias), a_view, b.as_ref(), Finish::Relu, Some(&mut whole_sums));
            let expected = reference(&Mat::zeros(m, n), Accum::Replace, a.as_ref(), b.as_ref());
            for (x, got) in whole.iter().enumerate() {
                let want = (expected[(x / n, x % n)] + bias[x % n] as f64).max(0.0);
                assert!((*got as f64 - want).abs() <= 1e-3, "a rows {a_rows} at {x}: {got} vs {want}");
            }
            for j0 in [0, 544, 1088] {
                let cols = (n - j0).min(544);
                let mut block = vec![0.0f32; m * cols];
                let mut sums = vec![0.5f32; m];
                let dst = MatMut::from_row_major_slice_mut(&mut block, m, cols);
                let bias = &bias[j0..j0 + cols];
                kernel.fused_summing(dst, Start::Row(bias), a_view, b.subcols(j0, cols), Finish::Relu, Some(&mut sums));
                let same = (0..m * cols).all(|x| block[x].to_bits() == whole[(x / cols) * n + j0 + x % cols].to_bits());
                assert!(same, "a rows {a_rows}: columns from {j0} differ from the same product run alone");
                assert!(sums == whole_sums, "a rows {a_rows}: each row's sum is taken once");
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
        // Chosen once for the whole product, as backprop::matmul chooses.
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
