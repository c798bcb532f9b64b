//! How a planar body is drawn (animation; inspection, allocates): the world points of its
//! outline and of its markers at a state, the elastic displacements magnified by `s` in the
//! body's reference frame (the floating frame; an ANCF cable's chord frame). Each kind says
//! which of its material points draw it (`outline_points` in its own file); this file only
//! places material points, so a new kind draws itself without any change in Python.

use super::marker::{Marker, MarkerShape};
use super::{Body, BodyKind};
use crate::error::{Error, Result};

/// Two body-frame points closer than this are one attachment point.
const SAME_POINT: f64 = 1e-12;

impl Body {
    /// World points (a polyline) drawing this body at `q` (the whole coordinate vector):
    /// `attach` are the body-frame points of the markers on it (a rigid body is drawn as a star
    /// from its centre of mass to them), `per_element` samples per beam element.
    pub fn outline(&self, q: &[f64], s: f64, per_element: usize, attach: &[[f64; 2]]) -> Result<Vec<[f64; 2]>> {
        let shapes = match &self.kind {
            BodyKind::Rigid(k) => k.outline_points(&distinct(attach)),
            BodyKind::PointMass(_) => vec![MarkerShape::Particle],
            BodyKind::Beam(k) => k.outline_points(per_element),
            BodyKind::Cable(k) => k.outline_points(per_element),
            BodyKind::Flexible(k) => k.outline_points(),
            BodyKind::Rigid3(_) | BodyKind::Point3(_) | BodyKind::Flexible3(_) => return Err(self.not_a("a planar body (its outline is drawn by the 3D animation)")),
        };
        Ok(shapes.iter().map(|sh| self.drawn_point(sh, q, s)).collect())
    }

    /// World position of the material point `shape` of this body at `q`, its elastic
    /// displacement magnified by `s` (1: the true position).
    pub fn drawn_point(&self, shape: &MarkerShape, q: &[f64], s: f64) -> [f64; 2] {
        let qb = self.seg(q);
        let frame = |p: [f64; 2]| {
            let (c, sn) = (qb[2].cos(), qb[2].sin());
            [qb[0] + c * p[0] - sn * p[1], qb[1] + sn * p[0] + c * p[1]]
        };
        match shape {
            MarkerShape::Ground(p) => *p,
            MarkerShape::Rigid(p) => frame(*p),
            MarkerShape::Particle | MarkerShape::Spatial => [qb[0], qb[1]],
            MarkerShape::Beam(ps) => {
                let (mut u, mut v) = (0.0, 0.0);
                for &(i, su, sv, _) in &ps.entries {
                    u += su * qb[3 + i];
                    v += sv * qb[3 + i];
                }
                frame([ps.x + s * u, ps.y + s * v])
            }
            MarkerShape::Cable(cp) => match &self.kind {
                BodyKind::Cable(k) => k.drawn_point(cp.xi, qb, s),
                _ => [qb[0], qb[1]],
            },
        }
    }
}

/// World position of marker `m` at `q` with magnification `s` (the ground's markers stay).
pub fn marker_point(bodies: &[Body], m: &Marker, q: &[f64], s: f64) -> [f64; 2] {
    match (m.body, &m.shape) {
        (None, MarkerShape::Ground(p)) => *p,
        (Some(bi), shape) => bodies[bi].drawn_point(shape, q, s),
        (None, _) => [f64::NAN; 2],
    }
}

fn distinct(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::new();
    for p in points {
        if out.iter().all(|u| (p[0] - u[0]).hypot(p[1] - u[1]) > SAME_POINT) {
            out.push(*p);
        }
    }
    out
}

/// `k + 1` equally spaced axis parameters for `k = max(2, per_element * elements)`.
pub fn axis_samples(per_element: usize, elements: usize) -> impl Iterator<Item = f64> {
    let k = (per_element * elements).max(2);
    (0..=k).map(move |i| i as f64 / k as f64)
}

/// An argument error for a drawing request (`per_element` 0, a non-finite magnification).
pub fn check_drawing(s: f64, per_element: usize) -> Result<()> {
    if !s.is_finite() {
        return Err(Error::argument("deform_scale", format!("must be finite, got {s}")));
    }
    if per_element == 0 {
        return Err(Error::argument("points_per_element", "must be at least 1"));
    }
    Ok(())
}
