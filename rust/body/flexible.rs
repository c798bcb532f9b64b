//! General planar FFRF body ("flexible"): a floating frame `(x, y, theta)` and `n_f` elastic
//! coordinates `q_f` (modal or nodal), defined by the body's constant inertia invariants and
//! elastic matrices instead of a built-in element (docs/flexible-bodies.md). With the
//! displacement field `u_f(P) = S(P) q_f` of a point with undeformed body-frame position `u0`:
//!
//! * `m`, `s_t = m c` (first moment), `j0 = int rho |u0|^2 dV` (+ rotary parts)
//! * `S_bar = int rho S dV` (2 x n_f), `s_u0 = int rho S^T u0 dV`, `s_ju0 = int rho S^T J u0 dV`
//! * `S_tilde = int rho S^T I~ S dV` (antisymmetric), `M_ff`, `M_ff^tr = int rho S^T S dV`
//! * `K_ff`, `D_ff`, and with `strain = nonlinear` the tensors `k3` (and `k4`) of the strain
//!   energy `U = q K q / 2 + k3 q q q / 6 + k4 q q q q / 24`.
//!
//! This file validates the description and builds these invariants (`ffrf::Ffrf`); the
//! equations on them are the floating-frame core's (`ffrf.rs`, shared with the FFRF beam), to
//! which the body adds `-D_ff qd_f` and the forces of `k3`, `k4`.

use super::ffrf::{Ffrf, FfrfData, PointShape};
use super::{finite_vec2, InitialState};
use serde_json::{Map, Value};
use crate::description::{FlexibleDesc, MarkerDesc, Strain};
use crate::error::{check_finite_item, positive, Error, Result};
use crate::linalg::dense::cholesky;
use crate::linalg::{dot4 as dot, Banded, BandedCholesky};

/// Largest number of elastic coordinates of one flexible body (its matrices are stored by
/// their band, up to dense).
pub const MAX_ELASTIC: usize = 2000;

/// Relative tolerance of the symmetry checks (entries compared with the largest one).
const SYM_TOL: f64 = 1e-9;

/// One flexible body with its constant invariants (see the module docs).
#[derive(Debug, Clone)]
pub struct Flexible {
    /// The floating-frame invariants (read through `Deref` as `modal.n_f`, ...).
    pub frame: Ffrf,
    pub d_ff: Option<Banded>,
    pub strain: Strain,
    /// `k3[i][j][k]` row-major (n_f^3), empty unless nonlinear.
    pub k3: Vec<f64>,
    /// `k4` row-major (n_f^4), empty unless given.
    pub k4: Vec<f64>,
    /// Interface points: name and shape (undeformed point, displacement and rotation rows).
    pub markers: Vec<(String, PointShape)>,
}

/// A matrix given as rows, checked `n x n` and finite, with its largest |entry|.
pub(crate) fn square(item: &str, what: &str, rows: &[Vec<f64>], n: usize) -> Result<(Vec<f64>, f64)> {
    if rows.len() != n || rows.iter().any(|r| r.len() != n) {
        let got: Vec<usize> = rows.iter().map(|r| r.len()).collect();
        return Err(Error::invalid(item, format!("{what} must be {n} x {n} (n_f = {n}, the size of k_ff), got {} rows of lengths {got:?}", rows.len())));
    }
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    check_finite_item(item, what, &flat)?;
    let big = flat.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    Ok((flat, big))
}

/// `a[i][j] = sign * a[j][i]` within `SYM_TOL` of the largest entry.
pub(crate) fn check_symmetry(item: &str, what: &str, a: &[f64], n: usize, big: f64, sign: f64) -> Result<()> {
    for i in 0..n {
        for j in 0..i {
            let (x, y) = (a[i * n + j], sign * a[j * n + i]);
            if (x - y).abs() > SYM_TOL * big {
                let kind = if sign > 0.0 { "symmetric" } else { "antisymmetric" };
                return Err(Error::invalid(item, format!("{what} must be {kind}: entry ({i}, {j}) = {} but ({j}, {i}) = {}", a[i * n + j], a[j * n + i])));
            }
        }
    }
    Ok(())
}

