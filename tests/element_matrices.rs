//! Element mass and stiffness from quadrature (rust/body/ffrf_beam.rs) against the closed
//! forms of the paper's Appendix A (eqs. 75 and the listed mass entries, read through the OCR;
//! they agree with Przemieniecki's consistent Timoshenko matrices).

use ukflex::body::ffrf_beam::{element_matrices, BeamSection};
use ukflex::description::BeamTheory;

fn section(theory: BeamTheory, rotary: bool, shear_stiffness: f64) -> BeamSection {
    let d: f64 = 0.00635;
    BeamSection {
        area: std::f64::consts::PI * d * d / 4.0,
        second_moment: std::f64::consts::PI * d.powi(4) / 64.0,
        density: 7834.56,
        youngs_modulus: 2.06843e11,
        shear_stiffness,
        rotary_inertia: rotary,
        theory,
    }
}

/// Appendix A mass matrix (1-based entries as printed), symmetric.
fn appendix_mass(s: &BeamSection, l: f64, phi: f64) -> [[f64; 6]; 6] {
    let (ra, ri) = (s.density * s.area, if s.rotary_inertia { s.density * s.second_moment } else { 0.0 });
    let p2 = (1.0 + phi) * (1.0 + phi);
    let mut m = [[0.0; 6]; 6];
    let mut set = |i: usize, j: usize, v: f64| {
        m[i - 1][j - 1] = v;
        m[j - 1][i - 1] = v;
    };
    set(1, 1, ra * l / 3.0);
    set(1, 4, ra * l / 6.0);
    set(4, 4, ra * l / 3.0);
    set(2, 2, ra * l * (70.0 * phi * phi + 147.0 * phi + 78.0) / (210.0 * p2) + 36.0 * ri / (30.0 * p2 * l));
    set(2, 3, ra * l * l * (35.0 * phi * phi + 77.0 * phi + 44.0) / (840.0 * p2) - ri * (15.0 * phi - 3.0) / (30.0 * p2));
    set(2, 5, ra * l * (35.0 * phi * phi + 63.0 * phi + 27.0) / (210.0 * p2) - 36.0 * ri / (30.0 * p2 * l));
    set(2, 6, -ra * l * l * (35.0 * phi * phi + 63.0 * phi + 26.0) / (840.0 * p2) - ri * (15.0 * phi - 3.0) / (30.0 * p2));
    set(3, 3, ra * l.powi(3) * (7.0 * phi * phi + 14.0 * phi + 8.0) / (840.0 * p2) + ri * (10.0 * phi * phi + 5.0 * phi + 4.0) * l / (30.0 * p2));
    set(3, 5, ra * l * l * (35.0 * phi * phi + 63.0 * phi + 26.0) / (840.0 * p2) + ri * (15.0 * phi - 3.0) / (30.0 * p2));
    set(3, 6, -ra * l.powi(3) * (7.0 * phi * phi + 14.0 * phi + 6.0) / (840.0 * p2) + ri * (5.0 * phi * phi - 5.0 * phi - 1.0) * l / (30.0 * p2));
    set(5, 5, ra * l * (70.0 * phi * phi + 147.0 * phi + 78.0) / (210.0 * p2) + 36.0 * ri / (30.0 * p2 * l));
    set(5, 6, -ra * l * l * (35.0 * phi * phi + 77.0 * phi + 44.0) / (840.0 * p2) + ri * (15.0 * phi - 3.0) / (30.0 * p2));
    set(6, 6, ra * l.powi(3) * (7.0 * phi * phi + 14.0 * phi + 8.0) / (840.0 * p2) + ri * (10.0 * phi * phi + 5.0 * phi + 4.0) * l / (30.0 * p2));
    m
}

/// Eq. 75.
fn appendix_stiffness(s: &BeamSection, l: f64, phi: f64) -> [[f64; 6]; 6] {
    let (e, a, i) = (s.youngs_modulus, s.area, s.second_moment);
    let f = e / (1.0 + phi);
    let ax = a * (1.0 + phi) / l;
    let (k1, k2) = (12.0 * i / l.powi(3), 6.0 * i / (l * l));
    let (k3, k4) = ((4.0 + phi) * i / l, (2.0 - phi) * i / l);
    let k = [
        [ax, 0.0, 0.0, -ax, 0.0, 0.0],
        [0.0, k1, k2, 0.0, -k1, k2],
        [0.0, k2, k3, 0.0, -k2, k4],
        [-ax, 0.0, 0.0, ax, 0.0, 0.0],
        [0.0, -k1, -k2, 0.0, k1, -k2],
        [0.0, k2, k4, 0.0, -k2, k3],
    ];
    k.map(|row| row.map(|v| f * v))
}

fn compare(theory: BeamTheory, rotary: bool, kg: f64, l: f64) {
    let s = section(theory, rotary, kg);
    let phi = s.phi(l);
    let (mt, mr, k) = element_matrices(&s, l);
    let (ma, ka) = (appendix_mass(&s, l, phi), appendix_stiffness(&s, l, phi));
    let mscale = ma.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let kscale = ka.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..6 {
        for j in 0..6 {
            let m = mt[6 * i + j] + mr[6 * i + j];
            // entry-wise relative error, guarded by the matrix scale for entries that are ~0
            let em = (m - ma[i][j]).abs() / (ma[i][j].abs() + 1e-12 * mscale);
            let ek = (k[6 * i + j] - ka[i][j]).abs() / (ka[i][j].abs() + 1e-12 * kscale);
            assert!(em < 1e-11, "{theory:?} phi={phi:.3e} mass ({},{}) quadrature {m:e} vs appendix {:e}", i + 1, j + 1, ma[i][j]);
            assert!(ek < 1e-11, "{theory:?} phi={phi:.3e} stiffness ({},{}) quadrature {:e} vs appendix {:e}", i + 1, j + 1, k[6 * i + j], ka[i][j]);
        }
    }
}

#[test]
fn timoshenko_paper_coupler_matches_appendix_a() {
    let g = 2.06843e11 / (2.0 * 1.285);
    compare(BeamTheory::Timoshenko, true, 0.8 * g, 0.3048);
}

#[test]
fn timoshenko_short_element_large_phi_matches_appendix_a() {
    // a short element makes phi O(1), so every phi term of the closed forms is exercised
    let g = 2.06843e11 / (2.0 * 1.285);
    let s = section(BeamTheory::Timoshenko, true, 0.8 * g);
    let l = 0.01;
    assert!(s.phi(l) > 0.5);
    compare(BeamTheory::Timoshenko, true, 0.8 * g, l);
}

#[test]
fn euler_bernoulli_is_phi_zero_without_rotary_inertia() {
    compare(BeamTheory::EulerBernoulli, false, 0.0, 0.3048);
}
