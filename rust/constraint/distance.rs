//! Distance constraint (massless rod between two markers): `|r_a - r_b| - length = 0`
//! (1 row). With `d = r_a - r_b`, `l = |d|`, `e = d / l`:
//! `A = e . (r_a - r_b)_q`, `gamma = -e . (h_a - h_b) - (|d_dot|^2 - (e . d_dot)^2) / l`.

use super::{Reaction, BuildContext, ConstraintOut};
use crate::body::{Body, Marker};
use crate::description::MarkerDesc;
use crate::error::{positive, Result};

#[derive(Debug, Clone)]
pub struct Distance {
    pub a: Marker,
    pub b: Marker,
    pub length: f64,
}

impl Distance {
    pub const ROWS: &'static [&'static str] = &[""];

    /// `length = None`: the distance between the markers at the initial guess.
    pub fn from_desc(ctx: &BuildContext, item: &str, a: &MarkerDesc, b: &MarkerDesc, length: Option<f64>) -> Result<Self> {
        let (a, b) = ctx.marker_pair(item, a, b)?;
        let length = match length {
            Some(l) => l,
            None => {
                let (sa, sb) = (ctx.state0(&a), ctx.state0(&b));
                (sa.r[0] - sb.r[0]).hypot(sa.r[1] - sb.r[1])
            }
        };
        let length = positive(item, "length (distance between the markers)", length)?;
        Ok(Distance { a, b, length })
    }

    #[inline]
    pub fn eval(&self, bodies: &[Body], q: &[f64], qd: &[f64], n: usize, out: &mut ConstraintOut) {
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        let d = [sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]];
        let dd = [sa.v[0] - sb.v[0], sa.v[1] - sb.v[1]];
        let l = d[0].hypot(d[1]);
        if let Some(phi) = out.phi.as_deref_mut() {
            phi[0] = l - self.length;
        }
        out.phi_t[0] = 0.0;
        if l == 0.0 {
            // direction undefined: the row drops out (the pseudoinverse reports the rank loss)
            out.gamma[0] = 0.0;
            return;
        }
        let e = [d[0] / l, d[1] / l];
        let layout = Some(out.layout);
        let row = &mut out.jac[0..n];
        self.a.add_point_jacobian_in(bodies, &sa, e, row, layout);
        self.b.add_point_jacobian_in(bodies, &sb, [-e[0], -e[1]], row, layout);
        let edd = e[0] * dd[0] + e[1] * dd[1];
        let hd = [sa.h[0] - sb.h[0], sa.h[1] - sb.h[1]];
        out.gamma[0] = -(e[0] * hd[0] + e[1] * hd[1]) - (dd[0] * dd[0] + dd[1] * dd[1] - edd * edd) / l;
    }

    /// Reaction on `a`'s body (force `-lambda e` along the rod, `e = (r_a - r_b)/l`; joint frame: x along `e`, so the local x component is the rod force, compression positive).
    pub fn reaction(&self, bodies: &[Body], q: &[f64], qd: &[f64], lam: &[f64]) -> Reaction {
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        let d = [sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]];
        let l = d[0].hypot(d[1]);
        if l == 0.0 {
            return Reaction::default();
        }
        Reaction { force: [-lam[0] * d[0] / l, -lam[0] * d[1] / l], torque: 0.0, frame: d[1].atan2(d[0]) }
    }
}
