//! The geometrically exact 3D beam (issue 31, docs/spatial-flexible.md): a Simo-Reissner beam of
//! two-node elements with one-point integration (`beam3/element.rs`), whose nodes carry the
//! coordinates of the spatial rigid body, `[r (3), p (4)]`, with its normalization row and its
//! regularization. A node *is* a `rigid3` body: the rigid segment of the beam around it (its
//! tributary segment `[x_i - L_e / 2, x_i + L_e / 2]` cut at the ends), with that segment's exact
//! mass, centre of mass (at the node for the interior nodes, a quarter element inwards for the
//! two end nodes) and inertia (the section's rotary inertia per length times the segment's
//! length, plus `m l^2 / 12` about the section's `y` and `z`). In a rigid motion of the beam
//! these segments carry exactly the beam's mass, first and second moments, whatever the number
//! of elements (point masses at the nodes would carry the second moment by the trapezoidal rule,
//! `1 / (2 N^2)` too large about the end). The mass blocks, the explicit
//! factor, the normalization row (eliminated in closed form by the UK kernel), gravity, markers,
//! joints, sensors and the scene format of `rigid3` serve the beam unchanged. The elements are
//! elastic force elements between consecutive node bodies (`force::spatial`,
//! `SpatialForce::Beam3`). This file holds the rules of the beam: its section data, the frame of
//! its sections and the expansion of a description into nodes and elements (`model::spatial`).

pub mod element;

use crate::description::spatial::{Beam3Desc, OrientationDesc, Rigid3Desc, Section3Desc};
use crate::error::{check_finite_item, positive, Error, Result};
use crate::linalg::rot3::{cross, dot, norm, scale, sub, M3, V3};
pub use element::ElementConsts;

/// Number of elements when the description gives none.
pub const DEFAULT_ELEMENTS: usize = 10;

/// Largest number of elements of one beam (each element is one force element, each node a body).
pub const MAX_ELEMENTS: usize = 10_000;

/// A 3D section: stiffnesses, mass and rotary inertia per length.
#[derive(Debug, Clone, Copy)]
pub struct Section3 {
    /// `[EA, kGA_y, kGA_z]`.
    pub c_n: V3,
    /// `[GJ, EI_y, EI_z]`.
    pub c_m: V3,
    pub mass_per_length: f64,
    /// Rotary inertia per length about the section axes `[x, y, z]`.
    pub rotary: V3,
}

/// Saint-Venant torsion constant of a `a x b` rectangle (`a >= b`):
/// `J = a b^3 (1/3 - 64 / pi^5 (b / a) sum_{n odd} tanh(n pi a / (2 b)) / n^5)`.
pub fn rectangle_torsion_constant(width: f64, height: f64) -> f64 {
    let (a, b) = if width >= height { (width, height) } else { (height, width) };
    let pi = std::f64::consts::PI;
    let mut s = 0.0;
    let mut n = 1.0f64;
    while n < 200.0 {
        s += (n * pi * a / (2.0 * b)).tanh() / n.powi(5);
        n += 2.0;
    }
    a * b * b * b * (1.0 / 3.0 - 64.0 / pi.powi(5) * (b / a) * s)
}

