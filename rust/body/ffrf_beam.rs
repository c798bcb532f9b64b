//! FFRF beam body: N equal Timoshenko (Davis et al.) or Euler-Bernoulli elements on a floating
//! frame. Everything that does not depend on the state -- mass, static moments, `S_bar`,
//! `S_tilde`, `M_ff`, `K_ff` and the Cholesky factor of `M_ff` -- is integrated here once, by
//! Gauss quadrature of the element shape functions (paper eqs. 6-9, 23, 26-33).

use super::{add_frame_gravity, add_frame_point_jacobian, axis_marker_xi, finite_vec2, frame_mass_block, frame_mass_moment, frame_point_state, InitialState, MarkerState};
use crate::description::{BeamDesc, BeamTheory, MarkerDesc, ReferenceConditions, SectionDesc, Strain};
use crate::error::{check_finite_item, non_negative, positive, Error, Result};
use crate::linalg::{cholesky3, solve_lower3, solve_upper3, Banded, BandedCholesky, GAUSS4};

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

/// Sparse shape of one axis point: `(q_f index, S_u, S_v, N_psi)` for each nonzero column.
#[derive(Debug, Clone, Default)]
pub struct PointShape {
    pub x: f64,
    /// Undeformed body-frame `y` (0 on a beam axis; interface points of flexible bodies).
    pub y: f64,
    pub entries: Vec<(usize, f64, f64, f64)>,
}

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

/// Nodal dofs `(u, v, psi)` per node removed by the reference conditions of the floating frame.
fn removed_dofs(elements: usize, frame: ReferenceConditions) -> [usize; 3] {
    match frame {
        // u_1 = v_1 = 0, v_{N+1} = 0
        ReferenceConditions::PinnedPinned => [0, 1, 3 * elements + 1],
        // u_1 = v_1 = psi_1 = 0
        ReferenceConditions::Clamped => [0, 1, 2],
    }
}

/// Number of elastic coordinates: the `3 (N + 1)` nodal dofs less the three removed by the
/// reference conditions.
pub fn elastic_dofs(elements: usize, frame: ReferenceConditions) -> usize {
    3 * (elements + 1) - removed_dofs(elements, frame).len()
}

/// Largest number of elements of one beam.
pub const MAX_ELEMENTS: usize = 4096;

/// Validate what every beam formulation reads from its description -- length, element count,
/// material, section, shear data (checked whenever given, required for Timoshenko) and damping
/// -- and derive its section. Returns `(length, section)`.
pub fn beam_section(d: &BeamDesc, item: &str) -> Result<(f64, BeamSection)> {
    let length = positive(item, "length", d.length)?;
    if d.elements == 0 || d.elements > MAX_ELEMENTS {
        return Err(Error::invalid(item, format!("elements must be in 1..={MAX_ELEMENTS}, got {}", d.elements)));
    }
    let density = positive(item, "density", d.density)?;
    let e = positive(item, "youngs_modulus", d.youngs_modulus)?;
    let (area, second_moment) = section_properties(item, &d.section)?;
    // shear data: validated whenever given, required by Timoshenko
    let g = match (d.shear_modulus, d.poisson_ratio) {
        (Some(_), Some(_)) => return Err(Error::invalid(item, "give either poisson_ratio or shear_modulus, not both")),
        (Some(g), None) => Some(positive(item, "shear_modulus", g)?),
        (None, Some(nu)) => {
            if !nu.is_finite() || nu <= -1.0 || nu >= 0.5 {
                return Err(Error::invalid(item, format!("poisson_ratio must be in (-1, 0.5), got {nu}")));
            }
            Some(e / (2.0 * (1.0 + nu)))
        }
        (None, None) => None,
    };
    let k = d.shear_factor.map(|k| positive(item, "shear_factor", k)).transpose()?;
    let shear_stiffness = match d.theory {
        BeamTheory::EulerBernoulli => 0.0,
        BeamTheory::Timoshenko => {
            let g = g.ok_or_else(|| Error::invalid(item, "a Timoshenko beam needs poisson_ratio or shear_modulus"))?;
            let k = k.ok_or_else(|| Error::invalid(item, "a Timoshenko beam needs shear_factor"))?;
            k * g
        }
    };
    non_negative(item, "damping", d.damping)?;
    derived_scales(item, length / d.elements as f64, density, e, area, second_moment, shear_stiffness)?;
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
    Ok((length, section))
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
        let removed = removed_dofs(n_el, d.frame);
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
            strain: d.strain,
            eal: section.youngs_modulus * section.area * l,
            g_el,
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
        PointShape { x: xi * self.length, y: 0.0, entries }
    }
}

