//! Bodies and markers. A closed set of body kinds, dispatched with `match` in the hot path.
//!
//! Each kind is one file that owns every per-body stage: building from its description
//! (`from_desc`), its workspace (`new_data`), mass blocks and generalized forces
//! (`mass_and_forces`), the factor `M_b = F_b F_b^T` (`factor`), `F_b^-1` (`finv`), `F_b^-T`
//! (`finvt`), the dense block (`dense_block`), energies, and the kinematics of the markers it
//! carries (`marker`, `marker_state`, `add_point_jacobian`, `add_angle_jacobian`). This file
//! only dispatches; `dynamics.rs` only loops over bodies. Adding a kind = one file here plus
//! one arm per `match` below (the compiler lists them).

pub mod ancf_cable;
pub mod ffrf;
pub mod ffrf_beam;
pub mod modal;
pub mod point_mass;
pub mod rigid;

pub use ancf_cable::{AncfCable, AncfCableData, CablePoint};
pub use ffrf::{Ffrf, FfrfData, PointShape};
pub use ffrf_beam::{Beam, BeamData};
pub use modal::Modal;
pub use point_mass::{PointMass, PointMassData};
pub use rigid::{Rigid, RigidData};

use crate::description::{BeamFormulation, BodyDesc, MarkerDesc};
use crate::error::{check_finite_item, Error, Result};

/// The closed set of body kinds (a scene has few bodies; the variants stay unboxed so that a
/// body's constants sit next to each other).
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
pub enum BodyKind {
    Rigid(Rigid),
    Beam(Beam),
    PointMass(PointMass),
    AncfBeam(AncfCable),
    Flexible(Modal),
}

/// Per-body workspace, one variant per kind (sized once in `Data::new`).
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
pub enum BodyData {
    Rigid(RigidData),
    Beam(BeamData),
    PointMass(PointMassData),
    AncfBeam(AncfCableData),
    Flexible(FfrfData),
}

#[derive(Debug, Clone)]
pub struct Body {
    pub name: String,
    /// Index of the body's first coordinate in `q`.
    pub offset: usize,
    pub n_coords: usize,
    pub kind: BodyKind,
}

/// Initial guess of one body's coordinates and their names (suffixes after `body.`).
pub struct InitialState {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub names: Vec<String>,
}

impl Body {
    /// Validate and build one body (constant shape integrals included) from its description.
    pub fn from_desc(d: &BodyDesc, offset: usize) -> Result<(Body, InitialState)> {
        let name = d.name().to_string();
        let item = format!("body '{name}'");
        if name.is_empty() || name == "ground" {
            return Err(Error::invalid(&item, "body names must be non-empty and not 'ground' (the name 'ground' is reserved)"));
        }
        let (kind, init) = match d {
            BodyDesc::Rigid(r) => {
                let k = Rigid::from_desc(r, &item)?;
                let init = k.initial_state(r, &item)?;
                (BodyKind::Rigid(k), init)
            }
            BodyDesc::Beam(b) if b.formulation == BeamFormulation::Ancf => {
                let k = AncfCable::from_desc(b, &item)?;
                let init = k.initial_state(b, &item)?;
                (BodyKind::AncfBeam(k), init)
            }
            BodyDesc::Beam(b) => {
                let k = Beam::from_desc(b, &item)?;
                let init = k.initial_state(b, &item)?;
                (BodyKind::Beam(k), init)
            }
            BodyDesc::PointMass(p) => {
                let k = PointMass::from_desc(p, &item)?;
                let init = k.initial_state(p, &item)?;
                (BodyKind::PointMass(k), init)
            }
            BodyDesc::Flexible(f) => {
                let k = Modal::from_desc(f, &item)?;
                let init = k.initial_state(f, &item)?;
                (BodyKind::Flexible(k), init)
            }
        };
        for (what, v) in [("initial state", &init.q), ("initial rates", &init.qd)] {
            check_finite_item(&item, what, v)?;
        }
        Ok((Body { name, offset, n_coords: init.q.len(), kind }, init))
    }

