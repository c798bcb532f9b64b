//! `method="auto"`: the integrator picked from the constrained system's natural frequencies
//! (docs/integrators.md; `python/ukflex/run/choice.py` is the glue that states the reason).
//!
//! A scene is *stiff* for a run when the step that resolves the motions the user asked about
//! is too long for its fastest mode. The motions of interest are every flexible body's lowest
//! elastic mode (a mode whose potential energy is mostly material strain or spring energy,
//! [`ELASTIC_SHARE`]) and everything slower; `omega_c` is the highest of those. RADAU5M at
//! the fixed step `h = y / omega_c`, `y = min(1, (phi / (RADAU_DECAY omega_c T))^(1/5))`,
//! `phi = min(1, 20 rtol)` (at most `T / 20`), when `h omega_max` exceeds what an explicit
//! step may take at equal cost, unless that mode is overdamped; otherwise DOPRI5, unless
//! overdamped modes make it stiff ([`overdamped`]: adaptive RADAU5M). The fast modes the start
//! sets off and the step damps give the run an error floor ([`floor`]).
//!
//! The whole analysis of a small system (below `System.SPARSE_MODES_MIN` coordinates) runs
//! here in one call ([`spectrum::dense_spectrum`], [`choose`]); a large system's lowest modes
//! come from the sparse Lanczos of `ukflex.analysis.modes` and are handed to [`choose`].

mod chains;
mod floor;
mod overdamped;
pub mod spectrum;

use serde_json::Value;

use crate::data::Data;
use crate::error::Result;
use crate::force::ForceKind;
use crate::integrate::RTOL_MIN;
use crate::model::Model;
pub use spectrum::Spectrum;

