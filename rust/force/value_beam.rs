//! The beam displacement quantities a planar load's value may read (docs/loads.md, "Load
//! values"): `u(B, XI)`, `v(B, XI)`, `psi(B, XI)`, the axial and transverse displacement of the
//! axis point `XI` of beam `B` in its beam frame and the section's rotation relative to that
//! frame, exactly the output expressions of docs/outputs.md (`Body::beam_point`: an FFRF beam's
//! floating frame, an ANCF cable's chord frame of its ends), and their rates `d:u(B, XI)`, ...
//! Each is resolved once (the point's shape functions, the coordinates it reads) and read into
//! the expression as a variable (`value.rs`, `Input::Beam`), with its gradient in the stiffness.
//!
//! On an FFRF beam the three are linear in the elastic coordinates (`u = S_u q_f`, `v = S_v q_f`,
//! `psi = N_psi q_f`): the gradient is the shape row, and a rate does not change with the
//! positions. On an ANCF cable they are functions of the point's element vector and the two end
//! positions (12 numbers): value and gradient analytic; a rate is `grad . qd`, whose change with
//! the positions is taken by central differences of that analytic gradient (on the stack).
//!
//! The strains and internal forces `N`, `V`, `M`, `eps`, `kappa(B, XI)` (the outputs of the same
//! spelling) and their rates are read the same way; their shapes are `value_strain.rs`'.

use super::value_strain::{self, Section};
use crate::body::BodyKind;
use crate::constraint::BuildContext;
use crate::error::{Error, Result};

/// What the quantity is: `u`, `v` or `psi`; then the sections' `N`, `V`, `M`, `eps`, `kappa`
/// (`value_strain::NAMES`).
const NAMES: [&str; 8] = ["u", "v", "psi", "N", "V", "M", "eps", "kappa"];

/// The first section quantity in [`NAMES`].
const SECTION: usize = 3;

/// What the beam quantities look like, for messages.
pub const HELP: &str = ", u(BEAM, XI), v(BEAM, XI), psi(BEAM, XI) (a beam's displacement in its frame), N(BEAM, XI), V(...), M(...), eps(...), kappa(...) (its internal forces and strains) or their rates d:u(...), d:M(...)";

#[derive(Debug, Clone)]
enum Shape {
    /// FFRF beam: `sum c_k q[i_k]` over the elastic coordinates.
    Linear(Vec<(usize, f64)>),
    /// ANCF cable: the global indices of `[r(0), r(L), e]` (2 + 2 + 8), the point's shape
    /// values `s`, slopes `d` and its undeformed axial place `xi L`.
    Cable { idx: [usize; 12], s: [f64; 4], d: [f64; 4], x0: f64 },
    /// A strain or internal force (`value_strain.rs`).
    Section(Section),
}

/// One beam quantity a value reads.
#[derive(Debug, Clone)]
pub struct BeamQuantity {
    /// 0: u, 1: v, 2: psi; from `SECTION` on a section quantity (its `Shape` knows which).
    what: usize,
    pub rate: bool,
    shape: Shape,
}

/// A beam quantity parsed from the start of `s`: `(what, rate, body, xi text, length of the
/// text)`; `None` when `s` does not start with one.
pub fn parse(s: &str) -> Option<(usize, bool, &str, &str, usize)> {
    let (rate, rest) = match s.strip_prefix("d:") {
        Some(r) => (true, r),
        None => (false, s),
    };
    // no name is a prefix of another
    let what = NAMES.iter().position(|n| rest.starts_with(n))?;
    let inner = rest[NAMES[what].len()..].trim_start().strip_prefix('(')?;
    let close = inner.find(')')?;
    let (body, xi) = inner[..close].split_once(',')?;
    let body = body.trim();
    if body.is_empty() || !body.chars().all(|c| c.is_alphanumeric() || "_.:-".contains(c)) {
        return None;
    }
    Some((what, rate, body, xi.trim(), (s.len() - inner.len()) + close + 1))
}

/// The refusal of a sensor at the start of `s` that a load cannot read: a joint's reaction
/// depends on the accelerations, which depend on the load (an algebraic loop).
pub fn refused_sensor(s: &str) -> Option<String> {
    let reaction = s.strip_prefix("reaction").is_some_and(|r| r.trim_start().starts_with('('));
    reaction.then(|| "a joint's reaction is not a load input: it depends on the accelerations, which depend on the load (an algebraic loop); a friction force that follows the reaction is joint_friction, which closes that loop in each acceleration call".into())
}

