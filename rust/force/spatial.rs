//! Spatial force elements (docs/spatial-design.md, section 4), each adding its generalized force
//! to `Q` through the markers' Jacobians:
//!
//! * gravity `m g` at every body's centre of mass (one element per scene, named `gravity`; a
//!   `flexible3` body's distributed gravity is its own, `Flexible3::add_gravity`);
//! * a point force `F` at a marker (world components, or components in the marker's axes that
//!   turn with the body: `F = A C F'`): `Q = J_P^T F`;
//! * a torque (world `n`, or body axes `n'`): `Q_p = 2 G^T n'`, `n' = A^T n`;
//! * a translational spring-damper: `f = k (L - L0) + c Ld` (tension positive), `Q = -f J_L^T`;
//! * a rotational spring-damper about `z_a`: `theta - theta0` read as
//!   `w = atan2(s cos t0 - c sin t0, s sin t0 + c cos t0)` (`s = y_a . x_b`, `c = x_a . x_b`)
//!   and counted over turns: the first reading is `w` (within half a turn of `theta0`), every
//!   later one the value `prev + wrap(w - prev)` nearest the previous reading (the workspace's
//!   `Data::turns`, as Chrono's rotational spring-damper counts its turns from call to call; a
//!   native run starts from a fresh workspace), so the spring winds up through any number of
//!   turns; `tau = -k (theta - theta0) - c thetad`, `Q = tau J_theta^T`,
//!   `J_theta = (c J_s - s J_c) / (s^2 + c^2)`;
//! * an element of a geometrically exact beam between two node bodies (`body/beam3.rs`):
//!   `Q = -dU/dx` on the two nodes' coordinates, its tangent `K = d^2 U / dx^2`.

use crate::body::marker3::{add_jacobian, Marker3};
use crate::body::beam3::element::{ElementConsts, NX};
use crate::body::{Body, BodyKind, Marker, MarkerShape};
use crate::constraint::spatial::prim;
use crate::description::spatial::FrameDesc;
use crate::constraint::rows::wrap_angle;
use crate::linalg::rot3::{dot, mat_t_vec, mat_vec, norm, rot_a, rot_g, scale, sub, V3};

#[derive(Debug, Clone)]
pub enum SpatialForce {
    Gravity { g: V3 },
    PointForce { point: Marker3, force: V3, frame: FrameDesc },
    Torque { body: usize, base: Marker, torque: V3, frame: FrameDesc },
    SpringDamper { a: Marker3, b: Marker3, stiffness: f64, damping: f64, rest_length: f64 },
    RotationalSpringDamper { a: Marker3, b: Marker3, stiffness: f64, damping: f64, angle0: f64 },
    /// A 3D beam element between the node bodies `nodes` (`rigid3`, coordinates `[r, p]`).
    Beam3 { nodes: [usize; 2], base: [Marker; 2], element: ElementConsts },
}

/// The 14 coordinates `[r_A, p_A, r_B, p_B]` of a beam element's nodes.
#[inline]
fn element_coords(nodes: &[usize; 2], bodies: &[Body], v: &[f64]) -> [f64; NX] {
    let (oa, ob) = (bodies[nodes[0]].offset, bodies[nodes[1]].offset);
    std::array::from_fn(|i| if i < 7 { v[oa + i] } else { v[ob + i - 7] })
}

/// The whole-`n` index of an element coordinate.
#[inline]
fn element_index(nodes: &[usize; 2], bodies: &[Body], i: usize) -> usize {
    if i < 7 {
        bodies[nodes[0]].offset + i
    } else {
        bodies[nodes[1]].offset + i - 7
    }
}

/// `m` and the coordinate offset of a spatial body (`None` for planar kinds).
fn spatial_mass(b: &Body) -> Option<f64> {
    match &b.kind {
        BodyKind::Rigid3(k) => Some(k.mass),
        BodyKind::Point3(k) => Some(k.mass),
        _ => None,
    }
}