/// Amplitude budget per rtol over the run, and its cap.
pub const PHASE_PER_RTOL: f64 = 20.0;
pub const PHASE_CAP: f64 = 1.0;
/// Fewest steps per run.
pub const MIN_STEPS: f64 = 20.0;
/// RADAU5M on a resolved mode: amplitude loss per step `RADAU_DECAY (omega h)^6` (|R(i y)| of
/// Radau IIA: 1.3e-10 at y = 0.1, 1.3e-4 at y = 1; the phase lag is 2.3e-5 y^6).
pub const RADAU_DECAY: f64 = 1.3e-4;
/// ... its largest step in radians of omega_c (reached at loose rtol: ~1e-3). Newton's failures
/// at such steps on ANCF couplers (109 of 337 attempts at 0.5) cost little since a fixed step
/// that Newton could not take stays short for a few steps.
pub const RADAU_MAX_STEP_OMEGA: f64 = 1.0;
/// RADAU5M's Newton tolerance (its `rtol` with a fixed step) per rtol: 1e-4 at the default rtol
/// (measured on five built-in scenes at auto's step: Newton at 1e-4 instead of 1e-6 keeps every
/// error within 10 %, 20-30 % less time) ...
pub const NEWTON_PER_RTOL: f64 = 100.0;
/// ... and at most this.
pub const NEWTON_MAX_RTOL: f64 = 1e-3;
/// ... and at most this on a scene with a geometrically exact beam (`beam3`): Newton's norm weighs
/// each coordinate's correction against how far the step moves it, and the beam's node bodies
/// carry its rigid motion in their absolute coordinates, of which the deformation is a small
/// part. On Kane's spin-up (8 elements, the fixed step 0.12 s of rtol 1e-5) Newton at 1e-3 left
/// the history 3.7e-3 of the dip off, at 1e-4 9.9e-5, at 1e-5 2.1e-5, at about the same cost; at
/// rtol 1e-3 .. 1e-6 auto's runs are 1.0e-4 .. 1.6e-4 off with this cap (docs/spatial-flexible.md,
/// "The Newton matrices co-rotated"). At the default rtol the cap changes nothing.
pub const NEWTON_MAX_RTOL_BEAM: f64 = 1e-4;
/// ... and on such a scene, below `NEWTON_BEAM_FULL_RTOL`, the cap times `(rtol /
/// NEWTON_BEAM_FULL_RTOL)^NEWTON_BEAM_EXPONENT` (10 rtol at rtol 1e-9, rtol at 1e-12): the
/// default keeps its Newton (1e-4; the right-angle cantilever's default time against Exudyn),
/// and below it Newton no longer sets the error. On that frame (5 el./member, with the load's
/// kinks as step stops) auto's history at 100 rtol stayed 1.5e-4 m off down to rtol 1e-6 and
/// 2.6-3.2e-5 m from 1e-7 to 1e-9 (Newton at 1e-9 at the same steps: 4-7e-6 m); docs/integrators.md,
/// "Does auto honour rtol" (benches/beam3_floor.py).
pub const NEWTON_BEAM_FULL_RTOL: f64 = 1e-6;
pub const NEWTON_BEAM_EXPONENT: f64 = 4.0 / 3.0;
/// DOPRI5's average `h omega_max` on stiff flexible scenes, and a RADAU5M step's cost in DOPRI5
/// steps (nonlinear FFRF coupler N = 4: 17 us against 6 UK calls of ~1.7 us).
pub const EXPLICIT_STEP_OMEGA: f64 = 0.5;
pub const RADAU_COST_RATIO: f64 = 1.6;
/// DOPRI5's stability interval on the negative real axis, `h |lambda| <= 3.3` (its step control
/// settles at 3.15 on A05's fastest overdamped decay, 8.1e3 1/s: 5 103 steps over 2 s).
pub const DOPRI5_REAL_STABILITY: f64 = 3.3;
/// GENALPHA by hand (`newton_local_error`): the fraction of the local error estimate at which
/// Newton may stop (2.3 instead of 3.2-4.4 iterations per step on the paper scene) ...
pub const NEWTON_LOCAL_ERROR: f64 = 0.3;
/// ... safe only on steps this coarse against the fastest mode, `h omega_max`: on the ANCF
/// coupler (N = 4 and 8) the looser test keeps the answer at `h omega_max` >= 3.5 with
/// `rho_inf` 0.9 and >= 8.7 with 1.0, and lets it drift off at 2.2-2.6 (0.9) and 4.4 (1.0).
pub const LOCAL_NEWTON_MIN_STEP_OMEGA: f64 = 8.0;
/// A mode is elastic when more than this share of `omega^2` is the material stiffness of its
/// strains (elastic bodies, springs) rather than gravity, constraint forces or stress.
pub const ELASTIC_SHARE: f64 = 0.5;
/// A mode belongs to a flexible body when it carries at least this share of its kinetic energy.
pub const BODY_SHARE: f64 = 0.2;
/// Large systems: the sparse modal analysis starts from this many lowest modes and takes four
/// times more until every flexible body's lowest elastic mode is among them.
pub const FIRST_MODES: usize = 8;
/// DOPRI5's rtol per rtol when auto runs it: its local error control at the user's rtol leaves
/// a global error of 5-30 rtol over 10 s on the scenes with closed forms (heavy top's energy and
/// angular momenta, a pendulum's swing, a harmonic slider; docs/integrators.md, "What rtol means
/// for auto's DOPRI5"); at 0.3 rtol it is at most 5.6 rtol from rtol 1e-5 to 1e-9, for ~30 %
/// more steps.
pub const DOPRI5_RTOL_PER_RTOL: f64 = 0.3;
/// Large systems up to this many coordinates get their floor from the whole dense spectrum,
/// computed for it alone (the sparse analysis finds the lowest modes, the floor sums over the
/// fast ones): at most the whole dense analysis' time, 8-10 ms at 70-84 coordinates, 17 ms at
/// 126, 62 ms at 203 (3D spin-up beams; benches/beam3_floor.py's scenes); beyond, the cubic
/// cost of the dense eigenproblem grows on and no floor is stated.
pub const FLOOR_DENSE_MAX: usize = 200;
/// The body points at which the floor's displacements are read (fractions of a beam's length).
pub const FLOOR_POINTS: [f64; 4] = [0.25, 0.5, 0.75, 1.0];

