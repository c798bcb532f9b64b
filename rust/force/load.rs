//! Loads that are functions of time and state: a force at a marker (world components) or a
//! torque on a marker frame, each component a [`Value`] (docs/loads.md).

use super::value::{Env, Scope, Value};
use crate::body::{Body, Marker};
use crate::constraint::BuildContext;
use crate::description::{LoadValueDesc, MarkerDesc};
use crate::error::Result;

#[derive(Debug, Clone)]
pub enum Load {
    /// `Q += r_q^T [fx, fy]`.
    Force { point: Marker, f: [Value; 2] },
    /// `Q += phi_q^T tau`.
    Torque { frame: Marker, tau: Value },
}

impl Load {
    pub fn force(ctx: &BuildContext, item: &str, point: &MarkerDesc, fx: &LoadValueDesc, fy: &LoadValueDesc) -> Result<Load> {
        let scope = Scope { coordinate_names: ctx.coordinate_names, local: &[], ctx: Some(ctx), spatial: None };
        let f = [Value::new(item, "fx", &scope, fx)?, Value::new(item, "fy", &scope, fy)?];
        Ok(Load::Force { point: ctx.marker(item, point)?, f })
    }

    pub fn torque(ctx: &BuildContext, item: &str, frame: &MarkerDesc, tau: &LoadValueDesc) -> Result<Load> {
        let scope = Scope { coordinate_names: ctx.coordinate_names, local: &[], ctx: Some(ctx), spatial: None };
        Ok(Load::Torque { frame: ctx.oriented_marker(item, frame)?, tau: Value::new(item, "torque", &scope, tau)? })
    }

    pub fn marker(&self) -> &Marker {
        match self {
            Load::Force { point, .. } => point,
            Load::Torque { frame, .. } => frame,
        }
    }

    pub fn scratch_len(&self) -> usize {
        match self {
            Load::Force { f, .. } => f[0].scratch_len().max(f[1].scratch_len()),
            Load::Torque { tau, .. } => tau.scratch_len(),
        }
    }

    #[inline]
    pub fn add_to(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], scratch: &mut [f64], qvec: &mut [f64]) {
        let env = Env { bodies, t, q, qd, local: [0.0; 2] };
        match self {
            Load::Force { point, f } => {
                let s = point.state(bodies, q, qd);
                let w = [f[0].eval(&env, scratch), f[1].eval(&env, scratch)];
                point.add_point_jacobian(bodies, &s, w, qvec);
            }
            Load::Torque { frame, tau } => {
                let s = frame.state(bodies, q, qd);
                frame.add_angle_jacobian(bodies, &s, tau.eval(&env, scratch), qvec);
            }
        }
    }

    /// Whether every component is a constant.
    pub fn is_constant(&self) -> bool {
        match self {
            Load::Force { f, .. } => f.iter().all(Value::is_const),
            Load::Torque { tau, .. } => tau.is_const(),
        }
    }

    /// `-F . r` (`-tau phi`) when every component is a constant (then the load has that
    /// potential, as a constant load); `None` otherwise (its work is not a potential's).
    pub fn potential(&self, bodies: &[Body], q: &[f64]) -> Option<f64> {
        let zeros = vec![0.0; q.len()];
        match self {
            Load::Force { point, f: [Value::Const(fx), Value::Const(fy)] } => {
                let s = point.state(bodies, q, &zeros);
                Some(-(fx * s.r[0] + fy * s.r[1]))
            }
            Load::Torque { frame, tau: Value::Const(tau) } => Some(-tau * frame.state(bodies, q, &zeros).phi),
            _ => None,
        }
    }
}