    /// The kind's name: as in the description (`"rigid"`, `"beam"`, `"point_mass"`), and
    /// `"ancf_beam"` for a beam with formulation `ancf`.
    pub fn kind_name(&self) -> &'static str {
        match &self.kind {
            BodyKind::Rigid(_) => "rigid",
            BodyKind::Beam(_) => "beam",
            BodyKind::PointMass(_) => "point_mass",
            BodyKind::AncfBeam(_) => "ancf_beam",
            BodyKind::Flexible(_) => "flexible",
        }
    }

    /// Coordinates `q[elastic_range]` that describe deformation alone (empty for rigid kinds,
    /// and for an ANCF cable, whose nodal coordinates carry its motion and deformation together).
    pub fn elastic_range(&self) -> std::ops::Range<usize> {
        match &self.kind {
            BodyKind::Beam(_) | BodyKind::Flexible(_) => self.offset + 3..self.offset + self.n_coords,
            BodyKind::Rigid(_) | BodyKind::PointMass(_) | BodyKind::AncfBeam(_) => self.offset..self.offset,
        }
    }

    /// Half-bandwidth, in body coordinates, of the body's own blocks of `M`, `K = -dQ/dq` and
    /// `C = -dQ/dqd` (entries `(i, j)` with `|i - j|` above it are zero): an ANCF cable's are
    /// element-coupled (`ancf_cable::HB`), every other kind's dense. The structural pattern of
    /// the implicit methods' sparse Newton matrices (`sparse_newton`).
    pub fn coupling_halfwidth(&self) -> usize {
        match &self.kind {
            BodyKind::AncfBeam(_) => ancf_cable::HB.min(self.n_coords.saturating_sub(1)),
            _ => self.n_coords.saturating_sub(1),
        }
    }

    /// Number of elastic coordinates.
    pub fn n_f(&self) -> usize {
        self.elastic_range().len()
    }

    pub fn total_mass(&self) -> f64 {
        match &self.kind {
            BodyKind::Rigid(k) => k.mass,
            BodyKind::Beam(k) => k.mass,
            BodyKind::PointMass(k) => k.mass,
            BodyKind::AncfBeam(k) => k.mass,
            BodyKind::Flexible(k) => k.mass,
        }
    }

    pub fn new_data(&self) -> BodyData {
        match &self.kind {
            BodyKind::Rigid(k) => BodyData::Rigid(k.new_data()),
            BodyKind::Beam(k) => BodyData::Beam(k.new_data()),
            BodyKind::PointMass(k) => BodyData::PointMass(k.new_data()),
            BodyKind::AncfBeam(k) => BodyData::AncfBeam(k.new_data()),
            BodyKind::Flexible(k) => BodyData::Flexible(k.new_data()),
        }
    }

    #[inline]
    fn seg<'a>(&self, v: &'a [f64]) -> &'a [f64] {
        &v[self.offset..self.offset + self.n_coords]
    }

    /// Mass blocks at `q` and generalized forces `Q_b(q, qd)` (inertial velocity terms,
    /// elastic forces, gravity) into `force` (the whole `Q`, this body's segment written).
    #[inline]
    pub fn mass_and_forces(&self, bd: &mut BodyData, q: &[f64], qd: &[f64], gravity: Option<[f64; 2]>, force: &mut [f64]) {
        let (qb, qdb) = (self.seg(q), self.seg(qd));
        let f = &mut force[self.offset..self.offset + self.n_coords];
        match (&self.kind, bd) {
            (BodyKind::Rigid(k), BodyData::Rigid(d)) => k.mass_and_forces(d, qb, qdb, gravity, f),
            (BodyKind::Beam(k), BodyData::Beam(d)) => k.mass_and_forces(d, qb, qdb, gravity, f),
            (BodyKind::PointMass(k), BodyData::PointMass(d)) => k.mass_and_forces(d, qb, qdb, gravity, f),
            (BodyKind::AncfBeam(k), BodyData::AncfBeam(d)) => k.mass_and_forces(d, qb, qdb, gravity, f),
            (BodyKind::Flexible(k), BodyData::Flexible(d)) => k.mass_and_forces(d, qb, qdb, gravity, f),
            _ => unreachable!("body data of another kind"),
        }
    }

    /// Factor the body block `M_b = F_b F_b^T` (after `mass_and_forces`).
    #[inline]
    pub fn factor(&self, bd: &mut BodyData) -> Result<()> {
        let ok = match (&self.kind, bd) {
            (BodyKind::Rigid(k), BodyData::Rigid(d)) => k.factor(d),
            (BodyKind::Beam(k), BodyData::Beam(d)) => k.factor(d),
            (BodyKind::PointMass(k), BodyData::PointMass(d)) => k.factor(d),
            (BodyKind::AncfBeam(k), BodyData::AncfBeam(d)) => k.factor(d),
            (BodyKind::Flexible(k), BodyData::Flexible(d)) => k.factor(d),
            _ => unreachable!("body data of another kind"),
        };
        if ok {
            Ok(())
        } else {
            Err(Error::SingularMass { item: format!("body '{}'", self.name) })
        }
    }

    /// `v <- F_b^-1 v` on this body's segment `v` (length `n_coords`).
    #[inline]
    pub fn finv(&self, bd: &BodyData, v: &mut [f64]) {
        match (&self.kind, bd) {
            (BodyKind::Rigid(k), BodyData::Rigid(d)) => k.finv(d, v),
            (BodyKind::Beam(k), BodyData::Beam(d)) => k.finv(d, v),
            (BodyKind::PointMass(k), BodyData::PointMass(d)) => k.finv(d, v),
            (BodyKind::AncfBeam(k), BodyData::AncfBeam(d)) => k.finv(d, v),
            (BodyKind::Flexible(k), BodyData::Flexible(d)) => k.finv(d, v),
            _ => unreachable!("body data of another kind"),
        }
    }

    /// `v <- F_b^-T v` on this body's segment.
    #[inline]
    pub fn finvt(&self, bd: &BodyData, v: &mut [f64]) {
        match (&self.kind, bd) {
            (BodyKind::Rigid(k), BodyData::Rigid(d)) => k.finvt(d, v),
            (BodyKind::Beam(k), BodyData::Beam(d)) => k.finvt(d, v),
            (BodyKind::PointMass(k), BodyData::PointMass(d)) => k.finvt(d, v),
            (BodyKind::AncfBeam(k), BodyData::AncfBeam(d)) => k.finvt(d, v),
            (BodyKind::Flexible(k), BodyData::Flexible(d)) => k.finvt(d, v),
            _ => unreachable!("body data of another kind"),
        }
    }

    /// `out += M_b x` on this body's segments (after `mass_and_forces`; allocation free).
    #[inline]
    pub fn mass_times(&self, bd: &BodyData, x: &[f64], out: &mut [f64]) {
        match (&self.kind, bd) {
            (BodyKind::Rigid(_), BodyData::Rigid(d)) => {
                for i in 0..3 {
                    out[i] += d.m_rr[i][0] * x[0] + d.m_rr[i][1] * x[1] + d.m_rr[i][2] * x[2];
                }
            }
            (BodyKind::Beam(k), BodyData::Beam(d)) => k.mass_times(d, x, out),
            (BodyKind::PointMass(k), BodyData::PointMass(_)) => {
                out[0] += k.mass * x[0];
                out[1] += k.mass * x[1];
            }
            (BodyKind::AncfBeam(k), BodyData::AncfBeam(_)) => k.mass_times(x, out),
            (BodyKind::Flexible(k), BodyData::Flexible(d)) => k.mass_times(d, x, out),
            _ => unreachable!("body data of another kind"),
        }
    }

    /// Visit the nonzero entries of the body block `M_b` (after `mass_and_forces`) in body
    /// coordinates: `put(i, j, M_b[i, j])`.
    pub fn dense_block(&self, bd: &BodyData, put: &mut impl FnMut(usize, usize, f64)) {
        match (&self.kind, bd) {
            (BodyKind::Rigid(k), BodyData::Rigid(d)) => k.dense_block(d, put),
            (BodyKind::Beam(k), BodyData::Beam(d)) => k.dense_block(d, put),
            (BodyKind::PointMass(k), BodyData::PointMass(d)) => k.dense_block(d, put),
            (BodyKind::AncfBeam(k), BodyData::AncfBeam(d)) => k.dense_block(d, put),
            (BodyKind::Flexible(k), BodyData::Flexible(d)) => k.dense_block(d, put),
            _ => unreachable!("body data of another kind"),
        }
    }

    /// Stiffness `-dQ_b/dq_b` and damping `-dQ_b/dqd_b` of the body's own forces that it knows
    /// analytically (elastic tangent, strain-rate damping), in body coordinates.
    pub fn tangent(&self, _bd: &BodyData, q: &[f64], _qd: &[f64], k: &mut impl FnMut(usize, usize, f64), c: &mut impl FnMut(usize, usize, f64)) {
        match &self.kind {
            BodyKind::Beam(b) => {
                let qf = &self.seg(q)[3..];
                b.elastic_tangent(qf, &mut |i, j, v| k(3 + i, 3 + j, v));
                if b.damping > 0.0 {
                    b.elastic_tangent(qf, &mut |i, j, v| c(3 + i, 3 + j, b.damping * v));
                }
            }
            BodyKind::AncfBeam(b) => {
                let qb = self.seg(q);
                b.visit_element_matrices(qb, false, k);
                if b.damping > 0.0 {
                    b.visit_element_matrices(qb, true, c);
                }
            }
            BodyKind::Flexible(b) => {
                let qf = &self.seg(q)[3..];
                b.elastic_tangent(qf, &mut |i, j, v| k(3 + i, 3 + j, v));
                b.damping_tangent(&mut |i, j, v| c(3 + i, 3 + j, v));
            }
            BodyKind::Rigid(_) | BodyKind::PointMass(_) => {}
        }
    }

    /// `1/2 qd_b^T M_b qd_b` (after `mass_and_forces` at the same `q`).
    pub fn kinetic_energy(&self, bd: &BodyData, qd: &[f64]) -> f64 {
        let qdb = self.seg(qd);
        match (&self.kind, bd) {
            (BodyKind::Rigid(k), BodyData::Rigid(d)) => k.kinetic_energy(d, qdb),
            (BodyKind::Beam(k), BodyData::Beam(d)) => k.kinetic_energy(d, qdb),
            (BodyKind::PointMass(k), BodyData::PointMass(d)) => k.kinetic_energy(d, qdb),
            (BodyKind::AncfBeam(k), BodyData::AncfBeam(d)) => k.kinetic_energy(d, qdb),
            (BodyKind::Flexible(k), BodyData::Flexible(d)) => k.kinetic_energy(d, qdb),
            _ => unreachable!("body data of another kind"),
        }
    }

    /// Elastic strain energy (zero for rigid kinds).
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        match &self.kind {
            BodyKind::Beam(k) => k.strain_energy(self.seg(q)),
            BodyKind::AncfBeam(k) => k.strain_energy(self.seg(q)),
            BodyKind::Flexible(k) => k.strain_energy(self.seg(q)),
            BodyKind::Rigid(_) | BodyKind::PointMass(_) => 0.0,
        }
    }

    /// `1/2 v^T K_m v`: the strain energy of the first-order strains of a motion `v` (whole
    /// `n`-vector) at `q`, with the material stiffness alone (no stress terms: a rigid motion of a
    /// stressed cable stores none; zero for rigid kinds). Tells elastic modes from rigid ones
    /// alike for every flexible kind (`System.material_energies`).
    pub fn material_energy(&self, q: &[f64], v: &[f64]) -> f64 {
        let vb = self.seg(v);
        match &self.kind {
            BodyKind::Beam(k) => 0.5 * k.k_ff.bilinear(&vb[3..], &vb[3..]),
            BodyKind::Flexible(k) => 0.5 * k.k_ff.bilinear(&vb[3..3 + k.n_f], &vb[3..3 + k.n_f]),
            BodyKind::AncfBeam(k) => k.material_energy(self.seg(q), vb),
            BodyKind::Rigid(_) | BodyKind::PointMass(_) => 0.0,
        }
    }

    /// The body's rigid motions at `(q, qd)`: a basis of them (columns `col0..`, entries given
    /// to `put(coordinate, column, value)` in whole-`n` coordinates) and the centripetal part of
    /// the rigid acceleration at the body's angular velocity (`cen`, whole `n`, this body's
    /// segment written); returns the number of columns. Rigid bodies, point masses and the
    /// floating frames of FFRF and modal bodies: their own coordinates; an ANCF cable: the
    /// translations and the rotation of its nodal field about its nodes' centre. The "rigidified"
    /// motion from which `method="auto"` reads what an initial state sets off in the fast modes.
    pub fn rigid_motions(&self, q: &[f64], qd: &[f64], col0: usize, put: &mut impl FnMut(usize, usize, f64), cen: &mut [f64]) -> usize {
        let o = self.offset;
        match &self.kind {
            BodyKind::AncfBeam(_) => {
                let (qb, vb) = (self.seg(q), self.seg(qd));
                ancf_cable::rigid_motions(qb, vb, o, col0, put, &mut cen[o..o + self.n_coords])
            }
            BodyKind::PointMass(_) => {
                put(o, col0, 1.0);
                put(o + 1, col0 + 1, 1.0);
                2
            }
            BodyKind::Rigid(_) | BodyKind::Beam(_) | BodyKind::Flexible(_) => {
                for k in 0..3 {
                    put(o + k, col0 + k, 1.0);
                }
                3
            }
        }
    }

    /// Move the body rigidly by `x` (its `rigid_motions` columns: the same order): the
    /// reference coordinates of rigid, point-mass, FFRF and modal bodies take `x` added; an ANCF
    /// cable's nodal field is translated and turned about its nodes' centre exactly (the
    /// linear field `k x (r - c)` would stretch it by `x^2 / 2`).
    pub fn move_rigidly(&self, q: &mut [f64], x: &[f64]) {
        let o = self.offset;
        match &self.kind {
            BodyKind::AncfBeam(_) => ancf_cable::move_rigidly(&mut q[o..o + self.n_coords], x),
            BodyKind::PointMass(_) => {
                q[o] += x[0];
                q[o + 1] += x[1];
            }
            BodyKind::Rigid(_) | BodyKind::Beam(_) | BodyKind::Flexible(_) => {
                for k in 0..3 {
                    q[o + k] += x[k];
                }
            }
        }
    }

    /// Potential of gravity `-g . int rho r dV`.
    pub fn gravity_energy(&self, q: &[f64], g: [f64; 2]) -> f64 {
        let qb = self.seg(q);
        let r = match &self.kind {
            BodyKind::Rigid(k) => k.mass_moment(qb),
            BodyKind::Beam(k) => k.mass_moment(qb),
            BodyKind::PointMass(k) => k.mass_moment(qb),
            BodyKind::AncfBeam(k) => k.mass_moment(qb),
            BodyKind::Flexible(k) => k.mass_moment(qb),
        };
        -(g[0] * r[0] + g[1] * r[1])
    }

    /// Resolve a marker description on this body (`index` = this body's index).
    pub fn marker(&self, index: usize, md: &MarkerDesc, item: &str) -> Result<Marker> {
        let shape = match &self.kind {
            BodyKind::Rigid(_) => MarkerShape::Rigid(rigid::marker_point(md, &self.name, item)?),
            BodyKind::Beam(k) => MarkerShape::Beam(k.marker_shape(md, &self.name, item)?),
            BodyKind::AncfBeam(k) => MarkerShape::Cable(k.marker_shape(md, &self.name, item)?),
            BodyKind::Flexible(k) => MarkerShape::Beam(k.marker_shape(md, &self.name, item)?),
            BodyKind::PointMass(_) => {
                point_mass::check_marker(md, &self.name, item)?;
                MarkerShape::Particle
            }
        };
        Ok(Marker { body: Some(index), angle: md.angle, shape })
    }

    /// `[x, y, u, v, psi]` of the axis point `xi` of a beam at `q` (inspection, allocates):
    /// world position, displacement in the beam frame from the undeformed `(xi L, 0)` and the
    /// section rotation relative to that frame. The frame is the floating frame of an FFRF
    /// beam (for the pinned-pinned frame: the chord of the ends) and the chord frame of the
    /// ends of an ANCF cable, so that both compare one to one. `None` for other kinds.
    pub fn beam_point(&self, xi: f64, q: &[f64]) -> Option<[f64; 5]> {
        let qb = self.seg(q);
        match &self.kind {
            BodyKind::Beam(k) => {
                let ps = k.point_shape(xi);
                let ms = ffrf::marker_state(&ps, 0.0, qb, qb);
                let (mut u, mut v) = (0.0, 0.0);
                for &(i, su, sv, _) in &ps.entries {
                    u += su * qb[3 + i];
                    v += sv * qb[3 + i];
                }
                Some([ms.r[0], ms.r[1], u, v, ms.phi - qb[2]])
            }
            BodyKind::AncfBeam(k) => Some(k.chord_displacement(xi, qb)),
            BodyKind::Rigid(_) | BodyKind::PointMass(_) | BodyKind::Flexible(_) => None,
        }
    }
}

