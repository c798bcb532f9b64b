//! Joints and drivers: `Phi(q, t) = 0`, its Jacobian `A = Phi_q`, `Phi_t`, and
//! `gamma = -(A qd)_q qd - 2 Phi_qt qd - Phi_tt` (paper eq. 43). Every joint works on markers,
//! so it works the same on rigid bodies and on beams.

use crate::body::{Body, Marker, MarkerState};
use crate::description::{Axis, MotionDesc};

/// Prescribed motion `f(t)` of a driver with its first two derivatives.
#[derive(Debug, Clone)]
pub enum Motion {
    ConstantSpeed { initial: f64, speed: f64 },
    Polynomial { coefficients: Vec<f64> },
    Harmonic { offset: f64, amplitude: f64, frequency: f64, phase: f64 },
}

impl Motion {
    pub fn from_desc(d: &MotionDesc) -> Motion {
        match d {
            MotionDesc::ConstantSpeed { initial, speed } => Motion::ConstantSpeed { initial: *initial, speed: *speed },
            MotionDesc::Polynomial { coefficients } => Motion::Polynomial { coefficients: coefficients.clone() },
            MotionDesc::Harmonic { offset, amplitude, frequency, phase } => {
                Motion::Harmonic { offset: *offset, amplitude: *amplitude, frequency: *frequency, phase: *phase }
            }
        }
    }

    pub fn parameters(&self) -> Vec<f64> {
        match self {
            Motion::ConstantSpeed { initial, speed } => vec![*initial, *speed],
            Motion::Polynomial { coefficients } => coefficients.clone(),
            Motion::Harmonic { offset, amplitude, frequency, phase } => vec![*offset, *amplitude, *frequency, *phase],
        }
    }

    /// `(f, f', f'')` at time `t`.
    #[inline]
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        match self {
            Motion::ConstantSpeed { initial, speed } => (initial + speed * t, *speed, 0.0),
            Motion::Polynomial { coefficients } => {
                // Horner for f, f', f''
                let (mut f, mut d1, mut d2) = (0.0, 0.0, 0.0);
                for &c in coefficients.iter().rev() {
                    d2 = d2 * t + 2.0 * d1;
                    d1 = d1 * t + f;
                    f = f * t + c;
                }
                (f, d1, d2)
            }
            Motion::Harmonic { offset, amplitude, frequency, phase } => {
                let (s, c) = (frequency * t + phase).sin_cos();
                (offset + amplitude * s, amplitude * frequency * c, -amplitude * frequency * frequency * s)
            }
        }
    }
}

#[derive(Debug, Clone)]
pub enum ConstraintKind {
    /// `r_a - r_b = 0` (2 rows).
    Revolute { a: Marker, b: Marker },
    /// `n . (r_point - r_line) = 0`, `n` = line direction turned +90 deg (1 row).
    PointOnLine { point: Marker, line: Marker },
    /// point-on-line of `a`'s origin on `b`'s x axis + `phi_a - phi_b - phi0 = 0` (2 rows).
    Prismatic { a: Marker, b: Marker, phi0: f64 },
    /// `r_a - r_b = 0`, `phi_a - phi_b - phi0 = 0` (3 rows).
    Weld { a: Marker, b: Marker, phi0: f64 },
    /// `phi_a - phi_b - f(t) = 0` (1 row).
    AngleDriver { a: Marker, b: Marker, motion: Motion },
    /// `r_point[axis] - f(t) = 0` (1 row).
    CoordinateDriver { point: Marker, axis: Axis, motion: Motion },
}

#[derive(Debug, Clone)]
pub struct Constraint {
    pub name: String,
    /// First row in `Phi`.
    pub row: usize,
    pub kind: ConstraintKind,
}

impl ConstraintKind {
    pub fn rows(&self) -> usize {
        match self {
            ConstraintKind::Revolute { .. } => 2,
            ConstraintKind::PointOnLine { .. } => 1,
            ConstraintKind::Prismatic { .. } => 2,
            ConstraintKind::Weld { .. } => 3,
            ConstraintKind::AngleDriver { .. } | ConstraintKind::CoordinateDriver { .. } => 1,
        }
    }

    pub fn is_driver(&self) -> bool {
        matches!(self, ConstraintKind::AngleDriver { .. } | ConstraintKind::CoordinateDriver { .. })
    }
}

/// Output of one constraint evaluation. Slices are the constraint's own rows.
pub struct ConstraintOut<'a> {
    /// `Phi` rows (written only when `Some`).
    pub phi: Option<&'a mut [f64]>,
    /// Jacobian rows, each `n` long (row-major), already zeroed by the caller.
    pub jac: &'a mut [f64],
    /// `Phi_t` rows.
    pub phi_t: &'a mut [f64],
    /// `gamma` rows.
    pub gamma: &'a mut [f64],
}

