//! The constraint Jacobian `A = Phi_q` in per-row segment form (the form every kernel writes
//! and the O(nnz) consumers read).
//!
//! Every row of a constraint touches only the coordinates of its markers' bodies
//! (`Constraint::bodies`): the pattern is fixed when the model is built. Row `i` is stored as
//! one contiguous block of `width` values, the coordinates of its bodies one after the other in
//! body order (a *layout* `(body, start in the row)` per constraint); `segs` maps each row's
//! pieces back to columns of `A`. A chain of K links has 6 values per row (two rigid bodies),
//! 12 K values in all, instead of the dense `m x n = 6 K^2`.
//!
//! The dense `m x n` copy (`Data::jac`, a `DenseJac`) exists only when something needs it (the
//! dense UK path, the implicit integrators' Newton matrices, `System.A`), and is scattered from
//! this form when it is read after `dynamics::constraints` changed it (`DenseJac::read`): a
//! call whose kernels read only the segment form (the spatial Gram path) pays nothing for it.

use super::Constraint;
use crate::body::Body;

/// One body piece of one row: columns `col..col + len` of `A` are `vals[val..val + len]`.
#[derive(Debug, Clone, Copy)]
pub struct Seg {
    pub body: usize,
    pub col: usize,
    pub len: usize,
    pub val: usize,
}

/// `A` in per-row segment form, pattern fixed by the model (allocated once per workspace).
#[derive(Debug, Clone)]
pub struct SegJac {
    pub m: usize,
    pub n: usize,
    /// Per constraint: `(body, start in the row)` of its bodies, and the row width.
    pub layouts: Vec<Vec<(usize, usize)>>,
    pub widths: Vec<usize>,
    /// Start of row `i` in `vals` (`m + 1` entries).
    pub row_ptr: Vec<usize>,
    /// Segments of row `i`: `segs[seg_ptr[i]..seg_ptr[i + 1]]`.
    pub seg_ptr: Vec<usize>,
    pub segs: Vec<Seg>,
    pub vals: Vec<f64>,
}

impl SegJac {
    /// The pattern of the constraint rows (`m` rows on `n` coordinates; a model's
    /// `constraints` and `bodies`).
    pub fn new(constraints: &[Constraint], bodies: &[Body], n: usize, m: usize) -> SegJac {
        let mut layouts = Vec::with_capacity(constraints.len());
        let mut widths = Vec::with_capacity(constraints.len());
        let mut row_ptr = Vec::with_capacity(m + 1);
        let mut seg_ptr = Vec::with_capacity(m + 1);
        let mut segs = Vec::new();
        row_ptr.push(0);
        seg_ptr.push(0);
        let mut val = 0;
        for c in constraints {
            debug_assert_eq!(row_ptr.len() - 1, c.row, "constraint rows are consecutive");
            let mut mine: Vec<usize> = c.bodies().into_iter().flatten().collect();
            mine.sort_unstable();
            mine.dedup();
            let mut layout = Vec::with_capacity(mine.len());
            let mut width = 0;
            for &b in &mine {
                layout.push((b, width));
                width += bodies[b].n_coords;
            }
            for _ in 0..c.rows() {
                for &(b, start) in &layout {
                    let body = &bodies[b];
                    segs.push(Seg { body: b, col: body.offset, len: body.n_coords, val: val + start });
                }
                val += width;
                row_ptr.push(val);
                seg_ptr.push(segs.len());
            }
            layouts.push(layout);
            widths.push(width);
        }
        SegJac { m, n, layouts, widths, row_ptr, seg_ptr, segs, vals: vec![0.0; val] }
    }

    /// Heap bytes of the pattern and values of `m` rows (without building it).
    pub fn bytes(constraints: &[Constraint], bodies: &[Body], m: usize) -> u64 {
        let nnz: u64 = constraints
            .iter()
            .map(|c| c.rows() as u64 * c.bodies().into_iter().flatten().map(|b| bodies[b].n_coords as u64).sum::<u64>())
            .sum();
        8 * nnz + 48 * nnz.min(8 * m as u64) + 16 * m as u64
    }

    /// Stored values (the nonzero pattern of `A`).
    #[inline]
    pub fn nnz(&self) -> usize {
        self.vals.len()
    }

    /// Segments of row `i`.
    #[inline]
    pub fn row_segs(&self, i: usize) -> &[Seg] {
        &self.segs[self.seg_ptr[i]..self.seg_ptr[i + 1]]
    }

    /// `(A v)_i`.
    #[inline]
    pub fn row_dot(&self, i: usize, v: &[f64]) -> f64 {
        let mut s = 0.0;
        for sg in self.row_segs(i) {
            s += crate::linalg::dot4(&self.vals[sg.val..sg.val + sg.len], &v[sg.col..sg.col + sg.len]);
        }
        s
    }

    /// `out += x A_i` (row `i` of `A` scaled by `x`, into an n-long vector).
    #[inline]
    pub fn add_row(&self, i: usize, x: f64, out: &mut [f64]) {
        for sg in self.row_segs(i) {
            for (o, a) in out[sg.col..sg.col + sg.len].iter_mut().zip(&self.vals[sg.val..sg.val + sg.len]) {
                *o += a * x;
            }
        }
    }

    /// Write the stored entries into a dense row-major `m x n` matrix (the entries outside the
    /// pattern are left as they are: zero once, zero for ever).
    pub fn scatter(&self, dense: &mut [f64]) {
        let n = self.n;
        for i in 0..self.m {
            for sg in self.row_segs(i) {
                dense[i * n + sg.col..i * n + sg.col + sg.len].copy_from_slice(&self.vals[sg.val..sg.val + sg.len]);
            }
        }
    }

    /// Rows `rows` of constraint `k` (its values block), for `dynamics::constraints`.
    #[inline]
    pub fn constraint_block(&mut self, k: usize, first_row: usize, rows: usize) -> (&mut [f64], &[(usize, usize)], usize) {
        let (a, b) = (self.row_ptr[first_row], self.row_ptr[first_row + rows]);
        (&mut self.vals[a..b], &self.layouts[k], self.widths[k])
    }
}

/// The dense row-major `m x n` copy of `A`, built from the segment form when read: its values
/// are private, so no reader sees a copy older than the last `dynamics::constraints`.
#[derive(Debug, Clone, Default)]
pub struct DenseJac {
    vals: Vec<f64>,
    on: bool,
    /// The values match the segment form (no `dynamics::constraints` since the last scatter).
    current: bool,
}

impl DenseJac {
    /// Allocated (`Data::ensure_dense_jac`).
    #[inline]
    pub fn is_on(&self) -> bool {
        self.on
    }

    /// Allocate the `m x n` zeros (entries outside the pattern stay zero for ever); the stored
    /// entries are scattered at the first read.
    pub fn allocate(&mut self, m: usize, n: usize) {
        self.vals = vec![0.0; m * n];
        self.on = true;
        self.current = false;
    }

    /// The segment form was rewritten (`dynamics::constraints`): the next read scatters it.
    #[inline]
    pub fn invalidate(&mut self) {
        self.current = false;
    }

    /// `A`, m x n row-major, as the segment form `ajac` holds it now (scattered here if it
    /// changed since the last read); empty when not allocated.
    #[inline]
    pub fn read(&mut self, ajac: &SegJac) -> &[f64] {
        if self.on && !self.current {
            ajac.scatter(&mut self.vals);
            self.current = true;
        }
        &self.vals
    }
}
