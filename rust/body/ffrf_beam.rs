//! FFRF beam body: N equal Timoshenko (Davis et al.) or Euler-Bernoulli elements on a floating
//! frame. Everything that does not depend on the state -- mass, static moments, `S_bar`,
//! `S_tilde`, `M_ff`, `K_ff` and the Cholesky factor of `M_ff` -- is integrated here once, by
//! Gauss quadrature of the element shape functions (paper eqs. 6-9, 23, 26-33).

use crate::description::{BeamDesc, BeamTheory, ReferenceConditions, SectionDesc};
use crate::error::{Error, Result};
use crate::linalg::{Banded, BandedCholesky, GAUSS4};

/// Half-bandwidth of element-coupled matrices in nodal order (6 nodal dofs per element).
const HB: usize = 5;

/// Values of the element shape functions at local abscissa `s` in [0, 1] (paper eqs. 6-7).
/// Local dofs: `[u_j, v_j, psi_j, u_{j+1}, v_{j+1}, psi_{j+1}]`.
#[derive(Debug, Clone, Copy, Default)]
pub struct ElementShape {
    pub nu: [f64; 6],
    pub nv: [f64; 6],
    pub npsi: [f64; 6],
    /// d/dx of the above
    pub dnu: [f64; 6],
    pub dnv: [f64; 6],
    pub dnpsi: [f64; 6],
}

/// Shape functions of the Davis et al. Timoshenko element with shear parameter
/// `phi = 12 E I / (k G a l^2)`; `phi = 0` gives the Euler-Bernoulli (cubic Hermite) element,
/// for which `N_psi = dN_v/dx`.
pub fn element_shape(s: f64, l: f64, phi: f64) -> ElementShape {
    let c = 1.0 / (1.0 + phi);
    let (s2, s3) = (s * s, s * s * s);
    let nu = [1.0 - s, 0.0, 0.0, s, 0.0, 0.0];
    let nv = [
        0.0,
        c * (2.0 * s3 - 3.0 * s2 - phi * s + 1.0 + phi),
        c * l * (s3 - (2.0 + 0.5 * phi) * s2 + (1.0 + 0.5 * phi) * s),
        0.0,
        c * (-2.0 * s3 + 3.0 * s2 + phi * s),
        c * l * (s3 - (1.0 - 0.5 * phi) * s2 - 0.5 * phi * s),
    ];
    let npsi = [
        0.0,
        c * 6.0 / l * (s2 - s),
        c * (3.0 * s2 - (4.0 + phi) * s + 1.0 + phi),
        0.0,
        -c * 6.0 / l * (s2 - s),
        c * (3.0 * s2 - (2.0 - phi) * s),
    ];
    // d/dx = (1/l) d/ds
    let dnu = [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0];
    let dnv = [
        0.0,
        c / l * (6.0 * s2 - 6.0 * s - phi),
        c * (3.0 * s2 - 2.0 * (2.0 + 0.5 * phi) * s + 1.0 + 0.5 * phi),
        0.0,
        c / l * (-6.0 * s2 + 6.0 * s + phi),
        c * (3.0 * s2 - 2.0 * (1.0 - 0.5 * phi) * s - 0.5 * phi),
    ];
    let dnpsi = [
        0.0,
        c * 6.0 / (l * l) * (2.0 * s - 1.0),
        c / l * (6.0 * s - (4.0 + phi)),
        0.0,
        -c * 6.0 / (l * l) * (2.0 * s - 1.0),
        c / l * (6.0 * s - (2.0 - phi)),
    ];
    ElementShape { nu, nv, npsi, dnu, dnv, dnpsi }
}

/// Section and material data of one beam, derived once from the description.
#[derive(Debug, Clone, Copy)]
pub struct BeamSection {
    pub area: f64,
    pub second_moment: f64,
    pub density: f64,
    pub youngs_modulus: f64,
    /// `k G` (shear factor times shear modulus); unused for Euler-Bernoulli.
    pub shear_stiffness: f64,
    pub rotary_inertia: bool,
    pub theory: BeamTheory,
}

