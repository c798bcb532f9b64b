//! The run options of the native methods: tolerances and budgets (`Options`), the methods by
//! name (`Method`), the default projection.

use super::*;

/// Tolerances and limits shared by the integrators.
#[derive(Debug, Clone)]
pub struct Options {
    pub rtol: f64,
    /// Absolute tolerance: one value, or one per state entry (2n).
    pub atol: Vec<f64>,
    /// Initial step (default: Hairer's estimate).
    pub first_step: Option<f64>,
    pub max_step: f64,
    /// Maximum number of step attempts.
    pub max_steps: usize,
    /// Maximum number of right-hand-side evaluations (`Stats::nfev`).
    pub max_nfev: usize,
    /// Wall-clock budget of the run [s] (checked before every step attempt).
    pub max_wall_time: f64,
    /// Smallest step size allowed [s]: a step below it ends the run (0: only the rounding
    /// limit `|t| eps`).
    pub min_step: f64,
    /// The drift bound: an accepted step whose `||Phi||` exceeds it ends the run
    /// (`Error::Drift`) when `stop_on_drift`, else is reported in `Solution::drift`
    /// (infinite: no check).
    pub drift_limit: f64,
    pub stop_on_drift: bool,
    /// Watch the conditioning of the constraints for singular passages (`Solution::singular`).
    pub monitor_singular: bool,
    /// How the implicit methods factor their Newton matrices (`newton::LinearSolver`).
    pub linear_solver: LinearSolver,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            rtol: 1e-6, atol: vec![1e-9], first_step: None, max_step: f64::INFINITY, max_steps: 1_000_000, max_nfev: usize::MAX,
            max_wall_time: f64::INFINITY, min_step: 0.0, linear_solver: LinearSolver::Auto, drift_limit: f64::INFINITY,
            stop_on_drift: true, monitor_singular: true,
        }
    }
}

impl Options {
    /// Check every setting once (the bindings and the steppers rely on it); returns the
    /// absolute tolerance expanded to `dim` entries.
    pub fn validate(&self, dim: usize) -> Result<Vec<f64>> {
        let v = check_tolerances(self.rtol, &self.atol, dim)?;
        let bad = |what: &str, m: String| Err(Error::argument(what, m));
        if let Some(h) = self.first_step {
            if !(h > 0.0) || !h.is_finite() {
                return bad("first_step", format!("must be positive and finite, got {h}"));
            }
        }
        if !(self.max_step > 0.0) {
            return bad("max_step", format!("must be positive, got {}", self.max_step));
        }
        if !(self.min_step >= 0.0) || !self.min_step.is_finite() {
            return bad("min_step", format!("must be >= 0 and finite, got {}", self.min_step));
        }
        if self.max_step < self.min_step || self.first_step.is_some_and(|h| h < self.min_step) {
            return bad("min_step", format!("max_step and first_step must be >= min_step = {:e}", self.min_step));
        }
        if !(self.max_wall_time > 0.0) {
            return bad("max_wall_time", format!("must be positive, got {}", self.max_wall_time));
        }
        if !(self.drift_limit > 0.0) {
            return bad("drift_limit", format!("must be positive, got {}", self.drift_limit));
        }
        Ok(v)
    }
}

/// The tolerance rule of every run (native or scipy): `rtol > 0` and finite, `atol >= 0` and
/// finite, one value or one per state entry; returns atol expanded to `dim` entries.
pub fn check_tolerances(rtol: f64, atol: &[f64], dim: usize) -> Result<Vec<f64>> {
    if !(rtol > 0.0) || !rtol.is_finite() {
        return Err(Error::argument("rtol", format!("must be positive and finite, got {rtol}")));
    }
    let v = match atol.len() {
        1 => vec![atol[0]; dim],
        k if k == dim => atol.to_vec(),
        k => return Err(Error::Shape { what: "atol".into(), expected: dim, got: k }),
    };
    if let Some(a) = v.iter().find(|a| !(**a >= 0.0) || !a.is_finite()) {
        return Err(Error::argument("atol", format!("must be >= 0 and finite, got {a}")));
    }
    Ok(v)
}