/// The constants above by name (`ukflex._core.AUTO`).
pub fn constants() -> Vec<(&'static str, f64)> {
    vec![
        ("PHASE_PER_RTOL", PHASE_PER_RTOL),
        ("PHASE_CAP", PHASE_CAP),
        ("MIN_STEPS", MIN_STEPS),
        ("RADAU_DECAY", RADAU_DECAY),
        ("RADAU_MAX_STEP_OMEGA", RADAU_MAX_STEP_OMEGA),
        ("NEWTON_PER_RTOL", NEWTON_PER_RTOL),
        ("NEWTON_MAX_RTOL", NEWTON_MAX_RTOL),
        ("NEWTON_MAX_RTOL_BEAM", NEWTON_MAX_RTOL_BEAM),
        ("NEWTON_BEAM_FULL_RTOL", NEWTON_BEAM_FULL_RTOL),
        ("NEWTON_BEAM_EXPONENT", NEWTON_BEAM_EXPONENT),
        ("EXPLICIT_STEP_OMEGA", EXPLICIT_STEP_OMEGA),
        ("RADAU_COST_RATIO", RADAU_COST_RATIO),
        ("DOPRI5_REAL_STABILITY", DOPRI5_REAL_STABILITY),
        ("NEWTON_LOCAL_ERROR", NEWTON_LOCAL_ERROR),
        ("LOCAL_NEWTON_MIN_STEP_OMEGA", LOCAL_NEWTON_MIN_STEP_OMEGA),
        ("ELASTIC_SHARE", ELASTIC_SHARE),
        ("BODY_SHARE", BODY_SHARE),
        ("FIRST_MODES", FIRST_MODES as f64),
        ("FLOOR_DENSE_MAX", FLOOR_DENSE_MAX as f64),
        ("DOPRI5_RTOL_PER_RTOL", DOPRI5_RTOL_PER_RTOL),
    ]
}

/// What the description says that the chooser needs before any analysis.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SceneTraits {
    /// A body or force dissipates (a nonzero `damping`, a modal body's `d_ff`).
    pub damped: bool,
    /// A mode can store strain or spring energy: a flexible body, a geometrically exact beam
    /// (`beam3_element`s) or a spring-damper with stiffness.
    pub elastic_potential: bool,
    /// Contacts (revolute joints with clearance): forces that switch on and off during the run,
    /// which the spectrum at the start does not see.
    pub contact: bool,
    /// A geometrically exact beam (`beam3_element`s): RADAU5M's Newton at most
    /// `NEWTON_MAX_RTOL_BEAM`, tighter below `NEWTON_BEAM_FULL_RTOL` ([`newton_rtol`]).
    pub beam: bool,
}

impl SceneTraits {
    /// Read from the model (flexible bodies) and its description (dampers, springs).
    pub fn of(model: &Model, desc: &Value) -> SceneTraits {
        let items = |key: &str| desc.get(key).and_then(Value::as_array).cloned().unwrap_or_default();
        let (bodies, forces) = (items("bodies"), items("forces"));
        fn nonzero(v: &Value) -> bool {
            match v {
                Value::Number(x) => x.as_f64().is_some_and(|x| x != 0.0),
                Value::Array(a) => a.iter().any(nonzero),
                _ => false,
            }
        }
        let damped = bodies.iter().chain(&forces).any(|it| ["damping", "d_ff"].iter().any(|k| it.get(*k).is_some_and(nonzero)));
        let spring = forces.iter().any(|f| {
            f.get("kind").and_then(Value::as_str) == Some("spring_damper") && f.get("stiffness").and_then(Value::as_f64).unwrap_or(0.0) > 0.0
        });
        // a geometrically exact beam's elements (`beam3_element`) store strain energy between
        // rigid node bodies: the beam is elastic though none of its bodies is
        let beam = model.forces.iter().any(|f| matches!(&f.kind, ForceKind::Spatial(s) if s.kind() == "beam3_element"));
        let flexible = beam || model.bodies.iter().any(|b| b.capabilities().elastic);
        let contact = forces.iter().any(|f| f.get("kind").and_then(Value::as_str) == Some("revolute_clearance"));
        SceneTraits { damped, elastic_potential: flexible || spring, contact, beam }
    }
}

/// Why the chooser picked what it picked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// No degree of freedom: the motion is prescribed (DOPRI5).
    NoDof,
    /// No flexible body and no spring: no frequency analysis needed (DOPRI5).
    NoElasticPotential,
    /// No mode is elastic (DOPRI5).
    NoElasticMode,
    /// RADAU5M at a fixed step.
    Stiff,
    /// Stiff with contacts: RADAU5M with its own step control (a step chosen before the run
    /// cannot see the impacts).
    StiffContact,
    /// Overdamped modes: adaptive RADAU5M.
    Overdamped,
    /// DOPRI5 resolves the fastest mode at the step the elastic modes need.
    NotStiff,
    /// A large system's sparse analysis has not yet found every flexible body's lowest
    /// elastic mode: ask for more modes.
    NeedMoreModes,
}

