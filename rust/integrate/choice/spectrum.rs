//! The constrained modal analysis of a small system at a state, and what the chooser reads
//! from its modes: which are elastic, and each flexible body's lowest elastic mode.
//!
//! The UK accelerations are linearized in `q` by central differences (as the core's
//! `System.jac`: elastic and spring stiffness, gravity, the constraint forces through the
//! multipliers) along the columns of an orthonormal basis `N` of the null space of `A(q)` (SVD,
//! singular values above `max(m, n) eps sigma_max` kept: `scipy.linalg.null_space`), two UK
//! evaluations per degree of freedom (`jacobian::position_directional`; before, two per
//! coordinate and then `Jq N`: on A05 8 evaluations instead of 68, auto's analysis 0.31 ms CPU
//! instead of 1.05, its frequencies the same to 1e-11), and the symmetric part of
//! `K_r = -N^T M (dqdd/dq) N` is solved against `M_r = N^T M N` (Cholesky of `M_r`, then the
//! symmetric eigenproblem: `scipy.linalg.eigh`). The same analysis as
//! `System.frequencies(modes=True)` below `System.SPARSE_MODES_MIN`.

use faer::{Mat, Side};

use crate::data::Data;
use crate::dynamics;
use crate::error::{Error, Result};
use crate::jacobian;
use crate::linalg::dense::{cholesky, solve_lower, solve_upper};
use crate::linalg::simd_state::after_wide;
use crate::linalg::small_svd::QrJacobi;
use crate::model::Model;

use super::{BODY_SHARE, ELASTIC_SHARE};

/// Frequencies [rad/s] (`sign(lam) sqrt(|lam|)`, ascending) and mass-normalized mode shapes.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrum {
    pub omega: Vec<f64>,
    /// Mode `k` is `shapes[k * n..(k + 1) * n]`.
    pub shapes: Vec<f64>,
    pub n: usize,
    /// The fastest frequency (of every mode, also of those not in `omega` for a large system).
    pub omega_max: f64,
    /// Degrees of freedom `n - rank(A)`: the spectrum is complete when it holds as many modes.
    pub n_dof: usize,
}

impl Spectrum {
    pub fn len(&self) -> usize {
        self.omega.len()
    }

    pub fn is_empty(&self) -> bool {
        self.omega.is_empty()
    }

    /// Every mode known (small systems): the floor and the overdamped rule need them all.
    pub fn complete(&self) -> bool {
        self.omega.len() >= self.n_dof
    }

    pub fn mode(&self, k: usize) -> &[f64] {
        &self.shapes[k * self.n..(k + 1) * self.n]
    }
}

/// `(rank, null-space basis)` of `A(q)`: the basis `n x (n - rank)` column-major (its columns
/// contiguous), from the QR of `A^T` where it certifies full rank, else from the SVD; the
/// identity without constraints.
pub struct NullSpace(pub usize, Vec<f64>);

/// The rank of `A(q)` and its null space (`NullSpace`).
pub fn constraint_rank(model: &Model, data: &mut Data, q: &[f64]) -> Result<NullSpace> {
    let (n, m) = (model.n, model.m);
    if m == 0 {
        let mut basis = vec![0.0; n * n];
        for i in 0..n {
            basis[i * n + i] = 1.0;
        }
        return Ok(NullSpace(0, basis));
    }
    dynamics::constraints(model, data, 0.0, q, &vec![0.0; n], false);
    let mut a = vec![0.0; m * n];
    data.ajac.scatter(&mut a);
    // full rank certified by the QR of A^T (its lower bound of sigma_min above the SVD's
    // tolerance, which its upper bound of sigma_max bounds): the SVD would keep every value, and
    // Q's last n - m columns are an orthonormal basis of the same null space
    if m < n {
        let mut qr = QrJacobi::new(n, m);
        qr.qr_cols(|i| &a[i * n..(i + 1) * n]);
        let (upper, lower) = qr.full_rank_bounds();
        if upper.is_finite() && lower > (m.max(n) as f64) * f64::EPSILON * upper {
            let mut basis = vec![0.0; n * (n - m)];
            qr.complement_into(&mut basis);
            return Ok(NullSpace(m, basis));
        }
    }
    svd_null_space(m, n, &a)
}

/// `NullSpace` of the m x n row-major `a` by the SVD (singular values above `max(m, n) eps
/// sigma_max` kept).
fn svd_null_space(m: usize, n: usize, a: &[f64]) -> Result<NullSpace> {
    let am = Mat::<f64>::from_fn(m, n, |i, j| a[i * n + j]);
    let svd = after_wide(|| am.svd()).map_err(|e| Error::Solver(format!("method='auto': the SVD of the constraint Jacobian failed ({e:?})")))?;
    let s = svd.S().column_vector();
    let smax = if s.nrows() > 0 { s[0] } else { 0.0 };
    let tol = (m.max(n) as f64) * f64::EPSILON * smax;
    let rank = (0..s.nrows()).filter(|&j| s[j] > tol).count();
    let v = svd.V();
    let k = n - rank;
    let mut basis = vec![0.0; n * k];
    for c in 0..k {
        for i in 0..n {
            basis[c * n + i] = v[(i, rank + c)];
        }
    }
    Ok(NullSpace(rank, basis))
}

