//! A planar revolute joint with clearance (docs/loads.md, "Revolute joint with clearance"): a
//! journal of radius `R_J` (marker `journal`) moves inside a bearing of radius `R_B = R_J + c`
//! (marker `bearing`) with no constraint rows. With `e = r_J - r_B`, the eccentricity
//! `eps = |e|` and the normal `n = e / eps`, the penetration is `delta = eps - c`: free flight
//! while `delta <= 0`, contact otherwise, with the continuous dissipative Hertz law
//!
//! `F_n = max(0, K delta^p (1 + D delta'))`, `delta' = n . (v_J - v_B)`,
//!
//! `D = 3 (1 - c_e^2) / (4 v_0)` (Lankarani-Nikravesh) or `8 (1 - c_e) / (5 c_e v_0)` (Flores
//! et al.), `v_0` the reference impact velocity at which the law's restitution is `c_e` (a law
//! of the state alone: the docs argue why the impact velocity is not held as a discrete state).
//! The tangential force is Ambrosio's modified Coulomb law `F_t = -mu c_d(|v_t|) F_n sign(v_t)`
//! with `c_d` 0 below `v_1`, 1 above `v_2`, linear between; `v_t = t . (v_J - v_B) + R_J
//! omega_J - R_B omega_B` the slip at the contact point, `t = (-n_y, n_x)`. The force
//! `F = -F_n n + F_t t` acts on the journal at its contact point `r_J + R_J n` and its opposite
//! on the bearing at `r_B + R_B n`, so
//!
//! `Q = (r_J - r_B)_q^T F + (R_J phi_J - R_B phi_B)_q^T F_t`.
//!
//! At `qd = 0` only `K delta^p` acts, the gradient of `V = K delta^(p+1) / (p + 1)`: the
//! potential (`springs`); the rest, `-qd . (Q(q, qd) - Q(q, 0))`, is the dissipated power.

use crate::body::{Body, Marker, MarkerState};
use crate::constraint::BuildContext;
use crate::description::{ClearanceLaw, MarkerDesc};
use crate::error::{non_negative, positive, Error, Result};

/// The parameters of a clearance joint as described (`ForceDesc::RevoluteClearance`).
#[derive(Debug, Clone, Copy)]
pub struct ClearanceParams {
    pub clearance: f64,
    pub journal_radius: f64,
    pub stiffness: f64,
    pub exponent: f64,
    pub restitution: f64,
    pub impact_velocity: f64,
    pub law: ClearanceLaw,
    pub friction: f64,
    pub friction_velocities: [f64; 2],
}

#[derive(Debug, Clone)]
pub struct Clearance {
    pub journal: Marker,
    pub bearing: Marker,
    pub p: ClearanceParams,
    /// The hysteresis factor `D` of the normal law.
    pub hysteresis: f64,
}

/// The contact's state at one instant (a sensor row, [`Clearance::contact`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct Contact {
    pub eccentricity: f64,
    pub penetration: f64,
    pub normal_force: f64,
    pub tangential_force: f64,
    /// `n` (world), the journal's direction from the bearing's centre.
    pub normal: [f64; 2],
    /// `delta' = n . (v_J - v_B)`.
    pub rate: f64,
}

impl Clearance {
    pub fn from_desc(ctx: &BuildContext, item: &str, journal: &MarkerDesc, bearing: &MarkerDesc, p: ClearanceParams) -> Result<Clearance> {
        let (journal, bearing) = ctx.marker_pair(item, journal, bearing)?;
        non_negative(item, "clearance", p.clearance)?;
        non_negative(item, "journal_radius", p.journal_radius)?;
        positive(item, "stiffness", p.stiffness)?;
        if !p.exponent.is_finite() || p.exponent < 1.0 {
            return Err(Error::invalid(item, format!("exponent must be >= 1 and finite (1.5: Hertz), got {}", p.exponent)));
        }
        if !p.restitution.is_finite() || p.restitution <= 0.0 || p.restitution > 1.0 {
            return Err(Error::invalid(item, format!("restitution must lie in (0, 1], got {}", p.restitution)));
        }
        positive(item, "impact_velocity", p.impact_velocity)?;
        non_negative(item, "friction", p.friction)?;
        let [v1, v2] = p.friction_velocities;
        non_negative(item, "friction_velocities", v1)?;
        if !v2.is_finite() || v2 <= v1 {
            return Err(Error::invalid(item, format!("friction_velocities [v1, v2] need 0 <= v1 < v2, got {:?}", p.friction_velocities)));
        }
        let ce = p.restitution;
        let hysteresis = match p.law {
            ClearanceLaw::LankaraniNikravesh => 3.0 * (1.0 - ce * ce) / (4.0 * p.impact_velocity),
            ClearanceLaw::Flores => 8.0 * (1.0 - ce) / (5.0 * ce * p.impact_velocity),
        };
        Ok(Clearance { journal, bearing, p, hysteresis })
    }

