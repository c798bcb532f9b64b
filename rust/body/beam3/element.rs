//! One two-node Simo-Reissner element of a 3D beam (docs/spatial-flexible.md): the nodes carry
//! the coordinates of `rigid3` bodies, `x = [r_A (3), p_A (4), r_B (3), p_B (4)]`. With
//! `R = A(p) / |p|^2` and one-point (midpoint) integration over the reference length `L`:
//!
//! * `kappa = log(R_A^T R_B) / L`, the rotation vector of the relative rotation, from the
//!   relative quaternion `p_r = conj(p_A) p_B = (w, v)`: `log = 2 atan(|v| / w) / |v| * v`,
//!   written `2 h(u) v / w` with `u = |v|^2 / w^2` and `h(u) = atan(sqrt u) / sqrt u` (a series
//!   below `u = 1e-4`): scale-free in `p_A`, `p_B`, and the shortest rotation for either sign
//!   of `w` (`(w, v)` and `(-w, -v)` give the same value);
//! * `Gamma = R_m^T (r_B - r_A) / L - e_1` with `R_m = R_A exp(log(R_A^T R_B) / 2)`, the slerp
//!   midpoint, whose quaternion is `p_A / |p_A| + s p_B / |p_B|` (`s` the sign of `p_A . p_B`);
//! * `U = L / 2 (Gamma^T C_N Gamma + kappa^T C_M kappa)`, `C_N = diag(EA, kGA_y, kGA_z)`,
//!   `C_M = diag(GJ, EI_y, EI_z)`.
//!
//! `r_A`, `r_B` are the nodes' points: a node body's coordinate `r` is its centre of mass, which
//! sits at `c'` (body axes) from the node for the two end nodes (`beam3.rs`), so the node's
//! point is `r - R c'` (the `offsets`; zero for the interior nodes).
//!
//! The energy is written once over `T: Real` (`linalg::dual`): its gradient (the elastic forces
//! `Q = -dU/dx`) comes exact to rounding from `Dual<14>` and its Hessian (the tangent stiffness
//! `K = d^2 U / dx^2`) from `HyperDual<14>`, both on the stack. The strains are objective
//! (a rigid rotation of both nodes leaves them alone) and vanish in the straight reference
//! state, whose nodes share one orientation.

use crate::linalg::dual::{Dual, HyperDual, Real};

/// Number of coordinates of one element (two nodes of `[r, p]`).
pub const NX: usize = 14;

/// The element's constants: reference length and the diagonal section stiffnesses.
#[derive(Debug, Clone, Copy)]
pub struct ElementConsts {
    pub length: f64,
    /// `[EA, kGA_y, kGA_z]`.
    pub c_n: [f64; 3],
    /// `[GJ, EI_y, EI_z]`.
    pub c_m: [f64; 3],
    /// `c'` of the two node bodies: the centre of mass from the node, body axes.
    pub offsets: [[f64; 3]; 2],
}

/// `h(u) = atan(sqrt u) / sqrt u` and its first two derivatives.
fn atan_ratio(u: f64) -> (f64, f64, f64) {
    if u < 1e-4 {
        let h = 1.0 - u * (1.0 / 3.0 - u * (1.0 / 5.0 - u * (1.0 / 7.0 - u * (1.0 / 9.0 - u / 11.0))));
        let h1 = -1.0 / 3.0 + u * (2.0 / 5.0 - u * (3.0 / 7.0 - u * (4.0 / 9.0 - u * 5.0 / 11.0)));
        let h2 = 2.0 / 5.0 - u * (6.0 / 7.0 - u * (12.0 / 9.0 - u * 20.0 / 11.0));
        return (h, h1, h2);
    }
    let t = u.sqrt();
    let h = t.atan() / t;
    let h1 = (1.0 / (1.0 + u) - h) / (2.0 * u);
    let h2 = (-1.0 / ((1.0 + u) * (1.0 + u)) - h1) / (2.0 * u) - h1 / u;
    (h, h1, h2)
}

