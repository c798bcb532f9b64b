//! Spatial loads that are functions of time and state (docs/loads.md, "In 3D"): a force at a
//! spatial marker and a torque on a `rigid3` body, each of the three components a [`Value`]
//! (`value.rs`: a constant, an expression of `t` and the coordinates by name, a table or a
//! callable). World components, or the marker's (body's) axes that turn with the body, as the
//! constant spatial point force and torque (`spatial.rs`): `Q = J_P^T F` with `F = A C F'` in
//! body axes, and `Q_p = 2 G^T n'`, `n' = A^T n`.

use super::spatial::{add_torque, world_force};
use super::value::{Env, Scope, Value};
use super::value3::Spatial;
use crate::body::marker3::{add_jacobian, Marker3};
use crate::body::{Body, Marker};
use crate::description::spatial::FrameDesc;
use crate::description::LoadValueDesc;
use crate::error::{Error, Result};
use crate::linalg::rot3::dot;

#[derive(Debug, Clone)]
pub enum SpatialLoad {
    Force { point: Marker3, f: [Value; 3], frame: FrameDesc },
    /// On body `body` (a `rigid3`); `base`: its marker (the force's marker list).
    Torque { body: usize, base: Marker, tau: [Value; 3], frame: FrameDesc },
}

/// The three values of a vector's components (`what`: `force`, `torque`); a wrong count is named.
fn values(item: &str, what: &str, coordinate_names: &[String], spatial: Spatial, d: &[LoadValueDesc]) -> Result<[Value; 3]> {
    if d.len() != 3 {
        return Err(Error::invalid(item, format!("{what} must have 3 components, got {}", d.len())));
    }
    // the spatial values read `t`, the coordinates (and rates) by name and the spatial point
    // quantities (`value3.rs`)
    let scope = Scope { coordinate_names, local: &[], ctx: None, spatial: Some(spatial) };
    let names = ["x", "y", "z"];
    let v = |c: usize| Value::new(item, &format!("{what}[{c}] ({})", names[c]), &scope, &d[c]);
    Ok([v(0)?, v(1)?, v(2)?])
}

impl SpatialLoad {
    pub fn force(item: &str, coordinate_names: &[String], spatial: Spatial, point: Marker3, d: &[LoadValueDesc], frame: FrameDesc) -> Result<SpatialLoad> {
        Ok(SpatialLoad::Force { f: values(item, "force", coordinate_names, spatial, d)?, point, frame })
    }

    pub fn torque(item: &str, coordinate_names: &[String], spatial: Spatial, body: usize, d: &[LoadValueDesc], frame: FrameDesc) -> Result<SpatialLoad> {
        let base = Marker { body: Some(body), angle: 0.0, shape: crate::body::MarkerShape::Spatial };
        Ok(SpatialLoad::Torque { tau: values(item, "torque", coordinate_names, spatial, d)?, body, base, frame })
    }

    pub fn marker(&self) -> &Marker {
        match self {
            SpatialLoad::Force { point, .. } => &point.base,
            SpatialLoad::Torque { base, .. } => base,
        }
    }

    pub fn values(&self) -> &[Value; 3] {
        match self {
            SpatialLoad::Force { f, .. } => f,
            SpatialLoad::Torque { tau, .. } => tau,
        }
    }

    pub fn values_mut(&mut self) -> &mut [Value; 3] {
        match self {
            SpatialLoad::Force { f, .. } => f,
            SpatialLoad::Torque { tau, .. } => tau,
        }
    }

    pub fn scratch_len(&self) -> usize {
        self.values().iter().map(Value::scratch_len).max().unwrap_or(0)
    }

    #[inline]
    pub fn add_to(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], scratch: &mut [f64], qv: &mut [f64]) {
        let env = Env { bodies, t, q, qd, local: [0.0; 2] };
        let [a, b, c] = self.values();
        let v = [a.eval(&env, scratch), b.eval(&env, scratch), c.eval(&env, scratch)];
        match self {
            SpatialLoad::Force { point, frame, .. } => {
                let st = point.state(bodies, q, qd);
                let f = world_force(point, *frame, bodies, q, &v);
                add_jacobian(bodies, &st, &st.point, &f, qv, None);
            }
            SpatialLoad::Torque { body, frame, .. } => add_torque(bodies, *body, *frame, q, &v, qv),
        }
    }

    /// `add(i, j, K_ij)` of `K = -J^T dF/dq` for the components whose value has a gradient (an
    /// expression or a table reading coordinates; one of `t` only adds zeros), as the planar
    /// loads' (`Force::add_stiffness`: the change of `J` with `q` left out). `p`, `r`: n-long
    /// scratch rows.
    pub fn add_stiffness(&self, env: &Env, scratch: &mut [f64], p: &mut [f64], r: &mut [f64], add: &mut dyn FnMut(usize, usize, f64)) {
        let (bodies, q) = (env.bodies, env.q);
        for (c, v) in self.values().iter().enumerate().filter(|(_, v)| v.reads_positions()) {
            r.fill(0.0);
            v.add_position_gradient(env, scratch, r);
            p.fill(0.0);
            let mut w = [0.0; 3];
            w[c] = 1.0;
            match self {
                SpatialLoad::Force { point, frame, .. } => {
                    let st = point.state(bodies, q, env.qd);
                    add_jacobian(bodies, &st, &st.point, &world_force(point, *frame, bodies, q, &w), p, None);
                }
                SpatialLoad::Torque { body, frame, .. } => add_torque(bodies, *body, *frame, q, &w, p),
            }
            super::outer(p, r, -1.0, add);
        }
    }

    /// `-F . P` of a world-frame force whose components are constants; `None` otherwise (a
    /// torque, a body-frame force or a function: its work is not a potential's).
    pub fn potential(&self, bodies: &[Body], q: &[f64]) -> Option<f64> {
        match self {
            SpatialLoad::Force { point, f: [Value::Const(x), Value::Const(y), Value::Const(z)], frame: FrameDesc::World } => {
                let zeros = vec![0.0; q.len()];
                Some(-dot(&[*x, *y, *z], &point.state(bodies, q, &zeros).point.v))
            }
            _ => None,
        }
    }

    /// Whether the load has a potential (`potential` is `Some`): a world-frame force of
    /// constant components; the others' work is counted by their power (`works_by_power`).
    pub fn has_potential(&self) -> bool {
        matches!(self, SpatialLoad::Force { frame: FrameDesc::World, .. }) && self.values().iter().all(Value::is_const)
    }

    /// Whether `add_stiffness` adds anything: a component whose gradient reads coordinates or
    /// points.
    pub fn has_stiffness(&self) -> bool {
        self.values().iter().any(Value::reads_positions)
    }
}
