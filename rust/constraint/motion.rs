//! Prescribed motions `f(t)` of drivers, with exact first and second derivatives.

use crate::description::MotionDesc;
use crate::error::{check_finite_item, Error, Result};
use crate::expr::TimeFunction;

#[derive(Debug, Clone)]
pub enum Motion {
    ConstantSpeed { initial: f64, speed: f64 },
    Polynomial { coefficients: Vec<f64> },
    Harmonic { offset: f64, amplitude: f64, frequency: f64, phase: f64 },
    Expression(Box<TimeFunction>),
    Spline(Box<Spline>),
}

impl Motion {
    pub fn from_desc(item: &str, d: &MotionDesc) -> Result<Motion> {
        let m = match d {
            MotionDesc::ConstantSpeed { initial, speed } => Motion::ConstantSpeed { initial: *initial, speed: *speed },
            MotionDesc::Polynomial { coefficients } => {
                if coefficients.is_empty() {
                    return Err(Error::invalid(item, "motion coefficients must not be empty"));
                }
                Motion::Polynomial { coefficients: coefficients.clone() }
            }
            MotionDesc::Harmonic { offset, amplitude, frequency, phase } => {
                Motion::Harmonic { offset: *offset, amplitude: *amplitude, frequency: *frequency, phase: *phase }
            }
            MotionDesc::Expression { expression } => Motion::Expression(Box::new(TimeFunction::parse(item, expression)?)),
            MotionDesc::Spline { times, values, slopes } => Motion::Spline(Box::new(Spline::new(item, times, values, *slopes)?)),
        };
        check_finite_item(item, "motion", &m.parameters())?;
        // an expression may leave its domain (sqrt of a negative, log of 0): refuse it where
        // the run starts rather than let NaN reach the integrator
        let (f, d1, d2) = m.eval(0.0, &mut vec![0.0; m.scratch_len()]);
        if !(f.is_finite() && d1.is_finite() && d2.is_finite()) {
            return Err(Error::invalid(item, format!("motion is not finite at t = 0: f = {f}, f' = {d1}, f'' = {d2}")));
        }
        Ok(m)
    }

    pub fn parameters(&self) -> Vec<f64> {
        match self {
            Motion::ConstantSpeed { initial, speed } => vec![*initial, *speed],
            Motion::Polynomial { coefficients } => coefficients.clone(),
            Motion::Harmonic { offset, amplitude, frequency, phase } => vec![*offset, *amplitude, *frequency, *phase],
            Motion::Expression(_) => vec![],
            Motion::Spline(s) => s.t.iter().chain(s.y.iter()).copied().collect(),
        }
    }

    /// Length of the evaluation buffer `eval` needs (an expression's tape; 0 for the others).
    pub fn scratch_len(&self) -> usize {
        match self {
            Motion::Expression(e) => e.scratch_len(),
            _ => 0,
        }
    }

    /// `(f, f', f'')` at time `t`; `scratch` is at least `scratch_len()` long (the workspace's
    /// `Data::motion_scratch` on the hot path: no allocation).
    #[inline]
    pub fn eval(&self, t: f64, scratch: &mut [f64]) -> (f64, f64, f64) {
        match self {
            Motion::ConstantSpeed { initial, speed } => (initial + speed * t, *speed, 0.0),
            Motion::Polynomial { coefficients } => {
                // Horner for f, f', f''
                let (mut f, mut d1, mut d2) = (0.0, 0.0, 0.0);
                for &c in coefficients.iter().rev() {
                    d2 = d2 * t + 2.0 * d1;
                    d1 = d1 * t + f;
                    f = f * t + c;
                }
                (f, d1, d2)
            }
            Motion::Harmonic { offset, amplitude, frequency, phase } => {
                let (s, c) = (frequency * t + phase).sin_cos();
                (offset + amplitude * s, amplitude * frequency * c, -amplitude * frequency * frequency * s)
            }
            Motion::Expression(e) => e.eval(t, scratch),
            Motion::Spline(s) => s.eval(t),
        }
    }
}

/// A C2 cubic spline through `(t_i, y_i)`: natural (`f'' = 0` at both ends) or clamped (given
/// end slopes). Second derivatives `m_i` at the knots are solved once at build (tridiagonal);
/// outside `[t_0, t_n]` the end cubic pieces continue (so `f`, `f'`, `f''` stay continuous).
#[derive(Debug, Clone)]
pub struct Spline {
    t: Vec<f64>,
    y: Vec<f64>,
    m: Vec<f64>,
}