/// Every mode of a small system at `(t, q, qd)` on the constraints' null space `ns`.
pub fn dense_spectrum(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], ns: NullSpace) -> Result<Spectrum> {
    let n = model.n;
    let NullSpace(rank, basis) = ns;
    let k = n - rank;
    // Jq N by differences along the null space's k directions (not Jq's n columns, then N)
    let mut jqn = vec![0.0; n * k];
    jacobian::position_directional(model, data, t, q, qd, &basis, k, &mut jqn)?;
    dynamics::mass_and_forces(model, data, t, q, qd);
    let mass = dynamics::dense_mass(model, data);
    // MN = M N, KN = M Jq N (n x k, column-major)
    let mut mn = vec![0.0; n * k];
    let mut kn = vec![0.0; n * k];
    for c in 0..k {
        let col = &basis[c * n..(c + 1) * n];
        let jn = &jqn[c * n..(c + 1) * n];
        for i in 0..n {
            let row = &mass[i * n..(i + 1) * n];
            mn[c * n + i] = (0..n).map(|j| row[j] * col[j]).sum();
            kn[c * n + i] = (0..n).map(|j| row[j] * jn[j]).sum();
        }
    }
    // reduced M_r = N^T M N and K_r = -N^T M Jq N, symmetric parts (row-major k x k)
    let mut mr = vec![0.0; k * k];
    let mut kr = vec![0.0; k * k];
    for a in 0..k {
        for b in 0..k {
            let na = &basis[a * n..(a + 1) * n];
            mr[a * k + b] = (0..n).map(|i| na[i] * mn[b * n + i]).sum();
            kr[a * k + b] = -(0..n).map(|i| na[i] * kn[b * n + i]).sum::<f64>();
        }
    }
    symmetrize(&mut mr, k);
    symmetrize(&mut kr, k);
    let (omega, v) = generalized_eigen(&mut mr, &kr, k)?;
    // shapes = N V (column k: mode k)
    let mut shapes = vec![0.0; n * k];
    for mode in 0..k {
        for c in 0..k {
            let x = v[c * k + mode];
            if x != 0.0 {
                let nc = &basis[c * n..(c + 1) * n];
                for i in 0..n {
                    shapes[mode * n + i] += nc[i] * x;
                }
            }
        }
    }
    let omega_max = omega.iter().fold(0.0f64, |m, w| m.max(w.abs()));
    Ok(Spectrum { omega, shapes, n, omega_max, n_dof: k })
}

fn symmetrize(a: &mut [f64], k: usize) {
    for i in 0..k {
        for j in 0..i {
            let s = 0.5 * (a[i * k + j] + a[j * k + i]);
            a[i * k + j] = s;
            a[j * k + i] = s;
        }
    }
}

/// `K v = lam M v` (`k x k` row-major, symmetric, `M` positive definite; `mr` is overwritten
/// by its Cholesky factor): `omega = sign(lam) sqrt(|lam|)` ascending and `V` (row-major,
/// column `j` the mode, `V^T M V = I`).
fn generalized_eigen(mr: &mut [f64], kr: &[f64], k: usize) -> Result<(Vec<f64>, Vec<f64>)> {
    cholesky(mr, k, 0.0).map_err(|(j, d)| Error::Solver(format!("method='auto': the reduced mass matrix is not positive definite (pivot {j}: {d:.3e})")))?;
    let l = &*mr;
    // C = L^-1 K L^-T: X = L^-1 K (columns), then C = L^-1 X^T (K symmetric, so X^T = K L^-T)
    let mut x = vec![0.0; k * k]; // row-major
    let mut col = vec![0.0; k];
    for j in 0..k {
        for i in 0..k {
            col[i] = kr[i * k + j];
        }
        solve_lower(l, k, &mut col);
        for i in 0..k {
            x[i * k + j] = col[i];
        }
    }
    let mut c = Mat::<f64>::zeros(k, k);
    for j in 0..k {
        // column j of L^-1 X^T: L^-1 times row j of X
        col.copy_from_slice(&x[j * k..(j + 1) * k]);
        solve_lower(l, k, &mut col);
        for i in 0..k {
            c[(i, j)] = col[i];
        }
    }
    for i in 0..k {
        for j in 0..i {
            let s = 0.5 * (c[(i, j)] + c[(j, i)]);
            c[(i, j)] = s;
            c[(j, i)] = s;
        }
    }
    let evd = after_wide(|| c.self_adjoint_eigen(Side::Lower)).map_err(|e| Error::Solver(format!("method='auto': the eigenproblem failed ({e:?})")))?;
    let (u, s) = (evd.U(), evd.S().column_vector());
    let omega: Vec<f64> = (0..k).map(|j| s[j].signum() * s[j].abs().sqrt()).collect();
    // V = L^-T U
    let mut v = vec![0.0; k * k];
    for j in 0..k {
        for i in 0..k {
            col[i] = u[(i, j)];
        }
        solve_upper(l, k, &mut col);
        for i in 0..k {
            v[i * k + j] = col[i];
        }
    }
    Ok((omega, v))
}