impl Body {
    /// `[N, V, M, eps, kappa]` at the axis point `xi` of a beam at `q` (see
    /// `ffrf_beam::Beam::internal_forces`, `ancf_cable::AncfCable::internal_forces`); `None`
    /// for other kinds.
    pub fn internal_forces(&self, xi: f64, q: &[f64]) -> Option<[f64; 5]> {
        let qb = self.seg(q);
        match &self.kind {
            BodyKind::Beam(k) => Some(k.internal_forces(xi, qb)),
            BodyKind::AncfBeam(k) => Some(k.internal_forces(xi, qb)),
            BodyKind::Rigid(_) | BodyKind::PointMass(_) | BodyKind::Flexible(_) => None,
        }
    }
}

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
            let MarkerShape::Ground(p) = self.shape else { unreachable!("ground markers are points") };
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
            MarkerShape::Ground(_) => {}
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
            MarkerShape::Particle | MarkerShape::Ground(_) => {}
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

/// `(sin, cos)` of a floating frame's angle `theta`, memoized per thread. One evaluation of a
/// scene reads the same body angle many times -- the body's own mass and forces, and every
/// marker a constraint or force evaluates on it (the paper's slider-crank: ~9 reads of 3 angles
/// per evaluation) -- and `sin_cos` is among the most expensive operations of the kernel. The
/// cache is keyed by the exact bits of `theta` (a hit returns exactly what `sin_cos` returns),
/// holds 8 angles, direct-mapped, and is per thread, so concurrent runs do not share it.
#[inline]
pub(crate) fn frame_sin_cos(theta: f64) -> (f64, f64) {
    use std::cell::Cell;
    thread_local! {
        static CACHE: [Cell<(u64, f64, f64)>; 8] = const { [const { Cell::new((u64::MAX, 0.0, 0.0)) }; 8] };
    }
    let bits = theta.to_bits();
    let slot = ((bits ^ (bits >> 17) ^ (bits >> 37)) & 7) as usize;
    CACHE.with(|c| {
        let (k, s, co) = c[slot].get();
        if k == bits {
            return (s, co);
        }
        let (s, co) = theta.sin_cos();
        c[slot].set((bits, s, co));
        (s, co)
    })
}

