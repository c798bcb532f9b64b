//! FFRF beam body: N equal Timoshenko (Davis et al.) or Euler-Bernoulli elements on a floating
//! frame. Everything that does not depend on the state -- mass, static moments, `S_bar`,
//! `S_tilde`, `M_ff`, `K_ff` and the Cholesky factor of `M_ff` -- is integrated here once, by
//! Gauss quadrature of the element shape functions (paper eqs. 6-9, 23, 26-33), into the
//! floating-frame invariants (`ffrf::Ffrf`); the equations of motion on them are the shared
//! floating-frame core's (`ffrf.rs`). The beam adds its element-level elastic terms: the
//! second-order axial strain (nonlinear strain), stiffness-proportional damping, the axial and
//! internal forces, and the shape of its axis points.

use super::ffrf::{Ffrf, FfrfData, PointShape};
use super::marker::{axis_element, axis_marker_xi};
use super::InitialState;
use super::inspect::{spelled, Array};
use serde_json::{Map, Value};
use crate::description::{BeamDesc, BeamTheory, MarkerDesc, ReferenceConditions, SectionDesc, Strain};
use crate::error::{non_negative, positive, Error, Result};
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

/// One FFRF beam body with its constant inertia shape integrals (body frame, `u0 = (x, 0)`:
/// `s_u0 = int rho a x S_u dx`, `s_ju0 = int rho a x S_v dx (+ int rho I N_psi dx)`).
#[derive(Debug, Clone)]
pub struct Beam {
    /// The floating-frame invariants (`beam.m_ff`, `beam.n_f`, ... read them through `Deref`).
    pub frame: Ffrf,
    pub length: f64,
    pub elements: usize,
    pub element_length: f64,
    pub section: BeamSection,
    pub phi: f64,
    pub reference: ReferenceConditions,
    /// Stiffness-proportional damping coefficient beta [s].
    pub damping: f64,
    /// Nodal dof index (3 (N+1)) -> elastic coordinate index, `None` where removed by the
    /// reference conditions.
    pub dof_map: Vec<Option<usize>>,
    /// Elastic coordinate index -> nodal dof index.
    pub dof_of_qf: Vec<usize>,
    pub strain: Strain,
    /// `E a l`: the axial stiffness of one element times its length.
    pub eal: f64,
    /// Element geometric matrix `G = int_0^l N_v'^T N_v' dx` on the transverse element dofs
    /// `(v_j, psi_j, v_j+1, psi_j+1)` (the same for every element): the element's averaged
    /// axial strain is `(u_j+1 - u_j)/l + d^T G d / (2 l)`.
    pub g_el: [[f64; 4]; 4],
}

/// Element dofs `(v_j, psi_j, v_j+1, psi_j+1)` within `(u_j, v_j, psi_j, u_j+1, v_j+1, psi_j+1)`.
const TRANSVERSE: [usize; 4] = [1, 2, 4, 5];