impl BeamQuantity {
    /// Resolve `what(body, xi)`; `err` builds the expression's error at the quantity.
    pub fn new(ctx: &BuildContext, item: &str, what: usize, rate: bool, body: &str, xi: &str, err: &dyn Fn(String) -> Error) -> Result<BeamQuantity> {
        let name = NAMES[what];
        let Some(&bi) = ctx.index.get(body) else {
            let known: Vec<&str> = ctx.bodies.iter().map(|b| b.name.as_str()).collect();
            return Err(Error::UnknownBody { item: item.to_string(), body: body.to_string(), known: known.join(", ") });
        };
        let xi = match xi.parse::<f64>() {
            Ok(x) if x.is_finite() && (0.0..=1.0).contains(&x) => x,
            _ => return Err(err(format!("{name}({body}, {xi}): XI must be a number in [0, 1] (the place along the beam's axis), got '{xi}'"))),
        };
        let b = &ctx.bodies[bi];
        let shape = match &b.kind {
            BodyKind::Beam(k) if what >= SECTION => Shape::Section(Section::ffrf(k, b.offset, what - SECTION, xi)),
            BodyKind::Cable(k) if what >= SECTION => Shape::Section(Section::cable(k, b.offset, what - SECTION, xi)),
            BodyKind::Beam(k) => {
                let ps = k.point_shape(xi);
                Shape::Linear(ps.entries.iter().map(|&(i, su, sv, sp)| (b.offset + 3 + i, [su, sv, sp][what])).collect())
            }
            BodyKind::Cable(k) => {
                let p = k.point(xi);
                let n = 4 * k.elements;
                let mut idx = [0; 12];
                for (j, l) in [0, 1, n, n + 1].into_iter().chain(p.first..p.first + 8).enumerate() {
                    idx[j] = b.offset + l;
                }
                Shape::Cable { idx, s: p.s, d: p.d, x0: xi * k.length }
            }
            _ if what >= SECTION => {
                return Err(err(format!(
                    "{name}({body}, ...): body '{body}' ({}) has no beam axis; {} are a beam's (FFRF or ANCF) internal forces and strains",
                    b.kind_name(),
                    value_strain::NAMES.join(", ")
                )))
            }
            _ => {
                return Err(err(format!(
                    "{name}({body}, ...): body '{body}' ({}) has no beam axis; u, v and psi are a beam's (FFRF or ANCF) displacement; a point's position is x(BODY, XI), y(BODY, XI)",
                    b.kind_name()
                )))
            }
        };
        Ok(BeamQuantity { what, rate, shape })
    }

    /// The global coordinates it reads.
    pub fn coords(&self) -> Vec<usize> {
        match &self.shape {
            Shape::Linear(c) => c.iter().map(|&(i, _)| i).collect(),
            Shape::Cable { idx, .. } => idx.to_vec(),
            Shape::Section(s) => s.coords(),
        }
    }

    /// Its value (or rate) at `q`, `qd`.
    #[inline]
    pub fn value(&self, q: &[f64], qd: &[f64]) -> f64 {
        match &self.shape {
            Shape::Linear(c) => {
                let v = if self.rate { qd } else { q };
                c.iter().map(|&(i, a)| a * v[i]).sum()
            }
            Shape::Cable { idx, s, d, x0 } => {
                let x = idx.map(|i| q[i]);
                let (f, g) = cable(&x, s, d, *x0);
                if self.rate {
                    g[self.what].iter().zip(idx).map(|(gi, &i)| gi * qd[i]).sum()
                } else {
                    f[self.what]
                }
            }
            Shape::Section(sec) => sec.value(self.rate, q, qd),
        }
    }

