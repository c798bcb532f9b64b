//! Spatial markers: a frame on a body (docs/spatial-design.md, section 2): a point `s'` and
//! axes `C` (columns `x, y, z`). World point and axes with their Jacobian blocks and the
//! quadratic terms of their second derivatives (`vdd = J qdd + h`):
//!
//! `P = r + A s'`, `J_P = [I, B(p, s')]`, `Pd = rd + B(p, s') pd`, `h_P = 2 A(pd) s'`;
//! `a = A c`, `J_a = [0, B(p, c)]`, `ad = B(p, c) pd`, `h_a = 2 A(pd) c`.
//!
//! Ground markers are constants; a point mass's marker is the particle with the world axes.
//! On a `flexible3` body a marker sits on an interface node and moves with the deformation:
//! `s' = u0 + Phi q_f` and axes `c' = c + (Psi q_f) x c` (the node's small rotation, linear in
//! `q_f` as the modal field is), so `J_P = [I, B(p, s'), A Phi]`,
//! `h_P = 2 A(pd) s' + 2 B(p, Phi qd_f) pd`, `J_a = [0, B(p, c'), -A ~c Psi]`,
//! `h_a = 2 A(pd) c' + 2 B(p, (Psi qd_f) x c) pd`.
//! `base` is the marker as the planar machinery sees it (its body, `MarkerShape::Spatial`),
//! which gives the structural pattern (`Marker::coords`) to `sparse_newton`.

use super::{Body, BodyKind, Flexible3, Marker, MarkerShape};
use crate::error::{check_finite_item, Error, Result};
use crate::description::spatial::Marker3Desc;
use crate::linalg::rot3::{add, col, cross, frame_from_z, m34_t_vec, m34_vec, mat_vec, norm, rot_a, rot_b, scale, sub, M3, M34, V3};

/// Every axis (`Marker3::state_axes`).
pub const ALL_AXES: u8 = 0b111;

/// Bit 3 of an axes mask: the point's rate `vd` is not read (a joint whose rows use the
/// points only through their coincidence: its `vd` is left NaN on a rigid3 body, where it
/// costs a 3 x 4 product).
pub const NO_POINT_RATE: u8 = 0b1000;

#[derive(Debug, Clone)]
pub struct Marker3 {
    pub base: Marker,
    pub body: Option<usize>,
    /// On a rigid body (its kinematics depend on `p`).
    pub rigid: bool,
    /// Point relative to the centre of mass in body axes (world point for the ground, zero for
    /// a point mass).
    pub s: V3,
    /// Axes (columns `x, y, z`) in body axes (world axes for the ground and point masses).
    pub c: M3,
    /// The interface node of a `flexible3` body the marker sits on.
    pub iface: Option<usize>,
}

/// A vector quantity of one marker with its Jacobian (`jr`: the identity `r` block of a point,
/// 0 for an axis; `jp`: `d v / d p`), velocity and quadratic acceleration term.
#[derive(Debug, Clone, Copy, Default)]
pub struct Kin3 {
    pub v: V3,
    pub vd: V3,
    pub h: V3,
    pub jr: f64,
    pub jp: M34,
    /// On a `flexible3` body: 1 the point, `2 + k` the axis `k` (its elastic Jacobian columns,
    /// `Flexible3::add_marker_jacobian`); 0 otherwise.
    pub flex: u8,
    /// The axis in body axes (undeformed) of an axis quantity on a `flexible3` body.
    pub c: V3,
}

#[derive(Debug, Clone, Copy, Default)]
pub struct Marker3State {
    pub body: Option<usize>,
    pub rigid: bool,
    pub point: Kin3,
    pub axes: [Kin3; 3],
    /// `flexible3`: the interface node and `A(p)` (the elastic Jacobian's rotation).
    pub iface: Option<usize>,
    pub rot: M3,
}

/// A spatial body's rotation at `(q, qd)`: `A(p)` and `A(pd)` (`rot3::rot_a`, not normalized),
/// computed once per body for all its markers (`Marker3Work::frames`, filled by
/// `dynamics::constraints` before the joint rows read it).
#[derive(Debug, Clone, Copy, Default)]
pub struct Frame3 {
    pub a: M3,
    pub ad: M3,
}

/// The joint rows' marker workspace (`Data::marker3`): each body's `Frame3` at the state of the
/// last `dynamics::constraints`, and the two states of the joint being evaluated
/// (`Marker3::state_into` writes every field its readers read: nothing of a previous joint is
/// read).
#[derive(Debug, Clone)]
pub struct Marker3Work {
    pub frames: Vec<Frame3>,
    pub states: [Marker3State; 2],
}

