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
//! `Q = -dU/dx`) and its Hessian (the tangent stiffness `K = d^2 U / dx^2`) come exact to
//! rounding from a dual and a hyper-dual pass in the 11 variables the strains depend on
//! (`d = r_B - r_A`, `p_A`, `p_B`) and the chain rule (`ElementConsts::hessian`), all on the
//! stack. The strains are objective
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
    let pa = [x[3], x[4], x[5], x[6]];
    let pb = [x[10], x[11], x[12], x[13]];
    let ra = node_point([x[0], x[1], x[2]], &pa, &el.offsets[0]);
    let rb = node_point([x[7], x[8], x[9]], &pb, &el.offsets[1]);
    strains_of(&[rb[0] - ra[0], rb[1] - ra[1], rb[2] - ra[2]], &pa, &pb, 1.0 / el.length)
}

/// `(Gamma, kappa)` from `d = r_B - r_A` (the nodes' points) and the two quaternions: the
/// strains see the positions only through `d`, 11 variables instead of 14 (`hessian`).
fn strains_of<T: Real>(d: &[T; 3], pa: &[T; 4], pb: &[T; 4], inv_l: f64) -> ([T; 3], [T; 3]) {
    // p_r = conj(p_A) p_B (Hamilton product)
    let w = dot4(pa, pb);
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
    let (ia, ib) = (dot4(pa, pa).sqrt().recip(), dot4(pb, pb).sqrt().recip().scale(s));
    let pm = [0, 1, 2, 3].map(|k| pa[k] * ia + pb[k] * ib);
    let nm2 = dot4(&pm, &pm);
    let md = rot_t_vec(&pm, d);
    let scale = nm2.recip().scale(inv_l);
    let gamma = [md[0] * scale - T::cst(1.0), md[1] * scale, md[2] * scale];
    (gamma, kappa)
}

/// The reduced variables of `hessian`: `y = [d, p_A, p_B]`.
const NY: usize = 11;
/// A hyper-dual number in the reduced variables (`NY (NY + 1) / 2` packed Hessian entries).
type HyperY = HyperDual<NY, 66>;
/// A hyper-dual number in one node's quaternion (the offset part of its point).
type HyperP = HyperDual<4, 10>;

/// `y = [d, p_A, p_B]` at `x` and `J = dy/dx`, from the offset parts `o = -A(p) c' / |p|^2` of
/// the two nodes' points (value and gradient in the node's quaternion): `d = (r_B + o_B) -
/// (r_A + o_A)`.
fn reduce(x: &[f64; NX], oa: [(f64, [f64; 4]); 3], ob: [(f64, [f64; 4]); 3]) -> ([f64; NY], [[f64; NX]; NY]) {
    let mut y = [0.0; NY];
    let mut jac = [[0.0; NX]; NY];
    for k in 0..3 {
        y[k] = (x[7 + k] + ob[k].0) - (x[k] + oa[k].0);
        jac[k][k] = -1.0;
        jac[k][7 + k] = 1.0;
        for m in 0..4 {
            jac[k][3 + m] = -oa[k].1[m];
            jac[k][10 + m] = ob[k].1[m];
        }
    }
    for m in 0..4 {
        (y[3 + m], y[7 + m]) = (x[3 + m], x[10 + m]);
        jac[3 + m][3 + m] = 1.0;
        jac[7 + m][10 + m] = 1.0;
    }
    (y, jac)
}

impl ElementConsts {
    /// `U(x)` over any scalar.
    pub fn energy<T: Real>(&self, x: &[T; NX]) -> T {
        let (g, k) = strains(x, self);
        self.energy_of(&g, &k)
    }

    /// `U` from the strains `(Gamma, kappa)`.
    fn energy_of<T: Real>(&self, g: &[T; 3], k: &[T; 3]) -> T {
        let mut e = T::cst(0.0);
        for i in 0..3 {
            e = e + (g[i] * g[i]).scale(self.c_n[i]) + (k[i] * k[i]).scale(self.c_m[i]);
        }
        e.scale(0.5 * self.length)
    }

    /// `U` and `dU/dx` (exact to rounding; no allocation): dual numbers in the reduced
    /// variables `y = [d, p_A, p_B]` and `dU/dx = J^T dU/dy` (`hessian`).
    pub fn gradient(&self, x: &[f64; NX]) -> (f64, [f64; NX]) {
        let zero = [Dual::<4>::cst(0.0); 3];
        let quat = |o: usize| -> [Dual<4>; 4] { std::array::from_fn(|m| Dual::var(x[o + m], m)) };
        let (oa, ob) = (node_point(zero, &quat(3), &self.offsets[0]), node_point(zero, &quat(10), &self.offsets[1]));
        let (y, jac) = reduce(x, oa.map(|o| (o.v, o.g)), ob.map(|o| (o.v, o.g)));
        let yd: [Dual<NY>; NY] = std::array::from_fn(|i| Dual::var(y[i], i));
        let e = self.energy_y(&yd);
        let mut g = [0.0; NX];
        for (ja, &ga) in jac.iter().zip(e.g.iter()) {
            for (gi, &j) in g.iter_mut().zip(ja.iter()) {
                *gi += ga * j;
            }
        }
        (e.v, g)
    }

