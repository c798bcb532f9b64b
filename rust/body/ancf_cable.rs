//! Planar ANCF cable (geometrically exact Euler-Bernoulli beam, absolute nodal coordinates).
//!
//! Node `j = 0..N` carries its position `r_j` and slope `r'_j` (`' = d/dx`, `x` the arc length
//! of the undeformed straight beam): body coordinates `[x_j, y_j, dx_j, dy_j]` per node,
//! `4 (N + 1)` in all. In element `k` (nodes `k`, `k + 1`, length `l`, local `s = x / l - k`)
//! `r = S_1 r_k + S_2 r'_k + S_3 r_{k+1} + S_4 r'_{k+1}`, cubic Hermite (Berzeri and Shabana's
//! interpolation, Exudyn's `ObjectANCFCable2D`).
//!
//! Strain measures as Gerstmayr and Irschik (2008) and Exudyn define them: axial strain
//! `eps = |r'| - 1`, material curvature `K = (r' x r'') / |r'|^2`; strain energy
//! `U = int EA/2 eps^2 + EI/2 K^2 dx`, generalized elastic force `-dU/de`; strain-rate damping
//! `N = EA (eps + beta eps_dot)`, `M = EI (K + beta K_dot)`.
//!
//! Membrane locking: the axial term is integrated at the three Lobatto points of each element
//! (`0, l/2, l`, weights `1/6, 2/3, 1/6`) and the bending term at two Gauss points -- Exudyn's
//! `useReducedOrderIntegration = 2`. With full Gauss integration of the axial term (Exudyn's
//! default, 5 points) a cubic element cannot bend without spurious stretching and locks: its
//! coarse-mesh error grows with the slenderness. The reduced rule keeps the element's linear
//! stiffness at full rank (only the three rigid motions are free, see the tests) and its error
//! independent of the thickness (docs/scene-format.md has the measured convergence).
//!
//! The mass matrix `rho A int S^T S dx` is constant: `M = M_s (x) I_2` with the scalar banded
//! `M_s` (`2 (N + 1)` square, half-bandwidth 3) factored once here, so `factor` does nothing and
//! `finv`/`finvt` are two banded triangular solves on the x and y components. No quadratic
//! velocity terms; gravity is a constant generalized force.

use super::ffrf_beam::{material_section, BeamSection};
use super::marker::{axis_element, axis_marker_xi};
use super::{finite_vec2, InitialState, MarkerState};
use super::inspect::Array;
use serde_json::{Map, Value};
use crate::description::{CableDesc, MarkerDesc};
use crate::error::{Error, Result};
use crate::linalg::{Banded, BandedCholesky, GAUSS4};

/// Half-bandwidth of the body coordinates' element-coupled matrices (8 coordinates an element).
pub const HB: usize = 7;
/// Half-bandwidth of the scalar mass matrix `M_s` (4 scalar shape functions an element).
const HB_S: usize = 3;

/// Axial-strain quadrature on `[0, 1]`: Lobatto 3 (`(abscissa, weight)`).
pub const AXIAL_RULE: [(f64, f64); 3] = [(0.0, 1.0 / 6.0), (0.5, 2.0 / 3.0), (1.0, 1.0 / 6.0)];
/// Bending quadrature on `[0, 1]`: Gauss 2.
pub const BENDING_RULE: [(f64, f64); 2] = {
    const A: f64 = 0.288_675_134_594_812_9; // 1 / (2 sqrt 3)
    [(0.5 - A, 0.5), (0.5 + A, 0.5)]
};

/// Which element matrix `AncfCable::visit_matrices` visits: the tangent stiffness, the strain-rate
/// damping (`beta` times the material part) or the material part alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    Tangent,
    Damping,
    Material,
}

mod element;
pub use element::{hermite, hermite_third};
use element::{cross, dot2, map, Axial, Bending};

/// Shape data of one quadrature point, the same for every element (equal element lengths).
#[derive(Debug, Clone, Copy)]
struct Point {
    /// weight times element length
    wl: f64,
    d: [f64; 4],
    dd: [f64; 4],
}

