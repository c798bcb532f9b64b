//! Regularized Coulomb and viscous friction in a planar revolute or prismatic joint, from the
//! joint's reaction (docs/loads.md, "Joint friction"):
//!
//! * revolute: torque `T = -mu r |F| sat(w / v_eps) - c w` on `a`, `-T` on `b`, `F` the
//!   reaction force (the joint's two multipliers), `w = omega_a - omega_b`, `r` the pin radius;
//! * prismatic: force `F_t = -mu N_eff sat(v / v_eps) - c v` along `b`'s axis on `a` (at `a`'s
//!   point), `-F_t` on `b`, `v` the sliding rate; `N_eff = |N|` (the normal force; the
//!   reaction moment `M` left out), or with a slider of length `L` centred at `a`'s point
//!   carried at its two ends, `N_eff = |N/2 + M/L| + |N/2 - M/L| = max(|N|, 2 |M| / L)`.
//!
//! `sat(x) = clamp(x, -1, 1)`: exact Coulomb friction above the regularization speed `v_eps`,
//! a linear viscous ramp below it. The friction force is a function of the joint's
//! multipliers `lambda` and of `(q, qd)`; the multipliers depend on it: the loop is closed by
//! the UK kernel (`uk::friction`). This file is the element: its build rules, its kinematics
//! (the slip rate `v = g . qd` and its generalized direction `g`, with `Q_f = F g`) and the law
//! `F(v, lambda)` with its derivative in `lambda`. The per-call buffers are `FrictionWork`.

use crate::body::{Body, Marker};
use crate::constraint::{Constraint, ConstraintKind};
use crate::error::{non_negative, positive, Error, Result};

/// The default regularization speed `v_eps` [m/s or rad/s]: below it the friction force is a
/// viscous ramp to the Coulomb value. A sticking joint creeps at `|v| <= v_eps` (exactly
/// `v_eps F_needed / (mu N)` on a constant load); the ramp's damping `mu N / v_eps` is the
/// stiffness an explicit method must resolve (docs/loads.md argues the value).
pub const DEFAULT_V_EPS: f64 = 1e-3;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact {
    /// Revolute: the pin radius.
    Pin { radius: f64 },
    /// Prismatic: the slider length (`None`: the reaction moment is left out).
    Slide { length: Option<f64> },
    /// Spatial joints (`friction3.rs`, with the joint's markers in `JointFriction::pair`).
    Spatial(super::friction3::Contact3),
}

pub use super::friction3::MAX_ROWS;

#[derive(Debug, Clone)]
pub struct JointFriction {
    /// Index of the joint in `Model::constraints` (joints come first, in their order).
    pub joint: usize,
    pub a: Marker,
    pub b: Marker,
    pub contact: Contact,
    pub mu: f64,
    pub damping: f64,
    pub v_eps: f64,
    /// A spatial joint's markers (`a`, `b` are then their planar handles, `Marker3::base`).
    pub pair: Option<crate::constraint::spatial::Pair>,
}