impl Marker3Work {
    pub fn new(bodies: usize) -> Marker3Work {
        Marker3Work { frames: vec![Frame3::default(); bodies], states: [Marker3State::default(); 2] }
    }
}

impl Frame3 {
    #[inline]
    pub fn of(p: &[f64], pd: &[f64]) -> Frame3 {
        Frame3 { a: rot_a(p), ad: rot_a(pd) }
    }

    /// One per body: the rigid3 and flexible3 bodies' rotations at `(q, qd)` (the others are
    /// left as they are: their markers read none). Out of line: the planar constraint loop
    /// (`dynamics::constraints`) keeps its code.
    #[inline(never)]
    pub fn fill(bodies: &[Body], q: &[f64], qd: &[f64], frames: &mut [Frame3]) {
        for (b, f) in bodies.iter().zip(frames.iter_mut()) {
            if matches!(b.kind, BodyKind::Rigid3(_) | BodyKind::Flexible3(_)) {
                let o = b.offset;
                *f = Frame3::of(&q[o + 3..o + 7], &qd[o + 3..o + 7]);
            }
        }
    }
}

/// A frame's axes from a description: `z` (default `(0, 0, 1)`, normalized; zero or non-finite
/// is an error) and an optional `x` hint.
pub fn axes_from_desc(item: &str, md: &Marker3Desc) -> Result<M3> {
    let z = md.z.unwrap_or([0.0, 0.0, 1.0]);
    check_finite_item(item, "marker axis z", &z)?;
    let nz = norm(&z);
    if !(nz > 0.0) || !nz.is_finite() {
        return Err(Error::invalid(item, format!("marker axis z must be finite and nonzero, got {z:?}")));
    }
    let z = scale(1.0 / nz, &z);
    if let Some(x) = &md.x {
        check_finite_item(item, "marker axis x", x)?;
        if !(norm(x) > 0.0) {
            return Err(Error::invalid(item, format!("marker axis x must be finite and nonzero, got {x:?}")));
        }
    }
    frame_from_z(&z, md.x.as_ref()).ok_or_else(|| Error::invalid(item, "marker axis x must not be parallel to its z axis"))
}

impl Marker3 {
    /// Resolve a marker description on the ground or a spatial body (`index`: name -> body).
    pub fn from_desc(item: &str, md: &Marker3Desc, bodies: &[Body], index: &std::collections::HashMap<String, usize>) -> Result<Marker3> {
        let c = axes_from_desc(item, md)?;
        let point = md.point.unwrap_or([0.0; 3]);
        check_finite_item(item, "marker point", &point)?;
        if md.body == "ground" {
            return Ok(Marker3 { base: Marker { body: None, angle: 0.0, shape: MarkerShape::Spatial }, body: None, rigid: false, s: point, c, iface: None });
        }
        let Some(&bi) = index.get(&md.body) else {
            let mut known: Vec<&str> = vec!["ground"];
            known.extend(bodies.iter().map(|b| b.name.as_str()));
            return Err(Error::UnknownBody { item: item.to_string(), body: md.body.clone(), known: known.join(", ") });
        };
        let base = Marker { body: Some(bi), angle: 0.0, shape: MarkerShape::Spatial };
        match &bodies[bi].kind {
            BodyKind::Rigid3(k) => Ok(Marker3 { base, body: Some(bi), rigid: true, s: sub(&point, &k.com), c, iface: None }),
            BodyKind::Flexible3(k) => {
                let Some(f) = k.interface_at(&point) else {
                    let pts: Vec<String> = k.interfaces.iter().map(|f| format!("{:?}", f.point)).collect();
                    return Err(Error::invalid(item, format!(
                        "a marker on flexible body '{}' must sit on one of its interface nodes (markers move with the node's deformation); no interface node at {point:?}; interface nodes: [{}]",
                        md.body,
                        pts.join(", ")
                    )));
                };
                Ok(Marker3 { base, body: Some(bi), rigid: true, s: point, c, iface: Some(f) })
            }
            BodyKind::Point3(_) => {
                if point != [0.0; 3] {
                    return Err(Error::invalid(item, format!("a marker on point mass '{}' is the particle itself: point must be [0, 0, 0], got {point:?}", md.body)));
                }
                Ok(Marker3 { base, body: Some(bi), rigid: false, s: point, c, iface: None })
            }
            _ => Err(Error::invalid(item, format!("body '{}' is planar: a spatial scene holds only rigid3, point3 and flexible3 bodies", md.body))),
        }
    }

    /// A marker that turns with its body (joints and forces that need an orientation).
    pub fn check_oriented(&self, item: &str, what: &str) -> Result<()> {
        if self.body.is_some() && !self.rigid {
            return Err(Error::invalid(item, format!("{what}: a point mass has no orientation; this needs a rigid3 body or the ground")));
        }
        Ok(())
    }

