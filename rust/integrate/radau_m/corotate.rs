//! RADAU5M's Newton matrices co-rotated with the node bodies of geometrically exact beams.
//!
//! Simplified Newton serves the three stages (and the following steps, while it contracts) with
//! one `M`, `K`, `A`, read at one state, the *reference*. A spinning beam's stiff axial and shear
//! directions turn with it: at a stage turned by `alpha` from the reference, the stiffness of
//! the matrix is misplaced by `alpha`, and a misplaced stiffness of `omega_ax^2` against the
//! bending directions' `1 / h^2` stops Newton unless `alpha (omega_ax h)^2` is small (issue 31:
//! the spin-up beam's fixed step of 0.12 s cut to 4-8 ms at 6 rad/s).
//!
//! A beam element's energy is invariant under a rotation `R` of both its nodes (`r -> R r`,
//! `p -> r (x) p` with `R = A(r)`), a linear orthogonal map `G` of their coordinates; so are the
//! node bodies' kinetic energy and normalization. Hence `K(G q) = G K(q) G^T`, `M(G q) = G M(q)
//! G^T`, `A(G q) = A(q) G^T`: the matrices at a stage are the reference's turned by that stage's
//! `G_i` (each node by its own rotation from the reference, `r_i = p_i (x) p_ref^*`). In the
//! stages' position increments `Z_i = h^2 sum_j (a^2)_ij W_j` the stiffness acts on its own stage
//! only, `K_i Z_i`: with `Z_i = G_i Z~_i` and stage `i`'s force residual turned back by
//! `G_i^T`, it is the reference's `K Z~_i` exactly, and what is left misplaced is the mass's
//! coupling of the stages, `M (G_i^T G_j - I)`, of the size of the turn, not of the stiffness.
//! So the iteration: turn each stage's residual back to the reference (`to_reference`), solve
//! with the factored matrices as before, and turn the corrections' position increments forward
//! (`from_reference`: `W = (a^2)^-1 G (a^2) W~`). The multipliers and every other body's
//! coordinates are untouched (with no beam the iteration is the plain one, to the bit).
//!
//! The same holds for a whole mechanism turned by one rotation about gravity's axis (A05, the
//! flyball governor spinning on its shaft; `integrate/corotation.rs` says when): `G` turns
//! every body (rigid bodies' `[r, p]`, point masses' `r`) by the rotation of the body on the
//! ground revolute since the reference. The joints between bodies turn their rows with them
//! (`A(G q) = H A(q) G^T`, `H` orthogonal on each joint's rows); the multipliers left
//! unturned leave the position corrections exact up to the turn times the constraint residual.

use crate::integrate::corotation::Corotated;
use crate::linalg::rot3::{cross, V3};

/// `a (x) b`, Euler parameters scalar first.
fn qmul(a: &[f64; 4], b: &[f64; 4]) -> [f64; 4] {
    let (av, bv) = ([a[1], a[2], a[3]], [b[1], b[2], b[3]]);
    let c = cross(&av, &bv);
    [
        a[0] * b[0] - av[0] * bv[0] - av[1] * bv[1] - av[2] * bv[2],
        a[0] * bv[0] + b[0] * av[0] + c[0],
        a[0] * bv[1] + b[0] * av[1] + c[1],
        a[0] * bv[2] + b[0] * av[2] + c[2],
    ]
}

fn conj(a: &[f64; 4]) -> [f64; 4] {
    [a[0], -a[1], -a[2], -a[3]]
}

/// `A(r) v` for a unit `r`: `v + 2 r0 (e x v) + 2 e x (e x v)`.
fn turn_vec(r: &[f64; 4], v: &V3) -> V3 {
    let e = [r[1], r[2], r[3]];
    let ev = cross(&e, v);
    let eev = cross(&e, &ev);
    std::array::from_fn(|k| v[k] + 2.0 * (r[0] * ev[k] + eev[k]))
}

/// The 7 coordinates `[r, p]` of a node turned by `r`: `[A(r) x_r, r (x) x_p]`.
fn turn7(r: &[f64; 4], x: &[f64; 7]) -> [f64; 7] {
    let t = turn_vec(r, &[x[0], x[1], x[2]]);
    let p = qmul(r, &[x[3], x[4], x[5], x[6]]);
    [t[0], t[1], t[2], p[0], p[1], p[2], p[3]]
}

fn unit(p: &[f64]) -> [f64; 4] {
    let s = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]).sqrt();
    if s > 0.0 && s.is_finite() { [p[0] / s, p[1] / s, p[2] / s, p[3] / s] } else { [1.0, 0.0, 0.0, 0.0] }
}

/// Turn a block of coordinates by `r`: `[r, p]` (7) or a point's `r` (3).
fn turn_block(r: &[f64; 4], x: &mut [f64], rigid: bool) {
    if rigid {
        let v: [f64; 7] = std::array::from_fn(|k| x[k]);
        x[..7].copy_from_slice(&turn7(r, &v));
    } else {
        let v = turn_vec(r, &[x[0], x[1], x[2]]);
        x[..3].copy_from_slice(&v);
    }
}