impl JointFriction {
    #[allow(clippy::too_many_arguments)]
    pub fn from_desc(item: &str, joints: &[Constraint], joint: &str, mu: f64, radius: Option<f64>, length: Option<f64>, damping: f64, v_eps: Option<f64>) -> Result<Self> {
        let Some(ji) = joints.iter().position(|c| c.name == joint) else {
            return Err(Error::UnknownName { what: format!("joint (of {item})"), name: joint.to_string(), valid: joints.iter().map(|c| c.name.clone()).collect() });
        };
        let mu = non_negative(item, "mu", mu)?;
        let damping = non_negative(item, "damping", damping)?;
        let v_eps = positive(item, "v_eps", v_eps.unwrap_or(DEFAULT_V_EPS))?;
        let (a, b, contact) = match &joints[ji].kind {
            ConstraintKind::Revolute(r) => {
                if length.is_some() {
                    return Err(Error::invalid(item, format!("length is the slider length of a prismatic joint; '{joint}' is a revolute joint (give radius)")));
                }
                let Some(radius) = radius else {
                    return Err(Error::invalid(item, format!("the revolute joint '{joint}' needs the pin radius (radius=, the friction torque's lever)")));
                };
                let radius = non_negative(item, "radius", radius)?;
                for m in [&r.a, &r.b] {
                    if !m.has_orientation() {
                        return Err(Error::invalid(item, format!("friction in the revolute joint '{joint}' is a torque between its two marker frames; a point mass has no orientation (use a rigid body or a beam)")));
                    }
                }
                (r.a.clone(), r.b.clone(), Contact::Pin { radius })
            }
            ConstraintKind::Prismatic(p) => {
                if radius.is_some() {
                    return Err(Error::invalid(item, format!("radius is the pin radius of a revolute joint; '{joint}' is a prismatic joint (give length, or nothing)")));
                }
                let length = length.map(|l| positive(item, "length", l)).transpose()?;
                (p.a.clone(), p.b.clone(), Contact::Slide { length })
            }
            other => {
                let kind = match other {
                    ConstraintKind::PointOnLine(_) => "point_on_line",
                    ConstraintKind::Weld(_) => "weld",
                    ConstraintKind::Distance(_) => "distance",
                    _ => "spatial",
                };
                return Err(Error::invalid(item, format!("joint friction works in revolute and prismatic joints; '{joint}' is a {kind} joint")));
            }
        };
        Ok(JointFriction { joint: ji, a, b, contact, mu, damping, v_eps, pair: None })
    }

    /// Friction in a spatial joint (`friction3.rs` checks it against its joint).
    pub fn from_desc3(item: &str, constraints: &[Constraint], d: &crate::description::spatial::JointFriction3Desc) -> Result<Self> {
        let p = super::friction3::parse(item, constraints, d)?;
        let v_eps = positive(item, "v_eps", d.v_eps.unwrap_or(DEFAULT_V_EPS))?;
        let (a, b) = (p.pair.i.base.clone(), p.pair.j.base.clone());
        Ok(JointFriction { joint: p.joint, a, b, contact: Contact::Spatial(p.contact), mu: p.mu, damping: p.damping, v_eps, pair: Some(p.pair) })
    }

    /// The slip rate `v` at `(q, qd)` (relative angular rate of a revolute, sliding rate of a
    /// prismatic along `b`'s axis) and its generalized direction `g = dv/dqd` added into `g`;
    /// `aux`: what the law needs of the state besides the multipliers (a spatial joint's axis).
    #[inline]
    pub fn kinematics(&self, bodies: &[Body], q: &[f64], qd: &[f64], g: &mut [f64], aux: &mut [f64; 3]) -> f64 {
        if let (Contact::Spatial(c), Some(pair)) = (self.contact, &self.pair) {
            return super::friction3::kinematics(c, pair, bodies, q, qd, g, aux);
        }
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        match self.contact {
            Contact::Pin { .. } => {
                self.a.add_angle_jacobian(bodies, &sa, 1.0, g);
                self.b.add_angle_jacobian(bodies, &sb, -1.0, g);
                sa.omega - sb.omega
            }
            Contact::Slide { .. } => {
                let (s, c) = sb.phi.sin_cos();
                self.a.add_point_jacobian(bodies, &sa, [c, s], g);
                self.b.add_point_jacobian(bodies, &sb, [-c, -s], g);
                c * (sa.v[0] - sb.v[0]) + s * (sa.v[1] - sb.v[1])
            }
            Contact::Spatial(_) => unreachable!("a spatial contact has its pair"),
        }
    }

    /// The regularized direction `sat(v / v_eps)` in `[-1, 1]`.
    #[inline]
    pub fn direction(&self, v: f64) -> f64 {
        (v / self.v_eps).clamp(-1.0, 1.0)
    }

    /// `mu` times the lever (the pin radius; 1 for a slider): the Coulomb force per unit
    /// effective normal force.
    #[inline]
    pub fn coulomb(&self) -> f64 {
        match self.contact {
            Contact::Pin { radius } => self.mu * radius,
            Contact::Slide { .. } => self.mu,
            Contact::Spatial(c) => self.mu * c.lever(),
        }
    }