    /// Ambrosio's dynamic correction coefficient `c_d(|v_t|)`.
    #[inline]
    fn slip_factor(&self, vt: f64) -> f64 {
        let [v1, v2] = self.p.friction_velocities;
        let s = vt.abs();
        if s <= v1 {
            0.0
        } else if s >= v2 {
            1.0
        } else {
            (s - v1) / (v2 - v1)
        }
    }

    /// The contact at the markers' states `sa` (journal), `sb` (bearing).
    #[inline]
    pub fn contact(&self, sa: &MarkerState, sb: &MarkerState) -> Contact {
        let e = [sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]];
        let eps = e[0].hypot(e[1]);
        let delta = eps - self.p.clearance;
        let mut c = Contact { eccentricity: eps, penetration: delta, ..Contact::default() };
        if delta <= 0.0 || eps == 0.0 {
            return c;
        }
        let n = [e[0] / eps, e[1] / eps];
        let dv = [sa.v[0] - sb.v[0], sa.v[1] - sb.v[1]];
        let rate = n[0] * dv[0] + n[1] * dv[1];
        let fn_ = (self.p.stiffness * delta.powf(self.p.exponent) * (1.0 + self.hysteresis * rate)).max(0.0);
        let rb = self.p.journal_radius + self.p.clearance;
        let vt = -n[1] * dv[0] + n[0] * dv[1] + self.p.journal_radius * sa.omega - rb * sb.omega;
        let ft = if self.p.friction > 0.0 && vt != 0.0 { -self.p.friction * self.slip_factor(vt) * fn_ * vt.signum() } else { 0.0 };
        c.normal = n;
        c.rate = rate;
        c.normal_force = fn_;
        c.tangential_force = ft;
        c
    }

    #[inline]
    pub fn add_to(&self, bodies: &[Body], q: &[f64], qd: &[f64], qvec: &mut [f64]) {
        let (sa, sb) = (self.journal.state(bodies, q, qd), self.bearing.state(bodies, q, qd));
        let c = self.contact(&sa, &sb);
        if c.normal_force == 0.0 {
            return;
        }
        let n = c.normal;
        let t = [-n[1], n[0]];
        let f = [-c.normal_force * n[0] + c.tangential_force * t[0], -c.normal_force * n[1] + c.tangential_force * t[1]];
        self.journal.add_point_jacobian(bodies, &sa, f, qvec);
        self.bearing.add_point_jacobian(bodies, &sb, [-f[0], -f[1]], qvec);
        if c.tangential_force != 0.0 {
            if self.journal.has_orientation() {
                self.journal.add_angle_jacobian(bodies, &sa, self.p.journal_radius * c.tangential_force, qvec);
            }
            if self.bearing.has_orientation() {
                let rb = self.p.journal_radius + self.p.clearance;
                self.bearing.add_angle_jacobian(bodies, &sb, -rb * c.tangential_force, qvec);
            }
        }
    }

    /// `add(i, j, K_ij)` of the normal force's position stiffness `K = -dQ/dq = J^T S J`, `J`
    /// the rows of `(r_J - r_B)_q`, `S = k_n n n^T + (F_n / eps) (I - n n^T)`, `k_n = p K
    /// delta^(p-1) (1 + D delta')` (for the implicit methods' Newton matrices). Left out, as for
    /// the loads: the friction's and `delta'`'s change with `q` and `(dJ^T/dq) F`. `px`, `py`:
    /// n-long scratch rows.
    pub fn add_stiffness(&self, bodies: &[Body], q: &[f64], qd: &[f64], px: &mut [f64], py: &mut [f64], add: &mut dyn FnMut(usize, usize, f64)) {
        let (sa, sb) = (self.journal.state(bodies, q, qd), self.bearing.state(bodies, q, qd));
        let c = self.contact(&sa, &sb);
        if c.normal_force == 0.0 {
            return;
        }
        let p = self.p.exponent;
        let kn = p * self.p.stiffness * c.penetration.powf(p - 1.0) * (1.0 + self.hysteresis * c.rate);
        let (n, g) = (c.normal, c.normal_force / c.eccentricity);
        let s = [[kn * n[0] * n[0] + g * (1.0 - n[0] * n[0]), (kn - g) * n[0] * n[1]], [(kn - g) * n[0] * n[1], kn * n[1] * n[1] + g * (1.0 - n[1] * n[1])]];
        for (row, w) in [(&mut *px, [1.0, 0.0]), (&mut *py, [0.0, 1.0])] {
            row.fill(0.0);
            self.journal.add_point_jacobian(bodies, &sa, w, row);
            self.bearing.add_point_jacobian(bodies, &sb, [-w[0], -w[1]], row);
        }
        let rows = [&*px, &*py];
        for i in 0..q.len() {
            let (ai, bi) = (rows[0][i], rows[1][i]);
            if ai == 0.0 && bi == 0.0 {
                continue;
            }
            for j in 0..q.len() {
                let (aj, bj) = (rows[0][j], rows[1][j]);
                if aj == 0.0 && bj == 0.0 {
                    continue;
                }
                add(i, j, ai * (s[0][0] * aj + s[0][1] * bj) + bi * (s[1][0] * aj + s[1][1] * bj));
            }
        }
    }

    /// `K delta^(p+1) / (p + 1)` in contact, 0 in free flight.
    pub fn potential(&self, bodies: &[Body], q: &[f64]) -> f64 {
        let zeros = vec![0.0; q.len()];
        let (sa, sb) = (self.journal.state(bodies, q, &zeros), self.bearing.state(bodies, q, &zeros));
        let delta = (sa.r[0] - sb.r[0]).hypot(sa.r[1] - sb.r[1]) - self.p.clearance;
        if delta <= 0.0 {
            return 0.0;
        }
        let p = self.p.exponent;
        self.p.stiffness * delta.powf(p + 1.0) / (p + 1.0)
    }

    /// `1/2 k_t delta_v^2` with the contact's tangent stiffness `k_t = p K delta^(p-1)` and the
    /// penetration's first-order change `delta_v = n . (v_J - v_B)` for the motion `v`.
    pub fn material_energy(&self, bodies: &[Body], q: &[f64], v: &[f64]) -> f64 {
        let (sa, sb) = (self.journal.state(bodies, q, v), self.bearing.state(bodies, q, v));
        let e = [sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]];
        let eps = e[0].hypot(e[1]);
        let delta = eps - self.p.clearance;
        if delta <= 0.0 || eps == 0.0 {
            return 0.0;
        }
        let rate = (e[0] * (sa.v[0] - sb.v[0]) + e[1] * (sa.v[1] - sb.v[1])) / eps;
        let p = self.p.exponent;
        0.5 * p * self.p.stiffness * delta.powf(p - 1.0) * rate * rate
    }
}

