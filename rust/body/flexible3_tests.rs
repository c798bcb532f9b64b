//! Checks of the flexible3 body against a body of point masses with random mode shapes, whose
//! kinetic energy is written from the positions `r + R(p) (u_i + S_i q_f)` alone: the mass
//! matrix, the quadratic velocity forces (Lagrange's equations by central differences), gravity
//! (virtual work), the explicit factor, and the markers' kinematics.

use super::flexible3::Flexible3;
use super::flexible3_stiffening::LOAD_CASES;
use super::marker3::{add_jacobian, Marker3};
use super::{Body, BodyKind};
use crate::description::spatial::{Flexible3Desc, Interface3Desc, Marker3Desc};
use crate::linalg::rot3::{mat_vec, rot_a, rot_b, V3};

const N: usize = 3;
const PTS: usize = 7;

/// A small deterministic generator (no dependency).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    fn v3(&mut self) -> V3 {
        [self.next(), self.next(), self.next()]
    }
}

/// Point masses `m_i` at `u_i` with mode shapes `S_i` (PTS x N vectors).
struct Cloud {
    m: Vec<f64>,
    u: Vec<V3>,
    s: Vec<Vec<V3>>,
}

fn cloud() -> Cloud {
    let mut g = Lcg(7);
    let m = (0..PTS).map(|_| 1.0 + 0.5 * g.next()).collect();
    let u = (0..PTS).map(|_| g.v3()).collect();
    let s = (0..PTS).map(|_| (0..N).map(|_| g.v3()).collect()).collect();
    Cloud { m, u, s }
}

fn desc(c: &Cloud) -> Flexible3Desc {
    let n1 = N + 1;
    let shape = |i: usize, a: usize| if a == 0 { c.u[i] } else { c.s[i][a - 1] };
    let mut first = vec![[0.0; 3]; n1];
    let mut second = vec![[[0.0; 3]; 3]; n1 * n1];
    for i in 0..PTS {
        for a in 0..n1 {
            for x in 0..3 {
                first[a][x] += c.m[i] * shape(i, a)[x];
            }
            for b in 0..n1 {
                for x in 0..3 {
                    for y in 0..3 {
                        second[a * n1 + b][x][y] += c.m[i] * shape(i, a)[x] * shape(i, b)[y];
                    }
                }
            }
        }
    }
    let k_ff = (0..N).map(|i| (0..N).map(|j| if i == j { 10.0 * (i + 1) as f64 } else { 1.0 }).collect()).collect();
    Flexible3Desc {
        name: "f".into(),
        mass: c.m.iter().sum(),
        first_moment: first,
        second_moment: second,
        k_ff,
        d_ff: None,
        geometric_stiffness: None,
        quadratic_strain: None,
        quadratic_strain_quartic: None,
        interfaces: vec![Interface3Desc { point: c.u[0], phi: c.s[0].clone(), psi: Some((0..N).map(|j| [0.1 * j as f64, -0.2, 0.3]).collect()) }],
        position: [0.0; 3],
        orientation: None,
        velocity: [0.0; 3],
        angular_velocity: [0.0; 3],
        elastic: None,
        elastic_rates: None,
    }
}

