//! One error type for the whole core. `bindings.rs` maps each variant to a Python exception
//! class under `ukflex.UkflexError`; nothing in the core panics on user input.

use thiserror::Error;

pub type Result<T> = std::result::Result<T, Error>;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum Error {
    /// The scene description is malformed (parse error, missing key, wrong type).
    #[error("malformed scene description: {0}")]
    Description(String),
    /// A property is non-physical (zero or negative length, mass, modulus, NaN, ...).
    #[error("{item}: {message}")]
    InvalidProperty { item: String, message: String },
    /// A joint, driver or force names a body that does not exist.
    #[error("{item}: unknown body '{body}'; bodies are [{known}]")]
    UnknownBody { item: String, body: String, known: String },
    /// An input array has the wrong length.
    #[error("{what}: expected length {expected}, got {got}")]
    Shape { what: String, expected: usize, got: usize },
    /// An input array holds NaN or infinity.
    #[error("{what}: contains NaN or infinity at index {index}")]
    NonFinite { what: String, index: usize },
    /// The mass matrix (or a body block of it) is not positive definite.
    #[error("mass matrix is not positive definite ({item})")]
    SingularMass { item: String },
    /// A function argument (not the scene) is out of range: tolerances, times, options.
    #[error("{what}: {message}")]
    Argument { what: String, message: String },
    /// An expression (a driver's motion, a load) does not parse (`position`: 0-based character index).
    #[error("{item}: cannot parse the expression {} at position {position}: {message}", excerpt(text, *position))]
    Expression { item: String, text: String, message: String, position: usize },
    /// A work budget of a run ran out (`what`: `max_steps`, `max_nfev`, `max_wall_time`,
    /// `min_step`).
    #[error("{message}")]
    Budget { what: String, message: String },
    /// A run left its constraints: `||Phi||` at an accepted step beyond the drift bound.
    #[error("the constraints drifted to ||Phi|| = {residual:.3e} at t = {t}, beyond the drift bound {limit:.3e}: the result is not the motion of the mechanism from there on")]
    Drift { t: f64, residual: f64, limit: f64 },
    /// A solver kernel could not produce a result (e.g. SVD did not converge).
    #[error("solver failure: {0}")]
    Solver(String),
    /// A name that is not one of the valid names of its kind (a body, a joint, ...): Python's
    /// `UnknownNameError` (a `KeyError`).
    #[error("unknown {what} '{name}'; valid: {}", listing(valid))]
    UnknownName { what: String, name: String, valid: Vec<String> },
    /// An allocation would exceed the configured memory limit (refused before allocating).
    #[error("{what} needs about {:.1} MiB, above the memory limit of {:.1} MiB; {hint}", *bytes as f64 / 1048576.0, *limit as f64 / 1048576.0)]
    Memory { what: String, bytes: u64, limit: u64, hint: String },
}

impl Error {
    pub fn argument(what: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Argument { what: what.into(), message: message.into() }
    }

    /// Refuse `bytes` above `limit` (checked before a large allocation).
    pub fn check_memory(what: &str, bytes: u64, limit: u64, hint: &str) -> Result<()> {
        if bytes > limit {
            return Err(Error::Memory { what: what.to_string(), bytes, limit, hint: hint.to_string() });
        }
        Ok(())
    }

    pub fn invalid(item: impl Into<String>, message: impl Into<String>) -> Self {
        Error::InvalidProperty { item: item.into(), message: message.into() }
    }
}

/// `x` with `p` significant digits as Python's `format(x, ".{p}g")` writes it (messages that
/// name a figure read alike from Rust and from Python).
pub fn fmt_g(x: f64, p: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return if x == 0.0 { "0".into() } else { format!("{x}") };
    }
    let p = p.max(1);
    let sci = format!("{:.*e}", p - 1, x);
    let (mant, exp) = sci.split_once('e').expect("exponent");
    let exp: i32 = exp.parse().expect("integer exponent");
    let strip = |s: &str| if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s.to_string() };
    if exp < -4 || exp >= p as i32 {
        format!("{}e{}{:02}", strip(mant), if exp < 0 { '-' } else { '+' }, exp.abs())
    } else {
        strip(&format!("{:.*}", (p as i32 - 1 - exp).max(0) as usize, x))
    }
}

/// Up to 20 names, then how many there are.
pub fn listing(names: &[String]) -> String {
    if names.len() <= 20 {
        return format!("{names:?}");
    }
    format!("{:?} ... ({} in all)", &names[..20], names.len())
}

/// `text` quoted, or for a long text the part around `position` with its length.
pub fn excerpt(text: &str, position: usize) -> String {
    const KEEP: usize = 30;
    let n = text.chars().count();
    if n <= 3 * KEEP {
        return format!("{text:?}");
    }
    let from = position.saturating_sub(KEEP).min(n.saturating_sub(2 * KEEP));
    let part: String = text.chars().skip(from).take(2 * KEEP).collect();
    let (head, tail) = (if from > 0 { "..." } else { "" }, if from + 2 * KEEP < n { "..." } else { "" });
    format!("{head}{part:?}{tail} ({n} characters)")
}

/// Check that every entry of `values` is finite.
pub fn check_finite(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(Error::NonFinite { what: what.to_string(), index }),
        None => Ok(()),
    }
}

/// Check that every entry of `v` is finite, as a property of a scene item.
pub fn check_finite_item(item: &str, what: &str, v: &[f64]) -> Result<()> {
    check_finite(what, v).map_err(|_| Error::invalid(item, format!("{what} must be finite, got {v:?}")))
}

/// A positive, finite property.
pub fn positive(item: &str, what: &str, v: f64) -> Result<f64> {
    if !v.is_finite() || v <= 0.0 {
        return Err(Error::invalid(item, format!("{what} must be positive and finite, got {v}")));
    }
    if v < f64::MIN_POSITIVE {
        return Err(Error::invalid(item, format!(
            "{what} = {v:e} is a subnormal number (below {:e}): it has almost no significant digits; check the units",
            f64::MIN_POSITIVE
        )));
    }
    Ok(v)
}

/// A non-negative, finite property.
pub fn non_negative(item: &str, what: &str, v: f64) -> Result<f64> {
    if !v.is_finite() || v < 0.0 {
        return Err(Error::invalid(item, format!("{what} must be >= 0 and finite, got {v}")));
    }
    Ok(v)
}

/// Check that `values` has length `expected`.
pub fn check_len(what: &str, values: &[f64], expected: usize) -> Result<()> {
    if values.len() != expected {
        return Err(Error::Shape { what: what.to_string(), expected, got: values.len() });
    }
    Ok(())
}