    /// Kinematics at `(q, qd)`, every axis.
    #[inline]
    pub fn state(&self, bodies: &[Body], q: &[f64], qd: &[f64]) -> Marker3State {
        self.state_axes(bodies, q, qd, ALL_AXES)
    }

    /// Kinematics at `(q, qd)` of the point and of the axes in `axes` (bit `k`: axis `k`); the
    /// other axes are not computed (`state_into`). A joint kind names the axes its rows read (`AXES`), so that a
    /// spherical joint computes no axis at all.
    #[inline]
    pub fn state_axes(&self, bodies: &[Body], q: &[f64], qd: &[f64], axes: u8) -> Marker3State {
        self.state_in(bodies, &[], q, qd, axes)
    }

    /// `state_axes` with the body's rotations read from `frames` (`Frame3::fill` at the same
    /// `(q, qd)`, one per body); an empty `frames` computes them here. The same numbers bit for
    /// bit: the cache only saves recomputing `A(p)` and `A(pd)` for every marker of a body.
    #[inline]
    pub fn state_in(&self, bodies: &[Body], frames: &[Frame3], q: &[f64], qd: &[f64], axes: u8) -> Marker3State {
        let mut st = Marker3State::default();
        self.state_into(&mut st, bodies, frames, q, qd, axes);
        st
    }

    /// `state_in` written into `st`, field by field: what a reader of this marker reads is
    /// written (never zeroed first and overwritten), so a caller's buffer is reused as it is.
    /// Written: `body`, `rigid`, `iface`; of the point and of each axis in `axes`, `v`, `vd`,
    /// `h`, `jr`, `flex`, and `jp` on a rigid3 / flexible3 body; `c` and `rot` on a flexible3
    /// body only (read only with `flex != 0`). An axis not in `axes` gets `v = NaN` and nothing
    /// else: a kind that read an axis it did not name in `AXES` would give NaN rows; the same
    /// for the point's `vd` on a rigid3 body with `NO_POINT_RATE` in `axes`.
    #[inline]
    pub fn state_into(&self, st: &mut Marker3State, bodies: &[Body], frames: &[Frame3], q: &[f64], qd: &[f64], axes: u8) {
        st.body = self.body;
        st.rigid = self.rigid;
        st.iface = self.iface;
        let fixed_axes = |st: &mut Marker3State| {
            for k in 0..3 {
                let ax = &mut st.axes[k];
                if axes & (1 << k) == 0 {
                    ax.v = [f64::NAN; 3];
                    continue;
                }
                ax.v = col(&self.c, k);
                ax.vd = [0.0; 3];
                ax.h = [0.0; 3];
                ax.jr = 0.0;
                ax.flex = 0;
            }
        };
        let Some(bi) = self.body else {
            let pt = &mut st.point;
            pt.v = self.s;
            pt.vd = [0.0; 3];
            pt.h = [0.0; 3];
            pt.jr = 0.0;
            pt.flex = 0;
            fixed_axes(st);
            return;
        };
        let o = bodies[bi].offset;
        let r = [q[o], q[o + 1], q[o + 2]];
        let rd = [qd[o], qd[o + 1], qd[o + 2]];
        if !self.rigid {
            let pt = &mut st.point;
            pt.v = r;
            pt.vd = rd;
            pt.h = [0.0; 3];
            pt.jr = 1.0;
            pt.flex = 0;
            fixed_axes(st);
            return;
        }
        let (p, pd) = (&q[o + 3..o + 7], &qd[o + 3..o + 7]);
        let own;
        let fr = match frames.get(bi) {
            Some(f) => f,
            None => {
                own = Frame3::of(p, pd);
                &own
            }
        };
        if let (Some(f), BodyKind::Flexible3(k)) = (self.iface, &bodies[bi].kind) {
            return self.flexible_state(st, k, f, fr, r, rd, q, qd, o, axes);
        }
        let (a, ad) = (&fr.a, &fr.ad);
        let pt = &mut st.point;
        pt.jp = rot_b(p, &self.s);
        pt.v = add(&r, &mat_vec(a, &self.s));
        pt.vd = if axes & NO_POINT_RATE == 0 { add(&rd, &m34_vec(&pt.jp, pd)) } else { [f64::NAN; 3] };
        pt.h = scale(2.0, &mat_vec(ad, &self.s));
        pt.jr = 1.0;
        pt.flex = 0;
        for k in 0..3 {
            let ax = &mut st.axes[k];
            if axes & (1 << k) == 0 {
                ax.v = [f64::NAN; 3];
                continue;
            }
            let ck = col(&self.c, k);
            // `quad_term(pd, ck)` with `A(pd)` computed once per body
            ax.jp = rot_b(p, &ck);
            ax.v = mat_vec(a, &ck);
            ax.vd = m34_vec(&ax.jp, pd);
            ax.h = scale(2.0, &mat_vec(ad, &ck));
            ax.jr = 0.0;
            ax.flex = 0;
        }
    }