/// Workspace of a beam: per-call mass blocks and the factor `F_b = [[L_s, X], [0, L_ff]]`.
///
/// `X = M_rf L_ff^-T` (3 x n_f). Its first two rows are the rotation of constants:
/// `M_Rf = A S_bar`, so `X_0 = c a - s b`, `X_1 = s a + c b` with `a = L_ff^-1 S_bar_x^T`,
/// `b = L_ff^-1 S_bar_y^T` fixed at model build (here, once per workspace). Only
/// `X_2 = L_ff^-1 m_thetaf^T` needs a banded solve per call, and the 3x3 Schur complement
/// `m_rr - X X^T` needs only `X_2 . (a, b, X_2)` besides the constant products `a.a`, `a.b`,
/// `b.b`.
#[derive(Debug, Clone)]
pub struct BeamData {
    /// Reference block `[[m_RR, m_Rtheta], [., m_thetatheta]]` (symmetric 3x3).
    pub m_rr: [[f64; 3]; 3],
    /// `(cos theta, sin theta)` of the last `mass_and_forces`.
    pub cs: [f64; 2],
    /// `m_thetaf = i_thf - S_tilde q_f` (n_f).
    pub m_thf: Vec<f64>,
    /// Constants `a = L_ff^-1 S_bar_x^T`, `b = L_ff^-1 S_bar_y^T` (n_f each) and
    /// `[a.a, a.b, b.b]`.
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    pub ab: [f64; 3],
    /// `X_2 = L_ff^-1 m_thetaf^T` (n_f).
    pub x2: Vec<f64>,
    /// Lower Cholesky factor of the Schur complement `m_rr - X X^T`.
    pub ls: [[f64; 3]; 3],
    /// Scratch of length n_f: `i_rf + M_ff^tr q_f`.
    pub w: Vec<f64>,
    /// Axial force of each element at the last `mass_and_forces` (`E a` times the element's
    /// averaged axial strain; tension positive).
    pub axial_force: Vec<f64>,
}

pub(crate) use crate::linalg::dot4 as dot;

impl Beam {
    /// Initial guess: frame state from the description, elastic coordinates (default zero).
    pub fn initial_state(&self, d: &BeamDesc, item: &str) -> Result<InitialState> {
        let p = finite_vec2(item, "position", d.position)?;
        let v = finite_vec2(item, "velocity", d.velocity)?;
        let mut q = vec![p[0], p[1], d.angle];
        let mut qd = vec![v[0], v[1], d.angular_velocity];
        for (what, given, out) in [("elastic", &d.elastic, &mut q), ("elastic_rates", &d.elastic_rates, &mut qd)] {
            match given {
                Some(v) if v.len() != self.n_f => {
                    return Err(Error::invalid(item, format!("{what} must have length {}, got {}", self.n_f, v.len())))
                }
                Some(v) => {
                    check_finite_item(item, what, v)?;
                    out.extend_from_slice(v);
                }
                None => out.resize(out.len() + self.n_f, 0.0),
            }
        }
        let mut names: Vec<String> = ["x", "y", "theta"].map(String::from).to_vec();
        names.extend((0..self.n_f).map(|i| format!("qf{i}")));
        Ok(InitialState { q, qd, names })
    }

