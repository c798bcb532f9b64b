//! The rigid motions of the initial-state correction with `rigid`: every body moves only
//! rigidly (an ANCF cable's nodal field turns and translates as a whole), and the Newton step
//! is the Gauss projection restricted to those motions.

use super::reduced_gauss_step;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::linalg::dense::{cholesky, solve_lower, solve_upper};
use crate::model::Model;

/// The bodies' rigid motions at `q` that touch no held coordinate (`Body::rigid_motions`):
/// per body its columns (first column index, count, the sizes of the body's full basis), and
/// per coordinate the `(column, value)` entries of the basis `B`.
pub(super) struct RigidBasis {
    bodies: Vec<(usize, usize)>,
    kept: Vec<Vec<usize>>,
    entries: Vec<Vec<(usize, f64)>>,
    k: usize,
}

impl RigidBasis {
    pub(super) fn new(model: &Model, q: &[f64], hold: &[bool]) -> RigidBasis {
        let n = model.n;
        let zeros = vec![0.0; n];
        let mut cen = vec![0.0; n];
        let (mut bodies, mut kept, mut entries) = (Vec::new(), Vec::new(), vec![Vec::new(); n]);
        let mut k = 0;
        for body in &model.bodies {
            let mut raw: Vec<(usize, usize, f64)> = Vec::new();
            let cols = body.rigid_motions(q, &zeros, 0, &mut |i, j, x| raw.push((i, j, x)), &mut cen);
            // a column that moves a held coordinate is left out
            let keep: Vec<usize> = (0..cols).filter(|&c| !raw.iter().any(|&(i, j, x)| j == c && x != 0.0 && hold[i])).collect();
            for &(i, j, x) in &raw {
                if let Some(p) = keep.iter().position(|&c| c == j) {
                    entries[i].push((k + p, x));
                }
            }
            bodies.push((k, cols));
            k += keep.len();
            kept.push(keep);
        }
        RigidBasis { bodies, kept, entries, k }
    }

    /// `x` (the kept columns) as each body's full rigid-motion vector.
    pub(super) fn body_motion(&self, b: usize, x: &[f64]) -> [f64; 3] {
        let mut out = [0.0; 3];
        let (first, _) = self.bodies[b];
        for (p, &c) in self.kept[b].iter().enumerate() {
            out[c] = x[first + p];
        }
        out
    }

    /// `B x` (n).
    pub(super) fn times(&self, x: &[f64]) -> Vec<f64> {
        self.entries.iter().map(|e| e.iter().map(|&(c, v)| v * x[c]).sum()).collect()
    }
}

/// Minimum-norm rigid motions `x` of the bodies with `A B x = r` in the metric `B^T M B` (the
/// Gauss projection restricted to rigid motions); `B^T M B` is block diagonal by body (at most
/// 3 x 3, from `M_b` times the columns: O(n)). Needs the mass blocks and `A` in `data`.
pub(super) fn rigid_step(model: &Model, data: &Data, basis: &RigidBasis, r: &[f64]) -> Result<Vec<f64>> {
    let (m, k) = (model.m, basis.k);
    if k == 0 || m == 0 {
        return Ok(vec![0.0; k]);
    }
    Error::check_memory("the initial-state correction (rigid motions x constraint rows)", 8 * (k as u64 + m as u64) * m as u64 * 3, data.memory_limit,
        "the initial-state correction solves densely in the bodies' rigid motions and the constraint rows; raise memory_limit")?;
    // per body: the Cholesky factor of its block of B^T M B
    let mut factors: Vec<Vec<f64>> = Vec::with_capacity(model.bodies.len());
    for (b, body) in model.bodies.iter().enumerate() {
        let (first, _) = basis.bodies[b];
        let kb = basis.kept[b].len();
        let seg = body.offset..body.offset + body.n_coords;
        let cols: Vec<Vec<f64>> = (0..kb)
            .map(|p| seg.clone().map(|i| basis.entries[i].iter().filter(|e| e.0 == first + p).map(|e| e.1).sum()).collect())
            .collect();
        let mut blk = vec![0.0; kb * kb];
        let mut mv = vec![0.0; body.n_coords];
        for p2 in 0..kb {
            mv.fill(0.0);
            body.mass_times(&data.bodies[b], &cols[p2], &mut mv);
            for p1 in 0..kb {
                blk[p1 * kb + p2] = cols[p1].iter().zip(&mv).map(|(a, b)| a * b).sum();
            }
        }
        if kb > 0 && cholesky(&mut blk, kb, 0.0).is_err() {
            return Err(Error::SingularMass { item: format!("body '{}': mass of its rigid motions", body.name) });
        }
        factors.push(blk);
    }
    let blocks = |v: &mut [f64], solve: fn(&[f64], usize, &mut [f64])| {
        for (b, f) in factors.iter().enumerate() {
            let (first, kb) = (basis.bodies[b].0, basis.kept[b].len());
            solve(f, kb, &mut v[first..first + kb]);
        }
    };
    reduced_gauss_step(
        k,
        r,
        |i, col| {
            // row i of A B, from the segment form
            for sg in data.ajac.row_segs(i) {
                for (j, &a) in data.ajac.vals[sg.val..sg.val + sg.len].iter().enumerate() {
                    for &(c, v) in &basis.entries[sg.col + j] {
                        col[c] += a * v;
                    }
                }
            }
        },
        |col| blocks(col, solve_lower),
        |y| blocks(y, solve_upper),
    )
}