/// Kinetic energy of the cloud from the positions alone (`R = A(p) / |p|^2`, its rate from
/// `d/dt (A(p) a) = B(p, a) pd`).
fn kinetic(c: &Cloud, q: &[f64], qd: &[f64]) -> f64 {
    let p = &q[3..7];
    let pd = &qd[3..7];
    let p2: f64 = p.iter().map(|x| x * x).sum();
    let ppd: f64 = (0..4).map(|l| p[l] * pd[l]).sum();
    let a = rot_a(p);
    let mut t = 0.0;
    for i in 0..PTS {
        let mut u = c.u[i];
        let mut ud = [0.0; 3];
        for j in 0..N {
            for x in 0..3 {
                u[x] += c.s[i][j][x] * q[7 + j];
                ud[x] += c.s[i][j][x] * qd[7 + j];
            }
        }
        let b = rot_b(p, &u);
        let au = mat_vec(&a, &u);
        let aud = mat_vec(&a, &ud);
        let mut v = [0.0; 3];
        for x in 0..3 {
            let bpd: f64 = (0..4).map(|l| b[x][l] * pd[l]).sum();
            v[x] = qd[x] + bpd / p2 - 2.0 * ppd / (p2 * p2) * au[x] + aud[x] / p2;
        }
        t += 0.5 * c.m[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }
    t
}

fn state() -> (Vec<f64>, Vec<f64>) {
    let mut p = [0.8, -0.3, 0.4, 0.35];
    let n: f64 = p.iter().map(|x| x * x).sum::<f64>().sqrt();
    p.iter_mut().for_each(|x| *x /= n);
    let mut pd = [0.2, 0.5, -0.4, 0.1];
    let d: f64 = (0..4).map(|l| p[l] * pd[l]).sum();
    (0..4).for_each(|l| pd[l] -= d * p[l]);
    let q = vec![0.1, 0.2, 0.3, p[0], p[1], p[2], p[3], 0.05, -0.02, 0.03];
    let qd = vec![0.3, -0.1, 0.2, pd[0], pd[1], pd[2], pd[3], 0.4, 0.1, -0.3];
    (q, qd)
}

fn body() -> (Flexible3, Cloud) {
    let c = cloud();
    (Flexible3::from_desc(&desc(&c), "body 'f'").unwrap(), c)
}

#[test]
fn mass_matrix_is_the_clouds() {
    let (b, c) = body();
    let (q, _) = state();
    let mut bd = b.new_data();
    let mut f = vec![0.0; 7 + N];
    b.mass_and_forces(&mut bd, &q, &vec![0.0; 7 + N], None, &mut f);
    // 1/2 x^T M x = T(q, x) for velocities x tangent to |p| = 1 (the regularization is along p)
    let mut g = Lcg(3);
    for _ in 0..5 {
        let mut x: Vec<f64> = (0..7 + N).map(|_| g.next()).collect();
        let d: f64 = (0..4).map(|l| q[3 + l] * x[3 + l]).sum();
        (0..4).for_each(|l| x[3 + l] -= d * q[3 + l]);
        let mut mx = vec![0.0; 7 + N];
        b.mass_times(&bd, &x, &mut mx);
        let e: f64 = 0.5 * x.iter().zip(&mx).map(|(a, b)| a * b).sum::<f64>();
        let t = kinetic(&c, &q, &x);
        assert!((e - t).abs() < 1e-12 * t.abs().max(1.0), "{e} vs {t}");
        assert!((b.kinetic_energy(&bd, &x) - t).abs() < 1e-12 * t.abs().max(1.0));
    }
}

#[test]
fn velocity_forces_follow_from_lagrange() {
    let (b, c) = body();
    let (q, qd) = state();
    let nb = 7 + N;
    let mut f = vec![0.0; nb];
    let mut bd = b.new_data();
    // no elastic force: compare the inertial terms alone
    let mut b0 = b.clone();
    b0.k_ff.iter_mut().for_each(|x| *x = 0.0);
    b0.mass_and_forces(&mut bd, &q, &qd, None, &mut f);
    let h = 1e-4;
    let t = |q: &[f64], qd: &[f64]| kinetic(&c, q, qd);
    let mut expect = vec![0.0; nb];
    for l in 0..nb {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[l] += h;
        qm[l] -= h;
        let dtdq = (t(&qp, &qd) - t(&qm, &qd)) / (2.0 * h);
        let dtdqd = |q: &[f64]| {
            let (mut a, mut m) = (qd.clone(), qd.clone());
            a[l] += h;
            m[l] -= h;
            (t(q, &a) - t(q, &m)) / (2.0 * h)
        };
        let qf: Vec<f64> = (0..nb).map(|k| q[k] + h * qd[k]).collect();
        let qb: Vec<f64> = (0..nb).map(|k| q[k] - h * qd[k]).collect();
        expect[l] = dtdq - (dtdqd(&qf) - dtdqd(&qb)) / (2.0 * h);
    }
    // the p block up to a multiple of p (the normalization multiplier's direction)
    let pf: f64 = (0..4).map(|l| q[3 + l] * (f[3 + l] - expect[3 + l])).sum();
    for l in 0..nb {
        let d = f[l] - expect[l] - if (3..7).contains(&l) { pf * q[l] } else { 0.0 };
        assert!(d.abs() < 1e-6 * (1.0 + expect[l].abs()), "coordinate {l}: {} vs {}", f[l], expect[l]);
    }
}

#[test]
fn gravity_is_the_gradient_of_its_potential() {
    let (b, _) = body();
    check_gravity(&b);
    // with stress stiffening: the prestress's potential 1/2 q_f^T K_g(R^T g) q_f as well
    check_gravity(&stiffened().0);
}

fn check_gravity(b: &Flexible3) {
    let (q, _) = state();
    let g = [0.3, -9.81, 1.2];
    let mut f = vec![0.0; 7 + N];
    b.add_gravity(&q, &g, &mut f);
    let h = 1e-6;
    let mut e = vec![0.0; 7 + N];
    for l in 0..7 + N {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[l] += h;
        qm[l] -= h;
        e[l] = -(b.gravity_potential(&qp, &g) - b.gravity_potential(&qm, &g)) / (2.0 * h);
    }
    let pf: f64 = (0..4).map(|l| q[3 + l] * (f[3 + l] - e[3 + l])).sum();
    for l in 0..7 + N {
        let d = f[l] - e[l] - if (3..7).contains(&l) { pf * q[l] } else { 0.0 };
        assert!(d.abs() < 1e-7 * (1.0 + e[l].abs()), "coordinate {l}: {} vs {}", f[l], e[l]);
    }
}

#[test]
fn explicit_factor_inverts_the_regularized_block() {
    let (b, _) = body();
    let (mut q, qd) = state();
    q[3] *= 1.1; // |p| != 1 on purpose
    let mut bd = b.new_data();
    let mut f = vec![0.0; 7 + N];
    b.mass_and_forces(&mut bd, &q, &qd, None, &mut f);
    assert!(b.factor(&mut bd));
    for c in 0..7 + N {
        let mut x = vec![0.0; 7 + N];
        x[c] = 1.0;
        let mut y = vec![0.0; 7 + N];
        b.mass_times(&bd, &x, &mut y);
        b.finv(&bd, &mut y);
        b.finvt(&bd, &mut y);
        for i in 0..7 + N {
            assert!((y[i] - x[i]).abs() < 1e-11, "column {c}, entry {i}: {}", y[i]);
        }
    }
    // the normalization row maps onto the unit coordinate 6
    let mut a = vec![0.0; 7 + N];
    for l in 0..4 {
        a[3 + l] = 2.0 * q[3 + l];
    }
    b.finv(&bd, &mut a);
    for (i, v) in a.iter().enumerate() {
        let want = if i == 6 { b.inv_sqrt_k } else { 0.0 };
        assert!((v - want).abs() < 1e-12, "entry {i}: {v}");
    }
}

#[test]
fn marker_kinematics_by_differences() {
    let (b, c) = body();
    let bodies = vec![Body { name: "f".into(), offset: 0, n_coords: 7 + N, kind: BodyKind::Flexible3(b) }];
    let index = [("f".to_string(), 0usize)].into_iter().collect();
    let md = Marker3Desc { body: "f".into(), point: Some(c.u[0]), z: Some([0.3, 0.2, 1.0]), x: None };
    let mk = Marker3::from_desc("m", &md, &bodies, &index).unwrap();
    let bad = Marker3Desc { point: Some([9.0, 9.0, 9.0]), ..md.clone() };
    assert!(format!("{}", Marker3::from_desc("m", &bad, &bodies, &index).unwrap_err()).contains("interface node"));
    let (q, qd) = state();
    let nb = 7 + N;
    let st = mk.state(&bodies, &q, &qd);
    let h = 1e-6;
    let along = |s: f64| -> (Vec<f64>, Vec<f64>) { ((0..nb).map(|k| q[k] + s * qd[k]).collect(), qd.clone()) };
    for which in 0..4 {
        let kin = |s: &super::marker3::Marker3State| if which == 0 { s.point } else { s.axes[which - 1] };
        let k0 = kin(&st);
        // velocity = J qd, and J by rows through add_jacobian
        for x in 0..3 {
            let mut w = [0.0; 3];
            w[x] = 1.0;
            let mut row = vec![0.0; nb];
            add_jacobian(&bodies, &st, &k0, &w, &mut row, None);
            let jqd: f64 = row.iter().zip(&qd).map(|(a, b)| a * b).sum();
            assert!((jqd - k0.vd[x]).abs() < 1e-12, "quantity {which}: J qd {jqd} vs {}", k0.vd[x]);
            for l in 0..nb {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[l] += h;
                qm[l] -= h;
                let d = (kin(&mk.state(&bodies, &qp, &qd)).v[x] - kin(&mk.state(&bodies, &qm, &qd)).v[x]) / (2.0 * h);
                assert!((d - row[l]).abs() < 1e-7, "quantity {which}, component {x}, coordinate {l}: {d} vs {}", row[l]);
            }
        }
        // h = d/dt(J) qd: the second derivative along q(s) = q + s qd
        let (qp, v) = along(h);
        let (qm, _) = along(-h);
        for x in 0..3 {
            let dd = (kin(&mk.state(&bodies, &qp, &v)).vd[x] - kin(&mk.state(&bodies, &qm, &v)).vd[x]) / (2.0 * h);
            assert!((dd - k0.h[x]).abs() < 1e-6, "quantity {which}: h {} vs {dd}", k0.h[x]);
        }
    }
}

/// The cloud's body with random symmetric geometric stiffness matrices of the 12 load cases.
fn stiffened() -> (Flexible3, Vec<Vec<Vec<f64>>>) {
    let c = cloud();
    let mut d = desc(&c);
    let mut g = Lcg(11);
    let kg: Vec<Vec<Vec<f64>>> = (0..LOAD_CASES.len())
        .map(|_| {
            let a: Vec<Vec<f64>> = (0..N).map(|_| (0..N).map(|_| g.next()).collect()).collect();
            (0..N).map(|i| (0..N).map(|j| a[i][j] + a[j][i]).collect()).collect()
        })
        .collect();
    d.geometric_stiffness = Some(kg.clone());
    (Flexible3::from_desc(&d, "body 'f'").unwrap(), kg)
}

/// The body force per unit mass of load case `c` at `x` (fe3_stiffening.py's definitions).
fn case_force(c: usize, x: &V3) -> V3 {
    let e = |k: usize| -> V3 { [0, 1, 2].map(|i| if i == k { 1.0 } else { 0.0 }) };
    if c < 6 {
        let (k, l) = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)][c];
        // (tr E I - E) x, E = e_k e_l^T (+ e_l e_k^T)
        let mut em = [[0.0; 3]; 3];
        em[k][l] += 1.0;
        if k != l {
            em[l][k] += 1.0;
        }
        let tr = em[0][0] + em[1][1] + em[2][2];
        let ex = mat_vec(&em, x);
        return [0, 1, 2].map(|i| tr * x[i] - ex[i]);
    }
    if c < 9 {
        let ek = e(c - 6);
        return [0, 1, 2].map(|i| -(ek[(i + 1) % 3] * x[(i + 2) % 3] - ek[(i + 2) % 3] * x[(i + 1) % 3]));
    }
    e(c - 9)
}