    pub fn new_data(&self) -> BeamData {
        BeamData::new(&self.s_bar, &self.l_ff, self.elements)
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

    /// Axial forces of the elements into `bd.axial_force` and, with nonlinear strain, the
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
    fn axial_forces(&self, bd: &mut BeamData, qf: &[f64], qfd: &[f64], ff: &mut [f64]) {
        let l = self.element_length;
        let ea = self.eal / l;
        let nonlinear = self.strain == Strain::Nonlinear;
        for el in 0..self.elements {
            let d = self.element_dofs(el, qf);
            let (eps_lin, gamma, gd) = self.element_strain(&d);
            if !nonlinear {
                bd.axial_force[el] = ea * eps_lin;
                continue;
            }
            let n = ea * (eps_lin + gamma);
            bd.axial_force[el] = n;
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

    /// Tangent stiffness of the elastic forces, `K_t = -dQ_el/dq_f` (n_f x n_f): `K_ff` plus,
    /// with nonlinear strain, `E a l (b b^T - B B^T) + N G` per element (`b = B + G d / l`).
    /// `put(i, j, v)` receives entries in elastic-coordinate indices (repeated indices add up).
    pub fn elastic_tangent(&self, qf: &[f64], put: &mut impl FnMut(usize, usize, f64)) {
        let nf = self.n_f;
        for i in 0..nf {
            for j in i.saturating_sub(self.k_ff.hb)..(i + self.k_ff.hb + 1).min(nf) {
                put(i, j, self.k_ff.get(i, j));
            }
        }
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

    /// `Sigma = s_t + S_bar q_f` (first moment in the body frame).
    #[inline]
    fn first_moment(&self, qf: &[f64]) -> [f64; 2] {
        [self.s_t[0] + dot(&self.s_bar[0], qf), self.s_t[1] + dot(&self.s_bar[1], qf)]
    }

    /// The banded products of `mass_and_forces` in one pass over the rows (the three constant
    /// matrices share one band layout): `w = i_rf + M_ff^tr q_f`, `m_thf = i_thf - S_tilde q_f`,
    /// `ff = thd^2 w + 2 thd S_tilde qd_f - K_ff q_f`.
    #[inline]
    fn banded_terms(&self, qf: &[f64], qfd: &[f64], thd: f64, w: &mut [f64], m_thf: &mut [f64], ff: &mut [f64]) {
        let (n, hb) = (self.n_f, self.k_ff.hb);
        let width = 2 * hb + 1;
        let (mt, st, kf) = (&self.m_ff_tr.data, &self.s_tilde.data, &self.k_ff.data);
        assert!(self.m_ff_tr.hb == hb && self.s_tilde.hb == hb && mt.len() >= n * width && st.len() >= n * width && kf.len() >= n * width);
        assert!(qf.len() >= n && qfd.len() >= n && w.len() >= n && m_thf.len() >= n && ff.len() >= n);
        for i in 0..n {
            let lo = i.saturating_sub(hb);
            let hi = (i + hb + 1).min(n);
            let base = i * width + hb - i;
            let (mut a_w, mut a_s, mut a_sd, mut a_k) = (0.0, 0.0, 0.0, 0.0);
            for j in lo..hi {
                // SAFETY: lo <= j < hi <= n (vector lengths checked above); base + j =
                // i width + hb + (j - i) with |j - i| <= hb lies in row i of each band
                unsafe {
                    let idx = base.wrapping_add(j);
                    let (x, xd) = (*qf.get_unchecked(j), *qfd.get_unchecked(j));
                    a_w += mt.get_unchecked(idx) * x;
                    let sv = *st.get_unchecked(idx);
                    a_s += sv * x;
                    a_sd += sv * xd;
                    a_k += kf.get_unchecked(idx) * x;
                }
            }
            let wi = self.i_rf[i] + a_w;
            w[i] = wi;
            m_thf[i] = self.i_thf[i] - a_s;
            ff[i] = thd * thd * wi + 2.0 * thd * a_sd - a_k;
        }
    }

    /// Mass blocks and generalized forces (paper eqs. 20-40), with `Sigma = s_t + S_bar q_f`,
    /// `J` = +90 deg turn:
    /// * `m_RR = m I`, `m_Rtheta = A J Sigma`, `m_Rf = A S_bar`                    (eqs. 21-25)
    /// * `m_thetatheta = j0 + 2 i_rf . q_f + q_f^T M_ff^tr q_f`                      (eqs. 26-30)
    /// * `m_thetaf = i_thf + q_f^T S_tilde`                                          (eq. 31)
    /// * `Q_v,R = thd^2 A Sigma - 2 thd A J S_bar qd_f`
    /// * `Q_v,theta = -2 thd qd_f . (i_rf + M_ff^tr q_f)`
    /// * `Q_v,f = thd^2 (i_rf + M_ff^tr q_f) + 2 thd S_tilde qd_f`                   (eq. 40)
    /// * `Q_el = -K_ff (q_f + beta qd_f)`                                           (eq. 38)
    /// * gravity: `Q_R = m g`, `Q_theta = g . A J Sigma`, `Q_f = S_bar^T A^T g`     (eq. 37)
    #[inline]
    pub fn mass_and_forces(&self, bd: &mut BeamData, q: &[f64], qd: &[f64], gravity: Option<[f64; 2]>, f: &mut [f64]) {
        let nf = self.n_f;
        let thd = qd[2];
        let (s, c) = super::frame_sin_cos(q[2]);
        let (qf, qfd) = (&q[3..], &qd[3..]);
        let sig = self.first_moment(qf);
        let sigd = [dot(&self.s_bar[0], qfd), dot(&self.s_bar[1], qfd)]; // S_bar qd_f
        let asig = [c * sig[0] - s * sig[1], s * sig[0] + c * sig[1]];
        let asigd = [c * sigd[0] - s * sigd[1], s * sigd[0] + c * sigd[1]];
        // one pass over the bands: w = i_rf + M_ff^tr q_f, m_thetaf = i_thf + S_tilde^T q_f =
        // i_thf - S_tilde q_f (M_Rf = A S_bar is not formed: the factor uses the rotated
        // constants, `dense_block` rebuilds it), Q_f = thd^2 w + 2 thd S_tilde qd_f - K_ff q_f
        let ff = &mut f[3..];
        self.banded_terms(qf, qfd, thd, &mut bd.w, &mut bd.m_thf, ff);
        let mut m_thth = self.j0;
        let mut qd_w = 0.0;
        for j in 0..nf {
            m_thth += qf[j] * (self.i_rf[j] + bd.w[j]);
            qd_w += qfd[j] * bd.w[j];
        }
        bd.m_rr = frame_mass_block(self.mass, sig, m_thth, c, s);
        bd.cs = [c, s];
        f[0] = thd * thd * asig[0] + 2.0 * thd * asigd[1];
        f[1] = thd * thd * asig[1] - 2.0 * thd * asigd[0];
        f[2] = -2.0 * thd * qd_w;
        let ff = &mut f[3..];
        self.axial_forces(bd, qf, qfd, ff);
        if self.damping > 0.0 {
            self.k_ff.mul_add(-self.damping, qfd, ff);
        }
        if let Some(g) = gravity {
            add_frame_gravity(self.mass, &bd.m_rr, g, f);
            let atg = [c * g[0] + s * g[1], -s * g[0] + c * g[1]];
            for j in 0..nf {
                f[3 + j] += self.s_bar[0][j] * atg[0] + self.s_bar[1][j] * atg[1];
            }
        }
    }

    #[inline]
    pub fn factor(&self, bd: &mut BeamData) -> bool {
        frame_factor(&self.l_ff, bd)
    }

    #[inline]
    pub fn finv(&self, bd: &BeamData, v: &mut [f64]) {
        frame_finv(&self.l_ff, bd, v)
    }

    #[inline]
    pub fn finvt(&self, bd: &BeamData, v: &mut [f64]) {
        frame_finvt(&self.l_ff, bd, v)
    }

    /// `out += M_b x` from the blocks (`x`, `out`: the body's segments).
    pub fn mass_times(&self, bd: &BeamData, x: &[f64], out: &mut [f64]) {
        frame_mass_times(&self.s_bar, &self.m_ff, bd, x, out)
    }

    pub fn dense_block(&self, bd: &BeamData, put: &mut impl FnMut(usize, usize, f64)) {
        frame_dense_block(&self.s_bar, &self.m_ff, bd, put)
    }

    /// `1/2 qd^T M_b qd` from the blocks (no dense matrix).
    pub fn kinetic_energy(&self, bd: &BeamData, qd: &[f64]) -> f64 {
        frame_kinetic_energy(&self.s_bar, &self.m_ff, bd, qd)
    }

    /// `1/2 q_f^T K_ff q_f`, plus `E a l (eps^2 - eps_lin^2) / 2` per element with nonlinear
    /// strain.
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        let qf = &q[3..];
        let mut u = 0.5 * self.k_ff.bilinear(qf, qf);
        if self.strain == Strain::Nonlinear {
            for el in 0..self.elements {
                let (eps_lin, gamma, _) = self.element_strain(&self.element_dofs(el, qf));
                let eps = eps_lin + gamma;
                u += 0.5 * self.eal * (eps * eps - eps_lin * eps_lin);
            }
        }
        u
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
        let n = self.elements;
        let t = xi * n as f64;
        let el = (t.floor() as usize).min(n - 1);
        let l = self.element_length;
        let sh = element_shape(t - el as f64, l, self.phi);
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
        frame_mass_moment(self.mass, self.first_moment(&q[3..]), q)
    }

    /// A marker on a beam is an axis point `xi` in [0, 1].
    pub fn marker_shape(&self, md: &MarkerDesc, body: &str, item: &str) -> Result<PointShape> {
        Ok(self.point_shape(axis_marker_xi(md, body, item)?))
    }
}

// ------------------------------------------------------------------------------------------
// The block factor and products of an FFRF body with a constant elastic mass block, shared by
// the beam and the general flexible body (`modal.rs`): they read only `S_bar`, `M_ff`, its
// Cholesky factor and the per-call blocks in `BeamData`.
// ------------------------------------------------------------------------------------------

impl BeamData {
    /// Workspace of an FFRF body with `S_bar` and `L_ff L_ff^T = M_ff` (`elements`: length of
    /// `axial_force`, 0 for a body without elements).
    pub fn new(s_bar: &[Vec<f64>; 2], l_ff: &BandedCholesky, elements: usize) -> BeamData {
        let (mut a, mut b) = (s_bar[0].clone(), s_bar[1].clone());
        l_ff.solve_lower(&mut a);
        l_ff.solve_lower(&mut b);
        let nf = a.len();
        BeamData {
            m_rr: [[0.0; 3]; 3],
            cs: [1.0, 0.0],
            m_thf: vec![0.0; nf],
            ab: [dot(&a, &a), dot(&a, &b), dot(&b, &b)],
            a,
            b,
            x2: vec![0.0; nf],
            ls: [[0.0; 3]; 3],
            w: vec![0.0; nf],
            axial_force: vec![0.0; elements],
        }
    }
}

/// `M_b = F_b F_b^T` in the order `[r; f]`: `F_b = [[L_s, X], [0, L_ff]]` with the constant
/// `L_ff L_ff^T = M_ff`, `X = M_rf L_ff^-T` and `L_s L_s^T = m_rr - X X^T`. A call costs one
/// banded solve (`X_2`), three dot products and a 3x3 Cholesky.
#[inline]
pub(crate) fn frame_factor(l_ff: &BandedCholesky, bd: &mut BeamData) -> bool {
    let mut ls = bd.m_rr;
    bd.x2.copy_from_slice(&bd.m_thf);
    l_ff.solve_lower(&mut bd.x2);
    let (mut ax, mut bx, mut xx) = (0.0, 0.0, 0.0);
    for ((x, a), bb) in bd.x2.iter().zip(&bd.a).zip(&bd.b) {
        ax += a * x;
        bx += bb * x;
        xx += x * x;
    }
    let [c, s] = bd.cs;
    let [aa, ab, bb] = bd.ab;
    ls[0][0] -= c * c * aa - 2.0 * c * s * ab + s * s * bb;
    ls[1][0] -= s * c * (aa - bb) + (c * c - s * s) * ab;
    ls[1][1] -= s * s * aa + 2.0 * s * c * ab + c * c * bb;
    ls[2][0] -= c * ax - s * bx;
    ls[2][1] -= s * ax + c * bx;
    ls[2][2] -= xx;
    let ok = cholesky3(&mut ls);
    bd.ls = ls;
    ok
}

/// `v <- F^-1 v`: `v_f <- L_ff^-1 v_f`, `v_r <- L_s^-1 (v_r - X v_f)`.
#[inline]
pub(crate) fn frame_finv(l_ff: &BandedCholesky, bd: &BeamData, v: &mut [f64]) {
    let (vr, vf) = v.split_at_mut(3);
    l_ff.solve_lower(vf);
    let (mut pa, mut pb, mut px) = (0.0, 0.0, 0.0);
    for (((f, a), bb), x) in vf.iter().zip(&bd.a).zip(&bd.b).zip(&bd.x2) {
        pa += a * f;
        pb += bb * f;
        px += x * f;
    }
    let [c, s] = bd.cs;
    vr[0] -= c * pa - s * pb;
    vr[1] -= s * pa + c * pb;
    vr[2] -= px;
    solve_lower3(&bd.ls, vr);
}

/// `v <- F^-T v`: `v_r <- L_s^-T v_r`, `v_f <- L_ff^-T (v_f - X^T v_r)`.
#[inline]
pub(crate) fn frame_finvt(l_ff: &BandedCholesky, bd: &BeamData, v: &mut [f64]) {
    let (vr, vf) = v.split_at_mut(3);
    solve_upper3(&bd.ls, vr);
    let [c, s] = bd.cs;
    // X^T v_r = (c v0 + s v1) a + (-s v0 + c v1) b + v2 X_2
    let (ka, kb, kx) = (c * vr[0] + s * vr[1], -s * vr[0] + c * vr[1], vr[2]);
    for (((f, a), bb), x) in vf.iter_mut().zip(&bd.a).zip(&bd.b).zip(&bd.x2) {
        *f -= ka * a + kb * bb + kx * x;
    }
    l_ff.solve_upper(vf);
}

/// `M_Rf = A S_bar` entry `(i, j)`, `i` in 0..3 (row 2: `m_thetaf`).
#[inline]
fn frame_m_rf(s_bar: &[Vec<f64>; 2], bd: &BeamData, i: usize, j: usize) -> f64 {
    let [c, s] = bd.cs;
    match i {
        0 => c * s_bar[0][j] - s * s_bar[1][j],
        1 => s * s_bar[0][j] + c * s_bar[1][j],
        _ => bd.m_thf[j],
    }
}

/// `out += M_b x` from the blocks (`x`, `out`: the body's segments).
pub(crate) fn frame_mass_times(s_bar: &[Vec<f64>; 2], m_ff: &Banded, bd: &BeamData, x: &[f64], out: &mut [f64]) {
    let (xr, xf) = x.split_at(3);
    let (or, of) = out.split_at_mut(3);
    let [c, s] = bd.cs;
    let (s0, s1, t) = (dot(&s_bar[0], xf), dot(&s_bar[1], xf), dot(&bd.m_thf, xf));
    for i in 0..3 {
        or[i] += bd.m_rr[i][0] * xr[0] + bd.m_rr[i][1] * xr[1] + bd.m_rr[i][2] * xr[2];
    }
    or[0] += c * s0 - s * s1;
    or[1] += s * s0 + c * s1;
    or[2] += t;
    let (ka, kb) = (c * xr[0] + s * xr[1], -s * xr[0] + c * xr[1]);
    for (((o, a), b), m) in of.iter_mut().zip(&s_bar[0]).zip(&s_bar[1]).zip(&bd.m_thf) {
        *o += ka * a + kb * b + xr[2] * m;
    }
    m_ff.mul_add(1.0, xf, of);
}

/// Visit the entries of `M_b` (body coordinates).
pub(crate) fn frame_dense_block(s_bar: &[Vec<f64>; 2], m_ff: &Banded, bd: &BeamData, put: &mut impl FnMut(usize, usize, f64)) {
    let nf = s_bar[0].len();
    for i in 0..3 {
        for j in 0..3 {
            put(i, j, bd.m_rr[i][j]);
        }
        for j in 0..nf {
            let v = frame_m_rf(s_bar, bd, i, j);
            put(i, 3 + j, v);
            put(3 + j, i, v);
        }
    }
    for i in 0..nf {
        for j in i.saturating_sub(m_ff.hb)..(i + m_ff.hb + 1).min(nf) {
            put(3 + i, 3 + j, m_ff.get(i, j));
        }
    }
}

/// `1/2 qd^T M_b qd` from the blocks (no dense matrix).
pub(crate) fn frame_kinetic_energy(s_bar: &[Vec<f64>; 2], m_ff: &Banded, bd: &BeamData, qd: &[f64]) -> f64 {
    let (qr, qf) = qd.split_at(3);
    let mut e = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            e += qr[i] * bd.m_rr[i][j] * qr[j];
        }
        let mut cross = 0.0;
        for (j, v) in qf.iter().enumerate() {
            cross += frame_m_rf(s_bar, bd, i, j) * v;
        }
        e += 2.0 * qr[i] * cross;
    }
    e += m_ff.bilinear(qf, qf);
    0.5 * e
}

/// Marker point: body-frame position `(x + u, y + v)`, elastic velocity, rotation `psi`.
#[inline]
pub fn marker_state(ps: &PointShape, angle: f64, q: &[f64], qd: &[f64]) -> MarkerState {
    let (qf, qfd) = (&q[3..], &qd[3..]);
    let (mut pl, mut vl, mut psi, mut psid) = ([ps.x, ps.y], [0.0; 2], 0.0, 0.0);
    for &(i, su, sv, sp) in &ps.entries {
        pl[0] += su * qf[i];
        pl[1] += sv * qf[i];
        vl[0] += su * qfd[i];
        vl[1] += sv * qfd[i];
        psi += sp * qf[i];
        psid += sp * qfd[i];
    }
    frame_point_state(pl, vl, angle + psi, psid, q, qd)
}

#[inline]
pub fn add_point_jacobian(ps: &PointShape, ms: &MarkerState, w: [f64; 2], row: &mut [f64]) {
    add_frame_point_jacobian(ms, w, row);
    let [c, s] = ms.cs;
    // w . A (S_u, S_v)
    let (wa0, wa1) = (w[0] * c + w[1] * s, -w[0] * s + w[1] * c);
    for &(i, su, sv, _) in &ps.entries {
        row[3 + i] += wa0 * su + wa1 * sv;
    }
}

#[inline]
pub fn add_angle_jacobian(ps: &PointShape, w: f64, row: &mut [f64]) {
    row[2] += w;
    for &(i, _, _, sp) in &ps.entries {
        row[3 + i] += w * sp;
    }
}