impl Verdict {
    pub fn name(self) -> &'static str {
        match self {
            Verdict::NoDof => "no_dof",
            Verdict::NoElasticPotential => "no_elastic_potential",
            Verdict::NoElasticMode => "no_elastic_mode",
            Verdict::Stiff => "stiff",
            Verdict::StiffContact => "stiff_contact",
            Verdict::Overdamped => "overdamped",
            Verdict::NotStiff => "not_stiff",
            Verdict::NeedMoreModes => "need_more_modes",
        }
    }
}

/// The overdamped mode that decided an adaptive RADAU5M run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverdampedMode {
    pub omega: f64,
    pub zeta: f64,
    /// Its fast decay rate `omega (zeta + sqrt(zeta^2 - 1))` [1/s].
    pub fast: f64,
    /// The explicit step that decay allows.
    pub h_explicit: f64,
}

/// The chooser's decision and the numbers its reason states.
#[derive(Debug, Clone, PartialEq)]
pub struct AutoChoice {
    pub verdict: Verdict,
    /// "DOPRI5" or "RADAU5M" (empty for `NeedMoreModes`).
    pub method: &'static str,
    pub omega_elastic: Option<f64>,
    pub omega_max: f64,
    /// The step the elastic modes need (RADAU5M's fixed step when `Stiff`).
    pub step: Option<f64>,
    /// RADAU5M's Newton tolerance with a fixed step.
    pub newton_rtol: Option<f64>,
    /// The amplitude budget over the run.
    pub phase: f64,
    /// The error floor [m] of a fixed-step RADAU5M run (every mode known), and its largest
    /// contributions `(omega, amplitude at a body point, error)`.
    pub floor: Option<f64>,
    pub floor_modes: Vec<[f64; 3]>,
    pub overdamped: Option<OverdampedMode>,
}

impl AutoChoice {
    /// The answer to a large system's first question: a spectrum is needed.
    pub fn needs_spectrum() -> AutoChoice {
        AutoChoice::plain(Verdict::NeedMoreModes, "", 0.0)
    }

    fn plain(verdict: Verdict, method: &'static str, omega_max: f64) -> AutoChoice {
        AutoChoice { verdict, method, omega_elastic: None, omega_max, step: None, newton_rtol: None, phase: 0.0, floor: None, floor_modes: Vec::new(), overdamped: None }
    }
}

/// The decisions that need no spectrum: `Some` when the scene has no degree of freedom or no
/// elastic potential.
pub fn prelude(traits: SceneTraits, n_dof: usize) -> Option<AutoChoice> {
    if n_dof == 0 {
        return Some(AutoChoice::plain(Verdict::NoDof, "DOPRI5", 0.0));
    }
    if !traits.elastic_potential {
        return Some(AutoChoice::plain(Verdict::NoElasticPotential, "DOPRI5", 0.0));
    }
    None
}

/// The rtol the integrator of `c` runs at for the user's `rtol`: DOPRI5 at
/// `DOPRI5_RTOL_PER_RTOL rtol` (not below `RTOL_MIN`), fixed-step RADAU5M at its Newton
/// tolerance; `None` for the user's own (adaptive RADAU5M).
pub fn integrator_rtol(c: &AutoChoice, rtol: f64) -> Option<f64> {
    match c.method {
        "DOPRI5" => Some((DOPRI5_RTOL_PER_RTOL * rtol).max(RTOL_MIN).min(rtol)),
        _ => c.newton_rtol,
    }
}

/// RADAU5M's Newton tolerance with auto's fixed step for the user's `rtol`.
pub fn newton_rtol(traits: SceneTraits, rtol: f64) -> f64 {
    if traits.beam {
        ((NEWTON_PER_RTOL * rtol).min(NEWTON_MAX_RTOL_BEAM)).min(NEWTON_MAX_RTOL_BEAM * (rtol / NEWTON_BEAM_FULL_RTOL).powf(NEWTON_BEAM_EXPONENT))
    } else {
        (NEWTON_PER_RTOL * rtol).min(NEWTON_MAX_RTOL)
    }
}