#[test]
fn stress_stiffening_forces_and_tangent() {
    let (b, kg) = stiffened();
    let (plain, _) = body();
    let (q, qd) = state();
    let (r, w, _) = Flexible3::frame(&q[3..7], &qd[3..7]);
    let v = crate::linalg::rot3::mat_t_vec(&r, &[qd[0], qd[1], qd[2]]);
    // the applied load factors, recovered from the body force they must reproduce: the
    // centrifugal -w x (w x x) and the velocity part of the frame acceleration -(w x v)
    let lambda = [w[0] * w[0], w[1] * w[1], w[2] * w[2], w[0] * w[1], w[1] * w[2], w[2] * w[0], 0.0, 0.0, 0.0];
    let wv = crate::linalg::rot3::cross(&w, &v);
    let mut g = Lcg(5);
    for _ in 0..3 {
        let x = g.v3();
        let wx = crate::linalg::rot3::cross(&w, &x);
        let want = crate::linalg::rot3::cross(&w, &wx).map(|y| -y);
        let mut mine = [0.0; 3];
        for c in 0..12 {
            let l = if c < 9 { lambda[c] } else { -wv[c - 9] };
            let f = case_force(c, &x);
            (0..3).for_each(|i| mine[i] += l * f[i]);
        }
        for i in 0..3 {
            assert!((mine[i] - (want[i] - wv[i])).abs() < 1e-12, "{mine:?} {want:?} {wv:?}");
        }
    }
    let (mut bd, mut bd0) = (b.new_data(), plain.new_data());
    let (mut f, mut f0) = (vec![0.0; 7 + N], vec![0.0; 7 + N]);
    b.mass_and_forces(&mut bd, &q, &qd, None, &mut f);
    plain.mass_and_forces(&mut bd0, &q, &qd, None, &mut f0);
    for j in 0..7 + N {
        let mut want = 0.0;
        if j >= 7 {
            for c in 0..12 {
                let l = if c < 9 { lambda[c] } else { -wv[c - 9] };
                want -= l * (0..N).map(|k| kg[c][j - 7][k] * q[7 + k]).sum::<f64>();
            }
        }
        assert!((f[j] - f0[j] - want).abs() < 1e-12 * (1.0 + want.abs()), "coordinate {j}: {} vs {want}", f[j] - f0[j]);
    }
    // the tangent -dQ_f/dq_f against central differences
    let mut kt = vec![0.0; (7 + N) * (7 + N)];
    b.tangent(&q, &qd, &mut |i, j, x| kt[i * (7 + N) + j] += x, &mut |_, _, _| {});
    let h = 1e-6;
    for l in 7..7 + N {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[l] += h;
        qm[l] -= h;
        let (mut fp, mut fm) = (vec![0.0; 7 + N], vec![0.0; 7 + N]);
        b.mass_and_forces(&mut bd, &qp, &qd, None, &mut fp);
        b.mass_and_forces(&mut bd, &qm, &qd, None, &mut fm);
        for j in 7..7 + N {
            // the quadratic velocity forces depend on q_f as well: compare the difference to the
            // plain body's
            let (mut gp, mut gm) = (vec![0.0; 7 + N], vec![0.0; 7 + N]);
            plain.mass_and_forces(&mut bd0, &qp, &qd, None, &mut gp);
            plain.mass_and_forces(&mut bd0, &qm, &qd, None, &mut gm);
            let num = -((fp[j] - gp[j]) - (fm[j] - gm[j])) / (2.0 * h);
            let mut kp = vec![0.0; (7 + N) * (7 + N)];
            plain.tangent(&q, &qd, &mut |i, jj, x| kp[i * (7 + N) + jj] += x, &mut |_, _, _| {});
            let ana = kt[j * (7 + N) + l] - kp[j * (7 + N) + l];
            assert!((num - ana).abs() < 1e-6 * (1.0 + ana.abs()), "({j}, {l}): {num} vs {ana}");
        }
    }
}