/// The native methods by name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    Dopri5,
    Radau5,
    GenAlpha(GenAlphaOptions),
    RadauM(RadauMOptions),
}

impl Method {
    pub fn from_name(name: &str) -> Option<Method> {
        match name.to_ascii_uppercase().as_str() {
            "DOPRI5" => Some(Method::Dopri5),
            "RADAU5" => Some(Method::Radau5),
            "GENALPHA" => Some(Method::GenAlpha(GenAlphaOptions::default())),
            "RADAU5M" => Some(Method::RadauM(RadauMOptions::default())),
            _ => None,
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Method::Dopri5 => "DOPRI5",
            Method::Radau5 => "RADAU5",
            Method::GenAlpha(_) => "GENALPHA",
            Method::RadauM(_) => "RADAU5M",
        }
    }
}

/// The default projection after every accepted step, for every method on a constrained
/// system: Newton on the positions until the correction's largest entry is at most
/// `PROJECTION_PER_ATOL` times the smallest absolute tolerance of the positions (1e-11 m at the
/// default `atol = 1e-9`), at most `PROJECTION_MAX_ITER` steps; the velocities in one step,
/// when their correction exceeds the same fraction of the velocities' smallest atol. Its cost
/// is two corrections with the step's own factorization and one evaluation of the constraints
/// per step; it keeps the drift of long runs at the tolerance and the motion on its branch at
/// singular configurations (`correct::ProjectionTolerance`).
pub const PROJECTION_PER_ATOL: f64 = 1e-2;
pub const PROJECTION_MAX_ITER: usize = 3;

/// `default_projection` for the expanded absolute tolerance `atol` (2n entries).
pub fn default_projection(atol: &[f64]) -> ProjectionTolerance {
    let n = atol.len() / 2;
    let tol = |part: &[f64]| {
        let smallest = part.iter().fold(f64::INFINITY, |m, a| m.min(*a));
        if smallest.is_finite() && smallest > 0.0 { PROJECTION_PER_ATOL * smallest } else { 0.0 }
    };
    ProjectionTolerance { position_tol: tol(&atol[..n]), velocity_tol: tol(&atol[n..]), max_iter: PROJECTION_MAX_ITER }
}


/// The native methods' names, in the order the docs list them.
pub const NATIVE_METHODS: [&str; 4] = ["DOPRI5", "RADAU5", "GENALPHA", "RADAU5M"];

/// Default relative tolerance of a run.
pub const DEFAULT_RTOL: f64 = 1e-6;
/// Default absolute tolerance per unit of rtol (`atol = ATOL_PER_RTOL rtol`).
pub const ATOL_PER_RTOL: f64 = 1e-3;
/// Smallest relative tolerance (100 machine epsilons, as solve_ivp): below it the error norm
/// divides by rounding; a smaller rtol is raised to it (with a warning in Python).
pub const RTOL_MIN: f64 = 100.0 * f64::EPSILON;

/// Options every native method takes (beyond `t0`, `y0`, `t_end`).
pub const COMMON_OPTIONS: [&str; 14] = [
    "rtol", "atol", "t_eval", "first_step", "max_step", "max_steps", "max_nfev", "max_wall_time", "min_step",
    "projection_tol", "dense", "drift_limit", "on_drift", "monitor_singular",
];

/// Options that only some methods take: `(option, methods)`.
pub const METHOD_OPTIONS: [(&str, &[&str]); 5] = [
    ("rho_inf", &["GENALPHA"]),
    ("newton_local_error", &["GENALPHA"]),
    ("step", &["GENALPHA", "RADAU5M"]),
    ("jacobian", &["RADAU5"]),
    ("linear_solver", &["RADAU5", "GENALPHA", "RADAU5M"]),
];

/// The options `method` takes: the common ones, then its own.
pub fn options_of(method: &str) -> Vec<&'static str> {
    let mut v = COMMON_OPTIONS.to_vec();
    v.extend(METHOD_OPTIONS.iter().filter(|(_, ms)| ms.contains(&method)).map(|(o, _)| *o));
    v
}