/// The planar kinematics shared by the kinds with a floating frame `(x, y, theta)` (rigid
/// bodies, FFRF beams): a body-frame point `pl` moving with body-frame velocity `vl`, on a
/// frame at `(q[0], q[1])` with angle `q[2]`.
#[inline]
pub(crate) fn frame_point_state(pl: [f64; 2], vl: [f64; 2], phi_local: f64, omega_local: f64, q: &[f64], qd: &[f64]) -> MarkerState {
    let (th, thd) = (q[2], qd[2]);
    let (s, c) = frame_sin_cos(th);
    let pw = [c * pl[0] - s * pl[1], s * pl[0] + c * pl[1]];
    let vw = [c * vl[0] - s * vl[1], s * vl[0] + c * vl[1]];
    let r_theta = [-pw[1], pw[0]];
    MarkerState {
        r: [q[0] + pw[0], q[1] + pw[1]],
        phi: th + phi_local,
        v: [qd[0] + thd * r_theta[0] + vw[0], qd[1] + thd * r_theta[1] + vw[1]],
        omega: thd + omega_local,
        // -theta_dot^2 A u + 2 theta_dot A J S qd_f
        h: [-thd * thd * pw[0] - 2.0 * thd * vw[1], -thd * thd * pw[1] + 2.0 * thd * vw[0]],
        h_phi: 0.0,
        r_theta,
        cs: [c, s],
        dphi_dslope: [0.0; 2],
    }
}