/// One ANCF cable with its constant mass matrix, its factor and the quadrature tables.
#[derive(Debug, Clone)]
pub struct AncfCable {
    pub length: f64,
    pub elements: usize,
    pub element_length: f64,
    pub section: BeamSection,
    /// Strain-rate damping coefficient beta [s].
    pub damping: f64,
    pub mass: f64,
    /// `E A`, `E I`.
    pub ea: f64,
    pub ei: f64,
    /// Scalar mass matrix `M_s = rho A int s_a s_b dx` over the scalar shape functions
    /// (position and slope of each node): `M = M_s (x) I_2`.
    pub m_s: Banded,
    /// Its Cholesky factor (the body factor is `L_s (x) I_2`, constant).
    pub l_s: BandedCholesky,
    /// `rho A int s_a dx` per scalar shape function: gravity is `load (x) g`, the first moment
    /// of mass `sum_a load_a e_a`.
    pub load: Vec<f64>,
    /// Angle of the undeformed beam in the description: marker angles are measured from it.
    pub angle0: f64,
    axial: [Point; 3],
    bending: [Point; 2],
}

/// An ANCF cable needs no per-call workspace (constant mass matrix and factor).
#[derive(Debug, Clone, Default)]
pub struct AncfCableData;

/// Shape of a marker on a cable: the element's first body coordinate (`4 k`), the Hermite
/// values and `d/dx` at the point, and the reference direction of the frame angle.
#[derive(Debug, Clone)]
pub struct CablePoint {
    pub xi: f64,
    pub first: usize,
    pub s: [f64; 4],
    pub d: [f64; 4],
    /// Reference angle (the description's beam angle) and its direction `t_ref`.
    pub phi_ref: f64,
    pub t_ref: [f64; 2],
}

impl AncfCable {
    pub fn from_desc(d: &CableDesc, item: &str) -> Result<AncfCable> {
        let (length, section) = material_section(item, d.length, d.elements, d.density, d.youngs_modulus, &d.section, d.damping)?;
        let n_el = d.elements;
        let l = length / n_el as f64;
        let rho_a = section.density * section.area;
        let ns = 2 * (n_el + 1);
        let mut m_s = Banded::zeros(ns, HB_S);
        let mut load = vec![0.0; ns];
        for el in 0..n_el {
            for &(s, w) in GAUSS4.iter() {
                let (h, _, _) = hermite(s, l);
                for a in 0..4 {
                    load[2 * el + a] += w * l * rho_a * h[a];
                    for b in 0..4 {
                        m_s.add(2 * el + a, 2 * el + b, w * l * rho_a * h[a] * h[b]);
                    }
                }
            }
        }
        let l_s = BandedCholesky::factor(&m_s).map_err(|i| Error::SingularMass { item: format!("{item}: cable mass matrix, pivot {i}") })?;
        let point = |(s, w): (f64, f64)| {
            let (_, d, dd) = hermite(s, l);
            Point { wl: w * l, d, dd }
        };
        Ok(AncfCable {
            length,
            elements: n_el,
            element_length: l,
            ea: section.youngs_modulus * section.area,
            ei: section.youngs_modulus * section.second_moment,
            mass: rho_a * length,
            section,
            damping: d.damping,
            m_s,
            l_s,
            load,
            angle0: d.angle,
            axial: AXIAL_RULE.map(point),
            bending: BENDING_RULE.map(point),
        })
    }

    /// Number of body coordinates `4 (N + 1)`.
    pub fn n_coords(&self) -> usize {
        4 * (self.elements + 1)
    }

    /// The straight undeformed beam from `position` (of the `xi = 0` end) and `angle`, in the
    /// rigid motion given by `velocity` (of the `xi = 0` end) and `angular_velocity`.
    pub fn initial_state(&self, d: &CableDesc, item: &str) -> Result<InitialState> {
        let p = finite_vec2(item, "position", d.position)?;
        let v = finite_vec2(item, "velocity", d.velocity)?;
        let (s, c) = d.angle.sin_cos();
        let w = d.angular_velocity;
        let (mut q, mut qd, mut names) = (Vec::new(), Vec::new(), Vec::new());
        for j in 0..=self.elements {
            let x = j as f64 * self.element_length;
            q.extend_from_slice(&[p[0] + x * c, p[1] + x * s, c, s]);
            qd.extend_from_slice(&[v[0] - w * x * s, v[1] + w * x * c, -w * s, w * c]);
            names.extend([format!("x{j}"), format!("y{j}"), format!("dx{j}"), format!("dy{j}")]);
        }
        Ok(InitialState { q, qd, names })
    }

    pub fn new_data(&self) -> AncfCableData {
        AncfCableData
    }

