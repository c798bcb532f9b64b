//! The row primitives every spatial joint is built from (docs/spatial-design.md, section 2):
//! point coincidence, dot-1 (`u_i . w_j`), dot-2 (`a_i . d`, `d = P_j - P_i`) and distance
//! (`d . d - L^2`), each with its value, Jacobian row, and `gamma = -h` (the quadratic term of
//! the row's second derivative; `Phi_t = 0`). The product rule gives them all:
//! `s = u . w`: `J_s = w^T J_u + u^T J_w`, `sd = u . wd + w . ud`, `h_s = u . h_w + w . h_u + 2 ud . wd`.

use crate::body::marker3::{add_jacobian, add_point_rows, Kin3, Marker3State};
use crate::body::Body;
use crate::constraint::ConstraintOut;
use crate::linalg::rot3::{dot, scale, sub, V3};

/// Value, rate and quadratic term of `u . w` (`u` of marker `i`, `w` of marker `j`).
#[inline]
pub fn dot_terms(u: &Kin3, w: &Kin3) -> (f64, f64, f64) {
    (dot(&u.v, &w.v), dot(&u.vd, &w.v) + dot(&u.v, &w.vd), dot(&u.v, &w.h) + dot(&w.v, &u.h) + 2.0 * dot(&u.vd, &w.vd))
}

/// `row += wt J_{u.w}`.
#[inline]
pub fn dot_jacobian(bodies: &[Body], si: &Marker3State, u: &Kin3, sj: &Marker3State, w: &Kin3, wt: f64, row: &mut [f64], layout: Option<&[(usize, usize)]>) {
    add_jacobian(bodies, si, u, &scale(wt, &w.v), row, layout);
    add_jacobian(bodies, sj, w, &scale(wt, &u.v), row, layout);
}

/// `d = P_j - P_i` with its rate and quadratic term.
#[inline]
pub fn separation(si: &Marker3State, sj: &Marker3State) -> (V3, V3, V3) {
    (sub(&sj.point.v, &si.point.v), sub(&sj.point.vd, &si.point.vd), sub(&sj.point.h, &si.point.h))
}

/// Value, rate and quadratic term of `a . d` (`a` an axis of marker `i`).
#[inline]
pub fn dot2_terms(a: &Kin3, si: &Marker3State, sj: &Marker3State) -> (f64, f64, f64) {
    let (d, dd, hd) = separation(si, sj);
    (dot(&a.v, &d), dot(&a.vd, &d) + dot(&a.v, &dd), dot(&a.v, &hd) + dot(&d, &a.h) + 2.0 * dot(&a.vd, &dd))
}

/// `row += wt J_{a.d}`.
#[inline]
pub fn dot2_jacobian(bodies: &[Body], a: &Kin3, si: &Marker3State, sj: &Marker3State, wt: f64, row: &mut [f64], layout: Option<&[(usize, usize)]>) {
    let (d, _, _) = separation(si, sj);
    add_jacobian(bodies, si, a, &scale(wt, &d), row, layout);
    add_jacobian(bodies, sj, &sj.point, &scale(wt, &a.v), row, layout);
    add_jacobian(bodies, si, &si.point, &scale(-wt, &a.v), row, layout);
}

#[inline]
fn put(out: &mut ConstraintOut, k: usize, value: f64, h: f64) {
    if let Some(phi) = out.phi.as_deref_mut() {
        phi[k] = value;
    }
    out.phi_t[k] = 0.0;
    out.gamma[k] = -h;
}

/// Rows `k..k + 3`: `P_j - P_i = 0`.
#[inline]
pub fn coincidence(bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut, k: usize) {
    let (d, _, hd) = separation(si, sj);
    let rows = &mut out.jac[k * n..(k + 3) * n];
    add_point_rows(bodies, sj, 1.0, rows, n, out.layout);
    add_point_rows(bodies, si, -1.0, rows, n, out.layout);
    for c in 0..3 {
        put(out, k + c, d[c], hd[c]);
    }
}

/// Row `k`: `x_i . w_j = 0` with axis `ai` of marker `i` and axis `aj` of marker `j` (dot-1).
#[inline]
pub fn dot1(bodies: &[Body], si: &Marker3State, ai: usize, sj: &Marker3State, aj: usize, n: usize, out: &mut ConstraintOut, k: usize) {
    let (u, w) = (&si.axes[ai], &sj.axes[aj]);
    let (v, _, h) = dot_terms(u, w);
    let layout = Some(out.layout);
    dot_jacobian(bodies, si, u, sj, w, 1.0, &mut out.jac[k * n..(k + 1) * n], layout);
    put(out, k, v, h);
}

/// Row `k`: `a_i . d = 0` with axis `ai` of marker `i` (dot-2).
#[inline]
pub fn dot2(bodies: &[Body], si: &Marker3State, ai: usize, sj: &Marker3State, n: usize, out: &mut ConstraintOut, k: usize) {
    let a = &si.axes[ai];
    let (v, _, h) = dot2_terms(a, si, sj);
    let layout = Some(out.layout);
    dot2_jacobian(bodies, a, si, sj, 1.0, &mut out.jac[k * n..(k + 1) * n], layout);
    put(out, k, v, h);
}

/// Row `k`: `d . d - L^2 = 0`.
#[inline]
pub fn distance(bodies: &[Body], si: &Marker3State, sj: &Marker3State, length: f64, n: usize, out: &mut ConstraintOut, k: usize) {
    let (d, dd, hd) = separation(si, sj);
    let layout = Some(out.layout);
    let row = &mut out.jac[k * n..(k + 1) * n];
    add_jacobian(bodies, sj, &sj.point, &scale(2.0, &d), row, layout);
    add_jacobian(bodies, si, &si.point, &scale(-2.0, &d), row, layout);
    put(out, k, dot(&d, &d) - length * length, 2.0 * dot(&d, &hd) + 2.0 * dot(&dd, &dd));
}
