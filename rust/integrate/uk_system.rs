//! The UK equations of motion of a model as a `SecondOrderSystem` (`UkSystem`): accelerations,
//! structured Jacobians, projection after accepted steps, conditioning.

use super::*;

/// The conditioning of the constraint Jacobian at a state (`SecondOrderSystem::conditioning`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Conditioning {
    /// Smallest kept and largest singular value of `B = A M^-1/2` (exact after an SVD; the
    /// certified bounds after the full-rank QR and sparse paths: `RankInfo`).
    pub sigma_min: f64,
    pub sigma_max: f64,
    pub rank: usize,
}

impl Conditioning {
    fn from_rank_info(r: &RankInfo) -> Self {
        Conditioning { sigma_min: r.sigma_min_kept, sigma_max: r.sigma_max, rank: r.rank }
    }
    /// `sigma_min / sigma_max` (1 without kept singular values).
    pub fn ratio(&self) -> f64 {
        if self.sigma_max > 0.0 && self.sigma_min.is_finite() { self.sigma_min / self.sigma_max } else { 1.0 }
    }
}

/// The UK equations of motion of a model as a `SecondOrderSystem`.
pub struct UkSystem<'a> {
    pub model: &'a Model,
    pub data: Data,
    pub jws: JacobianWorkspace,
    /// Projection onto `Phi = 0`, `A qd + Phi_t = 0` after each accepted step
    /// (`correct::ProjectionTolerance`); the steppers that project with their own last kernel
    /// call take it over (`integrate_uk`).
    pub projection: Option<ProjectionTolerance>,
    pws: ProjectWorkspace,
    /// UK evaluations spent inside finite-difference Jacobians (full, factorization-reusing).
    pub jac_full_evals: usize,
    pub jac_cheap_evals: usize,
    /// Positions and time of the last `acc` call; `ready`: `data` still holds its
    /// factorization and `Phi` (nothing else has written the workspace since).
    acc_q: Vec<f64>,
    acc_t: f64,
    ready: bool,
    /// The rank report of the last factorization of `B` and its positions (for `conditioning`).
    fact_q: Vec<f64>,
    fact_info: Option<RankInfo>,
    /// `||Phi||` at `res_q`, `res_t` when `res_valid`.
    res_q: Vec<f64>,
    res_t: f64,
    res_norm: f64,
    res_valid: bool,
    zeros: Vec<f64>,
    rm: Vec<f64>,
    lam: Vec<f64>,
    /// With joint friction: the multipliers of the last `augmented_residual` or `acc` call, at
    /// which `multiplier_terms` linearizes the friction.
    flam: Vec<f64>,
    /// The force elements' analytic damping (`dynamics::add_force_damping`) that the Newton
    /// matrices' `C` holds now, as `(i, j, C_ij)`: `stiff_structure` takes it out and puts in the
    /// one of its own state, so `C` is the differences of the last `structure` with the dampers
    /// moved to the latest positions.
    damping: Vec<(usize, usize, f64)>,
    /// The coordinates' pattern and its colouring (`sparse_newton::Pattern`, made at the first
    /// dense `structure`; `None` inside when over the memory limit): the dense velocity terms
    /// by colours, as the sparse form reads them.
    vpat: Option<Option<Pattern>>,
}

/// Positions this close (relative to their size) share their conditioning for
/// `SecondOrderSystem::conditioning` (the projection after a step moves them by the drift).
const CONDITIONING_SAME_Q: f64 = 1e-6;

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

impl<'a> UkSystem<'a> {
    pub fn new(model: &'a Model, data: Data) -> Self {
        let (n, m) = (model.n, model.m);
        let jws = JacobianWorkspace::new(model);
        UkSystem {
            model, data, jws, projection: None, pws: ProjectWorkspace::new(model), jac_full_evals: 0, jac_cheap_evals: 0,
            acc_q: vec![0.0; n], acc_t: f64::NAN, ready: false, fact_q: vec![0.0; n], fact_info: None,
            res_q: vec![0.0; n], res_t: f64::NAN, res_norm: 0.0, res_valid: false, zeros: vec![0.0; n], rm: vec![0.0; m], lam: vec![0.0; m], flam: vec![0.0; m],
            damping: Vec::new(),
            vpat: None,
        }
    }

