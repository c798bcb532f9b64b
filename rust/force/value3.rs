//! The spatial point quantities a load's value may read (docs/loads.md, "Point quantities in
//! 3D"): `x(BODY)`, `y(BODY)`, `z(BODY)`, the world position of a body's reference point (the
//! `position(BODY)` of the spatial outputs: a rigid3 body's centre of mass, a point mass, a
//! `beam3` node `a[3]`), `x(BODY, [sx, sy, sz])` of a body-fixed point (in the body's frame, as
//! a marker's `point`; on a `flexible3` body an interface node), and their velocities
//! `d:x(...)`. Each is resolved once into a spatial marker (`Marker3`) and read into the
//! expression as a variable (`value.rs`, `Input::Point3`), with its Jacobian in the stiffness.

use std::collections::HashMap;

use crate::body::marker3::{Kin3, Marker3};
use crate::body::Body;
use crate::linalg::rot3::{rot_b, V3};
use crate::body::{Marker, MarkerShape};
use crate::description::spatial::Marker3Desc;
use crate::error::Result;

/// A spatial scene's bodies and their index by name (the spatial point quantities' markers).
#[derive(Clone, Copy)]
pub struct Spatial<'a> {
    pub bodies: &'a [Body],
    pub index: &'a HashMap<String, usize>,
}

/// What the spatial point quantities look like, for messages.
pub const HELP: &str = ", x(BODY), y(BODY), z(BODY) (a body's reference point), x(BODY, [sx, sy, sz]) (a point fixed in it) or their rates d:x(...)";

/// The head of a point quantity at the start of `s`, planar or spatial: an optional `d:` (its
/// rate), one of the letters `axes` (`b"xy"`, `b"xyz"`) and a parenthesis: `(axis, rate, the
/// arguments' text, the length up to the closing parenthesis)`.
pub fn point_call<'s>(s: &'s str, axes: &[u8]) -> Option<(usize, bool, &'s str, usize)> {
    let (rate, rest) = match s.strip_prefix("d:") {
        Some(r) => (true, r),
        None => (false, s),
    };
    let axis = axes.iter().position(|a| Some(a) == rest.as_bytes().first())?;
    let inner = rest[1..].trim_start().strip_prefix('(')?;
    let close = inner.find(')')?;
    Some((axis, rate, &inner[..close], (s.len() - inner.len()) + close + 1))
}

/// A spatial point quantity as parsed: `(axis, rate, body, point, length of the text)`.
pub type PointQuantity = (usize, bool, String, Option<[f64; 3]>, usize);

/// A spatial point quantity parsed from the start of `s`: `(axis, rate, body, point, length of
/// the text)`; `None` when `s` does not start with one. A body name may hold brackets (a beam's
/// node `a[3]`) but no parentheses or commas.
pub fn point_quantity(s: &str) -> Option<PointQuantity> {
    let (axis, rate, args, consumed) = point_call(s, b"xyz")?;
    let (body, point) = match args.split_once(',') {
        None => (args.trim(), None),
        Some((body, p)) => {
            let p = p.trim().strip_prefix('[')?.strip_suffix(']')?;
            let v: Vec<f64> = p.split(',').map(|x| x.trim().parse::<f64>().ok()).collect::<Option<_>>()?;
            (body.trim(), Some(<[f64; 3]>::try_from(v).ok()?))
        }
    };
    if body.is_empty() || !body.chars().all(|c| c.is_alphanumeric() || "_.:-[]".contains(c)) {
        return None;
    }
    Some((axis, rate, body.to_string(), point, consumed))
}

/// The marker of a spatial point quantity: the body's point `point`, or its reference point
/// (its coordinates `r`: a rigid3 or flexible3 body's frame origin, which for a rigid3 body is
/// its centre of mass; a point mass) when `None`. An unknown body is named (`UnknownBody`), as
/// a marker's.
pub fn marker(item: &str, sp: Spatial, body: &str, point: Option<[f64; 3]>) -> Result<Marker3> {
    let md = Marker3Desc { body: body.to_string(), point, z: None, x: None };
    match (point, sp.index.get(body)) {
        (None, Some(&bi)) => {
            let base = Marker { body: Some(bi), angle: 0.0, shape: MarkerShape::Spatial };
            // `rigid: false`: the point is `r` itself, its Jacobian the identity on `r`
            Ok(Marker3 { base, body: Some(bi), rigid: false, s: [0.0; 3], c: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], iface: None })
        }
        _ => Marker3::from_desc(item, &md, sp.bodies, sp.index),
    }
}

/// The Jacobian of the rate of the body vector `v` of marker `m` (`v` its point `s` or an axis
/// `c_k`): `vd = B(p, v) pd` is bilinear in `p` and `pd`, so `d vd / dp = B(pd, v)` and
/// `d vd / dr = 0`, as a `Kin3` for `add_jacobian` (its `jr = 0`, its `jp = B(pd, v)`). Zero on
/// the ground and on a point mass (whose rate does not depend on `q`); on a `flexible3` body's
/// node the rate's change with the elastic coordinates is left out (its frame's part is in).
pub fn rate_kin(m: &Marker3, bodies: &[Body], qd: &[f64], v: &V3) -> Kin3 {
    match m.body {
        Some(b) if m.rigid => {
            let o = bodies[b].offset;
            Kin3 { jp: rot_b(&qd[o + 3..o + 7], v), ..Default::default() }
        }
        _ => Kin3::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::point_quantity;

    #[test]
    fn parses_bodies_points_and_rates() {
        assert_eq!(point_quantity("z(m) + 1"), Some((2, false, "m".into(), None, 4)));
        assert_eq!(point_quantity("d:x( a[3] )*2"), Some((0, true, "a[3]".into(), None, 11)));
        assert_eq!(point_quantity("y(w, [0.1, 0, -2e-1])"), Some((1, false, "w".into(), Some([0.1, 0.0, -0.2]), 21)));
        assert_eq!(point_quantity("y(w, 0.5)"), None);
        assert_eq!(point_quantity("y(w, [1, 2])"), None);
        assert_eq!(point_quantity("exp(2)"), None);
        assert_eq!(point_quantity("x"), None);
    }
}
