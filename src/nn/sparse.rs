//! Output gradients that are zero but at a few entries, and the two products a layer's backward pass takes of
//! them. A max pool passes each set's gradient to the one row that won each feature: the context model's
//! transition encoder sees about 2 % of its 50 000 × 128 output gradients nonzero at batch 512, and its dense
//! backward (two 2.6-GFLOP products over those zeros) was 3 % of its training step's FLOPs.
//!
//! Every sum runs in a fixed order (a column's entries by row, a row's by column), so the bytes do not depend
//! on the thread count.

use rayon::prelude::*;

use super::backprop::{relu_backward, zip_values};

/// A rows × width matrix of which only the pushed entries are nonzero, kept by column.
#[derive(Clone, Debug)]
pub struct SparseColumns {
    rows: usize,
    /// Each column's (row, value) entries, rows ascending.
    columns: Vec<Vec<(u32, f32)>>,
}

impl SparseColumns {
    pub fn new(rows: usize, width: usize) -> Self {
        assert!(u32::try_from(rows).is_ok(), "SparseColumns: {rows} rows do not fit a u32 index");
        SparseColumns { rows, columns: vec![Vec::new(); width] }
    }

    pub fn rows(&self) -> usize {
        self.rows
    }

    pub fn width(&self) -> usize {
        self.columns.len()
    }

    /// Sets entry (row, column) to `value`. A column's rows must come in ascending order, each at most once.
    pub fn push(&mut self, row: usize, column: usize, value: f32) {
        assert!(row < self.rows, "SparseColumns: row {row} of {}", self.rows);
        let entries = &mut self.columns[column];
        assert!(entries.last().is_none_or(|&(last, _)| (last as usize) < row), "SparseColumns: rows out of order");
        entries.push((row as u32, value));
    }

    /// The entries as a dense row-major matrix.
    #[cfg(test)]
    pub fn to_dense(&self) -> Vec<f32> {
        let width = self.width();
        let mut dense = vec![0.0; self.rows * width];
        for (j, entries) in self.columns.iter().enumerate() {
            for &(row, value) in entries {
                dense[row as usize * width + j] = value;
            }
        }
        dense
    }

    /// sums[j] += Σ_rows m[row, j], each column's entries in row order.
    pub fn add_column_sums(&self, sums: &mut [f32]) {
        assert_eq!(sums.len(), self.width(), "SparseColumns: column sums of the wrong width");
        for (sum, entries) in sums.iter_mut().zip(&self.columns) {
            *sum = entries.iter().fold(*sum, |sum, &(_, value)| sum + value);
        }
    }

    /// out (width × d, row-major) += mᵀ · x for x rows × d: each output row starts from its value and adds its
    /// column's entries in row order.
    pub fn add_transposed_product(&self, x: &[f32], d: usize, out: &mut [f32]) {
        assert_eq!(x.len(), self.rows * d, "SparseColumns: the right operand has the wrong shape");
        assert_eq!(out.len(), self.width() * d, "SparseColumns: the product has the wrong shape");
        if d == 0 {
            return;
        }
        out.par_chunks_mut(d).zip(&self.columns).for_each(|(out, entries)| {
            for &(row, value) in entries {
                let row = row as usize;
                zip_values(out, &x[row * d..(row + 1) * d], |sum, x| *sum = value.mul_add(x, *sum));
            }
        });
    }

    /// m · w (rows × d, row-major) for w width × d, each row's entries added in column order; with `relu_of`
    /// (rows × d), zero wherever that ReLU output is not positive: the gradient taken on through the ReLU.
    pub fn product(&self, w: &[f32], d: usize, relu_of: Option<&[f32]>) -> Vec<f32> {
        assert_eq!(w.len(), self.width() * d, "SparseColumns: the right operand has the wrong shape");
        assert!(relu_of.is_none_or(|y| y.len() == self.rows * d), "SparseColumns: the ReLU output has the wrong shape");
        let by_rows = self.by_rows();
        let mut out = vec![0.0; self.rows * d];
        if d == 0 {
            return out;
        }
        out.par_chunks_mut(d).enumerate().with_min_len(64).for_each(|(row, out)| {
            for &(j, value) in &by_rows.entries[by_rows.starts[row]..by_rows.starts[row + 1]] {
                let j = j as usize;
                zip_values(out, &w[j * d..(j + 1) * d], |sum, w| *sum = value.mul_add(w, *sum));
            }
            if let Some(y) = relu_of {
                relu_backward(out, &y[row * d..(row + 1) * d]);
            }
        });
        out
    }

