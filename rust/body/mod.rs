//! Bodies and markers. A closed set of body kinds, dispatched with `match` in the hot path.

pub mod ffrf_beam;
pub mod rigid;

pub use ffrf_beam::{Beam, PointShape};
pub use rigid::Rigid;

#[derive(Debug, Clone)]
pub enum BodyKind {
    Rigid(Rigid),
    Beam(Beam),
}

#[derive(Debug, Clone)]
pub struct Body {
    pub name: String,
    /// Index of the body's first coordinate in `q`.
    pub offset: usize,
    /// 3 + n_f.
    pub n_coords: usize,
    pub kind: BodyKind,
}

impl Body {
    pub fn n_f(&self) -> usize {
        self.n_coords - 3
    }
}

/// Where a marker sits on its body.
#[derive(Debug, Clone)]
pub enum MarkerShape {
    /// A point in the frame of a rigid body or of the ground.
    Point([f64; 2]),
    /// An axis point of a beam (elastic displacement included).
    Beam(PointShape),
}

/// A point and a frame attached to a body (`body == None` for the ground).
#[derive(Debug, Clone)]
pub struct Marker {
    pub body: Option<usize>,
    pub angle: f64,
    pub shape: MarkerShape,
}

/// Kinematics of a marker at one state (world frame).
#[derive(Debug, Clone, Copy, Default)]
pub struct MarkerState {
    /// Position.
    pub r: [f64; 2],
    /// Frame angle (`theta + angle + psi`).
    pub phi: f64,
    /// Velocity.
    pub v: [f64; 2],
    /// Angular velocity of the frame.
    pub omega: f64,
    /// Velocity-dependent part of the acceleration: `r_dd = r_q q_dd + h` (`(r_q qd)_q qd`).
    pub h: [f64; 2],
    /// `d r / d theta` of the carrying body.
    pub r_theta: [f64; 2],
    /// cos and sin of the body angle.
    pub cs: [f64; 2],
}

impl Marker {
    /// Evaluate position, velocity and velocity terms at `(q, qd)`.
    #[inline]
    pub fn state(&self, bodies: &[Body], q: &[f64], qd: &[f64]) -> MarkerState {
        let Some(bi) = self.body else {
            let p = match &self.shape {
                MarkerShape::Point(p) => *p,
                MarkerShape::Beam(_) => unreachable!("ground markers are points"),
            };
            return MarkerState { r: p, phi: self.angle, cs: [1.0, 0.0], ..Default::default() };
        };
        let body = &bodies[bi];
        let o = body.offset;
        let (th, thd) = (q[o + 2], qd[o + 2]);
        let (s, c) = th.sin_cos();
        // local point (body frame) and its elastic velocity in the body frame
        let mut pl: [f64; 2];
        let (mut vl, mut psi, mut psid) = ([0.0; 2], 0.0, 0.0);
        match &self.shape {
            MarkerShape::Point(p) => pl = *p,
            MarkerShape::Beam(ps) => {
                pl = [ps.x, 0.0];
                let qf = &q[o + 3..o + body.n_coords];
                let qfd = &qd[o + 3..o + body.n_coords];
                for &(i, su, sv, sp) in &ps.entries {
                    pl[0] += su * qf[i];
                    pl[1] += sv * qf[i];
                    vl[0] += su * qfd[i];
                    vl[1] += sv * qfd[i];
                    psi += sp * qf[i];
                    psid += sp * qfd[i];
                }
            }
        }
        let pw = [c * pl[0] - s * pl[1], s * pl[0] + c * pl[1]];
        let vw = [c * vl[0] - s * vl[1], s * vl[0] + c * vl[1]];
        let r_theta = [-pw[1], pw[0]];
        MarkerState {
            r: [q[o] + pw[0], q[o + 1] + pw[1]],
            phi: th + self.angle + psi,
            v: [qd[o] + thd * r_theta[0] + vw[0], qd[o + 1] + thd * r_theta[1] + vw[1]],
            omega: thd + psid,
            // -theta_dot^2 A u + 2 theta_dot A J S qd_f
            h: [-thd * thd * pw[0] - 2.0 * thd * vw[1], -thd * thd * pw[1] + 2.0 * thd * vw[0]],
            r_theta,
            cs: [c, s],
        }
    }

    /// `row += w . d r / d q` (row spans all of `q`).
    #[inline]
    pub fn add_point_jacobian(&self, bodies: &[Body], ms: &MarkerState, w: [f64; 2], row: &mut [f64]) {
        let Some(bi) = self.body else { return };
        let o = bodies[bi].offset;
        row[o] += w[0];
        row[o + 1] += w[1];
        row[o + 2] += w[0] * ms.r_theta[0] + w[1] * ms.r_theta[1];
        if let MarkerShape::Beam(ps) = &self.shape {
            let [c, s] = ms.cs;
            // w . A (S_u, S_v)
            let (wa0, wa1) = (w[0] * c + w[1] * s, -w[0] * s + w[1] * c);
            for &(i, su, sv, _) in &ps.entries {
                row[o + 3 + i] += wa0 * su + wa1 * sv;
            }
        }
    }

    /// `row += w . d phi / d q`.
    #[inline]
    pub fn add_angle_jacobian(&self, bodies: &[Body], w: f64, row: &mut [f64]) {
        let Some(bi) = self.body else { return };
        let o = bodies[bi].offset;
        row[o + 2] += w;
        if let MarkerShape::Beam(ps) = &self.shape {
            for &(i, _, _, sp) in &ps.entries {
                row[o + 3 + i] += w * sp;
            }
        }
    }
}