    /// Record the force elements' analytic damping at `(q, qd)` (`self.damping`), which `C`
    /// (just read by differences there) holds.
    fn record_damping(&mut self, q: &[f64], qd: &[f64]) {
        let Self { model, data, damping, .. } = self;
        damping.clear();
        dynamics::add_force_damping(model, data, q, qd, &mut |i, j, v| damping.push((i, j, v)));
    }

    /// Move the force elements' analytic damping in `C` to `(q, qd)`: `add(i, j, dC_ij)`.
    fn move_damping(&mut self, q: &[f64], qd: &[f64], add: &mut dyn FnMut(usize, usize, f64)) {
        for &(i, j, v) in &self.damping {
            add(i, j, -v);
        }
        self.record_damping(q, qd);
        for &(i, j, v) in &self.damping {
            add(i, j, v);
        }
    }

    /// After a kernel call that factored `B` at `(t, q)` with `Phi`.
    fn record_factorization(&mut self, t: f64, q: &[f64]) {
        if self.model.m == 0 {
            return;
        }
        self.acc_q.copy_from_slice(q);
        self.acc_t = t;
        self.ready = true;
        self.fact_q.copy_from_slice(q);
        self.fact_info = Some(self.data.rank_info);
        self.res_q.copy_from_slice(q);
        self.res_t = t;
        self.res_norm = norm2(&self.data.phi);
        self.res_valid = true;
    }

    fn at_last_acc(&self, t: f64, q: &[f64]) -> bool {
        self.ready && t == self.acc_t && q == &self.acc_q[..]
    }
}