#[test]
fn quadratic_strain_force_and_tangent_by_differences() {
    // random symmetric G_k (T_kij symmetric in (i, j) only, as the FE's are)
    let c = cloud();
    let mut d = desc(&c);
    let mut g = Lcg(13);
    let gk: Vec<Vec<Vec<f64>>> = (0..N)
        .map(|_| {
            let a: Vec<Vec<f64>> = (0..N).map(|_| (0..N).map(|_| g.next()).collect()).collect();
            (0..N).map(|i| (0..N).map(|j| 50.0 * (a[i][j] + a[j][i])).collect()).collect()
        })
        .collect();
    d.quadratic_strain = Some(gk);
    // H_ijkl = sum_p w_p b_ij^p b_kl^p from random symmetric b^p: the symmetries of int B_ij : C : B_kl
    let bs: Vec<Vec<f64>> = (0..4)
        .map(|_| {
            let a: Vec<f64> = (0..N * N).map(|_| g.next()).collect();
            (0..N * N).map(|x| a[x] + a[(x % N) * N + x / N]).collect()
        })
        .collect();
    d.quadratic_strain_quartic = Some((0..N * N).map(|r| (0..N * N).map(|c| bs.iter().map(|b| 30.0 * b[r] * b[c]).sum()).collect()).collect());
    let b = Flexible3::from_desc(&d, "body 'f'").unwrap();
    let (plain, _) = body();
    let (q, qd) = state();
    let m = 7 + N;
    let v3 = |x: &[f64]| b.strain_energy(x) - plain.strain_energy(x);
    let force = |x: &[f64]| {
        let (mut f, mut f0) = (vec![0.0; m], vec![0.0; m]);
        b.mass_and_forces(&mut b.new_data(), x, &qd, None, &mut f);
        plain.mass_and_forces(&mut plain.new_data(), x, &qd, None, &mut f0);
        (0..m).map(|j| f[j] - f0[j]).collect::<Vec<f64>>()
    };
    assert!(v3(&q).abs() > 1e-3, "the cubic energy is not exercised: {}", v3(&q));
    let f = force(&q);
    let mut kt = vec![0.0; m * m];
    b.tangent(&q, &qd, &mut |i, j, x| kt[i * m + j] += x, &mut |_, _, _| {});
    plain.tangent(&q, &qd, &mut |i, j, x| kt[i * m + j] -= x, &mut |_, _, _| {});
    let h = 1e-5;
    for l in 0..m {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[l] += h;
        qm[l] -= h;
        // the force is -dV3/dq (zero on the frame's coordinates)
        let num = -(v3(&qp) - v3(&qm)) / (2.0 * h);
        assert!((num - f[l]).abs() < 1e-6 * (1.0 + num.abs()), "force {l}: {} vs {num}", f[l]);
        if l < 7 {
            continue;
        }
        let (fp, fm) = (force(&qp), force(&qm));
        for j in 0..m {
            let num = -(fp[j] - fm[j]) / (2.0 * h);
            let ana = kt[j * m + l];
            assert!((num - ana).abs() < 1e-6 * (1.0 + ana.abs()), "tangent ({j}, {l}): {ana} vs {num}");
        }
    }
    // the tangent is symmetric (a Hessian)
    for i in 0..m {
        for j in 0..m {
            assert!((kt[i * m + j] - kt[j * m + i]).abs() < 1e-12 * (1.0 + kt[i * m + j].abs()));
        }
    }
}
