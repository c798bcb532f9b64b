//! Bodies. A closed set of body kinds, dispatched with `match` in the hot path.
//!
//! Each kind is one file that owns every per-body stage: building from its description
//! (`from_desc`, `initial_state`), its workspace (`new_data`), mass blocks and generalized
//! forces (`mass_and_forces`), the factor `M_b = F_b F_b^T` (`factor`), `F_b^-1` (`finv`),
//! `F_b^-T` (`finvt`), `M_b x` (`mass_times`), the dense block (`dense_block`), the tangent
//! stiffness and damping it knows analytically (`tangent`), energies (`kinetic_energy`,
//! `strain_energy`, `material_energy`, `mass_moment`), and the kinematics of the markers it
//! carries (`marker.rs` dispatches to them). The floating-frame kinds share `frame.rs` (rigid
//! bodies too) and `ffrf.rs` (FFRF beam, modal body). This file only dispatches (the two
//! macros below hold the one arm per kind of the stages the kinds share); `dynamics.rs` only
//! loops over bodies. Adding a kind = one file here, one line in each macro and one arm in each
//! remaining `match` (the compiler lists them).

pub mod ancf_cable;
pub mod beam3;
pub mod ffrf;
pub mod ffrf_beam;
pub mod frame;
pub mod marker;
pub mod flexible;
pub mod flexible3;
pub mod flexible3_stiffening;
pub mod flexible3_strain;
#[cfg(test)]
mod flexible3_tests;
pub mod inspect;
pub mod marker3;
pub mod outline;
pub mod point3;
pub mod point_mass;
pub mod rigid;
pub mod rigid3;

pub use ancf_cable::{AncfCable, AncfCableData, CablePoint};
pub use ffrf::{Ffrf, FfrfData, PointShape};
pub use ffrf_beam::{Beam, BeamData};
pub use inspect::{Array, Capabilities};
pub use marker::{Marker, MarkerShape, MarkerState};
pub use flexible::Flexible;
pub use flexible3::{Flexible3, Flexible3Data};
pub use point_mass::{PointMass, PointMassData};
pub use rigid::{Rigid, RigidData};
pub use point3::{Point3, Point3Data};
pub use rigid3::{Rigid3, Rigid3Data};

use crate::description::{BodyDesc, MarkerDesc};
use crate::error::{check_finite_item, Error, Result};

/// `$e` with `$k` bound to the body's kind, one arm per kind (every kind implements the stage
/// `$e` calls).
macro_rules! with_kind {
    ($kind:expr, |$k:ident| $e:expr) => {
        match $kind {
            BodyKind::Rigid($k) => $e,
            BodyKind::Beam($k) => $e,
            BodyKind::PointMass($k) => $e,
            BodyKind::Cable($k) => $e,
            BodyKind::Flexible($k) => $e,
            BodyKind::Rigid3($k) => $e,
            BodyKind::Point3($k) => $e,
            BodyKind::Flexible3($k) => $e,
        }
    };
}

/// `$e` with `$k` bound to the body's kind for the kinds with elastic forces (the stages of
/// deformation: strain energies, tangent stiffness); `$rigid` for the rigid kinds.
macro_rules! with_elastic_kind {
    ($kind:expr, |$k:ident| $e:expr, rigid => $rigid:expr) => {
        match $kind {
            BodyKind::Beam($k) => $e,
            BodyKind::Cable($k) => $e,
            BodyKind::Flexible($k) => $e,
            BodyKind::Flexible3($k) => $e,
            BodyKind::Rigid(_) | BodyKind::PointMass(_) | BodyKind::Rigid3(_) | BodyKind::Point3(_) => $rigid,
        }
    };
}

/// `$e` with `$k` bound to the body's kind and `$d` to its workspace (of the same kind).
macro_rules! with_kind_data {
    ($kind:expr, $data:expr, |$k:ident, $d:ident| $e:expr) => {
        match ($kind, $data) {
            (BodyKind::Rigid($k), BodyData::Rigid($d)) => $e,
            (BodyKind::Beam($k), BodyData::Beam($d)) => $e,
            (BodyKind::PointMass($k), BodyData::PointMass($d)) => $e,
            (BodyKind::Cable($k), BodyData::Cable($d)) => $e,
            (BodyKind::Flexible($k), BodyData::Flexible($d)) => $e,
            (BodyKind::Rigid3($k), BodyData::Rigid3($d)) => $e,
            (BodyKind::Point3($k), BodyData::Point3($d)) => $e,
            (BodyKind::Flexible3($k), BodyData::Flexible3($d)) => $e,
            _ => unreachable!("body data of another kind"),
        }
    };
}