    /// Generalized forces: gravity `load (x) g` (constant), elastic and damping forces by
    /// element quadrature. No velocity terms (the mass matrix is constant). Allocation free.
    #[inline]
    pub fn mass_and_forces(&self, _bd: &mut AncfCableData, q: &[f64], qd: &[f64], gravity: Option<[f64; 2]>, f: &mut [f64]) {
        match gravity {
            Some(g) => {
                for (i, ld) in self.load.iter().enumerate() {
                    f[2 * i] = ld * g[0];
                    f[2 * i + 1] = ld * g[1];
                }
            }
            None => f.fill(0.0),
        }
        let beta = self.damping;
        for el in 0..self.elements {
            let r = 4 * el..4 * el + 8;
            let (e, ed, fe) = (&q[r.clone()], &qd[r.clone()], &mut f[r]);
            for p in &self.axial {
                let ax = Axial::at(&p.d, e);
                let mut n = self.ea * ax.eps;
                if beta > 0.0 {
                    n += beta * self.ea * dot2(ax.rx, map(&p.d, ed)) / ax.norm;
                }
                // -w N d eps/de, d eps/d r' = r'/|r'|
                let c = -p.wl * n / ax.norm;
                for a in 0..4 {
                    fe[2 * a] += c * p.d[a] * ax.rx[0];
                    fe[2 * a + 1] += c * p.d[a] * ax.rx[1];
                }
            }
            for p in &self.bending {
                let b = Bending::at(&p.d, &p.dd, e);
                let mut m = self.ei * b.k;
                if beta > 0.0 {
                    m += beta * self.ei * (dot2(b.kr, map(&p.d, ed)) + dot2(b.krr, map(&p.dd, ed)));
                }
                let c = -p.wl * m;
                for a in 0..4 {
                    fe[2 * a] += c * (p.d[a] * b.kr[0] + p.dd[a] * b.krr[0]);
                    fe[2 * a + 1] += c * (p.d[a] * b.kr[1] + p.dd[a] * b.krr[1]);
                }
            }
        }
    }

    /// Stiffness `K_t` (`visit_element_matrices`) into `k` and, with damping, the strain-rate
    /// damping matrix into `c` (body coordinates; repeated entries add up).
    pub fn tangent(&self, q: &[f64], k: &mut impl FnMut(usize, usize, f64), c: &mut impl FnMut(usize, usize, f64)) {
        self.visit_element_matrices(q, false, k);
        if self.damping > 0.0 {
            self.visit_element_matrices(q, true, c);
        }
    }

    /// `out += K_t = -dQ_el/dq = d2U/dq2` (the undamped elastic force's tangent stiffness,
    /// symmetric) at `q`, element by element: axial `EA (t t^T + eps (I - t t^T)/|r'|)`,
    /// bending `EI (grad K grad K^T + K d2K)` in `(r', r'')`, mapped through the shape
    /// functions. `out` is `4 (N + 1)` square in body coordinates with half-bandwidth >= `HB`.
    pub fn add_tangent_stiffness(&self, q: &[f64], out: &mut Banded) {
        self.add_element_matrices(q, out, false);
    }

    /// `out += C = -dQ/dqd`, the damping matrix of the strain-rate damping:
    /// `beta (EA grad eps grad eps^T + EI grad K grad K^T)` (zero without damping).
    pub fn add_damping_matrix(&self, q: &[f64], out: &mut Banded) {
        if self.damping > 0.0 {
            self.add_element_matrices(q, out, true);
        }
    }

    fn add_element_matrices(&self, q: &[f64], out: &mut Banded, damping: bool) {
        assert!(out.n == self.n_coords() && out.hb >= HB, "tangent matrix of the wrong shape");
        self.visit_element_matrices(q, damping, &mut |i, j, v| out.add(i, j, v));
    }

    /// `1/2 v^T K_m v` with the material stiffness `K_m = EA grad eps grad eps^T +
    /// EI grad K grad K^T` at `q` (the tangent stiffness without its stress terms): the strain
    /// energy of the first-order strains of the motion `v` (zero for a rigid motion, whatever
    /// the axial force).
    pub fn material_energy(&self, q: &[f64], v: &[f64]) -> f64 {
        let mut e = 0.0;
        self.visit_matrices(q, Part::Material, &mut |i, j, k| e += v[i] * k * v[j]);
        0.5 * e
    }