    /// `state_axes` of a marker on an interface node of a `flexible3` body (module docs).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn flexible_state(&self, st: &mut Marker3State, k: &Flexible3, f: usize, fr: &Frame3, r: V3, rd: V3, q: &[f64], qd: &[f64], o: usize, axes: u8) {
        let n = k.n;
        let (p, pd) = (&q[o + 3..o + 7], &qd[o + 3..o + 7]);
        let [s, sd, th, thd] = k.interface_state(f, &q[o + 7..o + 7 + n], &qd[o + 7..o + 7 + n]);
        let a = fr.a;
        st.rot = a;
        let jp = rot_b(p, &s);
        let vd = add(&add(&rd, &m34_vec(&jp, pd)), &mat_vec(&a, &sd));
        let h = add(&scale(2.0, &mat_vec(&fr.ad, &s)), &scale(2.0, &m34_vec(&rot_b(p, &sd), pd)));
        st.point = Kin3 { v: add(&r, &mat_vec(&a, &s)), vd, h, jr: 1.0, jp, flex: 1, c: [0.0; 3] };
        for kx in 0..3 {
            if axes & (1 << kx) == 0 {
                st.axes[kx].v = [f64::NAN; 3];
                continue;
            }
            let ck = col(&self.c, kx);
            let cd = cross(&thd, &ck);
            let cc = add(&ck, &cross(&th, &ck));
            let jp = rot_b(p, &cc);
            let vd = add(&m34_vec(&jp, pd), &mat_vec(&a, &cd));
            let h = add(&scale(2.0, &mat_vec(&fr.ad, &cc)), &scale(2.0, &m34_vec(&rot_b(p, &cd), pd)));
            st.axes[kx] = Kin3 { v: mat_vec(&a, &cc), vd, h, jr: 0.0, jp, flex: 2 + kx as u8, c: ck };
        }
    }
}

/// `row += w . dv/dq` for the quantity `k` of the marker state `ms` (row layout as in
/// `Marker::add_point_jacobian_in`: `None` a full n-row, `Some` a constraint's compressed row).
#[inline]
pub fn add_jacobian(bodies: &[Body], ms: &Marker3State, k: &Kin3, w: &V3, row: &mut [f64], layout: Option<&[(usize, usize)]>) {
    let Some(bi) = ms.body else { return };
    let start = match layout {
        None => bodies[bi].offset,
        Some(l) => l.iter().find(|e| e.0 == bi).expect("the marker's body is in the constraint's layout").1,
    };
    if k.jr != 0.0 {
        for c in 0..3 {
            row[start + c] += k.jr * w[c];
        }
    }
    if ms.rigid {
        let g = m34_t_vec(&k.jp, w);
        for l in 0..4 {
            row[start + 3 + l] += g[l];
        }
    }
    if k.flex != 0 {
        if let (Some(f), BodyKind::Flexible3(b)) = (ms.iface, &bodies[bi].kind) {
            b.add_marker_jacobian(f, k.flex, &k.c, &ms.rot, w, &mut row[start + 7..start + 7 + b.n]);
        }
    }
}

/// `rows[c] += sign e_c^T dP/dq`, `c = 0, 1, 2`: the marker's point Jacobian written row by
/// row into three rows `n` apart (a point coincidence), its entries as they are instead of
/// `e_c^T J_P` formed per row by `add_jacobian` (the same numbers: the other terms are zeros).
#[inline]
pub fn add_point_rows(bodies: &[Body], ms: &Marker3State, sign: f64, rows: &mut [f64], n: usize, layout: &[(usize, usize)]) {
    let Some(bi) = ms.body else { return };
    if ms.point.flex != 0 {
        for c in 0..3 {
            let mut e = [0.0; 3];
            e[c] = sign;
            add_jacobian(bodies, ms, &ms.point, &e, &mut rows[c * n..(c + 1) * n], Some(layout));
        }
        return;
    }
    let start = layout.iter().find(|e| e.0 == bi).expect("the marker's body is in the constraint's layout").1;
    let k = &ms.point;
    for c in 0..3 {
        let row = &mut rows[c * n..(c + 1) * n];
        row[start + c] += sign * k.jr;
        if ms.rigid {
            for l in 0..4 {
                row[start + 3 + l] += sign * k.jp[c][l];
            }
        }
    }
}