/// The section data of a beam description (every rule of the 3D sections; named errors).
pub fn section3(item: &str, d: &Beam3Desc) -> Result<Section3> {
    let material = [("density", d.density), ("youngs_modulus", d.youngs_modulus), ("shear_modulus", d.shear_modulus), ("poisson_ratio", d.poisson_ratio), ("shear_factor", d.shear_factor)];
    if let Section3Desc::Custom3 { ea, ga_y, ga_z, gj, ei_y, ei_z, mass_per_length, rotary_inertia } = d.section {
        if let Some((what, _)) = material.iter().find(|(_, v)| v.is_some()) {
            return Err(Error::invalid(item, format!("a custom3 section carries its own stiffnesses and inertia: give no {what}")));
        }
        let p = |what: &str, v: f64| positive(item, &format!("section {what}"), v);
        let rotary = [p("rotary_inertia[0]", rotary_inertia[0])?, p("rotary_inertia[1]", rotary_inertia[1])?, p("rotary_inertia[2]", rotary_inertia[2])?];
        super::rigid3::check_inertia(&format!("{item}: section rotary_inertia"), &[[rotary[0], 0.0, 0.0], [0.0, rotary[1], 0.0], [0.0, 0.0, rotary[2]]])?;
        return Ok(Section3 { c_n: [p("ea", ea)?, p("ga_y", ga_y)?, p("ga_z", ga_z)?], c_m: [p("gj", gj)?, p("ei_y", ei_y)?, p("ei_z", ei_z)?], mass_per_length: p("mass_per_length", mass_per_length)?, rotary });
    }
    let need = |what: &str, v: Option<f64>| v.ok_or_else(|| Error::invalid(item, format!("a {} section needs {what}", if matches!(d.section, Section3Desc::Circular { .. }) { "circular" } else { "rectangular" })));
    let rho = positive(item, "density", need("density", d.density)?)?;
    let e = positive(item, "youngs_modulus", need("youngs_modulus", d.youngs_modulus)?)?;
    let (g, nu) = match (d.shear_modulus, d.poisson_ratio) {
        (Some(g), None) => {
            let g = positive(item, "shear_modulus", g)?;
            (g, e / (2.0 * g) - 1.0)
        }
        (None, Some(nu)) => {
            check_finite_item(item, "poisson_ratio", &[nu])?;
            if !(nu > -1.0 && nu < 0.5) {
                return Err(Error::invalid(item, format!("poisson_ratio must lie in (-1, 0.5), got {nu}")));
            }
            (e / (2.0 * (1.0 + nu)), nu)
        }
        _ => return Err(Error::invalid(item, "give exactly one of shear_modulus and poisson_ratio")),
    };
    let (area, iy, iz, j, cowper) = match d.section {
        Section3Desc::Circular { diameter } => {
            let dd = positive(item, "section diameter", diameter)?;
            let pi = std::f64::consts::PI;
            let i = pi * dd.powi(4) / 64.0;
            (pi * dd * dd / 4.0, i, i, 2.0 * i, 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu))
        }
        Section3Desc::Rectangular { width, height } => {
            let b = positive(item, "section width", width)?;
            let h = positive(item, "section height", height)?;
            (b * h, b * h.powi(3) / 12.0, h * b.powi(3) / 12.0, rectangle_torsion_constant(b, h), 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu))
        }
        Section3Desc::Custom3 { .. } => unreachable!("handled above"),
    };
    let k = match d.shear_factor {
        Some(k) => positive(item, "shear_factor", k)?,
        None => cowper,
    };
    Ok(Section3 { c_n: [e * area, k * g * area, k * g * area], c_m: [g * j, e * iy, e * iz], mass_per_length: rho * area, rotary: [rho * (iy + iz), rho * iy, rho * iz] })
}

/// The section frame of a straight axis `t` (unit), columns `[t, y, z]`: `y` the part of the
/// hint normal to `t`; without a hint `y = e_z x t` (the section's `z` as close to world `z`
/// as the axis allows), and world `y` (its part normal to `t`) for an axis within 0.1 rad of
/// `e_z`.
pub fn section_frame(item: &str, t: &V3, y_hint: Option<&V3>) -> Result<M3> {
    let hint = match y_hint {
        Some(h) => {
            check_finite_item(item, "y_axis", h)?;
            *h
        }
        None if norm(&cross(&[0.0, 0.0, 1.0], t)) > 0.1 => cross(&[0.0, 0.0, 1.0], t),
        None => [0.0, 1.0, 0.0],
    };
    let y = sub(&hint, &scale(dot(&hint, t), t));
    let ny = norm(&y);
    if !(ny > 1e-9 * norm(&hint)) {
        return Err(Error::invalid(item, "y_axis must not be parallel to the beam's axis"));
    }
    let y = scale(1.0 / ny, &y);
    let z = cross(t, &y);
    Ok([[t[0], y[0], z[0]], [t[1], y[1], z[1]], [t[2], y[2], z[2]]])
}

/// The tributary segment of node `i` of `ne` elements of length `le`, `[x_i - L_e / 2, x_i + L_e /
/// 2]` cut at the beam's ends: its length and its centre's offset from the node along the axis.
/// The node's body is this rigid segment (module docs).
fn tributary(i: usize, ne: usize, le: f64) -> (f64, f64) {
    let lo = if i == 0 { 0.0 } else { -0.5 * le };
    let hi = if i == ne { 0.0 } else { 0.5 * le };
    (hi - lo, 0.5 * (lo + hi))
}