/// Share of mode `k`'s `omega^2` that is elastic: `2 E_m / omega^2`, `E_m` the strain energy
/// of the mode's first-order strains with the material stiffness alone, plus its springs'
/// (`Body::material_energy`, `Force::material_energy`); zero for modes with `omega <= 0`.
fn elastic_share(model: &Model, q: &[f64], sp: &Spectrum, k: usize) -> f64 {
    let w = sp.omega[k];
    if !(w > 0.0) {
        return 0.0;
    }
    let v = sp.mode(k);
    let bodies: f64 = model.bodies.iter().map(|b| b.material_energy(q, v)).sum();
    let springs: f64 = model.forces.iter().map(|f| f.material_energy(&model.bodies, q, v)).sum();
    2.0 * (bodies + springs) / (w * w)
}

/// The [`elastic_share`]s of a spectrum's modes, each computed when first asked for: the rule
/// reads the lowest modes' only (their strain energies were ~10 % of a small system's analysis
/// when computed for every mode), the overdamped rule all of them.
pub struct Shares<'a> {
    model: &'a Model,
    q: &'a [f64],
    sp: &'a Spectrum,
    known: Vec<Option<f64>>,
}

impl<'a> Shares<'a> {
    pub fn new(model: &'a Model, q: &'a [f64], sp: &'a Spectrum) -> Shares<'a> {
        Shares { model, q, sp, known: vec![None; sp.len()] }
    }

    /// Mode `k`'s share.
    pub fn get(&mut self, k: usize) -> f64 {
        let (model, q, sp) = (self.model, self.q, self.sp);
        *self.known[k].get_or_insert_with(|| elastic_share(model, q, sp, k))
    }

    /// Whether mode `k` at the rate `omega[k]` is elastic.
    pub fn elastic(&mut self, omega: &[f64], k: usize) -> bool {
        omega[k] > 0.0 && self.get(k) > ELASTIC_SHARE
    }
}

/// Each flexible body's lowest elastic mode among the spectrum's (the lowest elastic mode with
/// at least `BODY_SHARE` of its kinetic energy in that body; `None` if none is there), in the
/// order of the bodies.
pub fn lowest_per_body(model: &Model, data: &mut Data, q: &[f64], sp: &Spectrum, shares: &mut Shares) -> Vec<Option<f64>> {
    lowest_per_body_of(model, data, q, sp, &sp.omega, shares)
}

/// [`lowest_per_body`] on given rates `omega` of the spectrum's modes (the overdamped rule's
/// slow rates). A mode no lower than the body's lowest so far is not looked at (its share is
/// not computed): the minimum is the same.
pub fn lowest_per_body_of(model: &Model, data: &mut Data, q: &[f64], sp: &Spectrum, omega: &[f64], shares: &mut Shares) -> Vec<Option<f64>> {
    let n = model.n;
    dynamics::mass_and_forces(model, data, 0.0, q, &vec![0.0; n]);
    let mut out = Vec::new();
    let mut mv = vec![0.0; n];
    for (body, bd) in model.bodies.iter().zip(&data.bodies) {
        if !body.capabilities().elastic {
            continue;
        }
        let (o, nb) = (body.offset, body.n_coords);
        let mut lowest: Option<f64> = None;
        for k in 0..sp.len() {
            let w = omega[k];
            if !(w > 0.0) || lowest.is_some_and(|l| w >= l) {
                continue;
            }
            let v = &sp.mode(k)[o..o + nb];
            mv[..nb].fill(0.0);
            body.mass_times(bd, v, &mut mv[..nb]);
            let kinetic: f64 = (0..nb).map(|i| v[i] * mv[i]).sum();
            if kinetic > BODY_SHARE && shares.elastic(omega, k) {
                lowest = Some(lowest.map_or(w, |l| l.min(w)));
            }
        }
        out.push(lowest);
    }
    out
}

/// The frequency the step must resolve: the highest of the flexible bodies' lowest elastic
/// modes; without any, the lowest elastic (spring) mode; `None` if no mode is elastic.
pub fn lowest_elastic_frequency(sp: &Spectrum, shares: &mut Shares, per_body: &[Option<f64>]) -> Option<f64> {
    lowest_elastic_of(&sp.omega, shares, per_body)
}

/// [`lowest_elastic_frequency`] on given rates `omega` (the overdamped rule's slow rates).
pub fn lowest_elastic_of(omega: &[f64], shares: &mut Shares, per_body: &[Option<f64>]) -> Option<f64> {
    if !(0..omega.len()).any(|k| shares.elastic(omega, k)) {
        return None;
    }
    let found: Vec<f64> = per_body.iter().flatten().copied().collect();
    if !found.is_empty() {
        return Some(found.iter().fold(f64::NEG_INFINITY, |m, &w| m.max(w)));
    }
    let mut lowest = f64::INFINITY;
    for k in 0..omega.len() {
        if omega[k] < lowest && shares.elastic(omega, k) {
            lowest = lowest.min(omega[k]);
        }
    }
    Some(lowest)
}

/// Each mode's damping ratio `zeta_k = -phi_k^T M dqdd/dqd phi_k / (2 omega_k)` by a central
/// difference of the acceleration along the mode's velocity (gyroscopic terms, skew, drop
/// out); zero for modes with `omega_k <= 0` and for the modes `want` leaves out. `mass`: the
/// dense `M(q)` (row-major).
pub fn damping_ratios(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], sp: &Spectrum, mass: &[f64], want: &dyn Fn(usize) -> bool) -> Result<Vec<f64>> {
    let n = model.n;
    let qd_max = qd.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    let (mut vp, mut up, mut dq) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut zeta = vec![0.0; sp.len()];
    for k in 0..sp.len() {
        let w = sp.omega[k];
        if !(w > 0.0) || !want(k) {
            continue;
        }
        let s = sp.mode(k);
        let smax = s.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
        let eps = 1e-6 * qd_max / smax;
        for i in 0..n {
            vp[i] = qd[i] + eps * s[i];
        }
        crate::uk::acceleration(model, data, t, q, &vp)?;
        up.copy_from_slice(&data.qdd);
        for i in 0..n {
            vp[i] = qd[i] - eps * s[i];
        }
        crate::uk::acceleration(model, data, t, q, &vp)?;
        for i in 0..n {
            dq[i] = (up[i] - data.qdd[i]) / (2.0 * eps);
        }
        let mut smd = 0.0;
        for i in 0..n {
            let row = &mass[i * n..(i + 1) * n];
            smd += s[i] * (0..n).map(|j| row[j] * dq[j]).sum::<f64>();
        }
        zeta[k] = (-smd / (2.0 * w)).max(0.0);
    }
    Ok(zeta)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Where the QR of `A^T` certifies full rank (A05, the spatial slider-crank) its basis spans
    /// the SVD's null space: the same rank, orthonormal columns, `A N = 0`, `N N^T` equal.
    #[test]
    fn the_qr_basis_spans_the_svds_null_space() {
        for json in [include_str!("../../../benches/data/spatial/flyball.json"), include_str!("../../../benches/data/spatial/slider_crank.json")] {
            let model = Model::from_json(json).unwrap();
            let mut data = Data::new(&model);
            let (n, m) = (model.n, model.m);
            let q: Vec<f64> = model.q0.iter().enumerate().map(|(i, x)| x + 1e-3 * (i as f64).sin()).collect();
            let NullSpace(rank, basis) = constraint_rank(&model, &mut data, &q).unwrap();
            let mut a = vec![0.0; m * n];
            data.ajac.scatter(&mut a);
            let NullSpace(rank_svd, basis_svd) = svd_null_space(m, n, &a).unwrap();
            assert_eq!((rank, rank_svd), (m, m));
            let k = n - m;
            let col = |b: &[f64], c: usize, i: usize| b[c * n + i];
            let amax = a.iter().fold(0.0f64, |s, x| s.max(x.abs()));
            for c in 0..k {
                for d in 0..k {
                    let dot: f64 = (0..n).map(|i| col(&basis, c, i) * col(&basis, d, i)).sum();
                    assert!((dot - if c == d { 1.0 } else { 0.0 }).abs() < 1e-13);
                }
                for r in 0..m {
                    let an: f64 = (0..n).map(|i| a[r * n + i] * col(&basis, c, i)).sum();
                    assert!(an.abs() < 1e-13 * amax, "A N [{r}, {c}] = {an}");
                }
            }
            for i in 0..n {
                for j in 0..n {
                    let p: f64 = (0..k).map(|c| col(&basis, c, i) * col(&basis, c, j)).sum();
                    let p_svd: f64 = (0..k).map(|c| col(&basis_svd, c, i) * col(&basis_svd, c, j)).sum();
                    assert!((p - p_svd).abs() < 1e-12, "N N^T [{i}, {j}]: {p} vs {p_svd}");
                }
            }
        }
    }
}