#[inline]
fn dot3<T: Real>(a: &[T; 3], b: &[T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn dot4<T: Real>(a: &[T; 4], b: &[T; 4]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// `A(p)^T d = (e0^2 - e.e) d + 2 e (e.d) - 2 e0 (e x d)` (`A` body -> world, `|p|^2` times a
/// rotation).
#[inline]
fn rot_t_vec<T: Real>(p: &[T; 4], d: &[T; 3]) -> [T; 3] {
    let e = [p[1], p[2], p[3]];
    let s = p[0] * p[0] - dot3(&e, &e);
    let ed = dot3(&e, d);
    let c = [e[1] * d[2] - e[2] * d[1], e[2] * d[0] - e[0] * d[2], e[0] * d[1] - e[1] * d[0]];
    [0, 1, 2].map(|i| s * d[i] + (e[i] * ed).scale(2.0) - (p[0] * c[i]).scale(2.0))
}

/// The node's point `r - A(p) c' / |p|^2` of a node body at `(r, p)`.
#[inline]
fn node_point<T: Real>(r: [T; 3], p: &[T; 4], c: &[f64; 3]) -> [T; 3] {
    if *c == [0.0; 3] {
        return r;
    }
    let e = [p[1], p[2], p[3]];
    let s = p[0] * p[0] - dot3(&e, &e);
    let ec = e[0].scale(c[0]) + e[1].scale(c[1]) + e[2].scale(c[2]);
    let x = [e[1].scale(c[2]) - e[2].scale(c[1]), e[2].scale(c[0]) - e[0].scale(c[2]), e[0].scale(c[1]) - e[1].scale(c[0])];
    let inv = dot4(p, p).recip();
    [0, 1, 2].map(|i| r[i] - (s.scale(c[i]) + (e[i] * ec).scale(2.0) + (p[0] * x[i]).scale(2.0)) * inv)
}

/// `(Gamma, kappa)` of the element at `x` (module docs).
pub fn strains<T: Real>(x: &[T; NX], el: &ElementConsts) -> ([T; 3], [T; 3]) {
    let inv_l = 1.0 / el.length;
    let pa = [x[3], x[4], x[5], x[6]];
    let pb = [x[10], x[11], x[12], x[13]];
    // p_r = conj(p_A) p_B (Hamilton product)
    let w = dot4(&pa, &pb);
    let (a0, a) = (pa[0], [pa[1], pa[2], pa[3]]);
    let (b0, b) = (pb[0], [pb[1], pb[2], pb[3]]);
    let axb = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let v = [0, 1, 2].map(|i| a0 * b[i] - b0 * a[i] - axb[i]);
    let u = dot3(&v, &v) / (w * w);
    let (h, h1, h2) = atan_ratio(u.val());
    let fac = u.unary(h, h1, h2) / w;
    let kappa = v.map(|vi| (fac * vi).scale(2.0 * inv_l));
    // the slerp midpoint
    let s = if w.val() >= 0.0 { 1.0 } else { -1.0 };
    let (ia, ib) = (dot4(&pa, &pa).sqrt().recip(), dot4(&pb, &pb).sqrt().recip().scale(s));
    let pm = [0, 1, 2, 3].map(|k| pa[k] * ia + pb[k] * ib);
    let nm2 = dot4(&pm, &pm);
    let ra = node_point([x[0], x[1], x[2]], &pa, &el.offsets[0]);
    let rb = node_point([x[7], x[8], x[9]], &pb, &el.offsets[1]);
    let d = [rb[0] - ra[0], rb[1] - ra[1], rb[2] - ra[2]];
    let md = rot_t_vec(&pm, &d);
    let scale = nm2.recip().scale(inv_l);
    let gamma = [md[0] * scale - T::cst(1.0), md[1] * scale, md[2] * scale];
    (gamma, kappa)
}

impl ElementConsts {
    /// `U(x)` over any scalar.
    pub fn energy<T: Real>(&self, x: &[T; NX]) -> T {
        let (g, k) = strains(x, self);
        let mut e = T::cst(0.0);
        for i in 0..3 {
            e = e + (g[i] * g[i]).scale(self.c_n[i]) + (k[i] * k[i]).scale(self.c_m[i]);
        }
        e.scale(0.5 * self.length)
    }

    /// `U` and `dU/dx` (exact to rounding; no allocation).
    pub fn gradient(&self, x: &[f64; NX]) -> (f64, [f64; NX]) {
        let xd: [Dual<NX>; NX] = std::array::from_fn(|i| Dual::var(x[i], i));
        let e = self.energy(&xd);
        (e.v, e.g)
    }

    /// `d^2 U / dx^2`, the tangent stiffness (exact to rounding).
    pub fn hessian(&self, x: &[f64; NX]) -> [[f64; NX]; NX] {
        let xd: [HyperDual<NX>; NX] = std::array::from_fn(|i| HyperDual::var(x[i], i));
        self.energy(&xd).h
    }

    /// `1/2 L (dGamma^T C_N dGamma + dkappa^T C_M dkappa)`: the material strain energy of the
    /// strain rates of a motion `v` at `x` (no stress terms).
    pub fn material_energy(&self, x: &[f64; NX], v: &[f64; NX]) -> f64 {
        let xd: [Dual<1>; NX] = std::array::from_fn(|i| Dual { v: x[i], g: [v[i]] });
        let (g, k) = strains(&xd, self);
        let s: f64 = (0..3).map(|i| self.c_n[i] * g[i].g[0] * g[i].g[0] + self.c_m[i] * k[i].g[0] * k[i].g[0]).sum();
        0.5 * self.length * s
    }

    /// Section forces and moments `[N, Q_y, Q_z, M_t, M_y, M_z]` (section axes): `C_N Gamma`,
    /// `C_M kappa`.
    pub fn section_forces(&self, x: &[f64; NX]) -> [f64; 6] {
        let (g, k) = strains(x, self);
        [self.c_n[0] * g[0], self.c_n[1] * g[1], self.c_n[2] * g[2], self.c_m[0] * k[0], self.c_m[1] * k[1], self.c_m[2] * k[2]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random element state near a bent, twisted and stretched configuration (unnormalized
    /// Euler parameters).
    fn state(seed: u64) -> [f64; NX] {
        let mut s = seed;
        let mut rnd = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut x = [0.0; NX];
        let pa = [1.0 + 0.2 * rnd(), 0.3 * rnd(), 0.3 * rnd(), 0.3 * rnd()];
        let pb = [pa[0] + 0.3 * rnd(), pa[1] + 0.3 * rnd(), pa[2] + 0.3 * rnd(), pa[3] + 0.3 * rnd()];
        x[3..7].copy_from_slice(&pa);
        x[10..14].copy_from_slice(&pb);
        for c in 0..3 {
            x[c] = 0.1 * rnd();
            x[7 + c] = x[c] + 0.1 * rnd() + if c == 0 { 0.5 } else { 0.0 };
        }
        x
    }

    const EL: ElementConsts = ElementConsts { length: 0.5, c_n: [3.0e3, 1.0e3, 1.3e3], c_m: [7.0, 11.0, 13.0], offsets: [[0.125, 0.0, 0.0], [-0.01, 0.02, 0.03]] };

    #[test]
    fn straight_reference_and_rigid_rotation_are_strain_free() {
        let h = 0.3f64;
        let p = [(0.5 * h).cos(), 0.0, (0.5 * h).sin() * 0.6, (0.5 * h).sin() * 0.8];
        let ax = crate::linalg::rot3::mat_vec(&crate::linalg::rot3::rot_a(&p), &[0.5, 0.0, 0.0]);
        let mut x = [0.0; NX];
        x[3..7].copy_from_slice(&p.map(|v| 2.0 * v));
        x[10..14].copy_from_slice(&p.map(|v| -0.5 * v));
        x[7..10].copy_from_slice(&ax);
        let (g, k) = strains(&x, &ElementConsts { offsets: [[0.0; 3]; 2], ..EL });
        for i in 0..3 {
            assert!(g[i].abs() < 1e-15 && k[i].abs() < 1e-15, "{g:?} {k:?}");
        }
    }

    #[test]
    fn gradient_and_hessian_match_central_differences() {
        for seed in 1..6 {
            let x = state(seed);
            let (e, g) = EL.gradient(&x);
            assert!((e - EL.energy(&x)).abs() <= 1e-14 * e.abs());
            let hs = EL.hessian(&x);
            let scale_g = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let scale_h = hs.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for j in 0..NX {
                let h = 1e-6;
                let (mut a, mut b) = (x, x);
                a[j] += h;
                b[j] -= h;
                let fd = (EL.energy(&a) - EL.energy(&b)) / (2.0 * h);
                assert!((fd - g[j]).abs() < 1e-7 * scale_g, "seed {seed} dU/dx[{j}]: {fd} vs {}", g[j]);
                let (ga, gb) = (EL.gradient(&a).1, EL.gradient(&b).1);
                for i in 0..NX {
                    let fd = (ga[i] - gb[i]) / (2.0 * h);
                    assert!((fd - hs[i][j]).abs() < 1e-6 * scale_h, "seed {seed} K[{i}][{j}]: {fd} vs {}", hs[i][j]);
                }
            }
        }
    }

    #[test]
    fn series_and_closed_form_of_h_meet() {
        let (a, b) = (atan_ratio(0.99999e-4), atan_ratio(1.00001e-4));
        assert!((a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-8 && (a.2 - b.2).abs() < 1e-7, "{a:?} {b:?}");
    }
}