    /// The element stiffness (or damping) matrices at `q`, entry by entry: `put(i, j, v)` in body
    /// coordinates (repeated indices add up). Allocation free.
    pub fn visit_element_matrices(&self, q: &[f64], damping: bool, put: &mut impl FnMut(usize, usize, f64)) {
        self.visit_matrices(q, if damping { Part::Damping } else { Part::Tangent }, put)
    }

    fn visit_matrices(&self, q: &[f64], part: Part, put: &mut impl FnMut(usize, usize, f64)) {
        let damping = part != Part::Tangent;
        let scale = if part == Part::Damping { self.damping } else { 1.0 };
        for el in 0..self.elements {
            let e = &q[4 * el..4 * el + 8];
            let mut ke = [[0.0; 8]; 8];
            for p in &self.axial {
                let ax = Axial::at(&p.d, e);
                let t = [ax.rx[0] / ax.norm, ax.rx[1] / ax.norm];
                let mut hz = [[0.0; 2]; 2];
                for i in 0..2 {
                    for j in 0..2 {
                        let tt = t[i] * t[j];
                        let geo = if damping { 0.0 } else { ax.eps * ((i == j) as u8 as f64 - tt) / ax.norm };
                        hz[i][j] = scale * p.wl * self.ea * (tt + geo);
                    }
                }
                for a in 0..4 {
                    for b in 0..4 {
                        let dab = p.d[a] * p.d[b];
                        for i in 0..2 {
                            for j in 0..2 {
                                ke[2 * a + i][2 * b + j] += dab * hz[i][j];
                            }
                        }
                    }
                }
            }
            for p in &self.bending {
                let b = Bending::at(&p.d, &p.dd, e);
                let grad = [b.kr[0], b.kr[1], b.krr[0], b.krr[1]];
                let mut hz = if damping { [[0.0; 4]; 4] } else { b.hessian() };
                for i in 0..4 {
                    for j in 0..4 {
                        hz[i][j] = scale * p.wl * self.ei * (grad[i] * grad[j] + b.k * hz[i][j]);
                    }
                }
                // z = (r', r'') = sum_a (d_a, dd_a) e_a
                for a in 0..4 {
                    let za = [p.d[a], p.dd[a]];
                    for bb in 0..4 {
                        let zb = [p.d[bb], p.dd[bb]];
                        for i in 0..2 {
                            for j in 0..2 {
                                let mut v = 0.0;
                                for (u, wu) in za.iter().enumerate() {
                                    for (w, ww) in zb.iter().enumerate() {
                                        v += wu * ww * hz[2 * u + i][2 * w + j];
                                    }
                                }
                                ke[2 * a + i][2 * bb + j] += v;
                            }
                        }
                    }
                }
            }
            for i in 0..8 {
                for j in 0..8 {
                    put(4 * el + i, 4 * el + j, ke[i][j]);
                }
            }
        }
    }

    /// The mass matrix is constant: its factor was computed at build.
    #[inline]
    pub fn factor(&self, _bd: &mut AncfCableData) -> bool {
        true
    }

    /// `v <- (L_s (x) I_2)^-1 v` (forward substitution on the x and y components together).
    #[inline]
    pub fn finv(&self, _bd: &AncfCableData, v: &mut [f64]) {
        self.l_s.solve_lower_pairs(v);
    }

    /// `v <- (L_s^T (x) I_2)^-1 v`.
    #[inline]
    pub fn finvt(&self, _bd: &AncfCableData, v: &mut [f64]) {
        self.l_s.solve_upper_pairs(v);
    }

    /// `out += (M_s (x) I_2) x` (`x`, `out`: the body's segments).
    pub fn mass_times(&self, _bd: &AncfCableData, x: &[f64], out: &mut [f64]) {
        let n = self.m_s.n;
        for i in 0..n {
            let (mut a, mut b) = (0.0, 0.0);
            for j in i.saturating_sub(HB_S)..(i + HB_S + 1).min(n) {
                let m = self.m_s.get(i, j);
                a += m * x[2 * j];
                b += m * x[2 * j + 1];
            }
            out[2 * i] += a;
            out[2 * i + 1] += b;
        }
    }