    /// The effective normal force `N_eff` from the joint's multipliers (its first rows) and
    /// its gradient `dN_eff / dlambda` (a subgradient at the kinks: 0 at a zero reaction);
    /// `aux` from `kinematics`.
    #[inline]
    pub fn normal(&self, lam: &[f64], aux: &[f64; 3]) -> (f64, [f64; MAX_ROWS]) {
        let mut g = [0.0; MAX_ROWS];
        let n = match self.contact {
            Contact::Pin { .. } => {
                let n = lam[0].hypot(lam[1]);
                if n != 0.0 {
                    (g[0], g[1]) = (lam[0] / n, lam[1] / n);
                }
                n
            }
            Contact::Slide { length: None } => {
                g[0] = sign(lam[0]);
                lam[0].abs()
            }
            Contact::Slide { length: Some(l) } => {
                let (n, m) = (lam[0].abs(), 2.0 * lam[1].abs() / l);
                if n >= m {
                    g[0] = sign(lam[0]);
                    n
                } else {
                    g[1] = 2.0 * sign(lam[1]) / l;
                    m
                }
            }
            Contact::Spatial(c) => c.normal(lam, aux, &mut g),
        };
        (n, g)
    }
}

fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// The friction elements' per-call buffers (`Data::friction`, present when the model has any),
/// sized once: per element its generalized direction `g` (n), slip rate, regularized direction,
/// the response of `qdd` (n) and of the multipliers (m) to a unit friction force, and the
/// Newton system of the closure (`uk::friction`).
#[derive(Debug, Clone)]
pub struct FrictionWork {
    /// Per element: (index in `Model::forces`, the joint's first row).
    pub items: Vec<(usize, usize)>,
    /// Per element: how many of its joint's rows the law reads (at most `MAX_ROWS`), and the
    /// state its law needs besides them (`JointFriction::kinematics`).
    pub rows: Vec<usize>,
    pub aux: Vec<[f64; 3]>,
    pub n: usize,
    pub m: usize,
    pub g: Vec<f64>,
    pub v: Vec<f64>,
    pub s: Vec<f64>,
    /// The friction forces (torques) of the last closed acceleration.
    pub f: Vec<f64>,
    pub dqdd: Vec<f64>,
    pub dlam: Vec<f64>,
    pub qdd0: Vec<f64>,
    pub lam0: Vec<f64>,
    pub gamma: Vec<f64>,
    pub jac: Vec<f64>,
    pub res: Vec<f64>,
    /// Newton iterations of the last closure.
    pub iterations: usize,
}

impl FrictionWork {
    /// The workspace of `forces` (`None` without friction elements); `constraints` give the
    /// joints' rows.
    pub fn new(forces: &[super::Force], constraints: &[Constraint], n: usize, m: usize) -> Option<Box<FrictionWork>> {
        let items: Vec<(usize, usize)> = forces
            .iter()
            .enumerate()
            .filter_map(|(i, f)| match &f.kind {
                super::ForceKind::JointFriction(fr) => Some((i, constraints[fr.joint].row)),
                _ => None,
            })
            .collect();
        if items.is_empty() {
            return None;
        }
        let k = items.len();
        let rows = items
            .iter()
            .map(|&(i, _)| match &forces[i].kind {
                super::ForceKind::JointFriction(fr) => constraints[fr.joint].rows().min(MAX_ROWS),
                _ => 0,
            })
            .collect();
        Some(Box::new(FrictionWork {
            items,
            rows,
            aux: vec![[0.0; 3]; k],
            n,
            m,
            g: vec![0.0; k * n],
            v: vec![0.0; k],
            s: vec![0.0; k],
            f: vec![0.0; k],
            dqdd: vec![0.0; k * n],
            dlam: vec![0.0; k * m],
            qdd0: vec![0.0; n],
            lam0: vec![0.0; m],
            gamma: vec![0.0; m],
            jac: vec![0.0; k * k],
            res: vec![0.0; k],
            iterations: 0,
        }))
    }

