//! The beam strains and internal forces a planar load's value may read (docs/loads.md, "Load
//! values"): `N(B, XI)`, `V(B, XI)`, `M(B, XI)`, `eps(B, XI)`, `kappa(B, XI)`, exactly the
//! output expressions of docs/outputs.md (`Body::internal_forces`: the elastic law's axial
//! force, shear, bending moment, axial strain and curvature at the axis point `XI`, in the
//! beam frame), and their rates `d:N(B, XI)`, ..., the time derivatives `grad . qd` (the
//! outputs have no rates; a strain-rate feedback needs them). Each is resolved once (the
//! element, its shape rows, the coordinates it reads) by `value_beam::BeamQuantity`, which
//! holds it as `Shape::Section`.
//!
//! On an FFRF beam (`ffrf_beam::Beam::internal_forces`) all five are linear in the element's
//! six nodal dofs (`eps = u'`, `kappa = psi'`, `V = -E I psi''`), but for the nonlinear strain's
//! `eps = u' + d^T G d / (2 l)` and its `N = E a eps`, which add a quadratic term on the
//! transverse dofs: value, gradient (`G d / l`) and a rate's change with the positions
//! (`G qd / l`) are exact. On an ANCF cable (`ancf_cable::AncfCable::internal_forces`) they are
//! functions of the point's element vector (8 numbers) through `r'`, `r''`, `r'''`: value and
//! gradient analytic; a rate's change with the positions is taken by central differences of
//! that analytic gradient (on the stack), as for the cable's `u`, `v`, `psi`.

use crate::body::ancf_cable::{hermite, hermite_third, AncfCable};
use crate::body::ffrf_beam::{element_shape, Beam};
use crate::body::marker::axis_element;
use crate::description::Strain;

/// The names, in the order of `Body::internal_forces`' `[N, V, M, eps, kappa]`.
pub const NAMES: [&str; 5] = ["N", "V", "M", "eps", "kappa"];

/// One strain or internal force of one beam point, resolved.
#[derive(Debug, Clone)]
pub enum Section {
    /// FFRF beam: `sum lin_a d_a + quad d_T^T G d_T / (2 l)`, `d` the element's nodal dofs at
    /// the global indices `idx` (`None`: removed by the reference conditions, zero), `d_T` its
    /// transverse part `(v_j, psi_j, v_j+1, psi_j+1)`.
    Ffrf { idx: [Option<usize>; 6], lin: [f64; 6], quad: f64, g: [[f64; 4]; 4], l: f64 },
    /// ANCF cable: the quantity `what` of the element vector at the global indices `idx`, with
    /// the point's first, second and third derivative shape values and the section's `E A`,
    /// `E I`.
    Cable { what: usize, idx: [usize; 8], d: [f64; 4], dd: [f64; 4], ddd: [f64; 4], ea: f64, ei: f64 },
}

/// The transverse dofs `(v_j, psi_j, v_j+1, psi_j+1)` within the element's six.
const TRANSVERSE: [usize; 4] = [1, 2, 4, 5];

impl Section {
    /// Quantity `what` (index into [`NAMES`]) at `xi` of the FFRF beam whose coordinates start
    /// at `offset`.
    pub fn ffrf(k: &Beam, offset: usize, what: usize, xi: f64) -> Section {
        let (el, s) = axis_element(xi, k.elements);
        let l = k.element_length;
        let sh = element_shape(s, l, k.phi);
        let (ea, ei) = (k.eal / l, k.section.youngs_modulus * k.section.second_moment);
        // psi'' = c (12 / l^3 (v_j - v_j+1) + 6 / l^2 (psi_j + psi_j+1)), constant in the element
        let c = 1.0 / (1.0 + k.phi);
        let (a, b) = (12.0 * c / (l * l * l), 6.0 * c / (l * l));
        let d2psi = [0.0, a, b, 0.0, -a, b];
        let scale = [ea, -ei, ei, 1.0, 1.0][what];
        let row = match what {
            0 | 3 => sh.dnu,
            1 => d2psi,
            _ => sh.dnpsi,
        };
        let nonlinear = k.strain == Strain::Nonlinear && (what == 0 || what == 3);
        let idx = std::array::from_fn(|a| k.dof_map[3 * el + a].map(|i| offset + 3 + i));
        Section::Ffrf { idx, lin: row.map(|r| scale * r), quad: if nonlinear { scale } else { 0.0 }, g: k.g_el, l }
    }

