//! The scene's length scale and the rules that refuse a scene double precision cannot resolve:
//! at build (`check_lengths`, called by `Model::from_json`) and at the corrected initial state
//! (`check_resolution`: positions and angles far from the origin; with the mass conditioning of
//! `correct::check_state`). One home for these rules: the Python `System` calls them through the
//! bindings (`_core.System.length_scale`, `_core.System.check_state`) and keeps no copy.

use serde_json::Value;

use super::Model;
use crate::error::{fmt_g, Error, Result};

/// Positions must be resolved by double precision to this fraction of the scene's length scale
/// (and angles to this many radians).
pub const RESOLUTION: f64 = 1e-9;
/// Largest length scale [m]: beyond it squares of positions and velocities (energies, the
/// centripetal terms) overflow double precision; it is a unit mistake.
pub const MAX_LENGTH_SCALE: f64 = 1e150;

/// The scene's length scale [m]: the largest body dimension -- beam lengths, centre-of-mass and
/// marker offsets on bodies (not on the ground: those place the mechanism), a flexible3 body's
/// radius of gyration about its frame origin, and distance lengths; 1 m for a scene without any. A spring's rest length is a force parameter, not a
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
        // a flexible3 body: its radius of gyration about the frame origin, sqrt(tr P_00 / m)
        if let (Some(p00), Some(m)) = (b.get("second_moment").and_then(|v| v.get(0)), b.get("mass").and_then(Value::as_f64)) {
            let tr: f64 = (0..3).filter_map(|i| p00.get(i).and_then(|r| r.get(i)).and_then(Value::as_f64)).sum();
            sizes.push((tr / m).sqrt());
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
pub fn is_rotation(name: &str) -> bool {
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