    /// The element of item `i`.
    #[inline]
    pub fn element<'a>(&self, forces: &'a [super::Force], i: usize) -> &'a JointFriction {
        match &forces[self.items[i].0].kind {
            super::ForceKind::JointFriction(fr) => fr,
            _ => unreachable!("FrictionWork::items index friction elements"),
        }
    }

    /// Slip rates, directions and generalized directions at `(q, qd)` (after the bodies'
    /// `mass_and_forces`, which this does not change).
    pub fn prepare(&mut self, forces: &[super::Force], bodies: &[Body], q: &[f64], qd: &[f64]) {
        let n = self.n;
        for i in 0..self.items.len() {
            let fr = self.element(forces, i);
            let g = &mut self.g[i * n..(i + 1) * n];
            g.fill(0.0);
            self.v[i] = fr.kinematics(bodies, q, qd, g, &mut self.aux[i]);
            self.s[i] = fr.direction(self.v[i]);
        }
    }

    /// The friction force of item `i` at the multipliers `lam` (all m), with `dF/dN_eff` and
    /// the gradient of `N_eff` in the joint's two multipliers.
    #[inline]
    pub fn force_at(&self, forces: &[super::Force], i: usize, lam: &[f64]) -> (f64, f64, [f64; MAX_ROWS]) {
        let fr = self.element(forces, i);
        let r0 = self.items[i].1;
        let (neff, grad) = fr.normal(&lam[r0..r0 + self.rows[i]], &self.aux[i]);
        let k = -fr.coulomb() * self.s[i];
        (k * neff - fr.damping * self.v[i], k, grad)
    }

    /// `out += sum_i F_i(lam) g_i`: the friction forces at given multipliers (the implicit
    /// methods' residual, whose multipliers are unknowns: there the loop closes in their
    /// Newton iteration). After `prepare` at the state.
    pub fn add_forces(&self, forces: &[super::Force], lam: &[f64], out: &mut [f64]) {
        let n = self.n;
        for i in 0..self.items.len() {
            let (f, _, _) = self.force_at(forces, i, lam);
            for (o, g) in out.iter_mut().zip(&self.g[i * n..(i + 1) * n]) {
                *o += f * g;
            }
        }
    }

    /// The multipliers' block of the implicit methods' Newton matrices: the friction forces'
    /// dependence on their joints' multipliers, `-dQ_f/dlambda` at `lam` (all m) with the slip
    /// rates and directions at `(q, qd)` (this calls `prepare`). `Q_f = sum_i F_i g_i` and
    /// `dF_i/dlambda_r = -k_i s_i dN_i/dlambda_r` on the joint's two rows, so `add(r, j, v)`
    /// receives `v = k_i s_i (dN_i/dlambda_r) g_ij` for each row `r` of element `i`'s joint and
    /// coordinate `j` with `g_ij != 0`: it belongs on `A^T`'s entry `(j, r)` of the residual's
    /// derivative `A^T - dQ_f/dlambda` (docs/loads.md, "What the methods see").
    pub fn add_multiplier_jacobian(&mut self, forces: &[super::Force], bodies: &[Body], q: &[f64], qd: &[f64], lam: &[f64], add: &mut impl FnMut(usize, usize, f64)) {
        self.prepare(forces, bodies, q, qd);
        let n = self.n;
        for i in 0..self.items.len() {
            let (_, slope, grad) = self.force_at(forces, i, lam);
            let r0 = self.items[i].1;
            for (dr, dn) in grad.iter().enumerate() {
                let c = -slope * dn;
                if c == 0.0 {
                    continue;
                }
                for (j, &g) in self.g[i * n..(i + 1) * n].iter().enumerate() {
                    if g != 0.0 {
                        add(r0 + dr, j, c * g);
                    }
                }
            }
        }
    }

    /// `out += sum_i F_i g_i` with the forces of the last closure (`f`).
    pub fn add_closed_forces(&self, out: &mut [f64]) {
        let n = self.n;
        for (i, f) in self.f.iter().enumerate() {
            for (o, g) in out.iter_mut().zip(&self.g[i * n..(i + 1) * n]) {
                *o += f * g;
            }
        }
    }

    /// The power `sum_i F_i v_i` of the friction forces of the last closure (<= 0).
    pub fn power(&self) -> f64 {
        self.f.iter().zip(&self.v).map(|(f, v)| f * v).sum()
    }
}
