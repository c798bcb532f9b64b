//! Rigid body: coordinates `(x, y, theta)` of a reference point and the body angle; the centre
//! of mass sits at `com` in the body frame. Mass block `[[m I, A J m com], [., J_ref]]`.

use super::frame::{add_frame_gravity, add_frame_point_jacobian, frame_mass_block, frame_mass_moment, frame_point_state, frame_sin_cos};
use super::{finite_vec2, InitialState, MarkerState};
use serde_json::{Map, Value};
use crate::description::{MarkerDesc, RigidDesc};
use crate::error::{positive, Error, Result};
use crate::linalg::{cholesky3, solve_lower3, solve_upper3};

#[derive(Debug, Clone)]
pub struct Rigid {
    pub mass: f64,
    /// Moment of inertia about the centre of mass.
    pub inertia: f64,
    /// Centre of mass in the body frame.
    pub com: [f64; 2],
    /// Moment of inertia about the reference point: `I_c + m |com|^2`.
    pub j_ref: f64,
}

/// Workspace of a rigid body.
#[derive(Debug, Clone, Default)]
pub struct RigidData {
    /// Mass block (symmetric 3x3) at the last `mass_and_forces`.
    pub m_rr: [[f64; 3]; 3],
    /// Its lower Cholesky factor.
    pub ls: [[f64; 3]; 3],
}

impl Rigid {
    pub fn from_desc(d: &RigidDesc, item: &str) -> Result<Rigid> {
        let mass = positive(item, "mass", d.mass)?;
        // A body without rotational inertia is a point mass (kind "point_mass"): its angle would
        // not be determined by the dynamics.
        let inertia = positive(item, "inertia", d.inertia)?;
        let com = finite_vec2(item, "com", d.com)?;
        let j_ref = inertia + mass * (com[0] * com[0] + com[1] * com[1]);
        if !j_ref.is_finite() {
            return Err(Error::invalid(item, format!("inertia about the reference point overflows: {j_ref}")));
        }
        Ok(Rigid { mass, inertia, com, j_ref })
    }

    pub fn initial_state(&self, d: &RigidDesc, item: &str) -> Result<InitialState> {
        let p = finite_vec2(item, "position", d.position)?;
        let v = finite_vec2(item, "velocity", d.velocity)?;
        Ok(InitialState {
            q: vec![p[0], p[1], d.angle],
            qd: vec![v[0], v[1], d.angular_velocity],
            names: ["x", "y", "theta"].map(String::from).to_vec(),
        })
    }

    pub fn new_data(&self) -> RigidData {
        RigidData::default()
    }

    fn sig(&self) -> [f64; 2] {
        [self.mass * self.com[0], self.mass * self.com[1]]
    }

    /// `Q_v = thd^2 A sig` (centripetal) plus gravity.
    #[inline]
    pub fn mass_and_forces(&self, bd: &mut RigidData, q: &[f64], qd: &[f64], gravity: Option<[f64; 2]>, f: &mut [f64]) {
        let thd = qd[2];
        let (s, c) = frame_sin_cos(q[2]);
        bd.m_rr = frame_mass_block(self.mass, self.sig(), self.j_ref, c, s);
        // A sig = (m_rr[1][2], -m_rr[0][2])
        f[0] = thd * thd * bd.m_rr[1][2];
        f[1] = -thd * thd * bd.m_rr[0][2];
        f[2] = 0.0;
        if let Some(g) = gravity {
            add_frame_gravity(self.mass, &bd.m_rr, g, f);
        }
    }

    #[inline]
    pub fn factor(&self, bd: &mut RigidData) -> bool {
        bd.ls = bd.m_rr;
        cholesky3(&mut bd.ls)
    }

    #[inline]
    pub fn finv(&self, bd: &RigidData, v: &mut [f64]) {
        solve_lower3(&bd.ls, v);
    }

    #[inline]
    pub fn finvt(&self, bd: &RigidData, v: &mut [f64]) {
        solve_upper3(&bd.ls, v);
    }

    pub fn dense_block(&self, bd: &RigidData, put: &mut impl FnMut(usize, usize, f64)) {
        for i in 0..3 {
            for j in 0..3 {
                put(i, j, bd.m_rr[i][j]);
            }
        }
    }

    /// `out += M_b x`.
    pub fn mass_times(&self, bd: &RigidData, x: &[f64], out: &mut [f64]) {
        for i in 0..3 {
            out[i] += bd.m_rr[i][0] * x[0] + bd.m_rr[i][1] * x[1] + bd.m_rr[i][2] * x[2];
        }
    }

    pub fn kinetic_energy(&self, bd: &RigidData, qd: &[f64]) -> f64 {
        let mut e = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                e += qd[i] * bd.m_rr[i][j] * qd[j];
            }
        }
        0.5 * e
    }

    /// `int rho r dV = m R + A sig`.
    pub fn mass_moment(&self, q: &[f64]) -> [f64; 2] {
        frame_mass_moment(self.mass, self.sig(), q)
    }
}

/// A marker on a rigid body is a body-frame point.
pub fn marker_point(md: &MarkerDesc, body: &str, item: &str) -> Result<[f64; 2]> {
    if md.xi.is_some() {
        return Err(Error::invalid(item, format!("a marker on rigid body '{body}' is given by a point, not by xi")));
    }
    finite_vec2(item, "marker point", md.point.unwrap_or([0.0, 0.0]))
}

#[inline]
pub fn marker_state(p: &[f64; 2], angle: f64, q: &[f64], qd: &[f64]) -> MarkerState {
    frame_point_state(*p, [0.0, 0.0], angle, 0.0, q, qd)
}

#[inline]
pub fn add_point_jacobian(ms: &MarkerState, w: [f64; 2], row: &mut [f64]) {
    add_frame_point_jacobian(ms, w, row);
}

#[inline]
pub fn add_angle_jacobian(w: f64, row: &mut [f64]) {
    row[2] += w;
}

impl Rigid {
    /// Inspection entries (`inspect.rs`).
    pub fn info(&self, m: &mut Map<String, Value>) {
        m.insert("inertia".into(), self.inertia.into());
        m.insert("com".into(), self.com.to_vec().into());
    }
}

impl Rigid {
    /// The body-frame points that draw it (`outline.rs`): its centre of mass alone, a bar
    /// symmetric about it through one attachment point, or a star from it to every attachment.
    pub fn outline_points(&self, attach: &[[f64; 2]]) -> Vec<super::marker::MarkerShape> {
        use super::marker::MarkerShape::Rigid as P;
        let c = self.com;
        match attach {
            [] => vec![P(c)],
            [p] => vec![P(*p), P([2.0 * c[0] - p[0], 2.0 * c[1] - p[1]])],
            _ => attach.iter().flat_map(|p| [P(c), P(*p), P(c)]).collect(),
        }
    }
}