/// The step that resolves `omega_c` to the amplitude budget `phase` over `span`: `(y, h)`.
pub fn resolving_step(omega_c: f64, phase: f64, span: f64) -> f64 {
    let y = RADAU_MAX_STEP_OMEGA.min((phase / (RADAU_DECAY * omega_c * span)).powf(0.2));
    (y / omega_c).min(span / MIN_STEPS)
}

/// Whether GENALPHA's Newton may stop at the local error level with step `h` on a system whose
/// fastest mode is `omega_max`: only on coarse steps.
pub fn local_newton_ok(h: f64, omega_max: f64) -> bool {
    h * omega_max >= LOCAL_NEWTON_MIN_STEP_OMEGA
}

/// The whole choice for a small system: the dense spectrum at `(t0, q, qd)` and the rule;
/// the floor only `with_floor` (it decides nothing: `simulate` states it when it is read).
pub fn choose_dense(model: &Model, data: &mut Data, traits: SceneTraits, t0: f64, q: &[f64], qd: &[f64], span: f64, rtol: f64, with_floor: bool) -> Result<AutoChoice> {
    let rank = spectrum::constraint_rank(model, data, q)?;
    if let Some(c) = prelude(traits, model.n - rank.0) {
        return Ok(c);
    }
    let sp = spectrum::dense_spectrum(model, data, t0, q, qd, rank)?;
    choose(model, data, traits, t0, q, qd, span, rtol, &sp, with_floor)
}