    /// `U` in the reduced variables `y = [d, p_A, p_B]`.
    fn energy_y<T: Real>(&self, y: &[T; NY]) -> T {
        let (g, k) = strains_of(&[y[0], y[1], y[2]], &[y[3], y[4], y[5], y[6]], &[y[7], y[8], y[9], y[10]], 1.0 / self.length);
        self.energy_of(&g, &k)
    }

    /// `d^2 U / dx^2`, the tangent stiffness (exact to rounding), by the chain rule through the
    /// reduced variables `y = [d, p_A, p_B]` (`strains_of`; `d = r_B - r_A` of the nodes'
    /// points `r - A(p) c' / |p|^2`): `K = J^T (d^2 U / dy^2) J + sum_k dU/dd_k d^2 d_k / dx^2`
    /// with `J = dy/dx`, the second term in the quaternion blocks of nodes with an offset.
    /// The hyper-dual pass runs in 11 variables with a packed Hessian (66 entries) instead of
    /// 14 (196 as a full square): the same energy (`energy_of`), a third of the work.
    pub fn hessian(&self, x: &[f64; NX]) -> [[f64; NX]; NX] {
        // the offset parts o = -A(p) c' / |p|^2 of the two nodes' points, in p
        let zero = [HyperP::cst(0.0); 3];
        let quat = |o: usize| -> [HyperP; 4] { std::array::from_fn(|m| HyperP::var(x[o + m], m)) };
        let (oa, ob) = (node_point(zero, &quat(3), &self.offsets[0]), node_point(zero, &quat(10), &self.offsets[1]));
        let (y, jac) = reduce(x, oa.map(|o| (o.v, o.g)), ob.map(|o| (o.v, o.g)));
        let yd: [HyperY; NY] = std::array::from_fn(|i| HyperY::var(y[i], i));
        let u = self.energy_y(&yd);
        let hy = u.hessian();
        // t = Hy J, then K = J^T t (J's zeros skipped)
        let mut t = [[0.0; NX]; NY];
        for (ti, hi) in t.iter_mut().zip(hy.iter()) {
            for (h, ja) in hi.iter().zip(jac.iter()) {
                for (tij, jaj) in ti.iter_mut().zip(ja.iter()) {
                    *tij += h * jaj;
                }
            }
        }
        let mut out = [[0.0; NX]; NX];
        for (ja, ta) in jac.iter().zip(t.iter()) {
            for (oi, &jai) in out.iter_mut().zip(ja.iter()) {
                if jai != 0.0 {
                    for (oij, taj) in oi.iter_mut().zip(ta.iter()) {
                        *oij += jai * taj;
                    }
                }
            }
        }
        for k in 0..3 {
            let (ha, hb) = (oa[k].hessian(), ob[k].hessian());
            for m in 0..4 {
                for n in 0..4 {
                    out[3 + m][3 + n] -= u.g[k] * ha[m][n];
                    out[10 + m][10 + n] += u.g[k] * hb[m][n];
                }
            }
        }
        out
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

    /// The direct hyper-dual Hessian in all 14 coordinates (the definition the chain rule of
    /// `hessian` must reproduce).
    fn direct_hessian(el: &ElementConsts, x: &[f64; NX]) -> [[f64; NX]; NX] {
        let xd: [HyperDual<NX, 105>; NX] = std::array::from_fn(|i| HyperDual::var(x[i], i));
        el.energy(&xd).hessian()
    }

    #[test]
    fn chain_rule_hessian_equals_the_direct_one() {
        // with and without node offsets, near the reference and bent
        let no_offsets = ElementConsts { offsets: [[0.0; 3]; 2], ..EL };
        for el in [EL, no_offsets] {
            for seed in 1..8 {
                let x = state(seed);
                let (a, b) = (el.hessian(&x), direct_hessian(&el, &x));
                let scale = b.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
                for i in 0..NX {
                    for j in 0..NX {
                        assert!((a[i][j] - b[i][j]).abs() <= 1e-12 * scale, "seed {seed} K[{i}][{j}]: {} vs {}", a[i][j], b[i][j]);
                    }
                }
            }
        }
    }

    /// The cost of one element's tangent and forces (an internal figure, not a check):
    /// `cargo test --release --lib beam3::element::tests::cost -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn cost() {
        let xs: Vec<[f64; NX]> = (1..65).map(state).collect();
        let time = |name: &str, f: &dyn Fn(&[f64; NX]) -> f64| {
            let mut acc = 0.0;
            let reps = 200;
            let t0 = std::time::Instant::now();
            for _ in 0..reps {
                for x in &xs {
                    acc += f(std::hint::black_box(x));
                }
            }
            let ns = t0.elapsed().as_nanos() as f64 / (reps * xs.len()) as f64;
            println!("{name}: {ns:.0} ns per element ({acc:.3e})");
        };
        time("hessian, chain rule (11 variables, packed)", &|x| EL.hessian(x)[3][10]);
        time("hessian, direct (14 variables, packed)", &|x| direct_hessian(&EL, x)[3][10]);
        time("gradient, chain rule (Dual<11>)", &|x| EL.gradient(x).1[3]);
    }

    #[test]
    fn series_and_closed_form_of_h_meet() {
        let (a, b) = (atan_ratio(0.99999e-4), atan_ratio(1.00001e-4));
        assert!((a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-8 && (a.2 - b.2).abs() < 1e-7, "{a:?} {b:?}");
    }
}