    /// Quantity `what` at `xi` of the ANCF cable whose coordinates start at `offset`.
    pub fn cable(k: &AncfCable, offset: usize, what: usize, xi: f64) -> Section {
        let (el, s) = axis_element(xi, k.elements);
        let l = k.element_length;
        let (_, d, dd) = hermite(s, l);
        let ddd = hermite_third(l);
        Section::Cable { what, idx: std::array::from_fn(|j| offset + 4 * el + j), d, dd, ddd, ea: k.ea, ei: k.ei }
    }

    /// The global coordinates it reads.
    pub fn coords(&self) -> Vec<usize> {
        match self {
            Section::Ffrf { idx, .. } => idx.iter().flatten().copied().collect(),
            Section::Cable { idx, .. } => idx.to_vec(),
        }
    }

    /// The value (`rate`: its time derivative) at `q`, `qd`.
    #[inline]
    pub fn value(&self, rate: bool, q: &[f64], qd: &[f64]) -> f64 {
        match self {
            Section::Ffrf { idx, lin, quad, g, l } => {
                let d = idx.map(|i| i.map_or(0.0, |i| q[i]));
                let gd = g_times(g, &d);
                if rate {
                    let dd = idx.map(|i| i.map_or(0.0, |i| qd[i]));
                    (0..6).map(|a| lin[a] * dd[a]).sum::<f64>() + quad / l * (0..4).map(|a| gd[a] * dd[TRANSVERSE[a]]).sum::<f64>()
                } else {
                    (0..6).map(|a| lin[a] * d[a]).sum::<f64>() + quad / (2.0 * l) * (0..4).map(|a| gd[a] * d[TRANSVERSE[a]]).sum::<f64>()
                }
            }
            Section::Cable { what, idx, d, dd, ddd, ea, ei } => {
                let (f, g) = cable(*what, &idx.map(|i| q[i]), d, dd, ddd, *ea, *ei);
                if rate {
                    g.iter().zip(idx).map(|(gi, &i)| gi * qd[i]).sum()
                } else {
                    f
                }
            }
        }
    }

    /// `row += w d(value)/dq` (`rate`: of the rate, at fixed `qd`).
    pub fn add_gradient(&self, rate: bool, q: &[f64], qd: &[f64], w: f64, row: &mut [f64]) {
        match self {
            Section::Ffrf { idx, lin, quad, g, l } => {
                // value: lin + quad G d / l on the transverse dofs; rate: quad G qd / l
                let v = if rate { qd } else { q };
                let gd = g_times(g, &idx.map(|i| i.map_or(0.0, |i| v[i])));
                for a in 0..6 {
                    let Some(i) = idx[a] else { continue };
                    let lin_a = if rate { 0.0 } else { lin[a] };
                    let quad_a = TRANSVERSE.iter().position(|&t| t == a).map_or(0.0, |t| quad / l * gd[t]);
                    row[i] += w * (lin_a + quad_a);
                }
            }
            Section::Cable { what, idx, d, dd, ddd, ea, ei } => {
                let mut x = idx.map(|i| q[i]);
                if !rate {
                    let g = cable(*what, &x, d, dd, ddd, *ea, *ei).1;
                    for (gi, &i) in g.iter().zip(idx) {
                        row[i] += w * gi;
                    }
                    return;
                }
                let xd = idx.map(|i| qd[i]);
                let rate_at = |x: &[f64; 8]| -> f64 { cable(*what, x, d, dd, ddd, *ea, *ei).1.iter().zip(&xd).map(|(g, v)| g * v).sum() };
                rate_position_gradient(&mut x, idx, rate_at, w, row);
            }
        }
    }
}