fn bandwidth(a: &[f64], n: usize) -> usize {
    let mut hb = 0;
    for i in 0..n {
        for j in 0..n {
            if a[i * n + j] != 0.0 {
                hb = hb.max(i.abs_diff(j));
            }
        }
    }
    hb
}

fn banded(a: &[f64], n: usize, hb: usize) -> Banded {
    let mut b = Banded::zeros(n, hb);
    for i in 0..n {
        for j in i.saturating_sub(hb)..(i + hb + 1).min(n) {
            b.add(i, j, a[i * n + j]);
        }
    }
    b
}

/// Check a tensor of order `order` (n^order entries, row-major) for length, finiteness and full
/// symmetry under index permutations (pairwise transpositions suffice).
fn check_tensor(item: &str, what: &str, t: &[f64], n: usize, order: u32) -> Result<f64> {
    let len = n.pow(order);
    if t.len() != len {
        return Err(Error::invalid(item, format!("{what} must have n_f^{order} = {len} entries, got {}", t.len())));
    }
    check_finite_item(item, what, t)?;
    let big = t.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let ord = order as usize;
    let mut idx = vec![0usize; ord];
    for (flat, &v) in t.iter().enumerate() {
        let mut r = flat;
        for k in (0..ord).rev() {
            idx[k] = r % n;
            r /= n;
        }
        for a in 0..ord - 1 {
            let mut sw = idx.clone();
            sw.swap(a, a + 1);
            let other = sw.iter().fold(0, |acc, &i| acc * n + i);
            if (t[other] - v).abs() > SYM_TOL * big {
                return Err(Error::invalid(item, format!("{what} must be symmetric in its indices: entry {idx:?} = {v} but {sw:?} = {}", t[other])));
            }
        }
    }
    Ok(big)
}

/// The description's square matrices, row-major and checked (sizes, finite, symmetric).
struct Matrices {
    k: Vec<f64>,
    m: Vec<f64>,
    st: Vec<f64>,
    mtr: Vec<f64>,
    dmp: Option<Vec<f64>>,
}

impl Matrices {
    fn read(d: &FlexibleDesc, item: &str, n: usize) -> Result<Matrices> {
        let (k, kbig) = square(item, "k_ff", &d.k_ff, n)?;
        let (m, mbig) = square(item, "m_ff", &d.m_ff, n)?;
        let (st, stbig) = square(item, "s_tilde", &d.s_tilde, n)?;
        let (mtr, mtrbig) = match &d.m_ff_tr {
            Some(rows) => square(item, "m_ff_tr", rows, n)?,
            None => (m.clone(), mbig),
        };
        let dmp = d.d_ff.as_ref().map(|rows| square(item, "d_ff", rows, n)).transpose()?;
        check_symmetry(item, "m_ff", &m, n, mbig, 1.0)?;
        check_symmetry(item, "m_ff_tr", &mtr, n, mtrbig, 1.0)?;
        check_symmetry(item, "k_ff", &k, n, kbig, 1.0)?;
        check_symmetry(item, "s_tilde", &st, n, stbig, -1.0)?;
        if let Some((dd, dbig)) = &dmp {
            check_symmetry(item, "d_ff", dd, n, *dbig, 1.0)?;
        }
        Ok(Matrices { k, m, st, mtr, dmp: dmp.map(|(dd, _)| dd) })
    }

    /// The common half-bandwidth of the banded copies.
    fn bandwidth(&self, n: usize) -> usize {
        let hb = bandwidth(&self.m, n).max(bandwidth(&self.k, n)).max(bandwidth(&self.st, n)).max(bandwidth(&self.mtr, n));
        self.dmp.as_ref().map_or(hb, |dd| hb.max(bandwidth(dd, n)))
    }