/// Area and second moment `(a, I)` of a section (`I` about the axis normal to the plane).
pub fn section_properties(item: &str, section: &SectionDesc) -> Result<(f64, f64)> {
    let (area, second_moment) = match *section {
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
    positive(item, "section area", area)?;
    positive(item, "section second_moment", second_moment)?;
    Ok((area, second_moment))
}

/// Nodal dofs `(u, v, psi)` per node removed by the reference conditions of the floating frame
/// (a beam's frame is defined on its end nodes: `mean-axis` is refused).
fn removed_dofs(elements: usize, frame: ReferenceConditions, item: &str) -> Result<[usize; 3]> {
    match frame {
        // u_1 = v_1 = 0, v_{N+1} = 0
        ReferenceConditions::PinnedPinned => Ok([0, 1, 3 * elements + 1]),
        // u_1 = v_1 = psi_1 = 0
        ReferenceConditions::Clamped => Ok([0, 1, 2]),
        ReferenceConditions::MeanAxis => Err(Error::invalid(item, format!(
            "an FFRF beam's frame is '{}' or '{}' (reference conditions on its end nodes); '{}' is the frame of modal bodies from FE data (ukflex.fe)",
            ReferenceConditions::PinnedPinned.word(), ReferenceConditions::Clamped.word(), ReferenceConditions::MeanAxis.word()))),
    }
}

/// Number of elastic coordinates: the `3 (N + 1)` nodal dofs less the three removed by the
/// reference conditions.
pub fn elastic_dofs(elements: usize, frame: ReferenceConditions, item: &str) -> Result<usize> {
    Ok(3 * (elements + 1) - removed_dofs(elements, frame, item)?.len())
}

/// Largest number of elements of one beam.
pub const MAX_ELEMENTS: usize = 4096;

/// Validate what an FFRF beam reads from its description -- length, element count, material,
/// section, shear data (checked whenever given, required for Timoshenko) and damping -- and
/// derive its section. Returns `(length, section)`.
pub fn beam_section(d: &BeamDesc, item: &str) -> Result<(f64, BeamSection)> {
    let (length, mut section) = material_section(item, d.length, d.elements, d.density, d.youngs_modulus, &d.section, d.damping)?;
    // shear data: validated whenever given, required by Timoshenko
    let g = match (d.shear_modulus, d.poisson_ratio) {
        (Some(_), Some(_)) => return Err(Error::invalid(item, "give either poisson_ratio or shear_modulus, not both")),
        (Some(g), None) => Some(positive(item, "shear_modulus", g)?),
        (None, Some(nu)) => {
            if !nu.is_finite() || nu <= -1.0 || nu >= 0.5 {
                return Err(Error::invalid(item, format!("poisson_ratio must be in (-1, 0.5), got {nu}")));
            }
            Some(section.youngs_modulus / (2.0 * (1.0 + nu)))
        }
        (None, None) => None,
    };
    let k = d.shear_factor.map(|k| positive(item, "shear_factor", k)).transpose()?;
    if d.theory == BeamTheory::Timoshenko {
        let g = g.ok_or_else(|| Error::invalid(item, "a Timoshenko beam needs poisson_ratio or shear_modulus"))?;
        let k = k.ok_or_else(|| Error::invalid(item, "a Timoshenko beam needs shear_factor"))?;
        section.shear_stiffness = k * g;
        derived_scales(item, length / d.elements as f64, section.density, section.youngs_modulus, section.area, section.second_moment, section.shear_stiffness)?;
    }
    section.rotary_inertia = d.rotary_inertia.unwrap_or(d.theory == BeamTheory::Timoshenko);
    section.theory = d.theory;
    Ok((length, section))
}

/// What every beam kind reads from its description (length, element count, density, modulus,
/// section, damping), validated; an Euler-Bernoulli section without rotary inertia.
pub fn material_section(item: &str, length: f64, elements: usize, density: f64, e: f64, section: &SectionDesc, damping: f64) -> Result<(f64, BeamSection)> {
    let length = positive(item, "length", length)?;
    if elements == 0 || elements > MAX_ELEMENTS {
        return Err(Error::invalid(item, format!("elements must be in 1..={MAX_ELEMENTS}, got {elements}")));
    }
    let density = positive(item, "density", density)?;
    let e = positive(item, "youngs_modulus", e)?;
    let (area, second_moment) = section_properties(item, section)?;
    non_negative(item, "damping", damping)?;
    derived_scales(item, length / elements as f64, density, e, area, second_moment, 0.0)?;
    Ok((length, BeamSection { area, second_moment, density, youngs_modulus: e, shear_stiffness: 0.0, rotary_inertia: false, theory: BeamTheory::EulerBernoulli }))
}

/// Highest elastic circular frequency a beam may have [rad/s]: beyond it no integrator can
/// resolve its modes or step over them in double precision (and the element matrices' products
/// approach overflow); such a scene is a unit mistake (E in N/mm^2 with lengths in m, ...).
pub const MAX_ELEMENT_OMEGA: f64 = 1e60;

/// Check the products the element matrices are made of (mass and stiffness per length, element
/// stiffnesses) for overflow/underflow, and the fastest element mode against
/// [`MAX_ELEMENT_OMEGA`]. Each property alone may be in range while a product is not
/// (area 1e-300 with I 1e300, density 1e308 times an area).
fn derived_scales(item: &str, le: f64, density: f64, e: f64, area: f64, second_moment: f64, shear_stiffness: f64) -> Result<()> {
    let products = [
        ("density x area (mass per length)", density * area),
        ("density x second_moment (rotary inertia per length)", density * second_moment),
        ("youngs_modulus x area (axial stiffness)", e * area),
        ("youngs_modulus x second_moment (bending stiffness)", e * second_moment),
        ("element mass", density * area * le),
        ("element axial stiffness EA/l", e * area / le),
        ("element bending stiffness 12 EI/l^3", 12.0 * e * second_moment / (le * le * le)),
    ];
    for (what, v) in products {
        if !(v.is_finite() && v > 0.0 && v.is_normal()) {
            return Err(Error::invalid(item, format!("{what} = {v:e} is out of double-precision range; check the units of density, youngs_modulus and the section")));
        }
    }
    // fastest element mode, order of magnitude: axial/shear waves over one element and its
    // bending mode (free-free element: omega^2 ~ 500 EI / (rho A l^4))
    let c2 = (e.max(shear_stiffness)) / density;
    let omega2 = 12.0 * c2 / (le * le) + 500.0 * e * second_moment / (density * area * le.powi(4));
    if !(omega2.is_finite() && omega2.sqrt() <= MAX_ELEMENT_OMEGA) {
        return Err(Error::invalid(item, format!(
            "elastic frequencies of about {:e} rad/s (youngs_modulus / density = {:e} m^2/s^2 over elements of {le:e} m) exceed {MAX_ELEMENT_OMEGA:e} rad/s, beyond any integrator; check the units",
            omega2.sqrt(), e / density)));
    }
    Ok(())
}

impl Beam {
    pub fn from_desc(d: &BeamDesc, item: &str) -> Result<Beam> {
        let (length, section) = beam_section(d, item)?;
        let (density, area, second_moment, rotary_inertia) = (section.density, section.area, section.second_moment, section.rotary_inertia);
        let n_el = d.elements;
        let l = length / n_el as f64;
        let n_nodal = 3 * (n_el + 1);
        let removed = removed_dofs(n_el, d.frame, item)?;
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
        let mut s_u0 = vec![0.0; n_f];
        let mut s_ju0 = vec![0.0; n_f];
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
                    s_u0[i] += wl * rho_a * x * sh.nu[a];
                    s_ju0[i] += wl * (rho_a * x * sh.nv[a] + if rotary_inertia { rho_i * sh.npsi[a] } else { 0.0 });
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
        let frame = Ffrf { n_f, mass, s_t, j0, s_bar, s_u0, s_ju0, s_tilde, m_ff_tr, m_ff, k_ff, l_ff };
        let mut g_el = [[0.0; 4]; 4];
        for &(s, w) in GAUSS4.iter() {
            let sh = element_shape(s, l, phi);
            for (a, &ia) in TRANSVERSE.iter().enumerate() {
                for (b, &ib) in TRANSVERSE.iter().enumerate() {
                    g_el[a][b] += w * l * sh.dnv[ia] * sh.dnv[ib];
                }
            }
        }
        Ok(Beam {
            frame,
            length,
            elements: n_el,
            element_length: l,
            section,
            phi,
            reference: d.frame,
            damping: d.damping,
            dof_map,
            dof_of_qf,
            strain: d.strain,
            eal: section.youngs_modulus * section.area * l,
            g_el,
        })
    }

    /// Shape of the axis point at `xi` in [0, 1]: `u_f = S q_f`, `psi = N_psi q_f`.
    pub fn point_shape(&self, xi: f64) -> PointShape {
        let (el, s) = axis_element(xi, self.elements);
        let sh = element_shape(s, self.element_length, self.phi);
        let mut entries = Vec::with_capacity(6);
        for a in 0..6 {
            if let Some(i) = self.dof_map[3 * el + a] {
                if sh.nu[a] != 0.0 || sh.nv[a] != 0.0 || sh.npsi[a] != 0.0 {
                    entries.push((i, sh.nu[a], sh.nv[a], sh.npsi[a]));
                }
            }
        }
        PointShape { x: xi * self.length, y: 0.0, entries }
    }

    /// The axis points that draw it (`outline.rs`), `per_element` samples per element.
    pub fn outline_points(&self, per_element: usize) -> Vec<super::marker::MarkerShape> {
        super::outline::axis_samples(per_element, self.elements).map(|xi| super::marker::MarkerShape::Beam(self.point_shape(xi))).collect()
    }
}

/// Workspace of a beam: the floating frame's (`FfrfData`) and the elements' axial forces.
#[derive(Debug, Clone)]
pub struct BeamData {
    pub frame: FfrfData,
    /// Axial force of each element at the last `mass_and_forces` (`E a` times the element's
    /// averaged axial strain; tension positive).
    pub axial_force: Vec<f64>,
}

impl Beam {
    /// Initial guess: frame state from the description, elastic coordinates (default zero).
    pub fn initial_state(&self, d: &BeamDesc, item: &str) -> Result<InitialState> {
        self.frame.initial_state(item, d.position, d.velocity, d.angle, d.angular_velocity, &d.elastic, &d.elastic_rates)
    }

    pub fn new_data(&self) -> BeamData {
        BeamData { frame: self.frame.new_data(), axial_force: vec![0.0; self.elements] }
    }

    /// Nodal dofs `(u_j, v_j, psi_j, u_j+1, v_j+1, psi_j+1)` of element `el` from `q_f`
    /// (zero where the reference conditions removed them).
    #[inline]
    fn element_dofs(&self, el: usize, qf: &[f64]) -> [f64; 6] {
        let mut d = [0.0; 6];
        for (a, v) in d.iter_mut().enumerate() {
            if let Some(i) = self.dof_map[3 * el + a] {
                *v = qf[i];
            }
        }
        d
    }

    /// Element axial strain parts: `(eps_lin, gamma, G d)` with `eps_lin = (u_j+1 - u_j)/l`,
    /// `gamma = d^T G d / (2 l)` (the averaged `v'^2 / 2`).
    #[inline]
    fn element_strain(&self, d: &[f64; 6]) -> (f64, f64, [f64; 4]) {
        let l = self.element_length;
        let mut gd = [0.0; 4];
        let mut gamma = 0.0;
        for a in 0..4 {
            for b in 0..4 {
                gd[a] += self.g_el[a][b] * d[TRANSVERSE[b]];
            }
            gamma += d[TRANSVERSE[a]] * gd[a];
        }
        ((d[3] - d[0]) / l, gamma / (2.0 * l), gd)
    }

    /// Axial forces of the elements into `axial_force` and, with nonlinear strain, the
    /// forces of the second-order axial strain into `ff` (the elastic part of `Q_f`): with the
    /// element's averaged strain `eps = eps_lin + gamma`, `U = E a l eps^2 / 2` adds to the
    /// linear `E a l eps_lin^2 / 2` (in `K_ff`) the force
    /// `-E a l [gamma B + eps G d / l]`, `B = (e_u,j+1 - e_u,j) / l`.
    ///
    /// Damping acts on the strain rates the model defines: with nonlinear strain the axial
    /// part of `-beta K_ff qd_f` (the rate of `eps_lin`) becomes the rate of `eps`, i.e. it
    /// adds `-beta E a l [(b . d_dot) b - (B . d_dot) B]` with `b = B + G d / l` (otherwise the
    /// foreshortening that keeps `eps` at zero while the beam bends would be damped as if it
    /// strained the beam).
    #[inline]
    fn axial_forces(&self, axial_force: &mut [f64], qf: &[f64], qfd: &[f64], ff: &mut [f64]) {
        let l = self.element_length;
        let ea = self.eal / l;
        let nonlinear = self.strain == Strain::Nonlinear;
        for el in 0..self.elements {
            let d = self.element_dofs(el, qf);
            let (eps_lin, gamma, gd) = self.element_strain(&d);
            if !nonlinear {
                axial_force[el] = ea * eps_lin;
                continue;
            }
            let n = ea * (eps_lin + gamma);
            axial_force[el] = n;
            // the damping's axial force: beta E a (b . d_dot - B . d_dot) on b, plus
            // beta E a (b . d_dot) (b - B) (see the doc above), as coefficients of B and G d / l
            let (mut nd_b, mut nd_g) = (0.0, 0.0);
            if self.damping > 0.0 {
                let dd = self.element_dofs(el, qfd);
                let bdot = (dd[3] - dd[0]) / l;
                let gdot: f64 = (0..4).map(|a| gd[a] * dd[TRANSVERSE[a]]).sum::<f64>() / l;
                // (b.dd) b - (B.dd) B = gdot B + (bdot + gdot) G d / l
                nd_b = self.damping * ea * gdot;
                nd_g = self.damping * ea * (bdot + gdot);
            }
            let map = |a: usize| self.dof_map[3 * el + a];
            if let Some(i) = map(0) {
                ff[i] += ea * gamma + nd_b;
            }
            if let Some(i) = map(3) {
                ff[i] -= ea * gamma + nd_b;
            }
            for (a, &ia) in TRANSVERSE.iter().enumerate() {
                if let Some(i) = map(ia) {
                    ff[i] -= (n + nd_g) * gd[a];
                }
            }
        }
    }

    /// Stiffness `K_t` of the elastic forces (`elastic_tangent`) into `k` and the damping
    /// `beta K_t` into `c` (body coordinates: the elastic block).
    pub fn tangent(&self, q: &[f64], k: &mut impl FnMut(usize, usize, f64), c: &mut impl FnMut(usize, usize, f64)) {
        let qf = &q[3..];
        self.elastic_tangent(qf, &mut |i, j, v| k(3 + i, 3 + j, v));
        if self.damping > 0.0 {
            self.elastic_tangent(qf, &mut |i, j, v| c(3 + i, 3 + j, self.damping * v));
        }
    }

    /// Tangent stiffness of the elastic forces, `K_t = -dQ_el/dq_f` (n_f x n_f): `K_ff` plus,
    /// with nonlinear strain, `E a l (b b^T - B B^T) + N G` per element (`b = B + G d / l`).
    /// `put(i, j, v)` receives entries in elastic-coordinate indices (repeated indices add up).
    pub fn elastic_tangent(&self, qf: &[f64], put: &mut impl FnMut(usize, usize, f64)) {
        self.frame.k_ff.visit(put);
        if self.strain != Strain::Nonlinear {
            return;
        }
        let l = self.element_length;
        for el in 0..self.elements {
            let d = self.element_dofs(el, qf);
            let (eps_lin, gamma, gd) = self.element_strain(&d);
            let n = self.eal / l * (eps_lin + gamma);
            let mut bl = [0.0; 6]; // B
            bl[0] = -1.0 / l;
            bl[3] = 1.0 / l;
            let mut b = bl; // B + G d / l
            for (a, &ia) in TRANSVERSE.iter().enumerate() {
                b[ia] += gd[a] / l;
            }
            let mut k = [[0.0; 6]; 6];
            for p in 0..6 {
                for r in 0..6 {
                    k[p][r] = self.eal * (b[p] * b[r] - bl[p] * bl[r]);
                }
            }
            for (a, &ia) in TRANSVERSE.iter().enumerate() {
                for (c, &ic) in TRANSVERSE.iter().enumerate() {
                    k[ia][ic] += n * self.g_el[a][c];
                }
            }
            for p in 0..6 {
                let Some(i) = self.dof_map[3 * el + p] else { continue };
                for r in 0..6 {
                    let Some(j) = self.dof_map[3 * el + r] else { continue };
                    if k[p][r] != 0.0 {
                        put(i, j, k[p][r]);
                    }
                }
            }
        }
    }

    /// Mass blocks and generalized forces: the floating-frame core's (`Ffrf::mass_and_forces`)
    /// with the beam's elastic terms: the elements' axial forces (with nonlinear strain, the
    /// forces of the second-order axial strain, `axial_forces`) and the damping
    /// `-beta K_ff qd_f` (eq. 38).
    #[inline]
    pub fn mass_and_forces(&self, bd: &mut BeamData, q: &[f64], qd: &[f64], gravity: Option<[f64; 2]>, f: &mut [f64]) {
        let axial_force = &mut bd.axial_force;
        self.frame.mass_and_forces(&mut bd.frame, q, qd, gravity, f, |qf, qfd, ff| {
            self.axial_forces(axial_force, qf, qfd, ff);
            if self.damping > 0.0 {
                self.frame.k_ff.mul_add(-self.damping, qfd, ff);
            }
        });
    }

    #[inline]
    pub fn factor(&self, bd: &mut BeamData) -> bool {
        self.frame.factor(&mut bd.frame)
    }

    #[inline]
    pub fn finv(&self, bd: &BeamData, v: &mut [f64]) {
        self.frame.finv(&bd.frame, v)
    }

    #[inline]
    pub fn finvt(&self, bd: &BeamData, v: &mut [f64]) {
        self.frame.finvt(&bd.frame, v)
    }

    pub fn mass_times(&self, bd: &BeamData, x: &[f64], out: &mut [f64]) {
        self.frame.mass_times(&bd.frame, x, out)
    }

    pub fn dense_block(&self, bd: &BeamData, put: &mut impl FnMut(usize, usize, f64)) {
        self.frame.dense_block(&bd.frame, put)
    }

    pub fn kinetic_energy(&self, bd: &BeamData, qd: &[f64]) -> f64 {
        self.frame.kinetic_energy(&bd.frame, qd)
    }

    /// `1/2 q_f^T K_ff q_f`, plus `E a l (eps^2 - eps_lin^2) / 2` per element with nonlinear
    /// strain.
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        let qf = &q[3..];
        let mut u = self.frame.linear_strain_energy(qf);
        if self.strain == Strain::Nonlinear {
            for el in 0..self.elements {
                let (eps_lin, gamma, _) = self.element_strain(&self.element_dofs(el, qf));
                let eps = eps_lin + gamma;
                u += 0.5 * self.eal * (eps * eps - eps_lin * eps_lin);
            }
        }
        u
    }

    /// `1/2 v_f^T K_ff v_f`: the material strain energy of the motion `v` (body segments).
    pub fn material_energy(&self, _q: &[f64], v: &[f64]) -> f64 {
        self.frame.linear_strain_energy(&v[3..])
    }

    /// Internal forces and strains of the elastic law at the axis point `xi` (body
    /// coordinates `q`), in the beam frame: `[N, V, M, eps, kappa]` -- the force and moment the
    /// part beyond `xi` exerts on the part before it (tension, shear along +y of the frame,
    /// counterclockwise moment positive). `eps` is the axial strain the model uses (linear:
    /// `u'`; nonlinear: the element's averaged `u' + v'^2/2`), `N = E a eps`,
    /// `kappa = psi'`, `M = E I kappa`, and `V = -dM/dx = -E I psi''` (constant in an
    /// element; for the Davis element it equals `k G a (v' - psi)`, the element being exact
    /// in statics). Elastic parts only (no strain-rate damping).
    pub fn internal_forces(&self, xi: f64, q: &[f64]) -> [f64; 5] {
        let (el, s) = axis_element(xi, self.elements);
        let l = self.element_length;
        let sh = element_shape(s, l, self.phi);
        let d = self.element_dofs(el, &q[3..]);
        let (eps_lin, gamma, _) = self.element_strain(&d);
        let eps = if self.strain == Strain::Nonlinear { eps_lin + gamma } else { eps_lin };
        let kappa: f64 = (0..6).map(|a| sh.dnpsi[a] * d[a]).sum();
        // psi'' of the element (the s-derivative of dnpsi over l): linear in s, so constant
        let c = 1.0 / (1.0 + self.phi);
        let d2psi = c * (12.0 / (l * l * l) * (d[1] - d[4]) + 6.0 / (l * l) * (d[2] + d[5]));
        let (ea, ei) = (self.eal / l, self.section.youngs_modulus * self.section.second_moment);
        [ea * eps, -ei * d2psi, ei * kappa, eps, kappa]
    }

    /// `int rho r dV = m R + A Sigma`.
    pub fn mass_moment(&self, q: &[f64]) -> [f64; 2] {
        self.frame.mass_moment(q)
    }

    /// A marker on a beam is an axis point `xi` in [0, 1].
    pub fn marker_shape(&self, md: &MarkerDesc, body: &str, item: &str) -> Result<PointShape> {
        Ok(self.point_shape(axis_marker_xi(md, body, item)?))
    }
}

