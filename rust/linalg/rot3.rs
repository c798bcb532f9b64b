//! Euler parameters (unit quaternions, scalar first) and the small vector algebra of the
//! spatial kinds (docs/spatial-design.md, section 2):
//!
//! `A(p) = (e0^2 - e.e) I + 2 e e^T + 2 e0 ~e` (body -> world; `|p|^2` times a rotation off
//! `|p| = 1`), `G(p) = [-e, -~e + e0 I]`, `E(p) = [-e, ~e + e0 I]`, `A = E G^T`,
//! `B(p, a) = d(A(p) a)/dp = 2 [(e0 I + ~e) a, e a^T - (e0 I + ~e) ~a]`.
//! Plain fixed-size arrays: nothing here allocates.

pub type V3 = [f64; 3];
pub type M3 = [[f64; 3]; 3];
/// A 3 x 4 matrix (rows).
pub type M34 = [[f64; 4]; 3];

#[inline]
pub fn dot(a: &V3, b: &V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub fn cross(a: &V3, b: &V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[inline]
pub fn sub(a: &V3, b: &V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub fn add(a: &V3, b: &V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub fn scale(s: f64, a: &V3) -> V3 {
    [s * a[0], s * a[1], s * a[2]]
}

#[inline]
pub fn norm(a: &V3) -> f64 {
    dot(a, a).sqrt()
}

#[inline]
pub fn mat_vec(m: &M3, v: &V3) -> V3 {
    [dot(&m[0], v), dot(&m[1], v), dot(&m[2], v)]
}

/// `m^T v`.
#[inline]
pub fn mat_t_vec(m: &M3, v: &V3) -> V3 {
    let mut o = [0.0; 3];
    for i in 0..3 {
        for j in 0..3 {
            o[j] += m[i][j] * v[i];
        }
    }
    o
}

#[inline]
pub fn m34_vec(b: &M34, x: &[f64]) -> V3 {
    let mut o = [0.0; 3];
    for i in 0..3 {
        o[i] = b[i][0] * x[0] + b[i][1] * x[1] + b[i][2] * x[2] + b[i][3] * x[3];
    }
    o
}

/// `b^T w` (4).
#[inline]
pub fn m34_t_vec(b: &M34, w: &V3) -> [f64; 4] {
    let mut o = [0.0; 4];
    for i in 0..3 {
        for l in 0..4 {
            o[l] += b[i][l] * w[i];
        }
    }
    o
}

/// `A(p)` (not normalized).
#[inline]
pub fn rot_a(p: &[f64]) -> M3 {
    let (e0, e1, e2, e3) = (p[0], p[1], p[2], p[3]);
    let d = e0 * e0 - e1 * e1 - e2 * e2 - e3 * e3;
    [
        [d + 2.0 * e1 * e1, 2.0 * (e1 * e2 - e0 * e3), 2.0 * (e1 * e3 + e0 * e2)],
        [2.0 * (e2 * e1 + e0 * e3), d + 2.0 * e2 * e2, 2.0 * (e2 * e3 - e0 * e1)],
        [2.0 * (e3 * e1 - e0 * e2), 2.0 * (e3 * e2 + e0 * e1), d + 2.0 * e3 * e3],
    ]
}

/// `G(p) = [-e, -~e + e0 I]`.
#[inline]
pub fn rot_g(p: &[f64]) -> M34 {
    let (e0, e1, e2, e3) = (p[0], p[1], p[2], p[3]);
    [[-e1, e0, e3, -e2], [-e2, -e3, e0, e1], [-e3, e2, -e1, e0]]
}

/// `E(p) = [-e, ~e + e0 I]`.
#[inline]
pub fn rot_e(p: &[f64]) -> M34 {
    let (e0, e1, e2, e3) = (p[0], p[1], p[2], p[3]);
    [[-e1, e0, -e3, e2], [-e2, e3, e0, -e1], [-e3, -e2, e1, e0]]
}

/// `B(p, a) = d(A(p) a)/dp = 2 [S a, e a^T - S ~a]` with `S = e0 I + ~e`; as
/// `~e ~a = a e^T - (e . a) I`, column `k` of the second block is
/// `2 (e a_k - a e_k + (e . a) e_k - e0 ~a e_k)`.
#[inline]
pub fn rot_b(p: &[f64], a: &V3) -> M34 {
    let (e0, e) = (p[0], [p[1], p[2], p[3]]);
    let ea = cross(&e, a);
    let ed = e[0] * a[0] + e[1] * a[1] + e[2] * a[2];
    // e0 ~a, row-major
    let t = [[0.0, -e0 * a[2], e0 * a[1]], [e0 * a[2], 0.0, -e0 * a[0]], [-e0 * a[1], e0 * a[0], 0.0]];
    let mut out = [[0.0; 4]; 3];
    for i in 0..3 {
        out[i][0] = 2.0 * (e0 * a[i] + ea[i]);
        for k in 0..3 {
            let d = if i == k { ed } else { 0.0 };
            out[i][k + 1] = 2.0 * (e[i] * a[k] - a[i] * e[k] + d - t[i][k]);
        }
    }
    out
}

/// `B(pd, a) pd = 2 A(pd) a`: the quadratic term of `d^2/dt^2 (A(p) a)`.
#[inline]
pub fn quad_term(pd: &[f64], a: &V3) -> V3 {
    scale(2.0, &mat_vec(&rot_a(pd), a))
}

/// Unit Euler parameters (`e0 >= 0`) of a rotation matrix (Shepperd's method).
pub fn p_from_matrix(r: &M3) -> [f64; 4] {
    let tr = r[0][0] + r[1][1] + r[2][2];
    let cand = [tr, r[0][0], r[1][1], r[2][2]];
    let mut k = 0;
    for i in 1..4 {
        if cand[i] > cand[k] {
            k = i;
        }
    }
    let mut p = [0.0; 4];
    if k == 0 {
        p[0] = 0.5 * (1.0 + tr).sqrt();
        let f = 0.25 / p[0];
        p[1] = (r[2][1] - r[1][2]) * f;
        p[2] = (r[0][2] - r[2][0]) * f;
        p[3] = (r[1][0] - r[0][1]) * f;
    } else {
        let i = k - 1;
        let (j, m) = ((i + 1) % 3, (i + 2) % 3);
        let ei = 0.5 * (1.0 + 2.0 * r[i][i] - tr).sqrt();
        let f = 0.25 / ei;
        p[1 + i] = ei;
        p[0] = (r[m][j] - r[j][m]) * f;
        p[1 + j] = (r[j][i] + r[i][j]) * f;
        p[1 + m] = (r[m][i] + r[i][m]) * f;
    }
    if p[0] < 0.0 {
        p = p.map(|x| -x);
    }
    let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]).sqrt();
    p.map(|x| x / n)
}

/// A right-handed frame (columns `x, y, z`) with `z` along `z` and `x` from the hint (`None`:
/// world `x`, or world `y` when `z` is near `x`). The caller has normalized `z`.
pub fn frame_from_z(z: &V3, x_hint: Option<&V3>) -> Option<M3> {
    let default = if z[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let h = x_hint.copied().unwrap_or(default);
    let x = sub(&h, &scale(dot(&h, z), z));
    let nx = norm(&x);
    if !(nx > 1e-12 * norm(&h)) || !nx.is_finite() {
        return None;
    }
    let x = scale(1.0 / nx, &x);
    let y = cross(z, &x);
    Some([[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]])
}

/// Column `k` of a 3x3 matrix.
#[inline]
pub fn col(m: &M3, k: usize) -> V3 {
    [m[0][k], m[1][k], m[2][k]]
}

/// `m1 m2`.
pub fn mat_mul(a: &M3, b: &M3) -> M3 {
    let mut o = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            o[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    o
}

pub fn transpose(a: &M3) -> M3 {
    let mut o = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            o[i][j] = a[j][i];
        }
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn b_is_the_derivative_of_a_times_a_vector() {
        let p = [0.7, -0.3, 0.5, 0.2];
        let a = [0.3, -1.1, 0.4];
        let b = rot_b(&p, &a);
        for l in 0..4 {
            let (mut pp, mut pm) = (p, p);
            pp[l] += 1e-6;
            pm[l] -= 1e-6;
            let d = sub(&mat_vec(&rot_a(&pp), &a), &mat_vec(&rot_a(&pm), &a));
            for i in 0..3 {
                assert!((d[i] / 2e-6 - b[i][l]).abs() < 1e-8, "B[{i}][{l}]");
            }
        }
        // A = E G^T and B(pd, a) pd = 2 A(pd) a
        let (e, g, aa) = (rot_e(&p), rot_g(&p), rot_a(&p));
        for i in 0..3 {
            for j in 0..3 {
                let s: f64 = (0..4).map(|k| e[i][k] * g[j][k]).sum();
                assert!((s - aa[i][j]).abs() < 1e-14);
            }
        }
        let bb = m34_vec(&rot_b(&p, &a), &p);
        let qa = quad_term(&p, &a);
        for i in 0..3 {
            assert!((bb[i] - qa[i]).abs() < 1e-14);
        }
    }

    #[test]
    fn quaternion_from_matrix_round_trips() {
        for p in [[0.9f64, 0.1, -0.3, 0.2], [0.1, 0.9, 0.3, -0.2], [0.05, -0.2, 0.1, 0.95], [0.0, 0.0, 1.0, 0.0]] {
            let n = (p.iter().map(|x| x * x).sum::<f64>()).sqrt();
            let p = p.map(|x| x / n);
            let q = p_from_matrix(&rot_a(&p));
            let s = if p[0] * q[0] + p[1] * q[1] + p[2] * q[2] + p[3] * q[3] < 0.0 { -1.0 } else { 1.0 };
            for k in 0..4 {
                assert!((s * q[k] - p[k]).abs() < 1e-14);
            }
        }
    }
}