    /// Definiteness: `M_ff` and the whole body block at `q_f = 0` positive definite (one mass
    /// distribution), `K_ff` positive definite (no rigid-body modes left), `D_ff` semi-definite.
    fn check_definite(&self, d: &FlexibleDesc, item: &str, n: usize, mass: f64, s_t: [f64; 2], j0: f64) -> Result<()> {
        let mut mc = self.m.clone();
        if let Err((p, v)) = cholesky(&mut mc, n, 1e-13) {
            return Err(Error::SingularMass { item: format!("{item}: m_ff is not positive definite (pivot {p} = {v:e})") });
        }
        let nb = n + 3;
        let mut full = vec![0.0; nb * nb];
        let put = |a: &mut Vec<f64>, i: usize, j: usize, v: f64| {
            a[i * nb + j] = v;
            a[j * nb + i] = v;
        };
        put(&mut full, 0, 0, mass);
        put(&mut full, 1, 1, mass);
        put(&mut full, 0, 2, -s_t[1]);
        put(&mut full, 1, 2, s_t[0]);
        put(&mut full, 2, 2, j0);
        for j in 0..n {
            put(&mut full, 0, 3 + j, d.s_bar[0][j]);
            put(&mut full, 1, 3 + j, d.s_bar[1][j]);
            put(&mut full, 2, 3 + j, d.s_ju0[j]);
            for i in 0..n {
                full[(3 + i) * nb + 3 + j] = self.m[i * n + j];
            }
        }
        if let Err((p, v)) = cholesky(&mut full, nb, 1e-13) {
            return Err(Error::SingularMass {
                item: format!("{item}: the body's mass matrix at q_f = 0 is not positive definite (pivot {p} = {v:e}): mass, inertia, com, s_bar, s_ju0 and m_ff do not belong to one mass distribution"),
            });
        }
        // K_ff positive definite: a null vector is a rigid-body motion the frame already carries
        let mut kc = self.k.clone();
        if let Err((p, v)) = cholesky(&mut kc, n, 1e-12) {
            return Err(Error::invalid(
                item,
                format!("k_ff must be positive definite (pivot {p} = {v:e}): a singular k_ff has rigid-body modes that were not removed (the floating frame already carries the rigid motion: fix the frame by reference conditions, mean axes or interface modes), a negative one is not a stiffness"),
            ));
        }
        if let Some(dd) = &self.dmp {
            let tr: f64 = (0..n).map(|i| dd[i * n + i]).sum();
            let mut dc = dd.clone();
            for i in 0..n {
                dc[i * n + i] += 1e-12 * tr.abs() + f64::MIN_POSITIVE;
            }
            if cholesky(&mut dc, n, 0.0).is_err() {
                return Err(Error::invalid(item, "d_ff must be positive semi-definite"));
            }
        }
        Ok(())
    }
}

/// `s_bar` (2 x n), `s_u0` and `s_ju0` (n): sizes and finite.
fn check_vectors(d: &FlexibleDesc, item: &str, n: usize) -> Result<()> {
    if d.s_bar.len() != 2 || d.s_bar.iter().any(|r| r.len() != n) {
        return Err(Error::invalid(item, format!("s_bar must be 2 x {n} (rows x and y), got {} rows of lengths {:?}", d.s_bar.len(), d.s_bar.iter().map(|r| r.len()).collect::<Vec<_>>())));
    }
    for (what, v) in [("s_u0", &d.s_u0), ("s_ju0", &d.s_ju0)] {
        if v.len() != n {
            return Err(Error::invalid(item, format!("{what} must have length n_f = {n}, got {}", v.len())));
        }
        check_finite_item(item, what, v)?;
    }
    check_finite_item(item, "s_bar", &d.s_bar.concat())
}

/// The strain law and its tensors `(strain, k3, k4)` (empty unless nonlinear / given).
fn strain_tensors(d: &FlexibleDesc, item: &str, n: usize) -> Result<(Strain, Vec<f64>, Vec<f64>)> {
    let strain = d.strain.unwrap_or(Strain::Linear);
    match strain {
        Strain::Linear => {
            if d.k3.is_some() || d.k4.is_some() {
                return Err(Error::invalid(item, "k3 and k4 need strain = \"nonlinear\""));
            }
            Ok((strain, Vec::new(), Vec::new()))
        }
        Strain::Nonlinear => {
            let Some(k3) = &d.k3 else {
                return Err(Error::invalid(item, "strain = \"nonlinear\" needs k3, the third-order stiffness tensor (n_f^3 entries)"));
            };
            check_tensor(item, "k3", k3, n, 3)?;
            let k4 = match &d.k4 {
                Some(t) => {
                    check_tensor(item, "k4", t, n, 4)?;
                    t.clone()
                }
                None => Vec::new(),
            };
            Ok((strain, k3.clone(), k4))
        }
    }
}