/// Point-on-line rows shared by `PointOnLine` and `Prismatic`:
/// `Phi = n . d`, `d = r_p - r_l`, `n = (-sin phi_l, cos phi_l)`;
/// `Phi_dd = n . d_dd + 2 phi_l_dot (J n) . d_dot + phi_l_dd (J n) . d - phi_l_dot^2 n . d`.
#[inline]
fn point_on_line(bodies: &[Body], p: &Marker, l: &Marker, sp: &MarkerState, sl: &MarkerState, n_cols: usize, out: &mut ConstraintOut, k: usize) {
    let (s, c) = sl.phi.sin_cos();
    let nv = [-s, c];
    let jn = [-c, -s]; // J n, J = [[0, -1], [1, 0]]
    let d = [sp.r[0] - sl.r[0], sp.r[1] - sl.r[1]];
    let dd = [sp.v[0] - sl.v[0], sp.v[1] - sl.v[1]];
    if let Some(phi) = out.phi.as_deref_mut() {
        phi[k] = nv[0] * d[0] + nv[1] * d[1];
    }
    let row = &mut out.jac[k * n_cols..(k + 1) * n_cols];
    p.add_point_jacobian(bodies, sp, nv, row);
    l.add_point_jacobian(bodies, sl, [-nv[0], -nv[1]], row);
    l.add_angle_jacobian(bodies, jn[0] * d[0] + jn[1] * d[1], row);
    out.phi_t[k] = 0.0;
    let hd = [sp.h[0] - sl.h[0], sp.h[1] - sl.h[1]];
    out.gamma[k] = -(nv[0] * hd[0] + nv[1] * hd[1] + 2.0 * sl.omega * (jn[0] * dd[0] + jn[1] * dd[1])
        - sl.omega * sl.omega * (nv[0] * d[0] + nv[1] * d[1]));
}

/// Relative angle row `phi_a - phi_b - c(t)`; the frame angles are linear in `q`.
#[inline]
fn angle_row(bodies: &[Body], a: &Marker, b: &Marker, sa: &MarkerState, sb: &MarkerState, f: (f64, f64, f64), n_cols: usize, out: &mut ConstraintOut, k: usize) {
    if let Some(phi) = out.phi.as_deref_mut() {
        phi[k] = sa.phi - sb.phi - f.0;
    }
    let row = &mut out.jac[k * n_cols..(k + 1) * n_cols];
    a.add_angle_jacobian(bodies, 1.0, row);
    b.add_angle_jacobian(bodies, -1.0, row);
    out.phi_t[k] = -f.1;
    out.gamma[k] = f.2; // -Phi_tt
}

#[inline]
fn coincidence_rows(bodies: &[Body], a: &Marker, b: &Marker, sa: &MarkerState, sb: &MarkerState, n_cols: usize, out: &mut ConstraintOut) {
    for k in 0..2 {
        if let Some(phi) = out.phi.as_deref_mut() {
            phi[k] = sa.r[k] - sb.r[k];
        }
        let mut w = [0.0; 2];
        w[k] = 1.0;
        let row = &mut out.jac[k * n_cols..(k + 1) * n_cols];
        a.add_point_jacobian(bodies, sa, w, row);
        b.add_point_jacobian(bodies, sb, [-w[0], -w[1]], row);
        out.phi_t[k] = 0.0;
        out.gamma[k] = -(sa.h[k] - sb.h[k]);
    }
}

impl Constraint {
    /// Evaluate this constraint's rows at `(t, q, qd)`.
    #[inline]
    pub fn eval(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], n_cols: usize, mut out: ConstraintOut) {
        match &self.kind {
            ConstraintKind::Revolute { a, b } => {
                let (sa, sb) = (a.state(bodies, q, qd), b.state(bodies, q, qd));
                coincidence_rows(bodies, a, b, &sa, &sb, n_cols, &mut out);
            }
            ConstraintKind::Weld { a, b, phi0 } => {
                let (sa, sb) = (a.state(bodies, q, qd), b.state(bodies, q, qd));
                coincidence_rows(bodies, a, b, &sa, &sb, n_cols, &mut out);
                angle_row(bodies, a, b, &sa, &sb, (*phi0, 0.0, 0.0), n_cols, &mut out, 2);
            }
            ConstraintKind::PointOnLine { point, line } => {
                let (sp, sl) = (point.state(bodies, q, qd), line.state(bodies, q, qd));
                point_on_line(bodies, point, line, &sp, &sl, n_cols, &mut out, 0);
            }
            ConstraintKind::Prismatic { a, b, phi0 } => {
                let (sa, sb) = (a.state(bodies, q, qd), b.state(bodies, q, qd));
                point_on_line(bodies, a, b, &sa, &sb, n_cols, &mut out, 0);
                angle_row(bodies, a, b, &sa, &sb, (*phi0, 0.0, 0.0), n_cols, &mut out, 1);
            }
            ConstraintKind::AngleDriver { a, b, motion } => {
                let (sa, sb) = (a.state(bodies, q, qd), b.state(bodies, q, qd));
                angle_row(bodies, a, b, &sa, &sb, motion.eval(t), n_cols, &mut out, 0);
            }
            ConstraintKind::CoordinateDriver { point, axis, motion } => {
                let sp = point.state(bodies, q, qd);
                let k = match axis {
                    Axis::X => 0,
                    Axis::Y => 1,
                };
                let f = motion.eval(t);
                if let Some(phi) = out.phi.as_deref_mut() {
                    phi[0] = sp.r[k] - f.0;
                }
                let mut w = [0.0; 2];
                w[k] = 1.0;
                point.add_point_jacobian(bodies, &sp, w, &mut out.jac[0..n_cols]);
                out.phi_t[0] = -f.1;
                out.gamma[0] = -sp.h[k] + f.2;
            }
        }
    }
}