/// The closed set of body kinds (a scene has few bodies; the variants stay unboxed so that a
/// body's constants sit next to each other).
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
pub enum BodyKind {
    Rigid(Rigid),
    Beam(Beam),
    PointMass(PointMass),
    Cable(AncfCable),
    Flexible(Flexible),
    /// Spatial rigid body (`rigid3.rs`, built by `model::spatial`).
    Rigid3(Rigid3),
    /// Spatial point mass (`point3.rs`).
    Point3(Point3),
    /// Spatial floating-frame modal body (`flexible3.rs`).
    Flexible3(Flexible3),
}

/// Per-body workspace, one variant per kind (sized once in `Data::new`).
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
pub enum BodyData {
    Rigid(RigidData),
    Beam(BeamData),
    PointMass(PointMassData),
    Cable(AncfCableData),
    Flexible(FfrfData),
    Rigid3(Rigid3Data),
    Point3(Point3Data),
    Flexible3(Flexible3Data),
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
        // the kind's constants, then its initial state from the same description
        macro_rules! build {
            ($variant:ident, $ty:ident, $d:expr) => {{
                let k = $ty::from_desc($d, &item)?;
                let init = k.initial_state($d, &item)?;
                (BodyKind::$variant(k), init)
            }};
        }
        let (kind, init) = match d {
            BodyDesc::Rigid(r) => build!(Rigid, Rigid, r),
            BodyDesc::Cable(c) => build!(Cable, AncfCable, c),
            BodyDesc::Beam(b) => build!(Beam, Beam, b),
            BodyDesc::PointMass(p) => build!(PointMass, PointMass, p),
            BodyDesc::Flexible(f) => build!(Flexible, Flexible, f),
        };
        for (what, v) in [("initial state", &init.q), ("initial rates", &init.qd)] {
            check_finite_item(&item, what, v)?;
        }
        Ok((Body { name, offset, n_coords: init.q.len(), kind }, init))
    }

    /// The kind's name, as in the description (`"rigid"`, `"beam"`, `"point_mass"`, `"cable"`,
    /// `"flexible"`).
    pub fn kind_name(&self) -> &'static str {
        match &self.kind {
            BodyKind::Rigid(_) => "rigid",
            BodyKind::Beam(_) => "beam",
            BodyKind::PointMass(_) => "point_mass",
            BodyKind::Cable(_) => "cable",
            BodyKind::Flexible(_) => "flexible",
            BodyKind::Rigid3(_) => "rigid3",
            BodyKind::Point3(_) => "point3",
            BodyKind::Flexible3(_) => "flexible3",
        }
    }

    /// Coordinates `q[elastic_range]` that describe deformation alone (empty for rigid kinds,
    /// and for an ANCF cable, whose nodal coordinates carry its motion and deformation together).
    pub fn elastic_range(&self) -> std::ops::Range<usize> {
        match &self.kind {
            BodyKind::Beam(_) | BodyKind::Flexible(_) => self.offset + 3..self.offset + self.n_coords,
            BodyKind::Flexible3(_) => self.offset + 7..self.offset + self.n_coords,
            BodyKind::Rigid(_) | BodyKind::PointMass(_) | BodyKind::Cable(_) | BodyKind::Rigid3(_) | BodyKind::Point3(_) => self.offset..self.offset,
        }
    }

    /// Half-bandwidth, in body coordinates, of the body's own blocks of `M`, `K = -dQ/dq` and
    /// `C = -dQ/dqd` (entries `(i, j)` with `|i - j|` above it are zero): an ANCF cable's are
    /// element-coupled (`ancf_cable::HB`), every other kind's dense. The structural pattern of
    /// the implicit methods' sparse Newton matrices (`sparse_newton`).
    pub fn coupling_halfwidth(&self) -> usize {
        match &self.kind {
            BodyKind::Cable(_) => ancf_cable::HB.min(self.n_coords.saturating_sub(1)),
            _ => self.n_coords.saturating_sub(1),
        }
    }

    /// Number of elastic coordinates.
    pub fn n_f(&self) -> usize {
        self.elastic_range().len()
    }

    pub fn total_mass(&self) -> f64 {
        with_kind!(&self.kind, |k| k.mass)
    }

    pub fn new_data(&self) -> BodyData {
        match &self.kind {
            BodyKind::Rigid(k) => BodyData::Rigid(k.new_data()),
            BodyKind::Beam(k) => BodyData::Beam(k.new_data()),
            BodyKind::PointMass(k) => BodyData::PointMass(k.new_data()),
            BodyKind::Cable(k) => BodyData::Cable(k.new_data()),
            BodyKind::Flexible(k) => BodyData::Flexible(k.new_data()),
            BodyKind::Rigid3(k) => BodyData::Rigid3(k.new_data()),
            BodyKind::Point3(k) => BodyData::Point3(k.new_data()),
            BodyKind::Flexible3(k) => BodyData::Flexible3(k.new_data()),
        }
    }

    #[inline]
    fn seg<'a>(&self, v: &'a [f64]) -> &'a [f64] {
        &v[self.offset..self.offset + self.n_coords]
    }

    /// Add a motor's rotor inertia `j` (it turns with this body: `j` adds to the body's
    /// moment of inertia, exactly, whatever the motor's place). Rigid bodies only.
    pub fn add_rotor_inertia(&mut self, item: &str, j: f64) -> Result<()> {
        match &mut self.kind {
            BodyKind::Rigid(r) => {
                r.inertia += j;
                r.j_ref += j;
                Ok(())
            }
            _ => Err(crate::error::Error::invalid(item, format!("a rotor inertia needs a rigid rotor body; '{}' is not rigid (add the rotor as a rigid body welded to it)", self.name))),
        }
    }

    /// Mass blocks at `q` and generalized forces `Q_b(q, qd)` (inertial velocity terms,
    /// elastic forces, gravity) into `force` (the whole `Q`, this body's segment written).
    #[inline]
    pub fn mass_and_forces(&self, bd: &mut BodyData, q: &[f64], qd: &[f64], gravity: Option<[f64; 2]>, force: &mut [f64]) {
        let (qb, qdb) = (self.seg(q), self.seg(qd));
        let f = &mut force[self.offset..self.offset + self.n_coords];
        with_kind_data!(&self.kind, bd, |k, d| k.mass_and_forces(d, qb, qdb, gravity, f))
    }

    /// Factor the body block `M_b = F_b F_b^T` (after `mass_and_forces`).
    #[inline]
    pub fn factor(&self, bd: &mut BodyData) -> Result<()> {
        if with_kind_data!(&self.kind, bd, |k, d| k.factor(d)) {
            Ok(())
        } else {
            Err(Error::SingularMass { item: format!("body '{}'", self.name) })
        }
    }

    /// `v <- F_b^-1 v` on this body's segment `v` (length `n_coords`).
    #[inline]
    pub fn finv(&self, bd: &BodyData, v: &mut [f64]) {
        with_kind_data!(&self.kind, bd, |k, d| k.finv(d, v))
    }

    /// `v <- F_b^-T v` on this body's segment.
    #[inline]
    pub fn finvt(&self, bd: &BodyData, v: &mut [f64]) {
        with_kind_data!(&self.kind, bd, |k, d| k.finvt(d, v))
    }

    /// `out += M_b x` on this body's segments (after `mass_and_forces`; allocation free).
    #[inline]
    pub fn mass_times(&self, bd: &BodyData, x: &[f64], out: &mut [f64]) {
        with_kind_data!(&self.kind, bd, |k, d| k.mass_times(d, x, out))
    }

    /// Visit the nonzero entries of the body block `M_b` (after `mass_and_forces`) in body
    /// coordinates: `put(i, j, M_b[i, j])`.
    pub fn dense_block(&self, bd: &BodyData, put: &mut impl FnMut(usize, usize, f64)) {
        with_kind_data!(&self.kind, bd, |k, d| k.dense_block(d, put))
    }

    /// Stiffness `-dQ_b/dq_b` and damping `-dQ_b/dqd_b` of the body's own forces that it knows
    /// analytically (elastic tangent, strain-rate damping), in body coordinates.
    pub fn tangent(&self, _bd: &BodyData, q: &[f64], qd: &[f64], k: &mut impl FnMut(usize, usize, f64), c: &mut impl FnMut(usize, usize, f64)) {
        match &self.kind {
            BodyKind::Beam(b) => b.tangent(self.seg(q), k, c),
            BodyKind::Cable(b) => b.tangent(self.seg(q), k, c),
            BodyKind::Flexible(b) => b.tangent(self.seg(q), k, c),
            // its stress stiffening reads the frame's rates
            BodyKind::Flexible3(b) => b.tangent(self.seg(q), self.seg(qd), k, c),
            BodyKind::Rigid(_) | BodyKind::PointMass(_) | BodyKind::Rigid3(_) | BodyKind::Point3(_) => (),
        }
    }

    /// `1/2 qd_b^T M_b qd_b` (after `mass_and_forces` at the same `q`).
    pub fn kinetic_energy(&self, bd: &BodyData, qd: &[f64]) -> f64 {
        let qdb = self.seg(qd);
        with_kind_data!(&self.kind, bd, |k, d| k.kinetic_energy(d, qdb))
    }

    /// Elastic strain energy (zero for rigid kinds).
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        with_elastic_kind!(&self.kind, |k| k.strain_energy(self.seg(q)), rigid => 0.0)
    }

    /// `1/2 v^T K_m v`: the strain energy of the first-order strains of a motion `v` (whole
    /// `n`-vector) at `q`, with the material stiffness alone (no stress terms: a rigid motion of a
    /// stressed cable stores none; zero for rigid kinds). Tells elastic modes from rigid ones
    /// alike for every flexible kind (`System.material_energies`).
    pub fn material_energy(&self, q: &[f64], v: &[f64]) -> f64 {
        with_elastic_kind!(&self.kind, |k| k.material_energy(self.seg(q), self.seg(v)), rigid => 0.0)
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
            BodyKind::Cable(_) => {
                let (qb, vb) = (self.seg(q), self.seg(qd));
                ancf_cable::rigid_motions(qb, vb, o, col0, put, &mut cen[o..o + self.n_coords])
            }
            BodyKind::PointMass(_) => {
                put(o, col0, 1.0);
                put(o + 1, col0 + 1, 1.0);
                2
            }
            BodyKind::Rigid3(_) | BodyKind::Point3(_) | BodyKind::Flexible3(_) => {
                let (qb, vb) = (&self.seg(q)[..self.n_coords.min(7)], &self.seg(qd)[..self.n_coords.min(7)]);
                rigid3_motions(qb, vb, o, col0, put, &mut cen[o..o + self.n_coords])
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
            BodyKind::Cable(_) => ancf_cable::move_rigidly(&mut q[o..o + self.n_coords], x),
            BodyKind::PointMass(_) => {
                q[o] += x[0];
                q[o + 1] += x[1];
            }
            BodyKind::Rigid3(_) | BodyKind::Point3(_) | BodyKind::Flexible3(_) => {
                let n = self.n_coords.min(7);
                rigid3_move(&mut q[o..o + n], x)
            }
            BodyKind::Rigid(_) | BodyKind::Beam(_) | BodyKind::Flexible(_) => {
                for k in 0..3 {
                    q[o + k] += x[k];
                }
            }
        }
    }

    /// Euler parameters (spatial rigid and modal bodies: `q[3..7]` of the body) back to unit
    /// length with their rates scaled alike (`rigid3::normalize_euler_parameters`: no physical
    /// quantity moves). Other kinds have none. Returns whether anything changed.
    pub fn normalize_orientation(&self, q: &mut [f64], qd: &mut [f64]) -> bool {
        match &self.kind {
            BodyKind::Rigid3(_) | BodyKind::Flexible3(_) => {
                let o = self.offset + 3;
                rigid3::normalize_euler_parameters(&mut q[o..o + 4], &mut qd[o..o + 4])
            }
            _ => false,
        }
    }

    /// Potential of gravity `-g . int rho r dV`.
    pub fn gravity_energy(&self, q: &[f64], g: [f64; 2]) -> f64 {
        let r = with_kind!(&self.kind, |k| k.mass_moment(self.seg(q)));
        -(g[0] * r[0] + g[1] * r[1])
    }

    /// Resolve a marker description on this body (`index` = this body's index).
    pub fn marker(&self, index: usize, md: &MarkerDesc, item: &str) -> Result<Marker> {
        let shape = match &self.kind {
            BodyKind::Rigid(_) => MarkerShape::Rigid(rigid::marker_point(md, &self.name, item)?),
            BodyKind::Beam(k) => MarkerShape::Beam(k.marker_shape(md, &self.name, item)?),
            BodyKind::Cable(k) => MarkerShape::Cable(k.marker_shape(md, &self.name, item)?),
            BodyKind::Flexible(k) => MarkerShape::Beam(k.marker_shape(md, &self.name, item)?),
            BodyKind::PointMass(_) => {
                point_mass::check_marker(md, &self.name, item)?;
                MarkerShape::Particle
            }
            BodyKind::Rigid3(_) | BodyKind::Point3(_) | BodyKind::Flexible3(_) => {
                return Err(Error::invalid(item, format!("body '{}' is spatial: a planar item cannot attach to it (a scene does not mix dimensions)", self.name)));
            }
        };
        Ok(Marker { body: Some(index), angle: md.angle, shape })
    }

    /// `[x, y, u, v, psi]` of the axis point `xi` of a beam at `q` (inspection, allocates):
    /// world position, displacement in the beam frame from the undeformed `(xi L, 0)` and the
    /// section rotation relative to that frame. The frame is the floating frame of an FFRF
    /// beam (for the pinned-pinned frame: the chord of the ends) and the chord frame of the
    /// ends of an ANCF cable, so that both compare one to one. An argument error for kinds
    /// without an axis (`Capabilities::beam`).
    pub fn beam_point(&self, xi: f64, q: &[f64]) -> Result<[f64; 5]> {
        inspect::check_xi(xi)?;
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
                Ok([ms.r[0], ms.r[1], u, v, ms.phi - qb[2]])
            }
            BodyKind::Cable(k) => Ok(k.chord_displacement(xi, qb)),
            _ => self.require_beam().map(|_| [0.0; 5]),
        }
    }

    /// `[N, V, M, eps, kappa]` at the axis point `xi` of a beam at `q` (see
    /// `ffrf_beam::Beam::internal_forces`, `ancf_cable::AncfCable::internal_forces`); an
    /// argument error for kinds without an axis.
    pub fn internal_forces(&self, xi: f64, q: &[f64]) -> Result<[f64; 5]> {
        inspect::check_xi(xi)?;
        let qb = self.seg(q);
        match &self.kind {
            BodyKind::Beam(k) => Ok(k.internal_forces(xi, qb)),
            BodyKind::Cable(k) => Ok(k.internal_forces(xi, qb)),
            _ => self.require_beam().map(|_| [0.0; 5]),
        }
    }
}