/// The interface points: names unique, points distinct, displacement (2 x n) and rotation (n)
/// rows finite; their sparse shapes.
fn interface_points(d: &FlexibleDesc, item: &str, n: usize) -> Result<Vec<(String, PointShape)>> {
    let mut markers: Vec<(String, PointShape)> = Vec::with_capacity(d.markers.len());
    for md in &d.markers {
        let what = format!("marker '{}'", md.name);
        if md.name.is_empty() || markers.iter().any(|(nm, _)| nm == &md.name) {
            return Err(Error::invalid(item, format!("marker names must be non-empty and unique, got '{}' twice or empty", md.name)));
        }
        let p = finite_vec2(item, &format!("{what} point"), md.point)?;
        if md.displacement.len() != 2 || md.displacement.iter().any(|r| r.len() != n) {
            return Err(Error::invalid(item, format!("{what}: displacement must be 2 x n_f = 2 x {n}, got {} rows of lengths {:?}", md.displacement.len(), md.displacement.iter().map(|r| r.len()).collect::<Vec<_>>())));
        }
        check_finite_item(item, &format!("{what} displacement"), &md.displacement.concat())?;
        if let Some(r) = &md.rotation {
            if r.len() != n {
                return Err(Error::invalid(item, format!("{what}: rotation must have length n_f = {n}, got {}", r.len())));
            }
            check_finite_item(item, &format!("{what} rotation"), r)?;
        }
        if let Some((other, _)) = markers.iter().find(|(_, s)| s.x == p[0] && s.y == p[1]) {
            return Err(Error::invalid(item, format!("{what} and marker '{other}' sit at the same point {p:?}")));
        }
        let mut entries = Vec::new();
        for i in 0..n {
            let (su, sv) = (md.displacement[0][i], md.displacement[1][i]);
            let sp = md.rotation.as_ref().map_or(0.0, |r| r[i]);
            if su != 0.0 || sv != 0.0 || sp != 0.0 {
                entries.push((i, su, sv, sp));
            }
        }
        markers.push((md.name.clone(), PointShape { x: p[0], y: p[1], entries }));
    }
    Ok(markers)
}

impl Flexible {
    /// Validate the description (in this order: sizes, mass data, matrices, vectors,
    /// definiteness, strain tensors, interface points) and build the invariants.
    pub fn from_desc(d: &FlexibleDesc, item: &str) -> Result<Flexible> {
        let n = d.k_ff.len();
        if n == 0 || n > MAX_ELASTIC {
            return Err(Error::invalid(item, format!("k_ff must be n_f x n_f with n_f in 1..={MAX_ELASTIC} elastic coordinates, got n_f = {n} (a body without elastic coordinates is a rigid body)")));
        }
        let mass = positive(item, "mass", d.mass)?;
        let inertia = positive(item, "inertia", d.inertia)?;
        let com = finite_vec2(item, "com", d.com)?;
        let mats = Matrices::read(d, item, n)?;
        check_vectors(d, item, n)?;
        let s_t = [mass * com[0], mass * com[1]];
        let j0 = inertia + mass * (com[0] * com[0] + com[1] * com[1]);
        mats.check_definite(d, item, n, mass, s_t, j0)?;
        let (strain, k3, k4) = strain_tensors(d, item, n)?;
        let hb = mats.bandwidth(n);
        let m_ff = banded(&mats.m, n, hb);
        let l_ff = BandedCholesky::factor(&m_ff).map_err(|i| Error::SingularMass { item: format!("{item}: m_ff, pivot {i}") })?;
        let markers = interface_points(d, item, n)?;
        let frame = Ffrf {
            n_f: n,
            mass,
            s_t,
            j0,
            s_bar: [d.s_bar[0].clone(), d.s_bar[1].clone()],
            s_u0: d.s_u0.clone(),
            s_ju0: d.s_ju0.clone(),
            s_tilde: banded(&mats.st, n, hb),
            m_ff_tr: banded(&mats.mtr, n, hb),
            k_ff: banded(&mats.k, n, hb),
            m_ff,
            l_ff,
        };
        Ok(Flexible { frame, d_ff: mats.dmp.map(|dd| banded(&dd, n, hb)), strain, k3, k4, markers })
    }

