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
//! The equations are those of the FFRF beam (`ffrf_beam.rs`) with these constants: the block
//! factor with the constant `M_ff` and the marker kinematics are shared with it.

use super::ffrf_beam::{dot, frame_dense_block, frame_factor, frame_finv, frame_finvt, frame_kinetic_energy, frame_mass_times, BeamData, PointShape};
use super::{add_frame_gravity, finite_vec2, frame_mass_block, frame_mass_moment, InitialState};
use crate::description::{FlexibleDesc, MarkerDesc, Strain};
use crate::error::{check_finite_item, positive, Error, Result};
use crate::linalg::dense::cholesky;
use crate::linalg::{Banded, BandedCholesky};

/// Largest number of elastic coordinates of one flexible body (its matrices are stored by
/// their band, up to dense).
pub const MAX_ELASTIC: usize = 2000;

/// Relative tolerance of the symmetry checks (entries compared with the largest one).
const SYM_TOL: f64 = 1e-9;

/// One flexible body with its constant invariants (see the module docs).
#[derive(Debug, Clone)]
pub struct Modal {
    pub n_f: usize,
    pub mass: f64,
    pub s_t: [f64; 2],
    pub j0: f64,
    pub s_bar: [Vec<f64>; 2],
    pub s_u0: Vec<f64>,
    pub s_ju0: Vec<f64>,
    pub s_tilde: Banded,
    pub m_ff: Banded,
    pub m_ff_tr: Banded,
    pub k_ff: Banded,
    pub d_ff: Option<Banded>,
    pub l_ff: BandedCholesky,
    pub strain: Strain,
    /// `k3[i][j][k]` row-major (n_f^3), empty unless nonlinear.
    pub k3: Vec<f64>,
    /// `k4` row-major (n_f^4), empty unless given.
    pub k4: Vec<f64>,
    /// Interface points: name and shape (undeformed point, displacement and rotation rows).
    pub markers: Vec<(String, PointShape)>,
}