impl SpatialForce {
    /// The element's kind as the description names it (`gravity` for the scene's gravity).
    pub fn kind(&self) -> &'static str {
        match self {
            SpatialForce::Gravity { .. } => "gravity",
            SpatialForce::PointForce { .. } => "point_force",
            SpatialForce::Torque { .. } => "torque",
            SpatialForce::SpringDamper { .. } => "spring_damper",
            SpatialForce::RotationalSpringDamper { .. } => "rotational_spring_damper",
            SpatialForce::Beam3 { .. } => "beam3_element",
        }
    }

    pub fn torque_marker(body: usize) -> Marker {
        Marker { body: Some(body), angle: 0.0, shape: MarkerShape::Spatial }
    }

    pub fn markers(&self) -> [Option<&Marker>; 2] {
        match self {
            SpatialForce::Gravity { .. } => [None, None],
            SpatialForce::PointForce { point, .. } => [Some(&point.base), None],
            SpatialForce::Torque { base, .. } => [Some(base), None],
            SpatialForce::SpringDamper { a, b, .. } | SpatialForce::RotationalSpringDamper { a, b, .. } => [Some(&a.base), Some(&b.base)],
            SpatialForce::Beam3 { base, .. } => [Some(&base[0]), Some(&base[1])],
        }
    }

    /// Spring length and its rate, with the unit direction `u = d / L` (`None` at `L = 0`).
    fn spring(a: &Marker3, b: &Marker3, bodies: &[Body], q: &[f64], qd: &[f64]) -> (f64, f64, Option<V3>, [crate::body::marker3::Marker3State; 2]) {
        // the points alone: a spring reads no axis
        let (sa, sb) = (a.state_axes(bodies, q, qd, 0), b.state_axes(bodies, q, qd, 0));
        let (d, dd, _) = prim::separation(&sa, &sb);
        let l = norm(&d);
        if l == 0.0 {
            return (0.0, 0.0, None, [sa, sb]);
        }
        let u = scale(1.0 / l, &d);
        (l, dot(&u, &dd), Some(u), [sa, sb])
    }

    /// `(theta - theta0, thetad, s, c, r2)` of a rotational spring: read within half a turn of
    /// `theta0` (`turn = None`, or its first reading), else counted from the previous reading
    /// `*turn`, which it updates.
    #[allow(clippy::type_complexity)]
    fn angle(a: &Marker3, b: &Marker3, angle0: f64, bodies: &[Body], q: &[f64], qd: &[f64], turn: Option<&mut f64>) -> (f64, f64, [crate::body::marker3::Marker3State; 2], f64, f64, f64) {
        let (sa, sb) = (a.state(bodies, q, qd), b.state(bodies, q, qd));
        let (s, sd, _) = prim::dot_terms(&sa.axes[1], &sb.axes[0]);
        let (c, cd, _) = prim::dot_terms(&sa.axes[0], &sb.axes[0]);
        let r2 = s * s + c * c;
        let (s0, c0) = angle0.sin_cos();
        let mut th = (s * c0 - c * s0).atan2(s * s0 + c * c0);
        if let Some(prev) = turn {
            if prev.is_finite() {
                th = *prev + wrap_angle(th - *prev);
            }
            *prev = th;
        }
        let thd = if r2 > 0.0 { (c * sd - s * cd) / r2 } else { 0.0 };
        (th, thd, [sa, sb], s, c, r2)
    }

    /// Add the generalized force to `qv` (length n); `turn`: the rotational spring's count
    /// (`Data::turns`).
    #[inline]
    pub fn add_to(&self, bodies: &[Body], q: &[f64], qd: &[f64], turn: &mut f64, qv: &mut [f64]) {
        match self {
            SpatialForce::Gravity { g } => {
                for b in bodies {
                    if let BodyKind::Flexible3(k) = &b.kind {
                        k.add_gravity(&q[b.offset..b.offset + b.n_coords], g, &mut qv[b.offset..b.offset + b.n_coords]);
                    } else if let Some(m) = spatial_mass(b) {
                        for c in 0..3 {
                            qv[b.offset + c] += m * g[c];
                        }
                    }
                }
            }
            SpatialForce::PointForce { point, force, frame } => {
                let st = point.state_axes(bodies, q, qd, 0);
                add_jacobian(bodies, &st, &st.point, &world_force(point, *frame, bodies, q, force), qv, None);
            }
            SpatialForce::Torque { body, torque, frame, .. } => add_torque(bodies, *body, *frame, q, torque, qv),
            SpatialForce::SpringDamper { a, b, stiffness, damping, rest_length } => {
                let (l, ld, u, [sa, sb]) = Self::spring(a, b, bodies, q, qd);
                let Some(u) = u else { return };
                let f = stiffness * (l - rest_length) + damping * ld;
                add_jacobian(bodies, &sb, &sb.point, &scale(-f, &u), qv, None);
                add_jacobian(bodies, &sa, &sa.point, &scale(f, &u), qv, None);
            }
            SpatialForce::RotationalSpringDamper { a, b, stiffness, damping, angle0 } => {
                let (th, thd, [sa, sb], s, c, r2) = Self::angle(a, b, *angle0, bodies, q, qd, Some(turn));
                if !(r2 > 0.0) {
                    return;
                }
                let tau = -stiffness * th - damping * thd;
                prim::dot_jacobian(bodies, &sa, &sa.axes[1], &sb, &sb.axes[0], tau * c / r2, qv, None);
                prim::dot_jacobian(bodies, &sa, &sa.axes[0], &sb, &sb.axes[0], -tau * s / r2, qv, None);
            }
            SpatialForce::Beam3 { nodes, element, .. } => {
                let (_, g) = element.gradient(&element_coords(nodes, bodies, q));
                for (i, gi) in g.iter().enumerate() {
                    qv[element_index(nodes, bodies, i)] -= gi;
                }
            }
        }
    }

    /// Section forces and moments `[N, Q_y, Q_z, M_t, M_y, M_z]` of a beam element at `q`
    /// (`ElementConsts::section_forces`); `None` for the other elements.
    pub fn section_forces(&self, bodies: &[Body], q: &[f64]) -> Option<[f64; 6]> {
        match self {
            SpatialForce::Beam3 { nodes, element, .. } => Some(element.section_forces(&element_coords(nodes, bodies, q))),
            _ => None,
        }
    }

    /// Whether `add_stiffness` adds anything (a spring-damper with stiffness or damping).
    pub fn has_stiffness(&self) -> bool {
        matches!(self, SpatialForce::SpringDamper { stiffness, damping, .. } if *stiffness > 0.0 || *damping > 0.0) || matches!(self, SpatialForce::Beam3 { .. })
    }

    /// The spring-damper's position stiffness, as the planar one's (`Force::add_stiffness`):
    /// with `G = d_q` (`d = P_b - P_a`, `u = d / l`), `p = G^T u` and `r_i = G^T n_i` for two
    /// unit vectors across `u`, `K = k p p^T + sum_i (c (v . n_i)/l p r_i^T + f/l r_i r_i^T)`.
    /// The rotational spring-damper adds nothing (left to the differences of the velocity terms
    /// and to Newton).
    pub fn add_stiffness(&self, bodies: &[Body], q: &[f64], qd: &[f64], p: &mut [f64], r: &mut [f64], add: &mut dyn FnMut(usize, usize, f64)) {
        if let SpatialForce::Beam3 { nodes, element, .. } = self {
            // the beam element's exact tangent (its Hessian)
            let h = element.hessian(&element_coords(nodes, bodies, q));
            for (i, row) in h.iter().enumerate() {
                for (j, v) in row.iter().enumerate() {
                    add(element_index(nodes, bodies, i), element_index(nodes, bodies, j), *v);
                }
            }
            return;
        }
        let SpatialForce::SpringDamper { a, b, stiffness, damping, rest_length } = self else { return };
        let (l, ld, u, [sa, sb]) = Self::spring(a, b, bodies, q, qd);
        let Some(u) = u else { return };
        let (_, v, _) = prim::separation(&sa, &sb);
        let f = stiffness * (l - rest_length) + damping * ld;
        let row = |w: &V3, out: &mut [f64]| {
            out.fill(0.0);
            add_jacobian(bodies, &sb, &sb.point, w, out, None);
            add_jacobian(bodies, &sa, &sa.point, &scale(-1.0, w), out, None);
        };
        row(&u, p);
        super::outer(p, p, *stiffness, add);
        // two unit vectors across u: the axis least aligned with u, orthogonalized, and u x n1
        let k = (0..3).min_by(|&i, &j| u[i].abs().total_cmp(&u[j].abs())).unwrap_or(0);
        let mut n1 = [0.0; 3];
        n1[k] = 1.0;
        let n1 = sub(&n1, &scale(u[k], &u));
        let n1 = scale(1.0 / norm(&n1), &n1);
        let n2 = [u[1] * n1[2] - u[2] * n1[1], u[2] * n1[0] - u[0] * n1[2], u[0] * n1[1] - u[1] * n1[0]];
        for nv in [n1, n2] {
            row(&nv, r);
            super::outer(p, r, damping * dot(&v, &nv) / l, add);
            super::outer(r, r, f / l, add);
        }
    }

    /// Whether `add_damping` adds anything (a spring-damper with damping).
    pub fn has_damping(&self) -> bool {
        matches!(self, SpatialForce::SpringDamper { damping, .. } if *damping > 0.0)
    }

    /// The spring-damper's damping `C = c p p^T`, `p = G^T u` (as the planar one's,
    /// `Force::add_damping`); nothing for the other elements.
    pub fn add_damping(&self, bodies: &[Body], q: &[f64], qd: &[f64], p: &mut [f64], add: &mut dyn FnMut(usize, usize, f64)) {
        let SpatialForce::SpringDamper { a, b, damping, .. } = self else { return };
        if !(*damping > 0.0) {
            return;
        }
        let (_, _, u, [sa, sb]) = Self::spring(a, b, bodies, q, qd);
        let Some(u) = u else { return };
        p.fill(0.0);
        add_jacobian(bodies, &sb, &sb.point, &u, p, None);
        add_jacobian(bodies, &sa, &sa.point, &scale(-1.0, &u), p, None);
        super::outer(p, p, *damping, add);
    }

    /// The potential `k (theta - theta0)^2 / 2` of a rotational spring-damper at its counted angle
    /// `turn` (`Data::turns` after an evaluation); `None` for the other elements.
    pub fn counted_potential(&self, turn: f64) -> Option<f64> {
        match self {
            SpatialForce::RotationalSpringDamper { stiffness, .. } if turn.is_finite() => Some(0.5 * stiffness * turn * turn),
            _ => None,
        }
    }

    /// Potential energy: gravity `-sum m g . r`, springs `k x^2 / 2` (a rotational spring read
    /// within half a turn of `angle0`: `counted_potential` has the counted one), a world-frame
    /// point force `-F . P`; 0 for body-frame loads and torques (not conservative in general).
    pub fn potential(&self, bodies: &[Body], q: &[f64]) -> f64 {
        let zeros = vec![0.0; q.len()];
        match self {
            SpatialForce::Gravity { g } => bodies.iter().map(|b| gravity_energy(g, b, q)).sum(),
            SpatialForce::PointForce { point, force, frame } => {
                if *frame == FrameDesc::World {
                    -dot(force, &point.state(bodies, q, &zeros).point.v)
                } else {
                    0.0
                }
            }
            SpatialForce::Torque { .. } => 0.0,
            SpatialForce::SpringDamper { a, b, stiffness, rest_length, .. } => {
                let (l, _, _, _) = Self::spring(a, b, bodies, q, &zeros);
                0.5 * stiffness * (l - rest_length).powi(2)
            }
            SpatialForce::RotationalSpringDamper { a, b, stiffness, angle0, .. } => {
                let th = Self::angle(a, b, *angle0, bodies, q, &zeros, None).0;
                0.5 * stiffness * th * th
            }
            SpatialForce::Beam3 { nodes, element, .. } => element.energy(&element_coords(nodes, bodies, q)),
        }
    }

    /// `1/2 k Ld^2` of a spring for the motion `v` (0 for the loads).
    pub fn material_energy(&self, bodies: &[Body], q: &[f64], v: &[f64]) -> f64 {
        match self {
            SpatialForce::SpringDamper { a, b, stiffness, .. } => 0.5 * stiffness * Self::spring(a, b, bodies, q, v).1.powi(2),
            SpatialForce::RotationalSpringDamper { a, b, stiffness, angle0, .. } => 0.5 * stiffness * Self::angle(a, b, *angle0, bodies, q, v, None).1.powi(2),
            SpatialForce::Beam3 { nodes, element, .. } => element.material_energy(&element_coords(nodes, bodies, q), &element_coords(nodes, bodies, v)),
            _ => 0.0,
        }
    }
}