    /// Initial guess: frame state from the description, elastic coordinates (default zero).
    pub fn initial_state(&self, d: &FlexibleDesc, item: &str) -> Result<InitialState> {
        self.frame.initial_state(item, d.position, d.velocity, d.angle, d.angular_velocity, &d.elastic, &d.elastic_rates)
    }

    pub fn new_data(&self) -> FfrfData {
        self.frame.new_data()
    }

    /// Nonlinear elastic force `-dU_nl/dq_f` added to `ff`: `-k3 q q / 2 - k4 q q q / 6`.
    #[inline]
    fn add_nonlinear_force(&self, qf: &[f64], ff: &mut [f64]) {
        let n = self.frame.n_f;
        if !self.k3.is_empty() {
            for (i, fi) in ff.iter_mut().enumerate().take(n) {
                let t = &self.k3[i * n * n..(i + 1) * n * n];
                let mut s = 0.0;
                for j in 0..n {
                    s += qf[j] * dot(&t[j * n..(j + 1) * n], qf);
                }
                *fi -= 0.5 * s;
            }
        }
        if !self.k4.is_empty() {
            let n3 = n * n * n;
            for (i, fi) in ff.iter_mut().enumerate().take(n) {
                let t = &self.k4[i * n3..(i + 1) * n3];
                let mut s = 0.0;
                for j in 0..n {
                    for k in 0..n {
                        s += qf[j] * qf[k] * dot(&t[(j * n + k) * n..(j * n + k + 1) * n], qf);
                    }
                }
                *fi -= s / 6.0;
            }
        }
    }

    /// Mass blocks and generalized forces: the floating-frame core's (`Ffrf::mass_and_forces`)
    /// with this body's elastic terms `-D_ff qd_f - dU_nl/dq_f`.
    #[inline]
    pub fn mass_and_forces(&self, bd: &mut FfrfData, q: &[f64], qd: &[f64], gravity: Option<[f64; 2]>, f: &mut [f64]) {
        self.frame.mass_and_forces(bd, q, qd, gravity, f, |qf, qfd, ff| {
            if let Some(dm) = &self.d_ff {
                dm.mul_add(-1.0, qfd, ff);
            }
            self.add_nonlinear_force(qf, ff);
        });
    }

    #[inline]
    pub fn factor(&self, bd: &mut FfrfData) -> bool {
        self.frame.factor(bd)
    }

    #[inline]
    pub fn finv(&self, bd: &FfrfData, v: &mut [f64]) {
        self.frame.finv(bd, v)
    }

    #[inline]
    pub fn finvt(&self, bd: &FfrfData, v: &mut [f64]) {
        self.frame.finvt(bd, v)
    }

    pub fn mass_times(&self, bd: &FfrfData, x: &[f64], out: &mut [f64]) {
        self.frame.mass_times(bd, x, out)
    }

    pub fn dense_block(&self, bd: &FfrfData, put: &mut impl FnMut(usize, usize, f64)) {
        self.frame.dense_block(bd, put)
    }

    pub fn kinetic_energy(&self, bd: &FfrfData, qd: &[f64]) -> f64 {
        self.frame.kinetic_energy(bd, qd)
    }

