//! Prescribed motions `f(t)` of drivers, with exact first and second derivatives.

use crate::description::MotionDesc;
use crate::error::{check_finite_item, Error, Result};

#[derive(Debug, Clone)]
pub enum Motion {
    ConstantSpeed { initial: f64, speed: f64 },
    Polynomial { coefficients: Vec<f64> },
    Harmonic { offset: f64, amplitude: f64, frequency: f64, phase: f64 },
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
        };
        check_finite_item(item, "motion", &m.parameters())?;
        Ok(m)
    }

    pub fn parameters(&self) -> Vec<f64> {
        match self {
            Motion::ConstantSpeed { initial, speed } => vec![*initial, *speed],
            Motion::Polynomial { coefficients } => coefficients.clone(),
            Motion::Harmonic { offset, amplitude, frequency, phase } => vec![*offset, *amplitude, *frequency, *phase],
        }
    }

    /// `(f, f', f'')` at time `t`.
    #[inline]
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
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
        }
    }
}
