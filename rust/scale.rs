//! The scene's length scale and the rules that refuse a scene double precision cannot resolve:
//! at build (`check_lengths`, called by `Model::from_json`) and at the corrected initial state
//! (`check_state`: positions and angles far from the origin, masses too disparate for the rank
//! decision). One home for these rules: the Python `System` calls them through the bindings
//! (`_core.System.length_scale`, `_core.System.check_state`) and keeps no copy.

use serde_json::Value;

use crate::data::Data;
use crate::dynamics;
use crate::error::{fmt_g, Error, Result};
use crate::model::Model;
use crate::uk;

/// Positions must be resolved by double precision to this fraction of the scene's length scale
/// (and angles to this many radians).
pub const RESOLUTION: f64 = 1e-9;
/// Largest length scale [m]: beyond it squares of positions and velocities (energies, the
/// centripetal terms) overflow double precision; it is a unit mistake.
pub const MAX_LENGTH_SCALE: f64 = 1e150;
/// Largest problem (`m n min(m, n)`) for which a rank-deficient start is cross-checked against
/// the unweighted Jacobian (a dense SVD: ~1 s at this size).
pub const CONDITIONING_CHECK_WORK: f64 = 2e9;

/// The scene's length scale [m]: the largest body dimension -- beam lengths, centre-of-mass and
/// marker offsets on bodies (not on the ground: those place the mechanism) and distance
/// lengths; 1 m for a scene without any. A spring's rest length is a force parameter, not a
/// size (0 is usual), so it does not count. `desc` is the description in its documented form
/// (`{"kind": .., ..}` items).
pub fn length_scale(desc: &Value) -> f64 {
    let mut sizes: Vec<f64> = Vec::new();
    let list = |key: &str| desc.get(key).and_then(Value::as_array).cloned().unwrap_or_default();
    for b in list("bodies") {
        if let Some(l) = b.get("length").and_then(Value::as_f64) {
            sizes.push(l.abs());
        }
        if let Some(com) = b.get("com").and_then(Value::as_array) {
            sizes.extend(com.iter().filter_map(Value::as_f64).map(f64::abs));
        }
    }
    for section in ["joints", "drivers", "forces"] {
        for item in list(section) {
            let Some(map) = item.as_object() else { continue };
            for (key, v) in map {
                if key == "length" {
                    if let Some(l) = v.as_f64() {
                        sizes.push(l.abs());
                    }
                } else if let Some(marker) = v.as_object() {
                    let body = marker.get("body").and_then(Value::as_str).unwrap_or("ground");
                    if body != "ground" {
                        if let Some(p) = marker.get("point").and_then(Value::as_array) {
                            sizes.extend(p.iter().filter_map(Value::as_f64).map(f64::abs));
                        }
                    }
                }
            }
        }
    }
    sizes.into_iter().filter(|s| s.is_finite() && *s > 0.0).fold(None, |m: Option<f64>, s| Some(m.map_or(s, |m| m.max(s)))).unwrap_or(1.0)
}

/// Refuse a scene too large for double precision, and a distance constraint shorter than the
/// scene resolves: its direction (the row of `A`) is rounding noise and the correction would put
/// the two points on top of each other.
pub fn check_lengths(desc: &Value, scale: f64) -> Result<()> {
    if scale > MAX_LENGTH_SCALE {
        return Err(Error::Description(format!(
            "the scene's length scale {} m is beyond {} m: squares of positions and velocities overflow double \
             precision there; check the units",
            fmt_g(scale, 3),
            fmt_g(MAX_LENGTH_SCALE, 6)
        )));
    }
    for j in desc.get("joints").and_then(Value::as_array).into_iter().flatten() {
        let kind = j.get("kind").and_then(Value::as_str);
        let Some(length) = j.get("length").and_then(Value::as_f64) else { continue };
        if kind == Some("distance") && 0.0 < length && length < RESOLUTION * scale {
            let name = j.get("name").and_then(Value::as_str).unwrap_or("distance");
            return Err(Error::Description(format!(
                "joint '{name}': length = {} m is below what the scene resolves ({} of its length scale {} m = {} m): \
                 the rod's direction is undefined there; use a revolute joint for coincident points",
                fmt_g(length, 3),
                fmt_g(RESOLUTION, 6),
                fmt_g(scale, 3),
                fmt_g(RESOLUTION * scale, 3)
            )));
        }
    }
    Ok(())
}