/// A run as asked for, before its checks: what the bindings read from the caller.
#[derive(Debug, Clone)]
pub struct RunRequest {
    pub method: String,
    pub rtol: f64,
    pub atol: Option<Vec<f64>>,
    pub first_step: Option<f64>,
    pub max_step: Option<f64>,
    pub max_steps: usize,
    pub max_nfev: Option<usize>,
    pub max_wall_time: Option<f64>,
    pub min_step: f64,
    pub projection_tol: Option<f64>,
    pub rho_inf: Option<f64>,
    pub step: Option<f64>,
    pub newton_local_error: Option<f64>,
    pub jacobian: String,
    pub linear_solver: String,
    pub drift_limit: Option<f64>,
    pub on_drift: String,
    pub monitor_singular: bool,
}

/// A checked run: the method with its settings, the shared options, the projection after
/// every step and the Jacobian's scheme.
#[derive(Debug, Clone)]
pub struct RunPlan {
    pub method: Method,
    pub opts: Options,
    pub projection: Option<ProjectionTolerance>,
    pub jacobian: Differences,
}

impl RunRequest {
    /// Every check of the method x option matrix and of the values, and every default, in one
    /// place (`dim`: the state's length 2n).
    pub fn plan(&self, dim: usize) -> Result<RunPlan> {
        let linear_solver = LinearSolver::parse(&self.linear_solver)?;
        let jacobian = match self.jacobian.as_str() {
            "central" => Differences::Central,
            "forward" => Differences::Forward,
            "structured" => Differences::Structured,
            other => return Err(Error::argument("jacobian", format!("unknown jacobian '{other}' (use 'structured', 'central' or 'forward')"))),
        };
        let mut method = Method::from_name(&self.method)
            .ok_or_else(|| Error::argument("method", format!("unknown native method '{}' (use one of {NATIVE_METHODS:?})", self.method)))?;
        // the method-specific options given to a method that does not take them
        for (option, given) in [("rho_inf", self.rho_inf.is_some()), ("newton_local_error", self.newton_local_error.is_some()), ("step", self.step.is_some())] {
            if given && !options_of(method.name()).contains(&option) {
                let takers = METHOD_OPTIONS.iter().find(|(o, _)| *o == option).map(|(_, m)| m.join(" and ")).unwrap_or_default();
                return Err(Error::argument(option, format!("applies to {takers} only, not to {}", method.name())));
            }
        }
        match &mut method {
            Method::GenAlpha(go) => {
                go.rho_inf = self.rho_inf.unwrap_or(go.rho_inf);
                go.step = self.step;
                go.newton_local_error = self.newton_local_error;
            }
            Method::RadauM(ro) => ro.step = self.step,
            _ => {}
        }
        if method == Method::Radau5 && jacobian != Differences::Structured && linear_solver == LinearSolver::Sparse {
            return Err(Error::argument("linear_solver", "'sparse' with RADAU5 needs jacobian='structured' (a difference Jacobian is dense)"));
        }
        let stop_on_drift = match self.on_drift.as_str() {
            "stop" => true,
            "warn" => false,
            other => return Err(Error::argument("on_drift", format!("must be 'stop' or 'warn', got {other:?}"))),
        };
        let opts = Options {
            rtol: self.rtol,
            atol: self.atol.clone().unwrap_or_else(|| vec![ATOL_PER_RTOL * self.rtol]),
            first_step: self.first_step,
            max_step: self.max_step.unwrap_or(f64::INFINITY),
            max_steps: self.max_steps,
            max_nfev: self.max_nfev.unwrap_or(usize::MAX),
            max_wall_time: self.max_wall_time.unwrap_or(f64::INFINITY),
            min_step: self.min_step,
            linear_solver,
            drift_limit: self.drift_limit.unwrap_or(f64::INFINITY),
            stop_on_drift,
            monitor_singular: self.monitor_singular,
        };
        let atol_full = opts.validate(dim)?;
        let projection = match self.projection_tol {
            None => Some(default_projection(&atol_full)),
            Some(0.0) => None,
            Some(p) if p > 0.0 && p.is_finite() => Some(ProjectionTolerance { position_tol: p, velocity_tol: p, max_iter: 20 }),
            Some(p) => return Err(Error::argument("projection_tol", format!("must be >= 0 and finite, got {p}"))),
        };
        Ok(RunPlan { method, opts, projection, jacobian })
    }
}