pub(crate) fn finite_vec2(item: &str, what: &str, v: [f64; 2]) -> Result<[f64; 2]> {
    check_finite_item(item, what, &v)?;
    Ok(v)
}

/// Rigid motions of a spatial body (`Body::rigid_motions`): translations (3 columns) and, for a
/// rigid3 body, rotations about the world axes through its centre of mass
/// (`pd = 1/2 E(p)^T e_k`), with the centripetal part of the rotation at its angular velocity
/// (`pdd = 1/2 E(pd)^T w`, `w = 2 E(p) pd / |p|^2`).
fn rigid3_motions(q: &[f64], qd: &[f64], o: usize, col0: usize, put: &mut impl FnMut(usize, usize, f64), cen: &mut [f64]) -> usize {
    for k in 0..3 {
        put(o + k, col0 + k, 1.0);
    }
    if q.len() < 7 {
        return 3;
    }
    use crate::linalg::rot3::rot_e;
    let e = rot_e(&q[3..7]);
    for k in 0..3 {
        for l in 0..4 {
            put(o + 3 + l, col0 + 3 + k, 0.5 * e[k][l]);
        }
    }
    let p2: f64 = q[3..7].iter().map(|x| x * x).sum();
    let mut w = [0.0; 3];
    for k in 0..3 {
        w[k] = 2.0 * (0..4).map(|l| e[k][l] * qd[3 + l]).sum::<f64>() / p2;
    }
    let ed = rot_e(&qd[3..7]);
    for l in 0..4 {
        cen[3 + l] = 0.5 * (ed[0][l] * w[0] + ed[1][l] * w[1] + ed[2][l] * w[2]);
    }
    6
}

/// Move a spatial body rigidly by `x` (its `rigid3_motions` columns): `r += x[0..3]`, and for a
/// rigid3 body `p <- exp(x[3..6] / 2) p` (the rotation by the vector `x[3..6]`, world axes).
fn rigid3_move(q: &mut [f64], x: &[f64]) {
    for k in 0..3 {
        q[k] += x[k];
    }
    if q.len() < 7 {
        return;
    }
    let th = (x[3] * x[3] + x[4] * x[4] + x[5] * x[5]).sqrt();
    if th == 0.0 {
        return;
    }
    let (s, c) = (0.5 * th).sin_cos();
    let u = [x[3] / th * s, x[4] / th * s, x[5] / th * s];
    let p = [q[3], q[4], q[5], q[6]];
    // r * p with r = (c, u) (world-frame rotation applied after p)
    q[3] = c * p[0] - u[0] * p[1] - u[1] * p[2] - u[2] * p[3];
    q[4] = c * p[1] + u[0] * p[0] + u[1] * p[3] - u[2] * p[2];
    q[5] = c * p[2] - u[0] * p[3] + u[1] * p[0] + u[2] * p[1];
    q[6] = c * p[3] + u[0] * p[2] - u[1] * p[1] + u[2] * p[0];
}
