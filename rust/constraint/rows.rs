//! Row equations shared by several joint kinds. Each writes rows `k..` of a `ConstraintOut`:
//! `Phi`, the Jacobian row(s), `Phi_t` and `gamma = -(A qd)_q qd - 2 Phi_qt qd - Phi_tt`.

use super::ConstraintOut;
use crate::body::{Body, Marker, MarkerState};

/// `r_a - r_b = 0` (rows `k`, `k + 1`).
#[inline]
pub fn coincidence(bodies: &[Body], a: &Marker, b: &Marker, sa: &MarkerState, sb: &MarkerState, n_cols: usize, out: &mut ConstraintOut, k: usize) {
    for c in 0..2 {
        if let Some(phi) = out.phi.as_deref_mut() {
            phi[k + c] = sa.r[c] - sb.r[c];
        }
        let mut w = [0.0; 2];
        w[c] = 1.0;
        let layout = Some(out.layout);
        let row = &mut out.jac[(k + c) * n_cols..(k + c + 1) * n_cols];
        a.add_point_jacobian_in(bodies, sa, w, row, layout);
        b.add_point_jacobian_in(bodies, sb, [-w[0], -w[1]], row, layout);
        out.phi_t[k + c] = 0.0;
        out.gamma[k + c] = -(sa.h[c] - sb.h[c]);
    }
}

/// Point on line: `Phi = n . d`, `d = r_p - r_l`, `n = (-sin phi_l, cos phi_l)`;
/// `Phi_dd = n . d_dd + 2 phi_l_dot (J n) . d_dot + phi_l_dd (J n) . d - phi_l_dot^2 n . d`.
#[inline]
pub fn point_on_line(bodies: &[Body], p: &Marker, l: &Marker, sp: &MarkerState, sl: &MarkerState, n_cols: usize, out: &mut ConstraintOut, k: usize) {
    let (s, c) = sl.phi.sin_cos();
    let nv = [-s, c];
    let jn = [-c, -s]; // J n, J = [[0, -1], [1, 0]]
    let d = [sp.r[0] - sl.r[0], sp.r[1] - sl.r[1]];
    let dd = [sp.v[0] - sl.v[0], sp.v[1] - sl.v[1]];
    let jnd = jn[0] * d[0] + jn[1] * d[1];
    if let Some(phi) = out.phi.as_deref_mut() {
        phi[k] = nv[0] * d[0] + nv[1] * d[1];
    }
    let layout = Some(out.layout);
    let row = &mut out.jac[k * n_cols..(k + 1) * n_cols];
    p.add_point_jacobian_in(bodies, sp, nv, row, layout);
    l.add_point_jacobian_in(bodies, sl, [-nv[0], -nv[1]], row, layout);
    l.add_angle_jacobian_in(bodies, sl, jnd, row, layout);
    out.phi_t[k] = 0.0;
    let hd = [sp.h[0] - sl.h[0], sp.h[1] - sl.h[1]];
    out.gamma[k] = -(nv[0] * hd[0] + nv[1] * hd[1] + 2.0 * sl.omega * (jn[0] * dd[0] + jn[1] * dd[1]) + sl.h_phi * jnd
        - sl.omega * sl.omega * (nv[0] * d[0] + nv[1] * d[1]));
}

/// `x` wrapped into `[-pi, pi)`: the same angle, the nearest turn.
#[inline]
pub fn wrap_angle(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    x - TAU * ((x + PI) / TAU).floor()
}

/// Relative angle `phi_a - phi_b - f(t)`, `f = (f, f', f'')`, wrapped to the nearest turn: a
/// marker angle read off a direction (an ANCF slope, `atan2`) jumps by `2 pi` where it passes
/// `+-pi`, and a body turns any number of times (docs/integrators.md, continuous angles).
#[inline]
pub fn angle(bodies: &[Body], a: &Marker, b: &Marker, sa: &MarkerState, sb: &MarkerState, f: (f64, f64, f64), n_cols: usize, out: &mut ConstraintOut, k: usize) {
    if let Some(phi) = out.phi.as_deref_mut() {
        phi[k] = wrap_angle(sa.phi - sb.phi - f.0);
    }
    let layout = Some(out.layout);
    let row = &mut out.jac[k * n_cols..(k + 1) * n_cols];
    a.add_angle_jacobian_in(bodies, sa, 1.0, row, layout);
    b.add_angle_jacobian_in(bodies, sb, -1.0, row, layout);
    out.phi_t[k] = -f.1;
    out.gamma[k] = -(sa.h_phi - sb.h_phi) + f.2; // -Phi_tt = f''
}