impl BeamSection {
    /// Shear parameter `phi = 12 E I / (k G a l^2)` for element length `l` (0 for E-B).
    pub fn phi(&self, l: f64) -> f64 {
        match self.theory {
            BeamTheory::EulerBernoulli => 0.0,
            BeamTheory::Timoshenko => {
                12.0 * self.youngs_modulus * self.second_moment / (self.shear_stiffness * self.area * l * l)
            }
        }
    }
}

/// 6x6 element mass and stiffness matrices (row-major) by 4-point Gauss quadrature of the
/// kinetic and strain energies (paper eqs. 8-9). Returns (translational mass, rotary mass,
/// stiffness): the translational part alone enters `m_theta_theta` (eq. 30).
pub fn element_matrices(sec: &BeamSection, l: f64) -> ([f64; 36], [f64; 36], [f64; 36]) {
    let phi = sec.phi(l);
    let (rho_a, rho_i) = (sec.density * sec.area, sec.density * sec.second_moment);
    let (ea, ei, kga) = (sec.youngs_modulus * sec.area, sec.youngs_modulus * sec.second_moment, sec.shear_stiffness * sec.area);
    let mut mt = [0.0; 36];
    let mut mr = [0.0; 36];
    let mut k = [0.0; 36];
    for &(s, w) in GAUSS4.iter() {
        let sh = element_shape(s, l, phi);
        let wl = w * l;
        let mut gamma = [0.0; 6]; // shear strain psi - dv/dx per dof
        for a in 0..6 {
            gamma[a] = sh.npsi[a] - sh.dnv[a];
        }
        for a in 0..6 {
            for b in 0..6 {
                mt[6 * a + b] += wl * rho_a * (sh.nu[a] * sh.nu[b] + sh.nv[a] * sh.nv[b]);
                if sec.rotary_inertia {
                    mr[6 * a + b] += wl * rho_i * sh.npsi[a] * sh.npsi[b];
                }
                let mut kab = ea * sh.dnu[a] * sh.dnu[b] + ei * sh.dnpsi[a] * sh.dnpsi[b];
                if sec.theory == BeamTheory::Timoshenko {
                    kab += kga * gamma[a] * gamma[b];
                }
                k[6 * a + b] += wl * kab;
            }
        }
    }
    (mt, mr, k)
}

/// One FFRF beam body with its constant inertia shape integrals (body frame, `u0 = (x, 0)`).
#[derive(Debug, Clone)]
pub struct Beam {
    pub length: f64,
    pub elements: usize,
    pub element_length: f64,
    pub section: BeamSection,
    pub phi: f64,
    pub reference: ReferenceConditions,
    /// Stiffness-proportional damping coefficient beta [s].
    pub damping: f64,
    /// Number of elastic coordinates.
    pub n_f: usize,
    /// Nodal dof index (3 (N+1)) -> elastic coordinate index, `None` where removed by the
    /// reference conditions.
    pub dof_map: Vec<Option<usize>>,
    /// Elastic coordinate index -> nodal dof index.
    pub dof_of_qf: Vec<usize>,
    pub mass: f64,
    /// `int rho a u0 dx` = static moment of the undeformed beam.
    pub s_t: [f64; 2],
    /// `int rho a |u0|^2 dx` (+ `rho I length` with rotary inertia): eq. 28.
    pub j0: f64,
    /// `S_bar = int rho a S dx`, rows (x, y), eq. 23.
    pub s_bar: [Vec<f64>; 2],
    /// `int rho a S^T u0 dx = int rho a x S_u dx` (enters m_theta_theta, eq. 29).
    pub i_rf: Vec<f64>,
    /// `int rho a u0^T I~ S dx = int rho a x S_v dx` (+ `int rho I N_psi dx`): eq. 31.
    pub i_thf: Vec<f64>,
    /// `S_tilde = int rho a S^T I~ S dx` (antisymmetric), eq. 32.
    pub s_tilde: Banded,
    /// Translational part of `M_ff` (enters `m_theta_theta` and the quadratic velocity forces).
    pub m_ff_tr: Banded,
    /// Full `M_ff` (with rotary inertia).
    pub m_ff: Banded,
    pub k_ff: Banded,
    /// Cholesky factor of `M_ff` (constant: the elastic block of the body factor).
    pub l_ff: BandedCholesky,
}