    /// `q_f K q_f / 2 + k3 q q q / 6 + k4 q q q q / 24`.
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        let n = self.frame.n_f;
        let qf = &q[3..3 + n];
        let mut u = self.frame.linear_strain_energy(qf);
        if !self.k3.is_empty() {
            let mut e = 0.0;
            for (ij, t) in self.k3.chunks_exact(n).enumerate() {
                e += qf[ij / n] * qf[ij % n] * dot(t, qf);
            }
            u += e / 6.0;
        }
        if !self.k4.is_empty() {
            let mut e = 0.0;
            for (ijk, t) in self.k4.chunks_exact(n).enumerate() {
                e += qf[ijk / (n * n)] * qf[(ijk / n) % n] * qf[ijk % n] * dot(t, qf);
            }
            u += e / 24.0;
        }
        u
    }

    /// Tangent stiffness `-dQ_el/dq_f`: `K_ff + k3 q + k4 q q / 2` (entries to `put`).
    pub fn elastic_tangent(&self, qf: &[f64], put: &mut impl FnMut(usize, usize, f64)) {
        let n = self.frame.n_f;
        for i in 0..n {
            for j in 0..n {
                let mut v = self.frame.k_ff.get(i, j);
                if !self.k3.is_empty() {
                    v += dot(&self.k3[(i * n + j) * n..(i * n + j + 1) * n], qf);
                }
                if !self.k4.is_empty() {
                    let base = (i * n + j) * n * n;
                    let mut s = 0.0;
                    for k in 0..n {
                        s += qf[k] * dot(&self.k4[base + k * n..base + (k + 1) * n], qf);
                    }
                    v += 0.5 * s;
                }
                if v != 0.0 {
                    put(i, j, v);
                }
            }
        }
    }

    /// Stiffness `K_t` (`elastic_tangent`) into `k` and `D_ff` into `c` (body coordinates: the
    /// elastic block).
    pub fn tangent(&self, q: &[f64], k: &mut impl FnMut(usize, usize, f64), c: &mut impl FnMut(usize, usize, f64)) {
        let qf = &q[3..];
        self.elastic_tangent(qf, &mut |i, j, v| k(3 + i, 3 + j, v));
        self.damping_tangent(&mut |i, j, v| c(3 + i, 3 + j, v));
    }

    /// `1/2 v_f^T K_ff v_f`: the material strain energy of the motion `v` (body segments).
    pub fn material_energy(&self, _q: &[f64], v: &[f64]) -> f64 {
        self.frame.linear_strain_energy(&v[3..3 + self.frame.n_f])
    }

    /// Damping `-dQ/dqd_f = D_ff`.
    pub fn damping_tangent(&self, put: &mut impl FnMut(usize, usize, f64)) {
        if let Some(dm) = &self.d_ff {
            dm.visit(put);
        }
    }

    pub fn mass_moment(&self, q: &[f64]) -> [f64; 2] {
        self.frame.mass_moment(q)
    }

    /// A marker on a flexible body is one of its interface points, given by its undeformed
    /// body-frame `point` (Python: `FlexibleBodyRef.marker(name)`).
    pub fn marker_shape(&self, md: &MarkerDesc, body: &str, item: &str) -> Result<PointShape> {
        let known = || self.markers.iter().map(|(n, s)| format!("'{n}' at ({}, {})", s.x, s.y)).collect::<Vec<_>>().join(", ");
        if md.xi.is_some() {
            return Err(Error::invalid(item, format!("a marker on flexible body '{body}' is one of its interface points, given by its point, not by xi; its points are [{}]", known())));
        }
        let Some(p) = md.point else {
            return Err(Error::invalid(item, format!("a marker on flexible body '{body}' needs the point of one of its interface points [{}]", known())));
        };
        let scale = self.markers.iter().fold(0.0f64, |a, (_, s)| a.max(s.x.abs()).max(s.y.abs())).max(f64::MIN_POSITIVE);
        match self.markers.iter().find(|(_, s)| (s.x - p[0]).abs() <= 1e-9 * scale && (s.y - p[1]).abs() <= 1e-9 * scale) {
            Some((_, s)) => Ok(s.clone()),
            None => Err(Error::invalid(item, format!("no interface point of flexible body '{body}' at ({}, {}): markers on it must sit at one of [{}]", p[0], p[1], known()))),
        }
    }
}

impl std::ops::Deref for Flexible {
    type Target = Ffrf;

    /// A flexible body is a floating-frame body with invariants given by its description.
    fn deref(&self) -> &Ffrf {
        &self.frame
    }
}

impl Flexible {
    /// Inspection entries (`inspect.rs`).
    pub fn info(&self, m: &mut Map<String, Value>) {
        m.insert("markers".into(), self.markers.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>().into());
        m.insert("strain".into(), super::inspect::spelled(&self.strain));
        m.insert("damping".into(), self.d_ff.is_some().into());
    }
}

impl Flexible {
    /// The interface points that draw it (`outline.rs`), in declaration order and closed; its
    /// frame's origin when it has none.
    pub fn outline_points(&self) -> Vec<super::marker::MarkerShape> {
        use super::marker::MarkerShape::Beam;
        let mut out: Vec<_> = self.markers.iter().map(|(_, ps)| Beam(ps.clone())).collect();
        match out.first().cloned() {
            Some(first) => out.push(first),
            None => out.push(Beam(PointShape { x: 0.0, y: 0.0, entries: Vec::new() })),
        }
        out
    }
}