    /// The entries regrouped by row, each row's columns ascending (a counting sort).
    fn by_rows(&self) -> ByRows {
        let mut starts = vec![0usize; self.rows + 1];
        for entries in &self.columns {
            for &(row, _) in entries {
                starts[row as usize + 1] += 1;
            }
        }
        for row in 0..self.rows {
            starts[row + 1] += starts[row];
        }
        let mut next = starts.clone();
        let mut entries = vec![(0u32, 0.0f32); starts[self.rows]];
        for (j, column) in self.columns.iter().enumerate() {
            for &(row, value) in column {
                let slot = &mut next[row as usize];
                entries[*slot] = (j as u32, value);
                *slot += 1;
            }
        }
        ByRows { starts, entries }
    }
}

struct ByRows {
    /// Row r's entries are entries[starts[r]..starts[r + 1]].
    starts: Vec<usize>,
    entries: Vec<(u32, f32)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(rows: usize, width: usize) -> SparseColumns {
        let mut m = SparseColumns::new(rows, width);
        for j in 0..width {
            for row in (j % 3..rows).step_by(3 + j % 4) {
                m.push(row, j, (row as f32 * 0.37 - j as f32 * 0.21).sin());
            }
        }
        m
    }

    fn values(n: usize, phase: f32) -> Vec<f32> {
        (0..n).map(|k| (k as f32 * 0.113 + phase).cos()).collect()
    }

    #[test]
    fn products_match_the_dense_matrix() {
        let (rows, width, d) = (37, 5, 19);
        let m = sample(rows, width);
        let dense = m.to_dense();
        assert!(dense.iter().filter(|v| **v != 0.0).count() < rows * width / 2);

        let x = values(rows * d, 0.3);
        let start = values(width * d, 1.1);
        let mut got = start.clone();
        m.add_transposed_product(&x, d, &mut got);
        for j in 0..width {
            for k in 0..d {
                let want = start[j * d + k] + (0..rows).map(|r| dense[r * width + j] * x[r * d + k]).sum::<f32>();
                assert!((got[j * d + k] - want).abs() < 1e-5, "mᵀx[{j}, {k}] = {} against {want}", got[j * d + k]);
            }
        }

        let w = values(width * d, 2.0);
        let relu_output = values(rows * d, 0.7);
        let plain = m.product(&w, d, None);
        let masked = m.product(&w, d, Some(&relu_output));
        for r in 0..rows {
            for k in 0..d {
                let want = (0..width).map(|j| dense[r * width + j] * w[j * d + k]).sum::<f32>();
                assert!((plain[r * d + k] - want).abs() < 1e-5, "mw[{r}, {k}] = {} against {want}", plain[r * d + k]);
                let through_relu = if relu_output[r * d + k] > 0.0 { want } else { 0.0 };
                assert!((masked[r * d + k] - through_relu).abs() < 1e-5);
            }
        }

        let mut sums = vec![1.0; width];
        m.add_column_sums(&mut sums);
        for (j, sum) in sums.iter().enumerate() {
            let want = 1.0 + (0..rows).map(|r| dense[r * width + j]).sum::<f32>();
            assert!((sum - want).abs() < 1e-5);
        }
    }

    #[test]
    fn the_bytes_do_not_depend_on_the_thread_count() {
        let (rows, width, d) = (3000, 16, 40);
        let m = sample(rows, width);
        let (x, w) = (values(rows * d, 0.5), values(width * d, 0.9));
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut out = vec![0.0; width * d];
                m.add_transposed_product(&x, d, &mut out);
                (out, m.product(&w, d, Some(&x)))
            })
        };
        assert_eq!(run(1), run(3));
    }

    #[test]
    #[should_panic(expected = "rows out of order")]
    fn a_column_takes_its_rows_in_order() {
        let mut m = SparseColumns::new(4, 2);
        m.push(2, 0, 1.0);
        m.push(1, 0, 1.0);
    }
}