    /// `row += w d(value)/dq`.
    pub fn add_gradient(&self, q: &[f64], qd: &[f64], w: f64, row: &mut [f64]) {
        match &self.shape {
            Shape::Linear(c) => {
                if !self.rate {
                    for &(i, a) in c {
                        row[i] += w * a;
                    }
                }
            }
            Shape::Cable { idx, s, d, x0 } => {
                let mut x = idx.map(|i| q[i]);
                if !self.rate {
                    let g = cable(&x, s, d, *x0).1[self.what];
                    for (gi, &i) in g.iter().zip(idx) {
                        row[i] += w * gi;
                    }
                    return;
                }
                let xd = idx.map(|i| qd[i]);
                value_strain::rate_position_gradient(&mut x, idx, |x| cable(x, s, d, *x0).1[self.what].iter().zip(&xd).map(|(g, v)| g * v).sum(), w, row);
            }
            Shape::Section(sec) => sec.add_gradient(self.rate, q, qd, w, row),
        }
    }
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `[u, v, psi]` of a cable's axis point and their gradients in `x = [r(0), r(L), e]`: `r = S e`,
/// `t = S' e`, chord `ch = r(L) - r(0)`, `c = ch / |ch|`, `d = r - r(0)`; `u = c . d - xi L`,
/// `v = c x d`, `psi = atan2(c x t, c . t)` (`ancf_cable::AncfCable::chord_displacement`). With
/// `n = (-c_y, c_x)`, `dc = n (n . dch) / |ch|`: `du = v (n . dch)/|ch| + c . dd`,
/// `dv = -(c . d)(n . dch)/|ch| + n . dd`, `dpsi = (t x dt)/|t|^2 - (n . dch)/|ch|`.
fn cable(x: &[f64; 12], s: &[f64; 4], d: &[f64; 4], x0: f64) -> ([f64; 3], [[f64; 12]; 3]) {
    let (mut r, mut t) = ([0.0; 2], [0.0; 2]);
    for a in 0..4 {
        for k in 0..2 {
            r[k] += s[a] * x[4 + 2 * a + k];
            t[k] += d[a] * x[4 + 2 * a + k];
        }
    }
    let ch = [x[2] - x[0], x[3] - x[1]];
    let len = ch[0].hypot(ch[1]);
    let c = [ch[0] / len, ch[1] / len];
    let n = [-c[1], c[0]];
    let dd = [r[0] - x[0], r[1] - x[1]];
    let (cd, v) = (c[0] * dd[0] + c[1] * dd[1], cross(c, dd));
    let f = [cd - x0, v, cross(c, t).atan2(c[0] * t[0] + c[1] * t[1])];
    let tt = t[0] * t[0] + t[1] * t[1];
    // the derivatives in the chord, the point's offset from r(0) and the slope
    let dch = [[v * n[0] / len, v * n[1] / len], [-cd * n[0] / len, -cd * n[1] / len], [-n[0] / len, -n[1] / len]];
    let ddd = [c, n, [0.0; 2]];
    let dt = [[0.0; 2], [0.0; 2], [-t[1] / tt, t[0] / tt]];
    let mut g = [[0.0; 12]; 3];
    for w in 0..3 {
        for k in 0..2 {
            g[w][k] = -dch[w][k] - ddd[w][k];
            g[w][2 + k] = dch[w][k];
            for a in 0..4 {
                g[w][4 + 2 * a + k] = s[a] * ddd[w][k] + d[a] * dt[w][k];
            }
        }
    }
    (f, g)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics;
    use crate::force::tests::{moving, stiffness_rows_against_differences};
    use crate::force::value_strain::tests::{along, scene};

    /// Where the displacement tests read.
    const DISPLACEMENT_XI: [f64; 6] = [0.3, 0.65, 0.9, 0.5, 0.85, 0.15];

    #[test]
    fn beam_quantities_are_the_outputs() {
        // the load's input against `Body::beam_point` (the outputs' u, v, psi) at a deformed,
        // moving state; a rate against central differences of beam_point along qd
        let (text, cases) = scene(3, &["u", "v", "psi", "d:u", "d:v", "d:psi"], &DISPLACEMENT_XI);
        let (model, mut data, q, qd) = moving(&text, 0.01, 0.5);
        dynamics::mass_and_forces(&model, &mut data, 0.0, &q, &qd);
        let h = 1e-6;
        let (qp, qm) = along(&q, &qd, h);
        for (k, (label, bi, name, xi, rate)) in cases.iter().enumerate() {
            let what = NAMES.iter().position(|n| n == name).unwrap();
            let beam = &model.bodies[*bi];
            let m = &model.bodies[3 + k];
            let expected = if *rate {
                (beam.beam_point(*xi, &qp).unwrap()[2 + what] - beam.beam_point(*xi, &qm).unwrap()[2 + what]) / (2.0 * h)
            } else {
                beam.beam_point(*xi, &q).unwrap()[2 + what]
            };
            let got = data.force[m.offset];
            assert!((got - expected).abs() < 1e-12 + 1e-7 * expected.abs(), "{label}: {got} vs {expected}");
            assert!(expected.abs() > 1e-4 || *xi == 0.0, "{label}: {expected} is no test");
        }
    }

    #[test]
    fn beam_quantity_stiffness_matches_differences() {
        // the point masses' rows of K = -dQ/dq (constant Jacobians: exactly -dF/dq; the beams'
        // own rows hold their inertia forces, which K leaves out) against central differences
        let (text, _) = scene(3, &["u", "v", "psi", "d:u", "d:v", "d:psi"], &DISPLACEMENT_XI);
        let k = stiffness_rows_against_differences(&text, 0.01, 0.5, |m, i| i >= m.bodies[3].offset);
        // the rows of the point masses (2 coordinates each, after the beams' 3 x 3 elements)
        let n = (k.len() as f64).sqrt() as usize;
        let loaded = k[(n - 36) * n..].iter().filter(|x| x.abs() > 1e-3).count();
        assert!(loaded > 60, "{loaded}");
    }

    #[test]
    fn cable_gradient_matches_differences() {
        let s = [0.2, 0.05, 0.8, -0.03];
        let d = [-1.1, 0.1, 1.1, 0.4];
        let x0 = [0.1, -0.2, 1.9, 0.4, 0.5, 0.1, 0.9, 0.3, 1.3, 0.2, 0.8, -0.4];
        let (_, g) = cable(&x0, &s, &d, 0.7);
        let h = 1e-6;
        for j in 0..12 {
            let (mut xp, mut xm) = (x0, x0);
            xp[j] += h;
            xm[j] -= h;
            let (fp, fm) = (cable(&xp, &s, &d, 0.7).0, cable(&xm, &s, &d, 0.7).0);
            for w in 0..3 {
                let fd = (fp[w] - fm[w]) / (2.0 * h);
                assert!((g[w][j] - fd).abs() < 1e-8, "{w} {j}: {} vs {fd}", g[w][j]);
            }
        }
        assert_eq!(parse("d:psi(bar, 0.5) + 1"), Some((2, true, "bar", "0.5", 15)));
        assert!(parse("psin(bar)").is_none() && parse("v(bar)").is_none());
    }
}
