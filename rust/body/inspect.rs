//! Inspection of one body (allocating; never on the per-step path): what a kind can be asked
//! (`Capabilities`), its description as the core derived it (`info`), and the arrays of the
//! beam-like kinds (`shape`, `matrices`, `tangent_stiffness`, `axial_forces`). Each kind answers
//! in its own file; this file only dispatches, and the bindings convert the answers without
//! knowing kinds.

use serde::Serialize;
use serde_json::{Map, Value};

use super::{Body, BodyData, BodyKind};
use crate::error::{Error, Result};

/// A dense answer: a vector or a row-major matrix.
#[derive(Debug, Clone, PartialEq)]
pub enum Array {
    Vector(Vec<f64>),
    Matrix { rows: usize, cols: usize, data: Vec<f64> },
}

impl Array {
    pub fn matrix(rows: usize, cols: usize, data: Vec<f64>) -> Array {
        debug_assert_eq!(data.len(), rows * cols);
        Array::Matrix { rows, cols, data }
    }

    pub fn values(&self) -> &[f64] {
        match self {
            Array::Vector(v) => v,
            Array::Matrix { data, .. } => data,
        }
    }
}

/// What a body can be asked and what it has, so that Python keeps no lists of kinds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Capabilities {
    /// It has an axis `xi in [0, 1]`: `beam_point`, `internal_forces`, `shape`, `matrices`.
    pub beam: bool,
    /// It has elastic forces (strain energy, `tangent_stiffness`).
    pub elastic: bool,
    /// Coordinates that describe deformation alone (`elastic_range` not empty: FFRF kinds).
    pub elastic_coordinates: bool,
    /// Per-element axial forces (`axial_forces`).
    pub axial_forces: bool,
    /// Named interface markers (`info()["markers"]`).
    pub named_markers: bool,
    /// It has an orientation (a frame angle; a point mass has none).
    pub oriented: bool,
    /// Its deformation and its motion share coordinates (an ANCF cable's nodal positions and
    /// slopes): holding its deformation means moving it rigidly (`rigid_motions`).
    pub nodal_deformation: bool,
    /// It has material damping (the scene is then truly stiff).
    pub damped: bool,
}

impl Body {
    pub fn capabilities(&self) -> Capabilities {
        match &self.kind {
            BodyKind::Rigid(_) | BodyKind::Rigid3(_) => Capabilities { oriented: true, ..Default::default() },
            BodyKind::PointMass(_) | BodyKind::Point3(_) => Capabilities::default(),
            BodyKind::Flexible3(f) => Capabilities { elastic: true, elastic_coordinates: true, oriented: true, damped: f.d_ff.is_some(), ..Default::default() },
            BodyKind::Beam(b) => Capabilities { beam: true, elastic: true, elastic_coordinates: true, axial_forces: true, oriented: true, damped: b.damping > 0.0, ..Default::default() },
            BodyKind::Cable(c) => Capabilities { beam: true, elastic: true, oriented: true, nodal_deformation: true, damped: c.damping > 0.0, ..Default::default() },
            BodyKind::Flexible(f) => Capabilities { elastic: true, elastic_coordinates: true, named_markers: true, oriented: true, damped: f.d_ff.is_some(), ..Default::default() },
        }
    }

    /// The body as the core derived it: `kind`, `mass`, `n_coords`, `n_f`, then the kind's own
    /// entries (`Rigid::info`, `Beam::info`, ...).
    pub fn info(&self) -> Map<String, Value> {
        let mut m = Map::new();
        m.insert("kind".into(), self.kind_name().into());
        m.insert("mass".into(), self.total_mass().into());
        m.insert("n_coords".into(), self.n_coords.into());
        m.insert("n_f".into(), self.n_f().into());
        match &self.kind {
            BodyKind::Rigid(k) => k.info(&mut m),
            BodyKind::Beam(k) => k.info(&mut m),
            BodyKind::Cable(k) => k.info(&mut m),
            BodyKind::Flexible(k) => k.info(&mut m),
            BodyKind::Rigid3(k) => k.info(&mut m),
            BodyKind::Flexible3(k) => k.info(&mut m),
            BodyKind::PointMass(_) | BodyKind::Point3(_) => {}
        }
        m
    }

    pub(super) fn not_a(&self, what: &str) -> Error {
        Error::argument("body", format!("body '{}' ({}) is not {what}", self.name, self.kind_name()))
    }

    /// Shape functions of the axis point `xi`: FFRF beam `(S (2, n_f), N_psi (n_f,))` (elastic
    /// displacement `S q_f` in the beam frame, section rotation `N_psi q_f`); ANCF cable
    /// `(S (2, n_b), S' (2, n_b))` (world position `S e` and slope `S' e`).
    pub fn shape(&self, xi: f64) -> Result<(Array, Array)> {
        check_xi(xi)?;
        match &self.kind {
            BodyKind::Beam(k) => Ok(k.shape_arrays(xi)),
            BodyKind::Cable(k) => Ok(k.shape_arrays(xi)),
            _ => Err(self.not_a("a beam")),
        }
    }

    /// Constant blocks `(M, K)` of a beam (FFRF: `M_ff`, `K_ff`; ANCF: the mass matrix and the
    /// tangent stiffness at `q0`, the undeformed initial guess).
    pub fn matrices(&self, q0: &[f64]) -> Result<(Array, Array)> {
        match &self.kind {
            BodyKind::Beam(k) => Ok(k.matrices()),
            BodyKind::Cable(k) => Ok(k.matrices(&q0[self.offset..self.offset + self.n_coords])),
            _ => Err(self.not_a("a beam")),
        }
    }

    /// `-dQ_el/dq_b` at `q` (n_b x n_b, row-major over the body's coordinates).
    pub fn tangent_stiffness(&self, q: &[f64]) -> Result<Vec<f64>> {
        let nb = self.n_coords;
        let qb = &q[self.offset..self.offset + nb];
        let mut k = vec![0.0; nb * nb];
        // the FFRF kinds' elastic block sits after the 3 frame coordinates
        let mut put = |i: usize, j: usize, v: f64| k[(3 + i) * nb + 3 + j] += v;
        match &self.kind {
            BodyKind::Cable(c) => return Ok(c.tangent_dense(qb)),
            BodyKind::Beam(b) => b.elastic_tangent(&qb[3..], &mut put),
            BodyKind::Flexible(f) => f.elastic_tangent(&qb[3..], &mut put),
            _ => return Err(self.not_a("a beam or a flexible body")),
        }
        Ok(k)
    }

    /// Per-element axial forces from the workspace after `mass_and_forces`.
    pub fn axial_forces(&self, bd: &BodyData) -> Result<Vec<f64>> {
        match bd {
            BodyData::Beam(d) => Ok(d.axial_force.clone()),
            _ => Err(self.not_a("an FFRF beam (per-element axial forces)")),
        }
    }

    /// Refuse a body that is not a beam (before an evaluation over many states).
    pub fn require_beam(&self) -> Result<()> {
        if self.capabilities().beam { Ok(()) } else { Err(self.not_a("a beam")) }
    }
}

pub fn check_xi(xi: f64) -> Result<()> {
    if xi.is_finite() && (0.0..=1.0).contains(&xi) {
        Ok(())
    } else {
        Err(Error::argument("xi", format!("must be in [0, 1], got {xi}")))
    }
}

/// The description's spelling of a serde enum value (`"euler-bernoulli"`, `"pinned-pinned"`).
pub fn spelled<T: Serialize>(v: &T) -> Value {
    serde_json::to_value(v).unwrap_or(Value::Null)
}