#[cfg(test)]
mod tests {
    use crate::data::Data;
    use crate::dynamics;
    use crate::model::Model;

    #[test]
    fn contact_stiffness_matches_differences() {
        // a journal at a rigid body's reference point (constant Jacobian) in a bearing on a
        // second body's: -dQ/dq at rest is exactly J^T S J
        let text = r#"{"bodies": [
            {"kind": "rigid", "name": "j", "mass": 1.0, "inertia": 0.01, "position": [0.0011, 0.0004], "angle": 0.3},
            {"kind": "rigid", "name": "b", "mass": 2.0, "inertia": 0.02, "position": [0.0, 0.0001], "angle": -0.2}],
          "forces": [{"kind": "revolute_clearance", "journal": {"body": "j"}, "bearing": {"body": "b"},
            "clearance": 0.001, "journal_radius": 0.01, "stiffness": 1e9, "restitution": 0.8,
            "impact_velocity": 1.0, "friction": 0.1}]}"#;
        let model = Model::from_json(text).unwrap();
        let mut data = Data::new(&model);
        let n = model.n;
        let q = model.q0.clone();
        let qd = vec![0.0; n];
        let mut k = vec![0.0; n * n];
        let mut c = vec![0.0; n * n];
        dynamics::mass_and_forces(&model, &mut data, 0.0, &q, &qd);
        dynamics::tangent_into(&model, &mut data, &q, &qd, &mut k, &mut c);
        let mut qv = q.clone();
        let h = 1e-9;
        let mut largest = 0.0_f64;
        for j in 0..n {
            qv[j] = q[j] + h;
            dynamics::mass_and_forces(&model, &mut data, 0.0, &qv, &qd);
            let fp = data.force.clone();
            qv[j] = q[j] - h;
            dynamics::mass_and_forces(&model, &mut data, 0.0, &qv, &qd);
            qv[j] = q[j];
            for i in 0..n {
                let fd = -(fp[i] - data.force[i]) / (2.0 * h);
                largest = largest.max(fd.abs());
                assert!((k[i * n + j] - fd).abs() < 1e-5 * (1.0 + fd.abs()), "K[{i}][{j}] = {} vs {fd}", k[i * n + j]);
            }
        }
        assert!(largest > 1e6, "the contact is closed: {largest}");
    }
}
