//! Joint friction in spatial joints (docs/loads.md, "Joint friction in spatial joints"): the
//! slip rate, its generalized direction and the effective normal force of the law of
//! `friction.rs` (`F = -mu N_eff sat(v / v_eps) - c v`, closed with the reactions by
//! `uk::friction`, the same closure as the planar joints'):
//!
//! * revolute about `z_j`: `v = (w_i - w_j) . z_j` the relative spin, the torque's lever in
//!   `N_eff = r |F_rad| + r_c |F_ax|`, `F` the reaction force (the coincidence rows'
//!   multipliers, world components), `F_ax = F . z_j`, `F_rad = F - F_ax z_j`, `r` the pin radius
//!   and `r_c` the effective radius of a thrust collar carrying the axial load (0: none). The
//!   reaction moments across the axis (rows `xz`, `yz`) are left out;
//! * prismatic along `z_j`: `v = z_j . (Pd_i - Pd_j)` (the slip of coincident material points:
//!   the joint locks the relative rotation and keeps `d` on the axis), `N_eff = |N|`, `N` the
//!   reaction across the axis (rows `xd`, `yd`: the force `lambda_xd x_i + lambda_yd y_i`, `x_i`,
//!   `y_i` orthonormal); the reaction moments are left out (no slider length in 3D yet);
//! * spherical: `v = |w_i - w_j|`, the torque about the relative rotation axis
//!   `e = (w_i - w_j) / v` (0 at rest), `N_eff = |F|`, lever the ball radius `r`.
//!
//! `w = 2 E(p) pd` is a rigid3 body's angular velocity (world), so `dv/dpd = 2 E(p)^T e` for a
//! direction `e` fixed at the state.

use crate::body::marker3::{add_jacobian, Marker3};
use crate::body::Body;
use crate::constraint::spatial::{Pair, SpatialConstraint};
use crate::constraint::{Constraint, ConstraintKind};
use crate::description::spatial::JointFriction3Desc;
use crate::error::{non_negative, Error, Result};
use crate::linalg::rot3::{dot, norm, rot_e, scale, sub, V3};

/// The most multipliers a friction law reads (the first rows of its joint: a spatial
/// revolute's five).
pub const MAX_ROWS: usize = 5;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact3 {
    /// Revolute: pin radius and thrust-collar radius.
    Pin { radius: f64, collar: f64 },
    /// Prismatic: the reaction across the axis.
    Slide,
    /// Spherical: the ball radius.
    Ball { radius: f64 },
}

impl Contact3 {
    /// The lever of `N_eff` in the law (`coulomb = mu lever`): the revolute's radii are in its
    /// `N_eff` (a moment), the ball's radius multiplies `|F|`.
    pub fn lever(&self) -> f64 {
        match self {
            Contact3::Pin { .. } | Contact3::Slide => 1.0,
            Contact3::Ball { radius } => *radius,
        }
    }

    /// `N_eff` from the joint's first rows' multipliers `lam` and its gradient into `g`;
    /// `aux` the revolute's axis `z_j` (world).
    pub fn normal(&self, lam: &[f64], aux: &[f64; 3], g: &mut [f64; MAX_ROWS]) -> f64 {
        match *self {
            Contact3::Pin { radius, collar } => {
                let f = [lam[0], lam[1], lam[2]];
                let ax = dot(&f, aux);
                let sign = if ax > 0.0 { 1.0 } else if ax < 0.0 { -1.0 } else { 0.0 };
                let rad = sub(&f, &scale(ax, aux));
                let nr = norm(&rad);
                for c in 0..3 {
                    g[c] = collar * sign * aux[c] + if nr > 0.0 { radius * rad[c] / nr } else { 0.0 };
                }
                radius * nr + collar * ax.abs()
            }
            Contact3::Slide => {
                let n = lam[2].hypot(lam[3]);
                if n > 0.0 {
                    (g[2], g[3]) = (lam[2] / n, lam[3] / n);
                }
                n
            }
            Contact3::Ball { .. } => {
                let n = norm(&[lam[0], lam[1], lam[2]]);
                if n > 0.0 {
                    for c in 0..3 {
                        g[c] = lam[c] / n;
                    }
                }
                n
            }
        }
    }
}

/// The angular velocity (world) of a marker's body: `2 E(p) pd` (zero on the ground).
fn omega(m: &Marker3, bodies: &[Body], q: &[f64], qd: &[f64]) -> V3 {
    let Some(b) = m.body else { return [0.0; 3] };
    let o = bodies[b].offset;
    let (e, pd) = (rot_e(&q[o + 3..o + 7]), &qd[o + 3..o + 7]);
    let mut w = [0.0; 3];
    for (i, row) in e.iter().enumerate() {
        w[i] = 2.0 * (row[0] * pd[0] + row[1] * pd[1] + row[2] * pd[2] + row[3] * pd[3]);
    }
    w
}

/// `g += s d(w . e)/dqd = s 2 E(p)^T e` on the marker's body (nothing on the ground).
fn add_spin_direction(m: &Marker3, bodies: &[Body], q: &[f64], e: &V3, s: f64, g: &mut [f64]) {
    let Some(b) = m.body else { return };
    let o = bodies[b].offset;
    let ep = rot_e(&q[o + 3..o + 7]);
    for l in 0..4 {
        g[o + 3 + l] += 2.0 * s * (ep[0][l] * e[0] + ep[1][l] * e[1] + ep[2][l] * e[2]);
    }
}