    pub fn dense_block(&self, _bd: &AncfCableData, put: &mut impl FnMut(usize, usize, f64)) {
        let n = self.m_s.n;
        for i in 0..n {
            for j in i.saturating_sub(HB_S)..(i + HB_S + 1).min(n) {
                let m = self.m_s.get(i, j);
                put(2 * i, 2 * j, m);
                put(2 * i + 1, 2 * j + 1, m);
            }
        }
    }

    /// `1/2 qd^T M qd = 1/2 sum_c qd_c^T M_s qd_c`.
    pub fn kinetic_energy(&self, _bd: &AncfCableData, qd: &[f64]) -> f64 {
        let n = self.m_s.n;
        let mut e = 0.0;
        for i in 0..n {
            for j in i.saturating_sub(HB_S)..(i + HB_S + 1).min(n) {
                e += self.m_s.get(i, j) * (qd[2 * i] * qd[2 * j] + qd[2 * i + 1] * qd[2 * j + 1]);
            }
        }
        0.5 * e
    }

    /// `U = sum_el [ sum_axial w l EA/2 eps^2 + sum_bending w l EI/2 K^2 ]` (the energy whose
    /// gradient is the elastic force, same quadrature).
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        let mut u = 0.0;
        for el in 0..self.elements {
            let e = &q[4 * el..4 * el + 8];
            for p in &self.axial {
                u += 0.5 * p.wl * self.ea * Axial::at(&p.d, e).eps.powi(2);
            }
            for p in &self.bending {
                u += 0.5 * p.wl * self.ei * Bending::at(&p.d, &p.dd, e).k.powi(2);
            }
        }
        u
    }

    /// Internal forces and strains of the elastic law at the axis point `xi` (body coordinates
    /// `q`), in the section frame (x along `r'`): `[N, V, M, eps, K]` with `eps = |r'| - 1`,
    /// `N = E A eps`, the material curvature `K = (r' x r'') / |r'|^2`, `M = E I K` and
    /// `V = -dM/dx = -E I K'`, `K' = (r' x r''') / g - 2 K (r' . r'') / g`, `g = |r'|^2`
    /// (signs as `ffrf_beam::Beam::internal_forces`). Elastic parts only (no strain-rate
    /// damping); `x` is the undeformed arc length.
    pub fn internal_forces(&self, xi: f64, q: &[f64]) -> [f64; 5] {
        let ((el, s), l) = (axis_element(xi, self.elements), self.element_length);
        let (_, d, dd) = hermite(s, l);
        let ddd = hermite_third(l);
        let e = &q[4 * el..4 * el + 8];
        let (rx, rxx, rxxx) = (map(&d, e), map(&dd, e), map(&ddd, e));
        let g = dot2(rx, rx);
        let eps = g.sqrt() - 1.0;
        let k = cross(rx, rxx) / g;
        let dk = cross(rx, rxxx) / g - 2.0 * k * dot2(rx, rxx) / g;
        [self.ea * eps, -self.ei * dk, self.ei * k, eps, k]
    }

    /// `int rho A r dx = sum_a load_a e_a`.
    pub fn mass_moment(&self, q: &[f64]) -> [f64; 2] {
        let mut r = [0.0; 2];
        for (i, ld) in self.load.iter().enumerate() {
            r[0] += ld * q[2 * i];
            r[1] += ld * q[2 * i + 1];
        }
        r
    }

    /// Shape of the axis point at `xi` in [0, 1].
    pub fn point(&self, xi: f64) -> CablePoint {
        let (el, s) = axis_element(xi, self.elements);
        let (s, d, _) = hermite(s, self.element_length);
        let (sn, cs) = self.angle0.sin_cos();
        CablePoint { xi, first: 4 * el, s, d, phi_ref: self.angle0, t_ref: [cs, sn] }
    }

    /// A marker on a cable is an axis point `xi` in [0, 1] (the same rule as on an FFRF beam).
    pub fn marker_shape(&self, md: &MarkerDesc, body: &str, item: &str) -> Result<CablePoint> {
        Ok(self.point(axis_marker_xi(md, body, item)?))
    }

    /// `[x, y, u, v, psi]` of the axis point at `xi`: world position, displacement in the chord
    /// frame of the beam ends (origin `r(0)`, X axis towards `r(L)`) from the undeformed
    /// `(xi L, 0)`, and the angle of the tangent `r'` relative to the chord.
    pub fn chord_displacement(&self, xi: f64, q: &[f64]) -> [f64; 5] {
        let p = self.point(xi);
        let e = &q[p.first..p.first + 8];
        let (r, t) = (map(&p.s, e), map(&p.d, e));
        let n = 4 * self.elements;
        let r0 = [q[0], q[1]];
        let ch = [q[n] - r0[0], q[n + 1] - r0[1]];
        let len = dot2(ch, ch).sqrt();
        let c = [ch[0] / len, ch[1] / len];
        let d = [r[0] - r0[0], r[1] - r0[1]];
        [r[0], r[1], dot2(c, d) - xi * self.length, cross(c, d), cross(c, t).atan2(dot2(c, t))]
    }

    /// The axis points that draw it (`outline.rs`), `per_element` samples per element.
    pub fn outline_points(&self, per_element: usize) -> Vec<super::marker::MarkerShape> {
        super::outline::axis_samples(per_element, self.elements).map(|xi| super::marker::MarkerShape::Cable(self.point(xi))).collect()
    }

    /// World position of the axis point `xi` with its displacement from the chord of the ends
    /// (`chord_displacement`) magnified by `s`, in the chord frame.
    pub fn drawn_point(&self, xi: f64, q: &[f64], s: f64) -> [f64; 2] {
        let p = self.chord_displacement(xi, q);
        let n = 4 * self.elements;
        let ch = [q[n] - q[0], q[n + 1] - q[1]];
        let len = dot2(ch, ch).sqrt();
        let c = [ch[0] / len, ch[1] / len];
        let (x, y) = (xi * self.length + s * p[2], s * p[3]);
        [q[0] + c[0] * x - c[1] * y, q[1] + c[1] * x + c[0] * y]
    }
}