impl SecondOrderSystem for UkSystem<'_> {
    fn n(&self) -> usize {
        self.model.n
    }
    #[inline]
    fn acc(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &mut [f64]) -> Result<()> {
        self.ready = false;
        if self.model.m == 0 {
            uk::acceleration(self.model, &mut self.data, t, q, qd)?;
        } else {
            uk::acceleration_with_phi(self.model, &mut self.data, t, q, qd)?;
            self.record_factorization(t, q);
            if self.data.friction.is_some() {
                self.flam.copy_from_slice(&self.data.lambda);
            }
        }
        qdd.copy_from_slice(&self.data.qdd);
        check_state_finite(t, q, qd, qdd)
    }
    fn jac(&mut self, t: f64, q: &[f64], qd: &[f64], jq: &mut [f64], jv: &mut [f64]) -> Result<()> {
        self.ready = false;
        uk_jacobian(self.model, &mut self.data, &mut self.jws, t, q, qd, jq, jv)?;
        self.jac_full_evals += self.jws.full_evals;
        self.jac_cheap_evals += self.jws.cheap_evals;
        Ok(())
    }
    fn post_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool> {
        let Some(p) = self.projection else { return Ok(false) };
        self.ready = false;
        let n = self.model.n;
        let (q, qd) = y.split_at_mut(n);
        let out = correct::project_in_place(self.model, &mut self.data, &mut self.pws, t, q, qd, p)?;
        self.res_q.copy_from_slice(q);
        self.res_t = t;
        self.res_norm = out.phi_norm;
        self.res_valid = true;
        Ok(out.changed)
    }
    fn n_constraints(&self) -> usize {
        self.model.m
    }
    fn projects(&self) -> bool {
        self.projection.is_some() && self.model.m > 0
    }
    fn augmented_residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], lambda: &[f64], r1: &mut [f64], r2: &mut [f64]) -> Result<bool> {
        self.ready = false;
        let (model, data) = (self.model, &mut self.data);
        let n = model.n;
        dynamics::mass_and_forces(model, data, t, q, qd);
        if let Some(w) = &data.friction {
            // joint friction at the iterate's multipliers: the loop closes in the Newton iteration
            w.add_forces(&model.forces, lambda, &mut data.force);
            self.flam.copy_from_slice(lambda);
        }
        dynamics::constraints(model, data, t, q, qd, false);
        dynamics::mass_times(model, data, qdd, r1);
        for i in 0..n {
            r1[i] -= data.force[i];
        }
        for (r, &l) in lambda.iter().enumerate() {
            data.ajac.add_row(r, l, r1);
            r2[r] = data.ajac.row_dot(r, qdd) - data.gamma[r];
        }
        Ok(true)
    }
    fn multipliers(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.data.lambda);
    }
    fn acc_projected(&mut self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64], tol: Option<ProjectionTolerance>) -> Result<ProjectOutcome> {
        self.acc(t, q, qd, qdd)?;
        match tol {
            Some(tol) => self.project_step(t, q, qd, tol),
            None => Ok(ProjectOutcome { phi_norm: self.res_norm, ..Default::default() }),
        }
    }
    fn project_step(&mut self, t: f64, q: &mut [f64], qd: &mut [f64], tol: ProjectionTolerance) -> Result<ProjectOutcome> {
        if self.model.m == 0 {
            return Ok(ProjectOutcome::default());
        }
        if !self.at_last_acc(t, q) {
            uk::acceleration_with_phi(self.model, &mut self.data, t, q, qd)?;
            self.record_factorization(t, q);
        }
        self.ready = false;
        let out = correct::project_with_factorization(self.model, &mut self.data, &mut self.pws, t, q, qd, tol)?;
        self.res_q.copy_from_slice(q);
        self.res_t = t;
        self.res_norm = out.phi_norm;
        self.res_valid = true;
        Ok(out)
    }
    fn project_tangent(&mut self, v: &mut [f64], keep: f64) {
        let (model, data) = (self.model, &mut self.data);
        if model.m == 0 {
            return;
        }
        for (i, r) in self.rm.iter_mut().enumerate() {
            *r = data.ajac.row_dot(i, v);
        }
        self.lam.copy_from_slice(&data.lambda);
        uk::min_norm_correction(model, data, &self.rm);
        for (x, d) in v.iter_mut().zip(&data.qdd) {
            *x -= (1.0 - keep) * d;
        }
        data.lambda.copy_from_slice(&self.lam);
    }
    fn conditioning_ratio(&self) -> f64 {
        if self.model.m == 0 {
            return 1.0;
        }
        Conditioning::from_rank_info(&self.data.rank_info).ratio()
    }
    fn conditioning_rank(&self) -> usize {
        if self.model.m == 0 { 0 } else { self.data.rank_info.rank }
    }
    fn corotated_bodies(&self) -> corotation::Corotated {
        corotation::Corotated::of_model(self.model)
    }
    fn conditioning(&mut self, t: f64, q: &[f64]) -> Result<Option<Conditioning>> {
        if self.model.m == 0 {
            return Ok(None);
        }
        if let Some(info) = self.fact_info {
            let size = q.iter().fold(1.0f64, |s, x| s.max(x.abs()));
            if q.iter().zip(&self.fact_q).all(|(a, b)| (a - b).abs() <= CONDITIONING_SAME_Q * size) {
                return Ok(Some(Conditioning::from_rank_info(&info)));
            }
        }
        self.ready = false;
        let (model, data) = (self.model, &mut self.data);
        uk::evaluate(model, data, t, q, &self.zeros, false)?;
        // the sparse path's estimate where its Cholesky succeeds (no dense fallback near a
        // singular configuration: that is where the monitor looks)
        // singular configuration: that is where the monitor looks). Where the steps have full
        // rank a failed Cholesky means sigma_min^2 below its rounding: singular to working
        // precision. With redundant rows it always fails: the dense path decides.
        let full_rank = self.fact_info.is_none_or(|i| i.rank == model.m);
        if let (Some(sp), true) = (data.sparse.as_mut(), full_rank) {
            let info = sp.factor(model, &data.bodies, &data.ajac, &data.tolerance);
            self.fact_info = None;
            let (sigma_min, sigma_max) = sp.conditioning_estimate().unwrap_or((0.0, sp.trace_s.sqrt()));
            let rank = info.map_or(model.m, |i| i.rank);
            return Ok(Some(Conditioning { sigma_min, sigma_max, rank }));
        }
        uk::factor_constraints(model, data)?;
        self.fact_q.copy_from_slice(q);
        self.fact_info = Some(data.rank_info);
        Ok(Some(Conditioning::from_rank_info(&data.rank_info)))
    }
    fn small_singular_values(&mut self, t: f64, q: &[f64], ratio: f64) -> Result<Option<usize>> {
        if self.model.m == 0 {
            return Ok(None);
        }
        self.ready = false;
        self.fact_info = None;
        let (model, data) = (self.model, &mut self.data);
        uk::evaluate(model, data, t, q, &self.zeros, false)?;
        // the sparse path: Sylvester's inertia of S - tau^2 I (tau: ratio x the upper bound
        // sqrt(trace S) of sigma_max); else every singular value from the dense SVD
        if let Some(sp) = data.sparse.as_mut() {
            sp.factor(model, &data.bodies, &data.ajac, &data.tolerance);
            let tau = ratio * sp.trace_s.sqrt();
            return Ok(Some(sp.count_below(tau * tau)));
        }
        let Some(s) = uk::singular_values(model, data)? else { return Ok(None) };
        let top = s.first().copied().unwrap_or(0.0);
        Ok(Some(s.iter().filter(|x| **x <= ratio * top).count()))
    }
    fn constraint_residual(&mut self, t: f64, q: &[f64]) -> Result<f64> {
        if self.model.m == 0 {
            return Ok(0.0);
        }
        if self.res_valid && t == self.res_t && q == &self.res_q[..] {
            return Ok(self.res_norm);
        }
        self.ready = false;
        dynamics::constraints(self.model, &mut self.data, t, q, &self.zeros, true);
        self.res_q.copy_from_slice(q);
        self.res_t = t;
        self.res_norm = norm2(&self.data.phi);
        self.res_valid = true;
        Ok(self.res_norm)
    }
    fn stiff_structure(&mut self, q: &[f64], qd: &[f64], m: &mut [f64], k: &mut [f64], c: &mut [f64], a: &mut [f64]) -> Result<bool> {
        // `uk::acceleration` / `augmented_residual` left the body blocks and A of (q, qd) in `data`
        self.ready = false;
        let (model, data) = (self.model, &mut self.data);
        data.ensure_dense_jac()?;
        dynamics::dense_mass_into(model, data, m);
        dynamics::stiffness_into(model, data, q, qd, k);
        a.copy_from_slice(data.jac.read(&data.ajac));
        let n = model.n;
        self.move_damping(q, qd, &mut |i, j, v| c[i * n + j] += v);
        Ok(true)
    }
    fn multiplier_terms(&mut self, q: &[f64], qd: &[f64], af: &mut [f64]) -> bool {
        let (model, data) = (self.model, &mut self.data);
        let Some(w) = data.friction.as_mut() else { return false };
        self.ready = false;
        af.fill(0.0);
        let n = model.n;
        w.add_multiplier_jacobian(&model.forces, &model.bodies, q, qd, &self.flam, &mut |r, j, v| af[r * n + j] += v);
        true
    }
    fn multiplier_terms_sparse(&mut self, q: &[f64], qd: &[f64], s: &mut Structure) -> bool {
        if self.data.friction.is_none() {
            return false;
        }
        self.ready = false;
        sparse_newton::fill_multiplier_terms(self.model, &mut self.data, q, qd, &self.flam, s);
        true
    }
    fn sparse_structure(&mut self) -> Result<Option<Structure>> {
        let p = Pattern::new(self.model, &self.data.ajac, false, self.data.memory_limit)?;
        Ok(Some(Structure::new(p)))
    }
    fn structure_sparse(&mut self, t: f64, q: &[f64], qd: &[f64], s: &mut Structure) -> Result<bool> {
        self.ready = false;
        sparse_newton::fill_structure(self.model, &mut self.data, t, q, qd, s);
        self.record_damping(q, qd);
        Ok(true)
    }
    fn stiff_structure_sparse(&mut self, q: &[f64], qd: &[f64], s: &mut Structure) -> Result<bool> {
        // `uk::acceleration` / `augmented_residual` left the body blocks and A of (q, qd) in `data`
        self.ready = false;
        sparse_newton::fill_mass(self.model, &self.data, s);
        sparse_newton::fill_stiffness(self.model, &mut self.data, q, qd, s);
        sparse_newton::fill_a(&self.data, s);
        let (p, c) = (&s.pattern, &mut s.c);
        self.move_damping(q, qd, &mut |i, j, v| c[p.find(i, j)] += v);
        Ok(true)
    }
    fn check_memory(&self, what: &str, bytes: u64) -> Result<()> {
        Error::check_memory(what, bytes, self.data.memory_limit, "raise memory_limit")
    }
    fn structured_jacobian(&self) -> bool {
        self.jws.scheme == Differences::Structured
    }
    fn structure(&mut self, t: f64, q: &[f64], qd: &[f64], m: &mut [f64], k: &mut [f64], c: &mut [f64], a: &mut [f64], bv: &mut [f64]) -> Result<bool> {
        self.ready = false;
        let (model, data) = (self.model, &mut self.data);
        data.ensure_dense_jac()?;
        dynamics::mass_and_forces(model, data, t, q, qd);
        dynamics::dense_mass_into(model, data, m);
        dynamics::tangent_into(model, data, q, qd, k, c);
        dynamics::constraints(model, data, t, q, qd, false);
        a.copy_from_slice(data.jac.read(&data.ajac));
        let vpat = self.vpat.get_or_insert_with(|| Pattern::new(model, &data.ajac, false, data.memory_limit).ok());
        match vpat {
            Some(p) => dense_velocity_terms(model, data, t, q, qd, p, &mut self.pws.v, c, bv),
            None => dynamics::velocity_jacobians_into(model, data, t, q, qd, &mut self.pws.v, c, bv),
        }
        self.record_damping(q, qd);
        Ok(true)
    }
}