/// `row[0..3] += w . d r / d (x, y, theta)` for a frame point.
#[inline]
pub(crate) fn add_frame_point_jacobian(ms: &MarkerState, w: [f64; 2], row: &mut [f64]) {
    row[0] += w[0];
    row[1] += w[1];
    row[2] += w[0] * ms.r_theta[0] + w[1] * ms.r_theta[1];
}

/// The floating-frame mass block of a body with total mass `mass` and first moment `sig`
/// (body frame) about the frame origin, rotated by `(c, s)`: `[[m I, A J sig], [., j]]`.
#[inline]
pub(crate) fn frame_mass_block(mass: f64, sig: [f64; 2], j: f64, c: f64, s: f64) -> [[f64; 3]; 3] {
    let asig = [c * sig[0] - s * sig[1], s * sig[0] + c * sig[1]];
    let ajsig = [-asig[1], asig[0]];
    [[mass, 0.0, ajsig[0]], [0.0, mass, ajsig[1]], [ajsig[0], ajsig[1], j]]
}

/// Gravity on a floating frame: `Q_R += m g`, `Q_theta += g . A J sig`.
#[inline]
pub(crate) fn add_frame_gravity(mass: f64, m_rr: &[[f64; 3]; 3], g: [f64; 2], f: &mut [f64]) {
    f[0] += mass * g[0];
    f[1] += mass * g[1];
    f[2] += g[0] * m_rr[0][2] + g[1] * m_rr[1][2];
}