/// Sparse shape of one axis point: `(q_f index, S_u, S_v, N_psi)` for each nonzero column.
#[derive(Debug, Clone, Default)]
pub struct PointShape {
    pub x: f64,
    pub entries: Vec<(usize, f64, f64, f64)>,
}

fn positive(item: &str, what: &str, v: f64) -> Result<f64> {
    if !v.is_finite() || v <= 0.0 {
        return Err(Error::invalid(item, format!("{what} must be positive and finite, got {v}")));
    }
    Ok(v)
}

impl Beam {
    pub fn new(d: &BeamDesc) -> Result<Beam> {
        let item = format!("beam '{}'", d.name);
        let item = item.as_str();
        let length = positive(item, "length", d.length)?;
        if d.elements == 0 || d.elements > 4096 {
            return Err(Error::invalid(item, format!("elements must be in 1..=4096, got {}", d.elements)));
        }
        let density = positive(item, "density", d.density)?;
        let e = positive(item, "youngs_modulus", d.youngs_modulus)?;
        let (area, second_moment) = match d.section {
            SectionDesc::Circular { diameter } => {
                let dd = positive(item, "section diameter", diameter)?;
                (std::f64::consts::PI * dd * dd / 4.0, std::f64::consts::PI * dd.powi(4) / 64.0)
            }
            SectionDesc::Rectangular { width, height } => {
                let b = positive(item, "section width", width)?;
                let h = positive(item, "section height", height)?;
                (b * h, b * h * h * h / 12.0)
            }
            SectionDesc::Custom { area, second_moment } => {
                (positive(item, "section area", area)?, positive(item, "section second_moment", second_moment)?)
            }
        };
        let shear_stiffness = match d.theory {
            BeamTheory::EulerBernoulli => 0.0,
            BeamTheory::Timoshenko => {
                let g = match (d.shear_modulus, d.poisson_ratio) {
                    (Some(g), _) => positive(item, "shear_modulus", g)?,
                    (None, Some(nu)) => {
                        if !nu.is_finite() || nu <= -1.0 || nu >= 0.5 {
                            return Err(Error::invalid(item, format!("poisson_ratio must be in (-1, 0.5), got {nu}")));
                        }
                        e / (2.0 * (1.0 + nu))
                    }
                    (None, None) => {
                        return Err(Error::invalid(item, "a Timoshenko beam needs poisson_ratio or shear_modulus"))
                    }
                };
                let k = d.shear_factor.ok_or_else(|| Error::invalid(item, "a Timoshenko beam needs shear_factor"))?;
                positive(item, "shear_factor", k)? * g
            }
        };
        if !d.damping.is_finite() || d.damping < 0.0 {
            return Err(Error::invalid(item, format!("damping must be >= 0 and finite, got {}", d.damping)));
        }
        let rotary_inertia = d.rotary_inertia.unwrap_or(d.theory == BeamTheory::Timoshenko);
        let section = BeamSection {
            area,
            second_moment,
            density,
            youngs_modulus: e,
            shear_stiffness,
            rotary_inertia,
            theory: d.theory,
        };
        let n_el = d.elements;
        let l = length / n_el as f64;
        let n_nodal = 3 * (n_el + 1);
        let removed: [usize; 3] = match d.frame {
            ReferenceConditions::PinnedPinned => [0, 1, 3 * n_el + 1],
            ReferenceConditions::Clamped => [0, 1, 2],
        };
        let mut dof_map = vec![None; n_nodal];
        let mut dof_of_qf = Vec::new();
        for (k, slot) in dof_map.iter_mut().enumerate() {
            if !removed.contains(&k) {
                *slot = Some(dof_of_qf.len());
                dof_of_qf.push(k);
            }
        }
        let n_f = dof_of_qf.len();
        let (mt_e, mr_e, k_e) = element_matrices(&section, l);
        let rho_a = density * area;
        let rho_i = density * second_moment;
        let phi = section.phi(l);
        let mut s_bar = [vec![0.0; n_f], vec![0.0; n_f]];
        let mut i_rf = vec![0.0; n_f];
        let mut i_thf = vec![0.0; n_f];
        let mut s_tilde = Banded::zeros(n_f, HB);
        let mut m_ff_tr = Banded::zeros(n_f, HB);
        let mut m_ff = Banded::zeros(n_f, HB);
        let mut k_ff = Banded::zeros(n_f, HB);
        let (mut mass, mut s_t, mut j0) = (0.0, [0.0; 2], 0.0);
        for el in 0..n_el {
            let map = |a: usize| dof_map[3 * el + a];
            for a in 0..6 {
                let Some(i) = map(a) else { continue };
                for b in 0..6 {
                    let Some(j) = map(b) else { continue };
                    m_ff_tr.add(i, j, mt_e[6 * a + b]);
                    m_ff.add(i, j, mt_e[6 * a + b] + mr_e[6 * a + b]);
                    k_ff.add(i, j, k_e[6 * a + b]);
                }
            }
            for &(s, w) in GAUSS4.iter() {
                let sh = element_shape(s, l, phi);
                let x = (el as f64 + s) * l;
                let wl = w * l;
                mass += wl * rho_a;
                s_t[0] += wl * rho_a * x;
                j0 += wl * (rho_a * x * x + if rotary_inertia { rho_i } else { 0.0 });
                for a in 0..6 {
                    let Some(i) = map(a) else { continue };
                    s_bar[0][i] += wl * rho_a * sh.nu[a];
                    s_bar[1][i] += wl * rho_a * sh.nv[a];
                    i_rf[i] += wl * rho_a * x * sh.nu[a];
                    i_thf[i] += wl * (rho_a * x * sh.nv[a] + if rotary_inertia { rho_i * sh.npsi[a] } else { 0.0 });
                    for b in 0..6 {
                        let Some(j) = map(b) else { continue };
                        // (S^T I~ S)_ij = S_u,i S_v,j - S_v,i S_u,j
                        s_tilde.add(i, j, wl * rho_a * (sh.nu[a] * sh.nv[b] - sh.nv[a] * sh.nu[b]));
                    }
                }
            }
        }
        let l_ff = BandedCholesky::factor(&m_ff)
            .map_err(|i| Error::SingularMass { item: format!("{item}: elastic mass block, pivot {i}") })?;
        Ok(Beam {
            length,
            elements: n_el,
            element_length: l,
            section,
            phi,
            reference: d.frame,
            damping: d.damping,
            n_f,
            dof_map,
            dof_of_qf,
            mass,
            s_t,
            j0,
            s_bar,
            i_rf,
            i_thf,
            s_tilde,
            m_ff_tr,
            m_ff,
            k_ff,
            l_ff,
        })
    }

    /// Shape of the axis point at `xi` in [0, 1]: `u_f = S q_f`, `psi = N_psi q_f`.
    pub fn point_shape(&self, xi: f64) -> PointShape {
        let n = self.elements;
        let t = xi * n as f64;
        let el = (t.floor() as usize).min(n - 1);
        let s = t - el as f64;
        let sh = element_shape(s, self.element_length, self.phi);
        let mut entries = Vec::with_capacity(6);
        for a in 0..6 {
            if let Some(i) = self.dof_map[3 * el + a] {
                if sh.nu[a] != 0.0 || sh.nv[a] != 0.0 || sh.npsi[a] != 0.0 {
                    entries.push((i, sh.nu[a], sh.nv[a], sh.npsi[a]));
                }
            }
        }
        PointShape { x: xi * self.length, entries }
    }
}