/// A matrix given as rows, checked `n x n` and finite, with its largest |entry|.
fn square(item: &str, what: &str, rows: &[Vec<f64>], n: usize) -> Result<(Vec<f64>, f64)> {
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
fn check_symmetry(item: &str, what: &str, a: &[f64], n: usize, big: f64, sign: f64) -> Result<()> {
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

impl Modal {
    pub fn from_desc(d: &FlexibleDesc, item: &str) -> Result<Modal> {
        let n = d.k_ff.len();
        if n == 0 || n > MAX_ELASTIC {
            return Err(Error::invalid(item, format!("k_ff must be n_f x n_f with n_f in 1..={MAX_ELASTIC} elastic coordinates, got n_f = {n} (a body without elastic coordinates is a rigid body)")));
        }
        let mass = positive(item, "mass", d.mass)?;
        let inertia = positive(item, "inertia", d.inertia)?;
        let com = finite_vec2(item, "com", d.com)?;
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
        if d.s_bar.len() != 2 || d.s_bar.iter().any(|r| r.len() != n) {
            return Err(Error::invalid(item, format!("s_bar must be 2 x {n} (rows x and y), got {} rows of lengths {:?}", d.s_bar.len(), d.s_bar.iter().map(|r| r.len()).collect::<Vec<_>>())));
        }
        for (what, v) in [("s_u0", &d.s_u0), ("s_ju0", &d.s_ju0)] {
            if v.len() != n {
                return Err(Error::invalid(item, format!("{what} must have length n_f = {n}, got {}", v.len())));
            }
            check_finite_item(item, what, v)?;
        }
        check_finite_item(item, "s_bar", &d.s_bar.concat())?;
        // M_ff positive definite, and the whole body block at q_f = 0
        let mut mc = m.clone();
        if let Err((p, v)) = cholesky(&mut mc, n, 1e-13) {
            return Err(Error::SingularMass { item: format!("{item}: m_ff is not positive definite (pivot {p} = {v:e})") });
        }
        let s_t = [mass * com[0], mass * com[1]];
        let j0 = inertia + mass * (com[0] * com[0] + com[1] * com[1]);
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
                full[(3 + i) * nb + 3 + j] = m[i * n + j];
            }
        }
        if let Err((p, v)) = cholesky(&mut full, nb, 1e-13) {
            return Err(Error::SingularMass {
                item: format!("{item}: the body's mass matrix at q_f = 0 is not positive definite (pivot {p} = {v:e}): mass, inertia, com, s_bar, s_ju0 and m_ff do not belong to one mass distribution"),
            });
        }
        // K_ff positive definite: a null vector is a rigid-body motion the frame already carries
        let mut kc = k.clone();
        if let Err((p, v)) = cholesky(&mut kc, n, 1e-12) {
            return Err(Error::invalid(
                item,
                format!("k_ff must be positive definite (pivot {p} = {v:e}): a singular k_ff has rigid-body modes that were not removed (the floating frame already carries the rigid motion: fix the frame by reference conditions, mean axes or interface modes), a negative one is not a stiffness"),
            ));
        }
        if let Some((dd, _)) = &dmp {
            let tr: f64 = (0..n).map(|i| dd[i * n + i]).sum();
            let mut dc = dd.clone();
            for i in 0..n {
                dc[i * n + i] += 1e-12 * tr.abs() + f64::MIN_POSITIVE;
            }
            if cholesky(&mut dc, n, 0.0).is_err() {
                return Err(Error::invalid(item, "d_ff must be positive semi-definite"));
            }
        }
        let strain = d.strain.unwrap_or(Strain::Linear);
        let (k3, k4) = match strain {
            Strain::Linear => {
                if d.k3.is_some() || d.k4.is_some() {
                    return Err(Error::invalid(item, "k3 and k4 need strain = \"nonlinear\""));
                }
                (Vec::new(), Vec::new())
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
                (k3.clone(), k4)
            }
        };
        let mut hb = bandwidth(&m, n).max(bandwidth(&k, n)).max(bandwidth(&st, n)).max(bandwidth(&mtr, n));
        if let Some((dd, _)) = &dmp {
            hb = hb.max(bandwidth(dd, n));
        }
        let m_ff = banded(&m, n, hb);
        let l_ff = BandedCholesky::factor(&m_ff).map_err(|i| Error::SingularMass { item: format!("{item}: m_ff, pivot {i}") })?;
        // interface points
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
        Ok(Modal {
            n_f: n,
            mass,
            s_t,
            j0,
            s_bar: [d.s_bar[0].clone(), d.s_bar[1].clone()],
            s_u0: d.s_u0.clone(),
            s_ju0: d.s_ju0.clone(),
            s_tilde: banded(&st, n, hb),
            m_ff_tr: banded(&mtr, n, hb),
            k_ff: banded(&k, n, hb),
            d_ff: dmp.map(|(dd, _)| banded(&dd, n, hb)),
            m_ff,
            l_ff,
            strain,
            k3,
            k4,
            markers,
        })
    }

    /// Initial guess: frame state from the description, elastic coordinates (default zero).
    pub fn initial_state(&self, d: &FlexibleDesc, item: &str) -> Result<InitialState> {
        let p = finite_vec2(item, "position", d.position)?;
        let v = finite_vec2(item, "velocity", d.velocity)?;
        let mut q = vec![p[0], p[1], d.angle];
        let mut qd = vec![v[0], v[1], d.angular_velocity];
        for (what, given, out) in [("elastic", &d.elastic, &mut q), ("elastic_rates", &d.elastic_rates, &mut qd)] {
            match given {
                Some(v) if v.len() != self.n_f => return Err(Error::invalid(item, format!("{what} must have length {}, got {}", self.n_f, v.len()))),
                Some(v) => out.extend_from_slice(v),
                None => out.resize(out.len() + self.n_f, 0.0),
            }
        }
        let mut names: Vec<String> = ["x", "y", "theta"].map(String::from).to_vec();
        names.extend((0..self.n_f).map(|i| format!("qf{i}")));
        Ok(InitialState { q, qd, names })
    }

    pub fn new_data(&self) -> BeamData {
        BeamData::new(&self.s_bar, &self.l_ff, 0)
    }

    /// Nonlinear elastic force `-dU_nl/dq_f` added to `ff`: `-k3 q q / 2 - k4 q q q / 6`.
    #[inline]
    fn add_nonlinear_force(&self, qf: &[f64], ff: &mut [f64]) {
        let n = self.n_f;
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

    /// Mass blocks and generalized forces (the FFRF beam's equations with this body's
    /// invariants), `Sigma = s_t + S_bar q_f`, `w = s_u0 + M_ff^tr q_f`:
    /// * `m_thetatheta = j0 + q_f . (s_u0 + w)`, `m_thetaf = s_ju0 - S_tilde q_f`
    /// * `Q_v,R = thd^2 A Sigma - 2 thd A J S_bar qd_f`, `Q_v,theta = -2 thd qd_f . w`
    /// * `Q_f = thd^2 w + 2 thd S_tilde qd_f - K_ff q_f - D_ff qd_f - dU_nl/dq_f`
    /// * gravity: `Q_R = m g`, `Q_theta = g . A J Sigma`, `Q_f = S_bar^T A^T g`
    #[inline]
    pub fn mass_and_forces(&self, bd: &mut BeamData, q: &[f64], qd: &[f64], gravity: Option<[f64; 2]>, f: &mut [f64]) {
        let nf = self.n_f;
        let thd = qd[2];
        let (s, c) = super::frame_sin_cos(q[2]);
        let (qf, qfd) = (&q[3..3 + nf], &qd[3..3 + nf]);
        let sig = [self.s_t[0] + dot(&self.s_bar[0], qf), self.s_t[1] + dot(&self.s_bar[1], qf)];
        let sigd = [dot(&self.s_bar[0], qfd), dot(&self.s_bar[1], qfd)];
        let asig = [c * sig[0] - s * sig[1], s * sig[0] + c * sig[1]];
        let asigd = [c * sigd[0] - s * sigd[1], s * sigd[0] + c * sigd[1]];
        bd.w.copy_from_slice(&self.s_u0);
        self.m_ff_tr.mul_add(1.0, qf, &mut bd.w);
        bd.m_thf.copy_from_slice(&self.s_ju0);
        self.s_tilde.mul_add(-1.0, qf, &mut bd.m_thf);
        let mut m_thth = self.j0;
        let mut qd_w = 0.0;
        for j in 0..nf {
            m_thth += qf[j] * (self.s_u0[j] + bd.w[j]);
            qd_w += qfd[j] * bd.w[j];
        }
        bd.m_rr = frame_mass_block(self.mass, sig, m_thth, c, s);
        bd.cs = [c, s];
        f[0] = thd * thd * asig[0] + 2.0 * thd * asigd[1];
        f[1] = thd * thd * asig[1] - 2.0 * thd * asigd[0];
        f[2] = -2.0 * thd * qd_w;
        let ff = &mut f[3..3 + nf];
        for (o, w) in ff.iter_mut().zip(&bd.w) {
            *o = thd * thd * w;
        }
        self.s_tilde.mul_add(2.0 * thd, qfd, ff);
        self.k_ff.mul_add(-1.0, qf, ff);
        if let Some(dm) = &self.d_ff {
            dm.mul_add(-1.0, qfd, ff);
        }
        self.add_nonlinear_force(qf, ff);
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

    pub fn mass_times(&self, bd: &BeamData, x: &[f64], out: &mut [f64]) {
        frame_mass_times(&self.s_bar, &self.m_ff, bd, x, out)
    }

    pub fn dense_block(&self, bd: &BeamData, put: &mut impl FnMut(usize, usize, f64)) {
        frame_dense_block(&self.s_bar, &self.m_ff, bd, put)
    }

    pub fn kinetic_energy(&self, bd: &BeamData, qd: &[f64]) -> f64 {
        frame_kinetic_energy(&self.s_bar, &self.m_ff, bd, qd)
    }

    /// `q_f K q_f / 2 + k3 q q q / 6 + k4 q q q q / 24`.
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        let qf = &q[3..3 + self.n_f];
        let mut u = 0.5 * self.k_ff.bilinear(qf, qf);
        let n = self.n_f;
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
        let n = self.n_f;
        for i in 0..n {
            for j in 0..n {
                let mut v = self.k_ff.get(i, j);
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

    /// Damping `-dQ/dqd_f = D_ff`.
    pub fn damping_tangent(&self, put: &mut impl FnMut(usize, usize, f64)) {
        let Some(dm) = &self.d_ff else { return };
        let n = self.n_f;
        for i in 0..n {
            for j in i.saturating_sub(dm.hb)..(i + dm.hb + 1).min(n) {
                put(i, j, dm.get(i, j));
            }
        }
    }

    pub fn mass_moment(&self, q: &[f64]) -> [f64; 2] {
        let qf = &q[3..3 + self.n_f];
        frame_mass_moment(self.mass, [self.s_t[0] + dot(&self.s_bar[0], qf), self.s_t[1] + dot(&self.s_bar[1], qf)], q)
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