/// `c = -dQ/dqd` and `bv = d gamma/dqd` (dense, row-major) at `(t, q, qd)` by central
/// differences in `qd`, one pair of evaluations per colour of `p`
/// (`sparse_newton::velocity_differences`, as the sparse form reads them): the values of
/// `dynamics::velocity_jacobians_into` in `2 colours` evaluations instead of `2 n` (A05: 34
/// coordinates). Entries outside the pattern are zero. `v` is an n-long scratch. Leaves `data`
/// at a perturbed state.
#[allow(clippy::too_many_arguments)]
fn dense_velocity_terms(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], p: &Pattern, v: &mut [f64], c: &mut [f64], bv: &mut [f64]) {
    let n = model.n;
    c.fill(0.0);
    bv.fill(0.0);
    sparse_newton::velocity_differences(model, data, t, q, qd, p, v, &mut |j, sign, s2, data| {
        for &i in &p.row[p.col_ptr[j]..p.col_ptr[j + 1]] {
            let (f, e) = (data.force[i], &mut c[i * n + j]);
            *e = if sign > 0.0 { -f } else { (*e + f) / s2 };
        }
        for &r in &p.arow[p.acol_ptr[j]..p.acol_ptr[j + 1]] {
            let (g, e) = (data.gamma[r], &mut bv[r * n + j]);
            *e = if sign > 0.0 { g } else { (*e - g) / s2 };
        }
    });
}
