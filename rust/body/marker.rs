//! Markers: a point and a frame attached to a body (Exudyn's markers). Joints and forces
//! attach to markers, never to body kinds: `Marker::state` and the Jacobian rows dispatch to
//! the kinematics of the kind that carries the marker.

use super::{ancf_cable, ffrf, point_mass, rigid, Body, CablePoint, PointShape};
use crate::description::MarkerDesc;
use crate::error::{Error, Result};

/// Where a marker sits on its body (one variant per kind that carries markers).
#[derive(Debug, Clone)]
pub enum MarkerShape {
    /// A point of the ground (world frame).
    Ground([f64; 2]),
    /// A point in the frame of a rigid body.
    Rigid([f64; 2]),
    /// An axis point of a beam or an interface point of a flexible body (elastic displacement
    /// included).
    Beam(PointShape),
    /// The particle itself (a point mass has no orientation).
    Particle,
    /// An axis point of an ANCF cable.
    Cable(CablePoint),
    /// A spatial marker (`marker3.rs` holds its frame and kinematics): here only its body, for
    /// the structural pattern; the planar kinematics below never see it.
    Spatial,
}

/// A point and a frame attached to a body (`body == None` for the ground).
#[derive(Debug, Clone)]
pub struct Marker {
    pub body: Option<usize>,
    pub angle: f64,
    pub shape: MarkerShape,
}

/// Kinematics of a marker at one state (world frame).
#[derive(Debug, Clone, Copy, Default)]
pub struct MarkerState {
    /// Position.
    pub r: [f64; 2],
    /// Frame angle (`theta + angle + psi`).
    pub phi: f64,
    /// Velocity.
    pub v: [f64; 2],
    /// Angular velocity of the frame.
    pub omega: f64,
    /// Velocity-dependent part of the acceleration: `r_dd = r_q q_dd + h` (`(r_q qd)_q qd`).
    pub h: [f64; 2],
    /// Velocity-dependent part of the angular acceleration `phi_dd = phi_q q_dd + h_phi`
    /// (zero where the angle is linear in `q`).
    pub h_phi: f64,
    /// `d r / d theta` of the carrying body.
    pub r_theta: [f64; 2],
    /// cos and sin of the body angle.
    pub cs: [f64; 2],
    /// `d phi / d r'` for a marker whose angle follows a slope `r'` (ANCF cable:
    /// `(-r'_y, r'_x) / |r'|^2`); zero for the other kinds.
    pub dphi_dslope: [f64; 2],
}

impl Marker {
    /// A marker fixed in the world frame.
    pub fn ground(point: [f64; 2], angle: f64) -> Marker {
        Marker { body: None, angle, shape: MarkerShape::Ground(point) }
    }

    /// The body and the range of its body coordinates this marker's position, angle and their
    /// rates depend on (`None`: the ground): an ANCF cable marker its element's eight
    /// coordinates, a marker on any other kind all of its body's. The structural pattern of the
    /// constraint rows and forces that use it (`sparse_newton`).
    pub fn coords(&self, bodies: &[Body]) -> Option<(usize, std::ops::Range<usize>)> {
        let bi = self.body?;
        Some(match &self.shape {
            MarkerShape::Cable(p) => (bi, p.first..p.first + 8),
            _ => (bi, 0..bodies[bi].n_coords),
        })
    }

    /// Whether the marker frame can rotate with its body (false for the ground and particles,
    /// whose marker angle is a constant).
    pub fn has_orientation(&self) -> bool {
        !matches!(self.shape, MarkerShape::Particle)
    }

    /// Evaluate position, velocity and velocity terms at `(q, qd)`.
    #[inline]
    pub fn state(&self, bodies: &[Body], q: &[f64], qd: &[f64]) -> MarkerState {
        let Some(bi) = self.body else {
            let MarkerShape::Ground(p) = self.shape else { return MarkerState::default() }; // a spatial ground marker: marker3.rs
            return MarkerState { r: p, phi: self.angle, cs: [1.0, 0.0], ..Default::default() };
        };
        let body = &bodies[bi];
        let (qb, qdb) = (body.seg(q), body.seg(qd));
        match &self.shape {
            MarkerShape::Rigid(p) => rigid::marker_state(p, self.angle, qb, qdb),
            MarkerShape::Beam(ps) => ffrf::marker_state(ps, self.angle, qb, qdb),
            MarkerShape::Particle => point_mass::marker_state(self.angle, qb, qdb),
            MarkerShape::Cable(p) => ancf_cable::marker_state(p, self.angle, qb, qdb),
            MarkerShape::Ground(_) => unreachable!("ground marker on a body"),
            MarkerShape::Spatial => MarkerState::default(),
        }
    }