/// Distance from `x` to the next double away from zero (NumPy's `spacing`).
fn spacing(x: f64) -> f64 {
    let a = x.abs();
    f64::from_bits(a.to_bits() + 1) - a
}

fn is_angle(name: &str) -> bool {
    name.ends_with(".theta")
}

fn is_position(name: &str) -> bool {
    name.ends_with(".x") || name.ends_with(".y") || name.ends_with(".z")
}

/// Orientation coordinates whose mass is an inertia (an angle; Euler parameters).
fn is_rotation(name: &str) -> bool {
    is_angle(name) || [".e0", ".e1", ".e2", ".e3"].iter().any(|s| name.ends_with(s))
}

/// Refuse a state whose positions are too far from the origin for double precision to resolve
/// the mechanism: at 1e17 m a coordinate moves in steps of 16 m, the constraints read zero
/// whatever the motion, and a run would "succeed" with garbage. Angles alike (give them modulo
/// 2 pi).
pub fn check_resolution(model: &Model, q: &[f64]) -> Result<()> {
    let names = &model.coordinate_names;
    let largest = |pick: fn(&str) -> bool| {
        (0..q.len()).filter(|&i| pick(&names[i])).fold(None, |best: Option<usize>, i| match best {
            Some(b) if q[b].abs() >= q[i].abs() => Some(b),
            _ => Some(i),
        })
    };
    let eps = f64::EPSILON;
    if let Some(k) = largest(is_angle) {
        if q[k].abs() * eps > RESOLUTION {
            return Err(Error::Description(format!(
                "{} = {} rad: double precision resolves angles there only to {} rad (resolving {} rad needs |angle| <= \
                 {} rad); give the angle modulo 2 pi",
                names[k],
                fmt_g(q[k], 3),
                fmt_g(spacing(q[k]), 2),
                fmt_g(RESOLUTION, 6),
                fmt_g(RESOLUTION / eps, 3)
            )));
        }
    }
    let scale = model.length_scale;
    if let Some(k) = largest(is_position) {
        let r = q[k].abs();
        if r * eps > RESOLUTION * scale {
            return Err(Error::Description(format!(
                "{} = {} m is {} times the scene's length scale {} m: double precision resolves positions there only \
                 to {} m (resolving {} of the length scale needs |r| <= {} m); place the origin near the mechanism",
                names[k],
                fmt_g(q[k], 3),
                fmt_g(r / scale, 2),
                fmt_g(scale, 3),
                fmt_g(spacing(r), 2),
                fmt_g(RESOLUTION, 6),
                fmt_g(RESOLUTION * scale / eps, 3)
            )));
        }
    }
    Ok(())
}