/// The slip rate and its generalized direction added into `g` (module docs); `aux`: the
/// revolute's axis.
pub fn kinematics(c: Contact3, pair: &Pair, bodies: &[Body], q: &[f64], qd: &[f64], g: &mut [f64], aux: &mut [f64; 3]) -> f64 {
    match c {
        Contact3::Pin { .. } => {
            let z = pair.j.state_axes(bodies, q, qd, 0b100).axes[2].v;
            *aux = z;
            add_spin_direction(&pair.i, bodies, q, &z, 1.0, g);
            add_spin_direction(&pair.j, bodies, q, &z, -1.0, g);
            dot(&sub(&omega(&pair.i, bodies, q, qd), &omega(&pair.j, bodies, q, qd)), &z)
        }
        Contact3::Slide => {
            let (si, sj) = pair.states_axes(bodies, &[], q, qd, [0, 0b100]);
            let z = sj.axes[2].v;
            *aux = z;
            add_jacobian(bodies, &si, &si.point, &z, g, None);
            add_jacobian(bodies, &sj, &sj.point, &scale(-1.0, &z), g, None);
            dot(&sub(&si.point.vd, &sj.point.vd), &z)
        }
        Contact3::Ball { .. } => {
            let w = sub(&omega(&pair.i, bodies, q, qd), &omega(&pair.j, bodies, q, qd));
            let v = norm(&w);
            if v > 0.0 {
                let e = scale(1.0 / v, &w);
                *aux = e;
                add_spin_direction(&pair.i, bodies, q, &e, 1.0, g);
                add_spin_direction(&pair.j, bodies, q, &e, -1.0, g);
            }
            v
        }
    }
}

/// A spatial joint friction's description checked against its joint: the joint's index, its
/// markers and the contact (`JointFriction::from_desc3` builds the element).
pub struct Parsed {
    pub joint: usize,
    pub pair: Pair,
    pub contact: Contact3,
    pub mu: f64,
    pub damping: f64,
}

/// Check friction in the spatial joint `d.joint` among `constraints` (the joints built so far).
pub fn parse(item: &str, constraints: &[Constraint], d: &JointFriction3Desc) -> Result<Parsed> {
    let joint = &d.joint;
    let Some(ji) = constraints.iter().position(|c| &c.name == joint) else {
        return Err(Error::UnknownName { what: format!("joint (of {item})"), name: joint.clone(), valid: constraints.iter().map(|c| c.name.clone()).collect() });
    };
    let mu = non_negative(item, "mu", d.mu)?;
    let damping = non_negative(item, "damping", d.damping)?;
    let refuse = |what: &str, why: &str| Err(Error::invalid(item, format!("{what} {why}; '{joint}' is a spatial {} joint", kind_name(&constraints[ji].kind))));
    let ConstraintKind::Spatial(sc) = &constraints[ji].kind else {
        return refuse("joint friction in a spatial scene", "needs a spatial joint");
    };
    let (pair, contact) = match sc {
        SpatialConstraint::Revolute(r) => {
            if d.length.is_some() {
                return refuse("length", "is a planar prismatic joint's slider length");
            }
            let Some(radius) = d.radius else {
                return refuse("radius", "(the pin radius, the friction torque's lever) is needed");
            };
            let radius = non_negative(item, "radius", radius)?;
            let collar = non_negative(item, "collar_radius", d.collar_radius.unwrap_or(0.0))?;
            (&r.pair, Contact3::Pin { radius, collar })
        }
        SpatialConstraint::Prismatic(p) => {
            for (given, what) in [(d.radius.is_some(), "radius"), (d.collar_radius.is_some(), "collar_radius"), (d.length.is_some(), "length")] {
                if given {
                    return refuse(what, "is not read: a spatial prismatic joint's friction takes the reaction across its axis (its reaction moments are left out)");
                }
            }
            (&p.pair, Contact3::Slide)
        }
        SpatialConstraint::Spherical(s) => {
            if d.collar_radius.is_some() || d.length.is_some() {
                return refuse("collar_radius and length", "are not read by a spherical joint's friction (give radius, the ball radius)");
            }
            let Some(radius) = d.radius else {
                return refuse("radius", "(the ball radius, the friction torque's lever) is needed");
            };
            (&s.pair, Contact3::Ball { radius: non_negative(item, "radius", radius)? })
        }
        _ => return refuse("joint friction", "works in revolute, prismatic and spherical joints"),
    };
    for m in [&pair.i, &pair.j] {
        if m.body.is_some() && (!m.rigid || m.iface.is_some()) {
            return refuse("joint friction", "needs rigid3 bodies (or the ground) on both markers: a point mass has no spin, a flexible body's node is not covered yet");
        }
    }
    Ok(Parsed { joint: ji, pair: pair.clone(), contact, mu, damping })
}

fn kind_name(k: &ConstraintKind) -> &'static str {
    let ConstraintKind::Spatial(c) = k else { return "planar" };
    match c {
        SpatialConstraint::Spherical(_) => "spherical",
        SpatialConstraint::Revolute(_) => "revolute",
        SpatialConstraint::Prismatic(_) => "prismatic",
        SpatialConstraint::Cylindrical(_) => "cylindrical",
        SpatialConstraint::Universal(_) => "universal",
        SpatialConstraint::Fixed(_) => "fixed",
        SpatialConstraint::Planar(_) => "planar",
        SpatialConstraint::Distance(_) => "distance",
        SpatialConstraint::PointOnLine(_) => "point_on_line",
        SpatialConstraint::PointOnPlane(_) => "point_on_plane",
        SpatialConstraint::Rotation(_) => "rotation driver",
        SpatialConstraint::Translation(_) => "translation driver",
        SpatialConstraint::Normalization(_) => "normalization",
    }
}