impl Spline {
    pub fn new(item: &str, t: &[f64], y: &[f64], slopes: Option<[f64; 2]>) -> Result<Spline> {
        let n = t.len();
        if n < 2 || y.len() != n {
            return Err(Error::invalid(item, format!("spline: times and values need the same length >= 2, got {} and {}", n, y.len())));
        }
        check_finite_item(item, "spline times", t)?;
        check_finite_item(item, "spline values", y)?;
        if let Some(s) = slopes {
            check_finite_item(item, "spline slopes", &s)?;
        }
        if let Some(i) = (1..n).find(|&i| t[i] <= t[i - 1]) {
            return Err(Error::invalid(item, format!("spline times must increase strictly: t[{}] = {} after t[{}] = {}", i, t[i], i - 1, t[i - 1])));
        }
        // tridiagonal system for m (Thomas algorithm): rows i = 0..n
        let h = |i: usize| t[i + 1] - t[i];
        let s = |i: usize| (y[i + 1] - y[i]) / h(i);
        let (mut sub, mut diag, mut sup, mut rhs) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        match slopes {
            None => diag[0] = 1.0,
            Some([d0, _]) => {
                diag[0] = h(0) / 3.0;
                sup[0] = h(0) / 6.0;
                rhs[0] = s(0) - d0;
            }
        }
        for i in 1..n - 1 {
            sub[i] = h(i - 1) / 6.0;
            diag[i] = (h(i - 1) + h(i)) / 3.0;
            sup[i] = h(i) / 6.0;
            rhs[i] = s(i) - s(i - 1);
        }
        match slopes {
            None => diag[n - 1] = 1.0,
            Some([_, dn]) => {
                sub[n - 1] = h(n - 2) / 6.0;
                diag[n - 1] = h(n - 2) / 3.0;
                rhs[n - 1] = dn - s(n - 2);
            }
        }
        for i in 1..n {
            let w = sub[i] / diag[i - 1];
            diag[i] -= w * sup[i - 1];
            rhs[i] -= w * rhs[i - 1];
        }
        let mut m = vec![0.0; n];
        m[n - 1] = rhs[n - 1] / diag[n - 1];
        for i in (0..n - 1).rev() {
            m[i] = (rhs[i] - sup[i] * m[i + 1]) / diag[i];
        }
        Ok(Spline { t: t.to_vec(), y: y.to_vec(), m })
    }

    /// `(f, f', f'')` at `x` (binary search for the interval; no allocation).
    pub fn eval(&self, x: f64) -> (f64, f64, f64) {
        let n = self.t.len();
        // interval i with t[i] <= x < t[i+1], clamped to the end pieces
        let i = self.t.partition_point(|&ti| ti <= x).clamp(1, n - 1) - 1;
        let (t0, t1, y0, y1, m0, m1) = (self.t[i], self.t[i + 1], self.y[i], self.y[i + 1], self.m[i], self.m[i + 1]);
        let h = t1 - t0;
        let (a, b) = ((t1 - x) / h, (x - t0) / h);
        let f = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let d1 = (y1 - y0) / h + ((1.0 - 3.0 * a * a) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0;
        let d2 = a * m0 + b * m1;
        (f, d1, d2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spline_reproduces_a_cubic_when_clamped() {
        // a clamped spline reproduces any cubic exactly
        let f = |t: f64| 1.0 - 2.0 * t + 0.5 * t * t + 0.25 * t * t * t;
        let df = |t: f64| -2.0 + t + 0.75 * t * t;
        let d2f = |t: f64| 1.0 + 1.5 * t;
        let ts = [0.0, 0.3, 1.0, 1.2, 2.0];
        let ys: Vec<f64> = ts.iter().map(|&t| f(t)).collect();
        let s = Spline::new("s", &ts, &ys, Some([df(0.0), df(2.0)])).unwrap();
        for &x in &[-0.1, 0.0, 0.15, 0.7, 1.1, 1.9, 2.0, 2.2] {
            let (v, d1, d2) = s.eval(x);
            assert!((v - f(x)).abs() < 1e-12 && (d1 - df(x)).abs() < 1e-12 && (d2 - d2f(x)).abs() < 1e-12, "{x}");
        }
        let nat = Spline::new("s", &ts, &ys, None).unwrap();
        assert!(nat.eval(0.0).2.abs() < 1e-14 && nat.eval(2.0).2.abs() < 1e-14);
    }
}