impl std::ops::Deref for Beam {
    type Target = Ffrf;

    /// A beam is a floating-frame body with element-built invariants.
    fn deref(&self) -> &Ffrf {
        &self.frame
    }
}

/// Inspection (`inspect.rs`).
impl Beam {
    pub fn shape_arrays(&self, xi: f64) -> (Array, Array) {
        let nf = self.n_f;
        let (mut s, mut npsi) = (vec![0.0; 2 * nf], vec![0.0; nf]);
        for &(i, su, sv, sp) in &self.point_shape(xi).entries {
            (s[i], s[nf + i], npsi[i]) = (su, sv, sp);
        }
        (Array::matrix(2, nf, s), Array::Vector(npsi))
    }

    pub fn matrices(&self) -> (Array, Array) {
        let nf = self.n_f;
        (Array::matrix(nf, nf, self.m_ff.to_dense()), Array::matrix(nf, nf, self.k_ff.to_dense()))
    }

    pub fn info(&self, m: &mut Map<String, Value>) {
        let sec = &self.section;
        m.insert("formulation".into(), "ffrf".into());
        for (k, v) in [("length", self.length), ("element_length", self.element_length), ("area", sec.area), ("second_moment", sec.second_moment), ("density", sec.density), ("youngs_modulus", sec.youngs_modulus), ("shear_stiffness", sec.shear_stiffness), ("damping", self.damping), ("shear_parameter", self.phi)] {
            m.insert(k.into(), v.into());
        }
        m.insert("elements".into(), self.elements.into());
        m.insert("rotary_inertia".into(), sec.rotary_inertia.into());
        m.insert("theory".into(), spelled(&sec.theory));
        m.insert("frame".into(), spelled(&self.reference));
        m.insert("strain".into(), spelled(&self.strain));
    }
}