/// The rule on a spectrum (every mode of a small system, or a large one's lowest modes); the
/// floor of a fixed-step RADAU5M choice only `with_floor` (a large system's from a dense
/// spectrum of its own: up to 62 ms, [`FLOOR_DENSE_MAX`]).
pub fn choose(model: &Model, data: &mut Data, traits: SceneTraits, t0: f64, q: &[f64], qd: &[f64], span: f64, rtol: f64, sp: &Spectrum, with_floor: bool) -> Result<AutoChoice> {
    if let Some(c) = prelude(traits, sp.n_dof) {
        return Ok(c);
    }
    let mut shares = spectrum::Shares::new(model, q, sp);
    let per_body = spectrum::lowest_per_body(model, data, q, sp, &mut shares);
    if !sp.complete() {
        let found = if per_body.is_empty() { (0..sp.len()).any(|k| shares.elastic(&sp.omega, k)) } else { per_body.iter().all(Option::is_some) };
        if !found {
            return Ok(AutoChoice::plain(Verdict::NeedMoreModes, "", sp.omega_max));
        }
    }
    let Some(omega_c) = spectrum::lowest_elastic_frequency(sp, &mut shares, &per_body) else {
        return Ok(AutoChoice::plain(Verdict::NoElasticMode, "DOPRI5", sp.omega_max));
    };
    let phase = PHASE_CAP.min(PHASE_PER_RTOL * rtol);
    let h = resolving_step(omega_c, phase, span);
    let mut c = AutoChoice::plain(Verdict::NotStiff, "DOPRI5", sp.omega_max);
    c.omega_elastic = Some(omega_c);
    c.step = Some(h);
    c.phase = phase;
    if h * sp.omega_max > EXPLICIT_STEP_OMEGA * RADAU_COST_RATIO && traits.contact {
        c.verdict = Verdict::StiffContact;
        c.method = "RADAU5M";
        return Ok(c);
    }
    if h * sp.omega_max > EXPLICIT_STEP_OMEGA * RADAU_COST_RATIO {
        // a fixed step resolves the lowest elastic mode's oscillation: an overdamped one has
        // none (its slow decay is the motion), so the overdamped rule decides
        if sp.complete() && traits.damped && overdamped::decides(model, data, t0, q, qd, sp, omega_c)? {
            if let Some(d) = overdamped::choice(model, data, t0, q, qd, sp, &mut shares, phase, span)? {
                return Ok(d);
            }
        }
        c.verdict = Verdict::Stiff;
        c.method = "RADAU5M";
        c.newton_rtol = Some(newton_rtol(traits, rtol));
        let dense;
        let full = if !with_floor {
            None
        } else if sp.complete() {
            Some(sp)
        } else if model.n <= FLOOR_DENSE_MAX {
            let rank = spectrum::constraint_rank(model, data, q)?;
            dense = spectrum::dense_spectrum(model, data, t0, q, qd, rank)?;
            Some(&dense)
        } else {
            None
        };
        if let Some(full) = full {
            let (total, top) = floor::transient_floor(model, data, traits, t0, q, qd, full, omega_c, h, span)?;
            c.floor = Some(total);
            c.floor_modes = top;
        }
        return Ok(c);
    }
    if sp.complete() && traits.damped {
        if let Some(d) = overdamped::choice(model, data, t0, q, qd, sp, &mut shares, phase, span)? {
            return Ok(d);
        }
    }
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_step_follows_rtol_up_to_its_caps() {
        let (w, span) = (100.0, 1.0);
        let phase = |rtol: f64| PHASE_CAP.min(PHASE_PER_RTOL * rtol);
        // loose: one radian of omega_c per step; never more than span / MIN_STEPS
        assert_eq!(resolving_step(w, phase(1e-3), span), RADAU_MAX_STEP_OMEGA / w);
        assert_eq!(resolving_step(1e-3, phase(1e-3), span), span / MIN_STEPS);
        // tight: y = (phi / (RADAU_DECAY omega_c T))^(1/5)
        let y = (phase(1e-8) / (RADAU_DECAY * w * span)).powf(0.2);
        assert!((resolving_step(w, phase(1e-8), span) - y / w).abs() < 1e-15);
        assert!(local_newton_ok(LOCAL_NEWTON_MIN_STEP_OMEGA / w, w) && !local_newton_ok(0.5 / w, w));
    }

    #[test]
    fn the_prelude_needs_no_spectrum_for_prescribed_or_rigid_scenes() {
        let rigid = SceneTraits { damped: false, elastic_potential: false, contact: false, beam: false };
        assert_eq!(prelude(rigid, 0).unwrap().verdict, Verdict::NoDof);
        assert_eq!(prelude(rigid, 3).unwrap().verdict, Verdict::NoElasticPotential);
        assert!(prelude(SceneTraits { damped: false, elastic_potential: true, contact: false, beam: false }, 3).is_none());
    }

    #[test]
    fn dopri5_runs_at_a_tighter_rtol_and_radau5m_at_its_newton_tolerance() {
        let rigid = prelude(SceneTraits::default(), 3).unwrap();
        assert_eq!(integrator_rtol(&rigid, 1e-6), Some(DOPRI5_RTOL_PER_RTOL * 1e-6));
        // never below the smallest rtol a run takes
        assert_eq!(integrator_rtol(&rigid, RTOL_MIN), Some(RTOL_MIN));
        let mut stiff = AutoChoice::plain(Verdict::Stiff, "RADAU5M", 1e4);
        stiff.newton_rtol = Some(1e-4);
        assert_eq!(integrator_rtol(&stiff, 1e-6), Some(1e-4));
        assert_eq!(integrator_rtol(&AutoChoice::plain(Verdict::Overdamped, "RADAU5M", 1e4), 1e-6), None);
    }

    #[test]
    fn a_beams_newton_tolerance_is_capped_lower() {
        let (plain, beam) = (SceneTraits::default(), SceneTraits { beam: true, ..SceneTraits::default() });
        assert_eq!(newton_rtol(plain, 1e-3), NEWTON_MAX_RTOL);
        assert_eq!(newton_rtol(beam, 1e-3), NEWTON_MAX_RTOL_BEAM);
        // at the default rtol the cap changes nothing; below it a beam's Newton tightens
        // faster than rtol: 10 rtol at 1e-9
        assert_eq!(newton_rtol(beam, 1e-6), newton_rtol(plain, 1e-6));
        assert!((newton_rtol(plain, 1e-8) - NEWTON_PER_RTOL * 1e-8).abs() < 1e-20);
        assert!((newton_rtol(beam, 1e-9) / 1e-8 - 1.0).abs() < 1e-12);
        assert!(newton_rtol(beam, 1e-7) < newton_rtol(plain, 1e-7) / 2.0);
    }
}