/// Refuse masses so disparate that the UK solve cannot tell independent constraints from
/// redundant ones: the rank of `A M^-1/2` at the state must equal the rank of `A` (columns
/// equilibrated, so units do not matter). Only a rank-deficient solve needs the check; it runs
/// the UK solve at the state (which leaves the workspace at that state).
pub fn check_conditioning(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]) -> Result<()> {
    let (m, n) = (model.m, model.n);
    if m == 0 {
        return Ok(());
    }
    uk::acceleration(model, data, t, q, qd)?;
    let rank = data.rank_info.rank;
    if rank >= m || (m * n * m.min(n)) as f64 > CONDITIONING_CHECK_WORK {
        return Ok(());
    }
    let mut a = vec![0.0; m * n];
    data.ajac.scatter(&mut a); // row-major m x n
    let dead: Vec<&str> = (0..m)
        .filter(|&i| a[i * n..(i + 1) * n].iter().all(|&v| v == 0.0))
        .map(|i| model.constraint_row_names[i].as_str())
        .collect();
    if !dead.is_empty() {
        return Err(Error::Description(format!(
            "constraint row(s) {} are degenerate at the start: their gradient vanishes (e.g. a distance between \
             coincident points, whose direction is undefined); use a revolute joint for coincident points, or check \
             the lengths and their units",
            dead.join(", ")
        )));
    }
    let mut norms = vec![0.0; n];
    for i in 0..m {
        for j in 0..n {
            norms[j] += a[i * n + j] * a[i * n + j];
        }
    }
    let scaled = faer::Mat::<f64>::from_fn(m, n, |i, j| {
        let s = norms[j].sqrt();
        a[i * n + j] / if s == 0.0 { 1.0 } else { s }
    });
    let svd = scaled.thin_svd().map_err(|_| Error::Solver("the singular values of A did not converge".into()))?;
    let sv: Vec<f64> = (0..m.min(n)).map(|k| svd.S().column_vector()[k]).collect();
    let top = sv.iter().cloned().fold(0.0_f64, f64::max);
    let tol = (m.max(n) as f64) * f64::EPSILON * top;
    let rank_a = if top > 0.0 { sv.iter().filter(|&&s| s > tol).count() } else { 0 };
    if rank_a <= rank {
        return Ok(()); // the redundancy is the constraints' own
    }
    dynamics::mass_and_forces(model, data, t, q, qd);
    let mass = dynamics::dense_mass(model, data);
    let scale = model.length_scale;
    let names = &model.coordinate_names;
    let d: Vec<f64> = (0..n).map(|i| mass[i * n + i] / if is_rotation(&names[i]) { scale * scale } else { 1.0 }).collect();
    let (mut lo, mut hi) = (0, 0);
    for i in 0..n {
        if d[i] < d[lo] {
            lo = i;
        }
        if d[i] > d[hi] {
            hi = i;
        }
    }
    let describe = |i: usize| {
        let per = if is_rotation(&names[i]) { format!(", inertia / {} m^2", fmt_g(scale, 3)) } else { String::new() };
        format!("{} kg ({}{per})", fmt_g(d[i], 3), names[i])
    };
    Err(Error::Description(format!(
        "the masses span too many orders of magnitude for double precision: the {m} constraints are independent (rank \
         {rank_a} of A at the start) but the mass-weighted UK solve resolves only rank {rank}; the mass matrix ranges \
         from {} to {}; check tiny bodies (lengths, masses, inertias) and their units",
        describe(lo),
        describe(hi)
    )))
}

/// The checks of a corrected initial state (`check_resolution`, `check_conditioning`).
pub fn check_state(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]) -> Result<()> {
    check_resolution(model, q)?;
    check_conditioning(model, data, t, q, qd)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn length_scale_reads_bodies_markers_and_distances_not_ground_points() {
        let d: Value = serde_json::json!({
            "bodies": [{"kind": "beam", "length": 0.3}, {"kind": "rigid", "com": [0.0, -0.7]}],
            "joints": [{"kind": "revolute", "a": {"body": "ground", "point": [100.0, 0.0]}, "b": {"body": "x", "point": [0.2, 0.0]}},
                       {"kind": "distance", "length": 0.5}],
            "forces": [{"kind": "spring_damper", "rest_length": 9.0}]
        });
        assert_eq!(length_scale(&d), 0.7);
        assert_eq!(length_scale(&serde_json::json!({"bodies": [{"kind": "point_mass"}]})), 1.0);
    }

    #[test]
    fn spacing_is_numpys() {
        assert_eq!(spacing(1.0), f64::EPSILON);
        assert_eq!(spacing(-1e17), 16.0);
    }
}