    /// `row += w . d r / d q` (row spans all of `q`).
    #[inline]
    pub fn add_point_jacobian(&self, bodies: &[Body], ms: &MarkerState, w: [f64; 2], row: &mut [f64]) {
        self.add_point_jacobian_in(bodies, ms, w, row, None);
    }

    /// `add_point_jacobian` into a row of layout `layout`: `None` spans all of `q`,
    /// `Some(l)` is a constraint's compressed row (`l` lists `(body, start)`, `constraint::jac`).
    #[inline]
    pub fn add_point_jacobian_in(&self, bodies: &[Body], ms: &MarkerState, w: [f64; 2], row: &mut [f64], layout: Option<&[(usize, usize)]>) {
        let Some(bi) = self.body else { return };
        let rb = body_slice(bodies, bi, row, layout);
        match &self.shape {
            MarkerShape::Rigid(_) => rigid::add_point_jacobian(ms, w, rb),
            MarkerShape::Beam(ps) => ffrf::add_point_jacobian(ps, ms, w, rb),
            MarkerShape::Particle => point_mass::add_point_jacobian(w, rb),
            MarkerShape::Cable(p) => ancf_cable::add_point_jacobian(p, w, rb),
            MarkerShape::Ground(_) | MarkerShape::Spatial => {}
        }
    }

    /// `row += w . d phi / d q` (`ms`: this marker's state at the same `q`).
    #[inline]
    pub fn add_angle_jacobian(&self, bodies: &[Body], ms: &MarkerState, w: f64, row: &mut [f64]) {
        self.add_angle_jacobian_in(bodies, ms, w, row, None);
    }

    /// `add_angle_jacobian` into a row of layout `layout` (see `add_point_jacobian_in`).
    #[inline]
    pub fn add_angle_jacobian_in(&self, bodies: &[Body], ms: &MarkerState, w: f64, row: &mut [f64], layout: Option<&[(usize, usize)]>) {
        let Some(bi) = self.body else { return };
        let rb = body_slice(bodies, bi, row, layout);
        match &self.shape {
            MarkerShape::Rigid(_) => rigid::add_angle_jacobian(w, rb),
            MarkerShape::Beam(ps) => ffrf::add_angle_jacobian(ps, w, rb),
            MarkerShape::Cable(p) => ancf_cable::add_angle_jacobian(p, ms, w, rb),
            MarkerShape::Particle | MarkerShape::Ground(_) | MarkerShape::Spatial => {}
        }
    }
}

/// Body `bi`'s coordinates in a row: at the body's offset in a full row (`layout = None`), at
/// its start in a constraint's compressed row otherwise.
#[inline]
fn body_slice<'r>(bodies: &[Body], bi: usize, row: &'r mut [f64], layout: Option<&[(usize, usize)]>) -> &'r mut [f64] {
    let body = &bodies[bi];
    let start = match layout {
        None => body.offset,
        Some(l) => l.iter().find(|e| e.0 == bi).expect("the marker's body is in the constraint's layout").1,
    };
    &mut row[start..start + body.n_coords]
}

/// The element of a beam of `n` equal elements that holds the axis point `xi` in [0, 1], and
/// the local abscissa `s` in [0, 1] there: the right element at a node, the last at `xi = 1`
/// (both beam formulations: shapes, outputs, load inputs).
pub fn axis_element(xi: f64, n: usize) -> (usize, f64) {
    let t = xi * n as f64;
    let el = (t.floor() as usize).min(n - 1);
    (el, t - el as f64)
}

/// The abscissa `xi` in [0, 1] of a marker on a beam axis (both beam formulations).
pub(crate) fn axis_marker_xi(md: &MarkerDesc, body: &str, item: &str) -> Result<f64> {
    if md.point.is_some() {
        return Err(Error::invalid(item, format!("a marker on beam '{body}' is given by xi in [0, 1], not by a point")));
    }
    let Some(xi) = md.xi else {
        return Err(Error::invalid(item, format!("a marker on beam '{body}' needs xi in [0, 1]")));
    };
    if !xi.is_finite() || !(0.0..=1.0).contains(&xi) {
        return Err(Error::invalid(item, format!("marker xi on beam '{body}' must lie in [0, 1], got {xi}")));
    }
    Ok(xi)
}