/// `row[idx_j] += w d(rate)/dx_j` by central differences of `rate_at` (a rate `grad . qd` whose
/// analytic gradient is known: its change with the positions `x`, read at `idx`).
pub(super) fn rate_position_gradient<const N: usize>(x: &mut [f64; N], idx: &[usize; N], rate_at: impl Fn(&[f64; N]) -> f64, w: f64, row: &mut [f64]) {
    for j in 0..N {
        let (xj, h) = (x[j], 1e-6 * (1.0 + x[j].abs()));
        x[j] = xj + h;
        let fp = rate_at(x);
        x[j] = xj - h;
        let fm = rate_at(x);
        x[j] = xj;
        row[idx[j]] += w * (fp - fm) / (2.0 * h);
    }
}

/// `G d_T` of the element dofs `d`.
#[inline]
fn g_times(g: &[[f64; 4]; 4], d: &[f64; 6]) -> [f64; 4] {
    std::array::from_fn(|a| (0..4).map(|b| g[a][b] * d[TRANSVERSE[b]]).sum())
}

/// Quantity `what` of an ANCF element `e` (`[r_1, r_1', r_2, r_2']`, 8 numbers) at a point with
/// the shape derivatives `d`, `dd`, `ddd`, and its gradient in `e`: with `r' = sum d_a e_a`
/// (and `r''`, `r'''`), `g = |r'|^2`, `eps = sqrt(g) - 1`, `K = (r' x r'') / g`,
/// `K' = (r' x r''') / g - 2 K (r' . r'') / g`; `N = E A eps`, `M = E I K`, `V = -E I K'`
/// (`ancf_cable::AncfCable::internal_forces`). The partials in `r'`, `r''`, `r'''` (`pa`, `pb`,
/// `pc`) chain to `e_a` through `d_a`, `dd_a`, `ddd_a`.
fn cable(what: usize, e: &[f64; 8], d: &[f64; 4], dd: &[f64; 4], ddd: &[f64; 4], ea: f64, ei: f64) -> (f64, [f64; 8]) {
    let map = |s: &[f64; 4]| -> [f64; 2] { std::array::from_fn(|k| (0..4).map(|a| s[a] * e[2 * a + k]).sum()) };
    let (rx, rxx, rxxx) = (map(d), map(dd), map(ddd));
    let g = rx[0] * rx[0] + rx[1] * rx[1];
    let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
    // d(a x b)/da = (b_y, -b_x), d(a x b)/db = (-a_y, a_x)
    let k = cross(rx, rxx) / g;
    let dk_drx = [rxx[1] / g - 2.0 * k * rx[0] / g, -rxx[0] / g - 2.0 * k * rx[1] / g];
    let dk_drxx = [-rx[1] / g, rx[0] / g];
    let zero = [0.0; 2];
    let (f, pa, pb, pc) = match what {
        0 | 3 => {
            let s = if what == 0 { ea } else { 1.0 };
            let n = g.sqrt();
            (s * (n - 1.0), [s * rx[0] / n, s * rx[1] / n], zero, zero)
        }
        2 | 4 => {
            let s = if what == 2 { ei } else { 1.0 };
            (s * k, dk_drx.map(|x| s * x), dk_drxx.map(|x| s * x), zero)
        }
        _ => {
            let (c3, p) = (cross(rx, rxxx), rx[0] * rxx[0] + rx[1] * rxx[1]);
            let dk = c3 / g - 2.0 * k * p / g;
            let pa: [f64; 2] = std::array::from_fn(|j| {
                let dc3 = [rxxx[1], -rxxx[0]][j];
                dc3 / g - 2.0 * c3 * rx[j] / (g * g) - 2.0 / g * (p * dk_drx[j] + k * rxx[j]) + 4.0 * k * p * rx[j] / (g * g)
            });
            let pb: [f64; 2] = std::array::from_fn(|j| -2.0 / g * (p * dk_drxx[j] + k * rx[j]));
            let pc = [-rx[1] / g, rx[0] / g];
            (-ei * dk, pa.map(|x| -ei * x), pb.map(|x| -ei * x), pc.map(|x| -ei * x))
        }
    };
    (f, std::array::from_fn(|j| d[j / 2] * pa[j % 2] + dd[j / 2] * pb[j % 2] + ddd[j / 2] * pc[j % 2]))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::dynamics;
    use crate::force::tests::{moving, stiffness_rows_against_differences};

    /// FFRF beams: `a` linear Euler-Bernoulli, `b` nonlinear Timoshenko (clamped frame), `d`
    /// nonlinear Euler-Bernoulli, `e` linear Timoshenko (clamped); `c` an ANCF cable; 3
    /// elements each.
    const BEAMS: [&str; 5] = [
        r#"{"kind": "beam", "name": "a", "length": 1.2, "elements": 3, "theory": "euler-bernoulli", "strain": "linear", "density": 7800, "youngs_modulus": 2e11, "section": {"rectangular": {"width": 0.02, "height": 0.01}}, "angle": 0.4}"#,
        r#"{"kind": "beam", "name": "b", "length": 0.8, "elements": 3, "poisson_ratio": 0.3, "shear_factor": 0.9, "frame": "clamped", "density": 7800, "youngs_modulus": 2e11, "section": {"circular": {"diameter": 0.01}}, "position": [0.3, 0.1]}"#,
        r#"{"kind": "cable", "name": "c", "length": 1.0, "elements": 3, "density": 7800, "youngs_modulus": 2e11, "section": {"circular": {"diameter": 0.01}}, "angle": -0.3}"#,
        r#"{"kind": "beam", "name": "d", "length": 0.9, "elements": 3, "theory": "euler-bernoulli", "strain": "nonlinear", "density": 2700, "youngs_modulus": 7e10, "section": {"rectangular": {"width": 0.03, "height": 0.02}}, "angle": -0.7}"#,
        r#"{"kind": "beam", "name": "e", "length": 0.5, "elements": 3, "poisson_ratio": 0.3, "shear_factor": 0.85, "strain": "linear", "frame": "clamped", "density": 7800, "youngs_modulus": 2e11, "section": {"rectangular": {"width": 0.04, "height": 0.05}}, "angle": 1.1}"#,
    ];

    /// The first `beams` of [`BEAMS`] and one point mass per beam and quantity `quantities`,
    /// loaded by `fx` = that quantity of that beam at one of the places `xis` (in turn); the
    /// cases `(label, beam, what, xi, rate)`.
    pub(crate) fn scene(beams: usize, quantities: &[&str], xis: &[f64]) -> (String, Vec<(String, usize, String, f64, bool)>) {
        let mut bodies: Vec<String> = BEAMS[..beams].iter().map(|b| b.to_string()).collect();
        let (mut forces, mut cases) = (Vec::new(), Vec::new());
        for (bi, beam) in ["a", "b", "c", "d", "e"][..beams].iter().enumerate() {
            for (k, qty) in quantities.iter().enumerate() {
                let xi = xis[(k + bi) % xis.len()];
                let name = format!("m{bi}_{k}");
                bodies.push(format!(r#"{{"kind": "point_mass", "name": "{name}", "mass": 1.0}}"#));
                let what = qty.trim_start_matches("d:");
                forces.push(format!(r#"{{"kind": "point_load", "point": {{"body": "{name}"}}, "fx": "{qty}({beam}, {xi})", "fy": 0}}"#));
                cases.push((format!("{qty}({beam}, {xi})"), bi, what.to_string(), xi, qty.starts_with("d:")));
            }
        }
        (format!(r#"{{"bodies": [{}], "forces": [{}]}}"#, bodies.join(", "), forces.join(", ")), cases)
    }

    /// `q + h qd` and `q - h qd`: the states a rate's central difference reads.
    pub(crate) fn along(q: &[f64], qd: &[f64], h: f64) -> (Vec<f64>, Vec<f64>) {
        (q.iter().zip(qd).map(|(x, v)| x + h * v).collect(), q.iter().zip(qd).map(|(x, v)| x - h * v).collect())
    }

    const QUANTITIES: [&str; 10] = ["N", "V", "M", "eps", "kappa", "d:N", "d:V", "d:M", "d:eps", "d:kappa"];
    /// Where they are read (in turn): inside elements, at nodes (the right element's value) and
    /// at the ends.
    const XI: [f64; 11] = [0.3, 0.65, 0.9, 0.5, 0.85, 0.15, 0.0, 1.0, 0.4, 0.72, 2.0 / 3.0];

    #[test]
    fn section_quantities_are_the_outputs() {
        // the load's input against `Body::internal_forces` (the outputs N, V, M, eps, kappa) at
        // three deformed, moving states of each beam kind (FFRF linear and nonlinear strain,
        // Euler-Bernoulli and Timoshenko, ANCF); a rate against central differences of
        // internal_forces along qd
        let (text, cases) = scene(5, &QUANTITIES, &XI);
        let (model, mut data, q0, _) = moving(&text, 0.0, 0.0);
        for seed in 0..3 {
            let q: Vec<f64> = q0.iter().enumerate().map(|(i, x)| x + 0.004 * (1.7 * i as f64 + seed as f64).sin()).collect();
            let qd: Vec<f64> = (0..model.n).map(|i| 0.8 * (0.9 * i as f64 - 2.0 * seed as f64).cos()).collect();
            dynamics::mass_and_forces(&model, &mut data, 0.0, &q, &qd);
            let h = 1e-6;
            let (qp, qm) = along(&q, &qd, h);
            for (k, (label, bi, name, xi, rate)) in cases.iter().enumerate() {
                let what = NAMES.iter().position(|n| n == name).unwrap();
                let (beam, m) = (&model.bodies[*bi], &model.bodies[5 + k]);
                let at = |q: &[f64]| beam.internal_forces(*xi, q).unwrap()[what];
                let (expected, tol) = if *rate {
                    // the difference quotient's rounding: eps |f| / h
                    ((at(&qp) - at(&qm)) / (2.0 * h), 1e-7 * (at(&q).abs() / h).max(1.0) + 1e-7 * ((at(&qp) - at(&qm)) / (2.0 * h)).abs())
                } else {
                    (at(&q), 1e-11 * at(&q).abs())
                };
                let got = data.force[m.offset];
                assert!((got - expected).abs() <= tol, "state {seed}, {label}: {got} vs {expected}");
                assert!(expected.abs() > 1e-5, "state {seed}, {label}: {expected} is no test");
            }
        }
    }

    #[test]
    fn section_quantity_stiffness_matches_differences() {
        // the point masses' rows of K = -dQ/dq against central differences (the beams' own
        // rows hold their inertia forces, which K leaves out)
        let (text, cases) = scene(5, &QUANTITIES, &XI);
        let k = stiffness_rows_against_differences(&text, 0.002, 0.5, |m, i| i >= m.bodies[5].offset);
        // a value's row is its gradient: never empty; a rate's is empty where the quantity is
        // linear in q (FFRF but the nonlinear eps, N: beams b and d), full on the cable (c)
        let model = crate::model::Model::from_json(&text).unwrap();
        let n = model.n;
        for (j, (label, bi, name, _, rate)) in cases.iter().enumerate() {
            let i = model.bodies[5 + j].offset;
            let loaded = k[i * n..(i + 1) * n].iter().filter(|x| x.abs() > 1e-9).count();
            let linear = *rate && (*bi != 2) && !((*bi == 1 || *bi == 3) && (name == "N" || name == "eps"));
            assert!((loaded == 0) == linear, "{label}: {loaded} entries");
        }
    }

    #[test]
    fn cable_section_gradient_matches_differences() {
        let (d, dd) = ([-1.1, 0.1, 1.1, 0.4], [-3.0, -1.2, 3.0, -0.8]);
        let ddd = [12.0, 6.0, -12.0, 6.0];
        let e0 = [0.1, -0.2, 0.9, 0.3, 0.5, 0.1, 1.1, -0.4];
        let h = 1e-6;
        for what in 0..5 {
            let (ea, ei) = if what == 0 || what == 1 || what == 2 { (3.0, 0.7) } else { (1.0, 1.0) };
            let g = cable(what, &e0, &d, &dd, &ddd, ea, ei).1;
            for j in 0..8 {
                let (mut ep, mut em) = (e0, e0);
                ep[j] += h;
                em[j] -= h;
                let fd = (cable(what, &ep, &d, &dd, &ddd, ea, ei).0 - cable(what, &em, &d, &dd, &ddd, ea, ei).0) / (2.0 * h);
                assert!((g[j] - fd).abs() < 1e-7 * (1.0 + fd.abs()), "{} {j}: {} vs {fd}", NAMES[what], g[j]);
            }
            assert!(g.iter().any(|x| x.abs() > 0.1), "{}: {g:?} is no test", NAMES[what]);
        }
    }
}