/// The node whose rigid segment holds the material point at arc length `s` from the start of a
/// beam of `ne` elements and `length` (the nearer node; halfway between two, the later one), and
/// the point's offset from that node along the section axis: a marker there moves with the
/// segment (the beam's mass model), exact at the nodes and off the element's own centreline by
/// the curvature times the offset squared in between.
pub fn material_point(ne: usize, length: f64, s: f64) -> Result<(usize, f64)> {
    if ne == 0 || ne > MAX_ELEMENTS || !(length.is_finite() && length > 0.0) {
        return Err(Error::argument("elements", format!("a beam of 1 to {MAX_ELEMENTS} elements and a positive length, got {ne} and {length}")));
    }
    if !(s.is_finite() && (-1e-12 * length..=length * (1.0 + 1e-12)).contains(&s)) {
        return Err(Error::argument("s", format!("the arc length must lie on the beam, 0 to {length}, got {s}")));
    }
    let le = length / ne as f64;
    let i = ((s / le + 0.5).floor().max(0.0) as usize).min(ne);
    Ok((i, s - i as f64 * le))
}

/// A beam description's node bodies (`name[i]`, kind `rigid3`, in order from `start`) and the
/// constants of its elements (element `j` between nodes `j` and `j + 1`).
pub fn expand(item: &str, d: &Beam3Desc) -> Result<(Vec<Rigid3Desc>, Vec<ElementConsts>)> {
    for (what, v) in [("start", &d.start), ("end", &d.end), ("velocity", &d.velocity), ("angular_velocity", &d.angular_velocity)] {
        check_finite_item(item, what, v)?;
    }
    let ne = d.elements.unwrap_or(DEFAULT_ELEMENTS);
    if ne == 0 || ne > MAX_ELEMENTS {
        return Err(Error::invalid(item, format!("elements must be between 1 and {MAX_ELEMENTS}, got {ne}")));
    }
    let axis = sub(&d.end, &d.start);
    let length = norm(&axis);
    if !(length > 0.0) {
        return Err(Error::invalid(item, "the beam has zero length (start and end coincide)"));
    }
    let t = scale(1.0 / length, &axis);
    let frame = section_frame(item, &t, d.y_axis.as_ref())?;
    let sec = section3(item, d)?;
    let le = length / ne as f64;
    let w = d.angular_velocity;
    let segment = |i: usize| tributary(i, ne, le);
    let nodes = (0..=ne)
        .map(|i| {
            let (l, c) = segment(i);
            let x = [0, 1, 2].map(|k| d.start[k] + axis[k] * i as f64 / ne as f64);
            let wx = cross(&w, &sub(&x, &d.start));
            let m = sec.mass_per_length * l;
            let j = [sec.rotary[0] * l, sec.rotary[1] * l + m * l * l / 12.0, sec.rotary[2] * l + m * l * l / 12.0];
            Rigid3Desc {
                name: format!("{}[{i}]", d.name),
                mass: m,
                inertia: [[j[0], 0.0, 0.0], [0.0, j[1], 0.0], [0.0, 0.0, j[2]]],
                com: [c, 0.0, 0.0],
                position: x,
                orientation: Some(OrientationDesc::Matrix(frame)),
                velocity: [0, 1, 2].map(|c| d.velocity[c] + wx[c]),
                angular_velocity: w,
            }
        })
        .collect();
    let elements = (0..ne).map(|j| ElementConsts { length: le, c_n: sec.c_n, c_m: sec.c_m, offsets: [[segment(j).1, 0.0, 0.0], [segment(j + 1).1, 0.0, 0.0]] }).collect();
    Ok((nodes, elements))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn material_points_go_to_the_segment_that_holds_them() {
        // 4 elements of 0.25: node i holds [0.25 i - 0.125, 0.25 i + 0.125] within [0, 1]
        for (s, i, off) in [(0.0, 0, 0.0), (0.1, 0, 0.1), (0.13, 1, -0.12), (0.5, 2, 0.0), (0.6, 2, 0.1), (1.0, 4, 0.0), (0.9, 4, -0.1)] {
            let (k, o) = material_point(4, 1.0, s).unwrap();
            assert_eq!(k, i, "{s}");
            assert!((o - off).abs() < 1e-12, "{s}: {o}");
        }
        for bad in [-0.01, 1.01, f64::NAN] {
            assert!(matches!(material_point(4, 1.0, bad), Err(Error::Argument { .. })), "{bad}");
        }
        assert!(material_point(0, 1.0, 0.5).is_err() && material_point(4, 0.0, 0.0).is_err());
    }

    #[test]
    fn torsion_constant_of_a_square_and_a_thin_strip() {
        // square: 0.1406 a^4 (Timoshenko and Goodier); thin strip: a b^3 / 3 (1 - 0.630 b / a)
        assert!((rectangle_torsion_constant(1.0, 1.0) / 0.140577 - 1.0).abs() < 1e-5);
        let j = rectangle_torsion_constant(0.01, 1.0);
        assert!((j / (1e-6 / 3.0 * (1.0 - 0.630_2 * 0.01)) - 1.0).abs() < 1e-4, "{j}");
    }
}
