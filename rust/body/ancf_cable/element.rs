//! The element-level kinematics of the ANCF cable (`ancf_cable.rs`): the cubic Hermite shape
//! functions and the strain measures at a quadrature point with their derivatives.

/// Hermite shape functions of an element of length `l` at local `s`: values, `d/dx`, `d2/dx2`.
#[inline]
pub fn hermite(s: f64, l: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let (s2, s3) = (s * s, s * s * s);
    (
        [1.0 - 3.0 * s2 + 2.0 * s3, l * (s - 2.0 * s2 + s3), 3.0 * s2 - 2.0 * s3, l * (s3 - s2)],
        [6.0 * (s2 - s) / l, 1.0 - 4.0 * s + 3.0 * s2, 6.0 * (s - s2) / l, 3.0 * s2 - 2.0 * s],
        [(12.0 * s - 6.0) / (l * l), (6.0 * s - 4.0) / l, (6.0 - 12.0 * s) / (l * l), (6.0 * s - 2.0) / l],
    )
}

/// The third derivatives (in x) of the Hermite shapes of an element of length `l`: constant.
pub fn hermite_third(l: f64) -> [f64; 4] {
    [12.0 / (l * l * l), 6.0 / (l * l), -12.0 / (l * l * l), 6.0 / (l * l)]
}

/// `sum_a c[a] e_a` for the element vector `e` (8 numbers, `e_a = (e[2a], e[2a + 1])`).
#[inline]
pub(super) fn map(c: &[f64; 4], e: &[f64]) -> [f64; 2] {
    let mut r = [0.0; 2];
    for a in 0..4 {
        r[0] += c[a] * e[2 * a];
        r[1] += c[a] * e[2 * a + 1];
    }
    r
}

#[inline]
pub(super) fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

#[inline]
pub(super) fn dot2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Strain measures at a quadrature point and their derivatives with respect to `(r', r'')`.
pub(super) struct Axial {
    /// `r'`, `|r'|`, `eps = |r'| - 1`.
    pub(super) rx: [f64; 2],
    pub(super) norm: f64,
    pub(super) eps: f64,
}

impl Axial {
    #[inline]
    pub(super) fn at(d: &[f64; 4], e: &[f64]) -> Axial {
        let rx = map(d, e);
        let norm = dot2(rx, rx).sqrt();
        Axial { rx, norm, eps: norm - 1.0 }
    }
}

pub(super) struct Bending {
    pub(super) rx: [f64; 2],
    pub(super) rxx: [f64; 2],
    /// `|r'|^2`, `r' x r''`, `K = (r' x r'') / |r'|^2`.
    pub(super) g: f64,
    pub(super) f: f64,
    pub(super) k: f64,
    /// `dK/dr'`, `dK/dr''`.
    pub(super) kr: [f64; 2],
    pub(super) krr: [f64; 2],
}

impl Bending {
    #[inline]
    pub(super) fn at(d: &[f64; 4], dd: &[f64; 4], e: &[f64]) -> Bending {
        let (rx, rxx) = (map(d, e), map(dd, e));
        let g = dot2(rx, rx);
        let f = cross(rx, rxx);
        let k = f / g;
        // df/dr' = (r''_y, -r''_x), df/dr'' = (-r'_y, r'_x), dg/dr' = 2 r'
        let kr = [(rxx[1] - 2.0 * k * rx[0]) / g, (-rxx[0] - 2.0 * k * rx[1]) / g];
        let krr = [-rx[1] / g, rx[0] / g];
        Bending { rx, rxx, g, f, k, kr, krr }
    }

    /// `d2K / dz2` in `z = (r'_x, r'_y, r''_x, r''_y)`:
    /// `f''/g - (f' g'^T + g' f'^T)/g^2 - f g''/g^2 + 2 f g' g'^T / g^3`.
    pub(super) fn hessian(&self) -> [[f64; 4]; 4] {
        let (rx, rxx, g, f) = (self.rx, self.rxx, self.g, self.f);
        let df = [rxx[1], -rxx[0], -rx[1], rx[0]];
        let dg = [2.0 * rx[0], 2.0 * rx[1], 0.0, 0.0];
        let mut h = [[0.0; 4]; 4];
        let (g2, g3) = (g * g, g * g * g);
        for i in 0..4 {
            for j in 0..4 {
                h[i][j] = -(df[i] * dg[j] + dg[i] * df[j]) / g2 + 2.0 * f * dg[i] * dg[j] / g3;
            }
        }
        // f'' (constant): d2f / dr'_x dr''_y = 1, d2f / dr'_y dr''_x = -1
        h[0][3] += 1.0 / g;
        h[3][0] += 1.0 / g;
        h[1][2] -= 1.0 / g;
        h[2][1] -= 1.0 / g;
        // g'' = diag(2, 2, 0, 0)
        h[0][0] -= 2.0 * f / g2;
        h[1][1] -= 2.0 * f / g2;
        h
    }
}