/// Axis point of a cable: `r = S e`, `v = S e_dot`, `h = 0` (linear in `e`); frame angle
/// `angle + phi_ref + atan2(t_ref x r', t_ref . r')` -- continuous, and valid while the tangent
/// stays within +-pi of the beam's direction in the description; `omega = (r' x r'_dot)/|r'|^2`,
/// `h_phi = -2 (r' . r'_dot)(r' x r'_dot)/|r'|^4`.
#[inline]
pub fn marker_state(p: &CablePoint, angle: f64, q: &[f64], qd: &[f64]) -> MarkerState {
    let (e, ed) = (&q[p.first..p.first + 8], &qd[p.first..p.first + 8]);
    let (r, v, t, td) = (map(&p.s, e), map(&p.s, ed), map(&p.d, e), map(&p.d, ed));
    let g = dot2(t, t);
    let (tw, ttd) = (cross(t, td), dot2(t, td));
    MarkerState {
        r,
        phi: angle + p.phi_ref + cross(p.t_ref, t).atan2(dot2(p.t_ref, t)),
        v,
        omega: tw / g,
        h: [0.0; 2],
        h_phi: -2.0 * ttd * tw / (g * g),
        r_theta: [0.0; 2],
        cs: [1.0, 0.0],
        dphi_dslope: [-t[1] / g, t[0] / g],
    }
}

#[inline]
pub fn add_point_jacobian(p: &CablePoint, w: [f64; 2], row: &mut [f64]) {
    for a in 0..4 {
        row[p.first + 2 * a] += w[0] * p.s[a];
        row[p.first + 2 * a + 1] += w[1] * p.s[a];
    }
}

/// `d phi / d e_a = d_a (-r'_y, r'_x) / |r'|^2`.
#[inline]
pub fn add_angle_jacobian(p: &CablePoint, ms: &MarkerState, w: f64, row: &mut [f64]) {
    for a in 0..4 {
        row[p.first + 2 * a] += w * p.d[a] * ms.dphi_dslope[0];
        row[p.first + 2 * a + 1] += w * p.d[a] * ms.dphi_dslope[1];
    }
}