/// The world components of a force `f` at `point` given in `frame` (world, or the marker's
/// axes: `A C f` on a rigid body, `C f` on the ground).
#[inline]
pub fn world_force(point: &Marker3, frame: FrameDesc, bodies: &[Body], q: &[f64], f: &V3) -> V3 {
    match frame {
        FrameDesc::World => *f,
        FrameDesc::Body if point.rigid => {
            let o = bodies[point.body.expect("rigid")].offset;
            mat_vec(&rot_a(&q[o + 3..o + 7]), &mat_vec(&point.c, f))
        }
        FrameDesc::Body => mat_vec(&point.c, f),
    }
}

/// `qv[p] += 2 G^T n'` of a torque `n` in `frame` on the rigid3 body `body` (`n' = A^T n` for
/// world components).
#[inline]
pub fn add_torque(bodies: &[Body], body: usize, frame: FrameDesc, q: &[f64], n: &V3, qv: &mut [f64]) {
    let o = bodies[body].offset;
    let p = &q[o + 3..o + 7];
    let nb = if frame == FrameDesc::Body { *n } else { mat_t_vec(&rot_a(p), n) };
    let g = rot_g(p);
    for l in 0..4 {
        qv[o + 3 + l] += 2.0 * (g[0][l] * nb[0] + g[1][l] * nb[1] + g[2][l] * nb[2]);
    }
}

/// Gravity potential `-m g . r` of one body (0 for planar kinds).
pub fn gravity_energy(g: &V3, b: &Body, q: &[f64]) -> f64 {
    if let BodyKind::Flexible3(k) = &b.kind {
        return k.gravity_potential(&q[b.offset..b.offset + b.n_coords], g);
    }
    spatial_mass(b).map_or(0.0, |m| -m * (g[0] * q[b.offset] + g[1] * q[b.offset + 1] + g[2] * q[b.offset + 2]))
}

/// The world point of a marker at `q` (inspection).
pub fn marker_point(m: &Marker3, bodies: &[Body], q: &[f64]) -> V3 {
    let zeros = vec![0.0; q.len()];
    m.state(bodies, q, &zeros).point.v
}