/// `m R + A sig` (world first moment of a floating-frame body).
#[inline]
pub(crate) fn frame_mass_moment(mass: f64, sig: [f64; 2], q: &[f64]) -> [f64; 2] {
    let (s, c) = frame_sin_cos(q[2]);
    [mass * q[0] + c * sig[0] - s * sig[1], mass * q[1] + s * sig[0] + c * sig[1]]
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

pub(crate) fn finite_vec2(item: &str, what: &str, v: [f64; 2]) -> Result<[f64; 2]> {
    check_finite_item(item, what, &v)?;
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::frame_sin_cos;

    #[test]
    fn memoized_frame_sin_cos_is_exactly_sin_cos() {
        // many angles through the 8 slots (collisions evict), each asked twice, and revisited
        let angles: Vec<f64> = (0..200).map(|k| -7.0 + 0.0713 * k as f64).chain([0.0, -0.0, 1e-300, 3.0e5]).collect();
        for _ in 0..2 {
            for &a in &angles {
                for _ in 0..2 {
                    let (s, c) = frame_sin_cos(a);
                    let (s0, c0) = a.sin_cos();
                    assert_eq!((s.to_bits(), c.to_bits()), (s0.to_bits(), c0.to_bits()), "angle {a}");
                }
            }
        }
        // a non-finite angle is not cached as a finite one
        assert!(frame_sin_cos(f64::NAN).0.is_nan());
    }
}