/// The co-rotation of RADAU5M's Newton matrices (module docs); empty without beams or a
/// mechanism spinning about gravity's axis (`integrate/corotation.rs`).
pub(super) struct Corotation {
    /// Coordinate offsets of the bodies whose rotations turn the matrices (`[r (3), p (4)]`).
    sources: Vec<usize>,
    /// The turned blocks: offset, `[r, p]` (else a point's `r`), the source turning it.
    blocks: Vec<(usize, bool, usize)>,
    /// The sources' Euler parameters where the matrices were read.
    p_ref: Vec<[f64; 4]>,
    /// Per stage, per source: its rotation from the reference.
    rot: [Vec<[f64; 4]>; 3],
    /// `a^2` of Radau IIA and its inverse.
    s: [[f64; 3]; 3],
    si: [[f64; 3]; 3],
}

impl Corotation {
    pub(super) fn new(c: Corotated, a2: &[[f64; 3]; 3]) -> Self {
        let k = c.sources.len();
        let one = [1.0, 0.0, 0.0, 0.0];
        Corotation { p_ref: vec![one; k], rot: std::array::from_fn(|_| vec![one; k]), sources: c.sources, blocks: c.blocks, s: *a2, si: inverse3(a2) }
    }

    pub(super) fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// The matrices were read at `q`: it is the reference.
    pub(super) fn set_reference(&mut self, q: &[f64]) {
        for (p, &o) in self.p_ref.iter_mut().zip(&self.sources) {
            *p = unit(&q[o + 3..o + 7]);
        }
    }

    /// Each source's rotation from the reference at the stages `qs`.
    pub(super) fn follow(&mut self, qs: &[Vec<f64>; 3]) {
        for (rot, q) in self.rot.iter_mut().zip(qs) {
            for ((r, p), &o) in rot.iter_mut().zip(&self.p_ref).zip(&self.sources) {
                *r = unit(&qmul(&unit(&q[o + 3..o + 7]), &conj(p)));
            }
        }
    }

    /// Turn the blocks' part of each stage's force residual (the first `n` entries) back to the
    /// reference: `G_i^T r_i`.
    pub(super) fn to_reference(&self, res: &mut [Vec<f64>; 3]) {
        for (rot, r) in self.rot.iter().zip(res.iter_mut()) {
            for &(o, rigid, g) in &self.blocks {
                turn_block(&conj(&rot[g]), &mut r[o..], rigid);
            }
        }
    }

    /// The stages' corrections `d` (accelerations, the blocks' entries) solved in the reference
    /// turned to their stages: `d <- (a^2)^-1 G (a^2) d` (their position increments turned).
    pub(super) fn from_reference(&self, d: &mut [Vec<f64>; 3]) {
        for &(o, rigid, g) in &self.blocks {
            let len = if rigid { 7 } else { 3 };
            let z: [[f64; 7]; 3] = std::array::from_fn(|i| {
                let mut x: [f64; 7] = std::array::from_fn(|k| if k < len { (0..3).map(|j| self.s[i][j] * d[j][o + k]).sum() } else { 0.0 });
                turn_block(&self.rot[i][g], &mut x, rigid);
                x
            });
            for (i, di) in d.iter_mut().enumerate() {
                for k in 0..len {
                    di[o + k] = (0..3).map(|j| self.si[i][j] * z[j][k]).sum();
                }
            }
        }
    }

    /// `x <- G_3^T x` (`back`: `G_3 x`) on the blocks' entries: the step's end against the
    /// reference (the error estimate's filter, which solves with the reference's matrices).
    pub(super) fn turn_end(&self, x: &mut [f64], back: bool) {
        for &(o, rigid, g) in &self.blocks {
            let r = if back { self.rot[2][g] } else { conj(&self.rot[2][g]) };
            turn_block(&r, &mut x[o..], rigid);
        }
    }
}

/// Inverse of a 3 x 3 matrix (Radau IIA's `a^2`, well conditioned).
fn inverse3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |i: usize, j: usize| {
        let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
        m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    std::array::from_fn(|i| std::array::from_fn(|j| c(j, i) / det))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turns_are_orthogonal_and_inverse_is_exact() {
        let r = unit(&[0.9, 0.1, -0.3, 0.2]);
        let x = [0.3, -1.2, 0.7, 0.5, -0.1, 0.8, 0.2];
        let y = turn7(&r, &x);
        let back = turn7(&conj(&r), &y);
        let n = |v: &[f64; 7]| v.iter().map(|a| a * a).sum::<f64>();
        assert!((n(&y) - n(&x)).abs() < 1e-14);
        assert!(back.iter().zip(&x).all(|(a, b)| (a - b).abs() < 1e-14));
        // A(r) of rot3 and the quaternion turn agree
        let a = crate::linalg::rot3::rot_a(&r);
        let v = crate::linalg::rot3::mat_vec(&a, &[x[0], x[1], x[2]]);
        assert!((0..3).all(|k| (v[k] - y[k]).abs() < 1e-14));
        let m = [[0.2, 0.1, -0.05], [0.3, 0.4, 0.02], [0.5, 0.3, 0.1]];
        let mi = inverse3(&m);
        for i in 0..3 {
            for j in 0..3 {
                let e: f64 = (0..3).map(|k| m[i][k] * mi[k][j]).sum();
                assert!((e - if i == j { 1.0 } else { 0.0 }).abs() < 1e-13);
            }
        }
    }
}