/// The rigid motions of a cable's nodal field (`Body::rigid_motions`): translations along X and
/// Y and the rotation about the nodes' centre `c` (positions `k x (r - c)`, slopes `k x r'`); the
/// centripetal part `-w^2 (r - c)`, `-w^2 r'` at the angular velocity `w` that fits the nodes'
/// velocities best (least squares on the positions). `q`, `qd`, `cen`: the body's segment.
pub fn rigid_motions(q: &[f64], qd: &[f64], offset: usize, col0: usize, put: &mut impl FnMut(usize, usize, f64), cen: &mut [f64]) -> usize {
    let nodes = q.len() / 4;
    let (mut c, mut v) = ([0.0f64; 2], [0.0f64; 2]);
    for i in 0..nodes {
        for d in 0..2 {
            c[d] += q[4 * i + d] / nodes as f64;
            v[d] += qd[4 * i + d] / nodes as f64;
        }
    }
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..nodes {
        let (rx, ry) = (q[4 * i] - c[0], q[4 * i + 1] - c[1]);
        num += rx * (qd[4 * i + 1] - v[1]) - ry * (qd[4 * i] - v[0]);
        den += rx * rx + ry * ry;
    }
    let w = if den > 0.0 { num / den } else { 0.0 };
    for i in 0..nodes {
        let k = 4 * i;
        let (rx, ry, sx, sy) = (q[k] - c[0], q[k + 1] - c[1], q[k + 2], q[k + 3]);
        put(offset + k, col0, 1.0);
        put(offset + k + 1, col0 + 1, 1.0);
        for (j, val) in [(k, -ry), (k + 1, rx), (k + 2, -sy), (k + 3, sx)] {
            put(offset + j, col0 + 2, val);
        }
        for (j, val) in [(k, rx), (k + 1, ry), (k + 2, sx), (k + 3, sy)] {
            cen[j] = -w * w * val;
        }
    }
    3
}

/// Translate a cable's nodal field by `(x[0], x[1])` and turn it by `x[2]` about its nodes'
/// centre (`rigid_motions`' columns, exactly: positions `c + t + R (r - c)`, slopes `R r'`).
pub fn move_rigidly(q: &mut [f64], x: &[f64]) {
    let nodes = q.len() / 4;
    let mut c = [0.0f64; 2];
    for i in 0..nodes {
        c[0] += q[4 * i] / nodes as f64;
        c[1] += q[4 * i + 1] / nodes as f64;
    }
    let (s, co) = x[2].sin_cos();
    for i in 0..nodes {
        let k = 4 * i;
        let (rx, ry, sx, sy) = (q[k] - c[0], q[k + 1] - c[1], q[k + 2], q[k + 3]);
        q[k] = c[0] + x[0] + co * rx - s * ry;
        q[k + 1] = c[1] + x[1] + s * rx + co * ry;
        q[k + 2] = co * sx - s * sy;
        q[k + 3] = s * sx + co * sy;
    }
}

/// Inspection (`inspect.rs`).
impl AncfCable {
    pub fn shape_arrays(&self, xi: f64) -> (Array, Array) {
        let nb = self.n_coords();
        let p = self.point(xi);
        let (mut s, mut d) = (vec![0.0; 2 * nb], vec![0.0; 2 * nb]);
        for (a, c) in (0..4).flat_map(|a| [(a, 0), (a, 1)]) {
            (s[c * nb + p.first + 2 * a + c], d[c * nb + p.first + 2 * a + c]) = (p.s[a], p.d[a]);
        }
        (Array::matrix(2, nb, s), Array::matrix(2, nb, d))
    }

    pub fn matrices(&self, q0: &[f64]) -> (Array, Array) {
        let nb = self.n_coords();
        let mut m = vec![0.0; nb * nb];
        self.dense_block(&Default::default(), &mut |i, j, v| m[i * nb + j] = v);
        (Array::matrix(nb, nb, m), Array::matrix(nb, nb, self.tangent_dense(q0)))
    }

    /// `d2U/dq2` at `q` (the body's coordinates), dense row-major.
    pub fn tangent_dense(&self, q: &[f64]) -> Vec<f64> {
        let mut k = Banded::zeros(self.n_coords(), HB);
        self.add_tangent_stiffness(q, &mut k);
        k.to_dense()
    }

    pub fn info(&self, m: &mut Map<String, Value>) {
        let sec = &self.section;
        for (k, v) in [("formulation", "ancf"), ("theory", "euler-bernoulli"), ("axial_quadrature", "lobatto-3"), ("bending_quadrature", "gauss-2")] {
            m.insert(k.into(), v.into());
        }
        for (k, v) in [("length", self.length), ("element_length", self.element_length), ("area", sec.area), ("second_moment", sec.second_moment), ("density", sec.density), ("youngs_modulus", sec.youngs_modulus), ("damping", self.damping)] {
            m.insert(k.into(), v.into());
        }
        m.insert("elements".into(), self.elements.into());
        m.insert("rotary_inertia".into(), false.into());
    }
}
