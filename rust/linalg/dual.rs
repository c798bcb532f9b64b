//! Forward-mode automatic differentiation for small generic energies: a scalar trait [`Real`]
//! implemented by `f64`, by [`Dual<N>`] (value and gradient in `N` seeded directions) and by
//! [`HyperDual<N, M>`] (value, gradient and the Hessian's `M = N (N + 1) / 2` packed entries). A function written once over `T: Real`
//! gives its value, its exact gradient (to rounding) and its exact Hessian; everything lives on
//! the stack (no allocation per call). Only the operations the elements need: `+ - * /`, and
//! unary functions given with their first two derivatives (`Real::unary`; `sqrt` is one).
//!
//! The chain rule of a unary `f` on a hyper-dual `a = (v, g, H)`:
//! `f(a) = (f(v), f'(v) g, f'(v) H + f''(v) g g^T)`; products and quotients follow from the
//! product rule (`H_ab = a H_b + b H_a + g_a g_b^T + g_b g_a^T`) and `1 / b` as a unary.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// A real scalar for generic energies.
pub trait Real: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self> {
    /// A constant (zero derivatives).
    fn cst(x: f64) -> Self;
    /// The value (derivatives dropped).
    fn val(&self) -> f64;
    /// `f(self)` from `f(v), f'(v), f''(v)` at the value `v`.
    fn unary(self, f: f64, df: f64, d2f: f64) -> Self;
    /// `self * s` for a plain number.
    fn scale(self, s: f64) -> Self;
    fn sqrt(self) -> Self {
        let v = self.val();
        let s = v.sqrt();
        self.unary(s, 0.5 / s, -0.25 / (s * v))
    }
    fn recip(self) -> Self {
        let v = self.val();
        self.unary(1.0 / v, -1.0 / (v * v), 2.0 / (v * v * v))
    }
}

impl Real for f64 {
    #[inline]
    fn cst(x: f64) -> Self {
        x
    }
    #[inline]
    fn val(&self) -> f64 {
        *self
    }
    #[inline]
    fn unary(self, f: f64, _df: f64, _d2f: f64) -> Self {
        f
    }
    #[inline]
    fn scale(self, s: f64) -> Self {
        self * s
    }
    #[inline]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline]
    fn recip(self) -> Self {
        1.0 / self
    }
}

/// `-a` and `a / b` from `scale` and `recip` (the same for both dual types).
macro_rules! neg_and_div {
    ($t:ident < $($n:ident),+ >) => {
        impl<$(const $n: usize),+> Neg for $t<$($n),+> {
            type Output = Self;
            #[inline]
            fn neg(self) -> Self {
                self.scale(-1.0)
            }
        }

        impl<$(const $n: usize),+> Div for $t<$($n),+> {
            type Output = Self;
            #[inline]
            #[allow(clippy::suspicious_arithmetic_impl)] // a / b = a * (1 / b), the chain rule of 1 / b
            fn div(self, o: Self) -> Self {
                self * o.recip()
            }
        }
    };
}

neg_and_div!(Dual<N>);
neg_and_div!(HyperDual<N, M>);

/// Value and gradient in `N` directions.
#[derive(Debug, Clone, Copy)]
pub struct Dual<const N: usize> {
    pub v: f64,
    pub g: [f64; N],
}

impl<const N: usize> Dual<N> {
    /// The `i`-th independent variable at `x`.
    pub fn var(x: f64, i: usize) -> Self {
        let mut g = [0.0; N];
        g[i] = 1.0;
        Dual { v: x, g }
    }
}

impl<const N: usize> Add for Dual<N> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        for i in 0..N {
            self.g[i] += o.g[i];
        }
        self
    }
}

impl<const N: usize> Sub for Dual<N> {
    type Output = Self;
    #[inline]
    fn sub(mut self, o: Self) -> Self {
        self.v -= o.v;
        for i in 0..N {
            self.g[i] -= o.g[i];
        }
        self
    }
}

impl<const N: usize> Mul for Dual<N> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let mut g = [0.0; N];
        for i in 0..N {
            g[i] = self.v * o.g[i] + o.v * self.g[i];
        }
        Dual { v: self.v * o.v, g }
    }
}

impl<const N: usize> Real for Dual<N> {
    #[inline]
    fn cst(x: f64) -> Self {
        Dual { v: x, g: [0.0; N] }
    }
    #[inline]
    fn val(&self) -> f64 {
        self.v
    }
    #[inline]
    fn unary(self, f: f64, df: f64, _d2f: f64) -> Self {
        Dual { v: f, g: self.g.map(|x| df * x) }
    }
    #[inline]
    fn scale(self, s: f64) -> Self {
        Dual { v: self.v * s, g: self.g.map(|x| s * x) }
    }
}

/// Value, gradient and Hessian in `N` directions. The Hessian is symmetric and stored packed:
/// its upper triangle row by row (`M = N (N + 1) / 2` entries, checked at compile time), so a
/// product costs half the work and half the copies of a full square.
#[derive(Debug, Clone, Copy)]
pub struct HyperDual<const N: usize, const M: usize> {
    pub v: f64,
    pub g: [f64; N],
    /// `H[i][j]` for `j >= i`, row by row (`HyperDual::hessian` unpacks it).
    pub h: [f64; M],
}

impl<const N: usize, const M: usize> HyperDual<N, M> {
    const PACKED: () = assert!(M == N * (N + 1) / 2, "HyperDual<N, M> needs M = N (N + 1) / 2");

    /// The `i`-th independent variable at `x`.
    pub fn var(x: f64, i: usize) -> Self {
        let mut g = [0.0; N];
        g[i] = 1.0;
        Self::with(x, g, [0.0; M])
    }

    #[inline]
    fn with(v: f64, g: [f64; N], h: [f64; M]) -> Self {
        #[allow(clippy::let_unit_value)]
        let _ = Self::PACKED;
        HyperDual { v, g, h }
    }

    /// The full symmetric Hessian.
    pub fn hessian(&self) -> [[f64; N]; N] {
        let mut out = [[0.0; N]; N];
        let mut k = 0;
        for i in 0..N {
            for j in i..N {
                out[i][j] = self.h[k];
                out[j][i] = self.h[k];
                k += 1;
            }
        }
        out
    }
}

impl<const N: usize, const M: usize> Add for HyperDual<N, M> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        for i in 0..N {
            self.g[i] += o.g[i];
        }
        for k in 0..M {
            self.h[k] += o.h[k];
        }
        self
    }
}

impl<const N: usize, const M: usize> Sub for HyperDual<N, M> {
    type Output = Self;
    #[inline]
    fn sub(mut self, o: Self) -> Self {
        self.v -= o.v;
        for i in 0..N {
            self.g[i] -= o.g[i];
        }
        for k in 0..M {
            self.h[k] -= o.h[k];
        }
        self
    }
}

impl<const N: usize, const M: usize> Mul for HyperDual<N, M> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let (a, b) = (self.v, o.v);
        let g = std::array::from_fn(|i| a * o.g[i] + b * self.g[i]);
        let mut h = [0.0; M];
        // row by row as slices (one bounds check a row, the inner loop vectorizes)
        let mut k = 0;
        for i in 0..N {
            let (ga, gb) = (self.g[i], o.g[i]);
            let end = k + N - i;
            let rows = h[k..end].iter_mut().zip(&self.h[k..end]).zip(&o.h[k..end]);
            for (((hv, &ha), &hb), (&gaj, &gbj)) in rows.zip(self.g[i..].iter().zip(&o.g[i..])) {
                *hv = a * hb + b * ha + ga * gbj + gb * gaj;
            }
            k = end;
        }
        Self::with(a * b, g, h)
    }
}

impl<const N: usize, const M: usize> Real for HyperDual<N, M> {
    #[inline]
    fn cst(x: f64) -> Self {
        Self::with(x, [0.0; N], [0.0; M])
    }
    #[inline]
    fn val(&self) -> f64 {
        self.v
    }
    #[inline]
    fn unary(self, f: f64, df: f64, d2f: f64) -> Self {
        let mut h = [0.0; M];
        let mut k = 0;
        for i in 0..N {
            let gi = d2f * self.g[i];
            let end = k + N - i;
            for ((hv, &hs), &gj) in h[k..end].iter_mut().zip(&self.h[k..end]).zip(&self.g[i..]) {
                *hv = df * hs + gi * gj;
            }
            k = end;
        }
        Self::with(f, self.g.map(|x| df * x), h)
    }
    #[inline]
    fn scale(self, s: f64) -> Self {
        Self::with(self.v * s, self.g.map(|x| s * x), self.h.map(|x| s * x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f<T: Real>(x: T, y: T) -> T {
        // x^2 y / sqrt(x + y^2)
        x * x * y / (x + y * y).sqrt()
    }

    #[test]
    fn gradient_and_hessian_match_differences() {
        let (x, y) = (0.7, 1.3);
        let hd = f(HyperDual::<2, 3>::var(x, 0), HyperDual::<2, 3>::var(y, 1));
        let hh = hd.hessian();
        let d = f(Dual::<2>::var(x, 0), Dual::<2>::var(y, 1));
        let h = 1e-5;
        let fx = (f(x + h, y) - f(x - h, y)) / (2.0 * h);
        let fy = (f(x, y + h) - f(x, y - h)) / (2.0 * h);
        assert!((d.g[0] - fx).abs() < 1e-9 && (d.g[1] - fy).abs() < 1e-9);
        assert!((hd.g[0] - d.g[0]).abs() < 1e-14 && (hd.v - f(x, y)).abs() < 1e-15);
        let gx = |x: f64, y: f64| f(Dual::<2>::var(x, 0), Dual::<2>::var(y, 1)).g;
        for j in 0..2 {
            let (mut a, mut b) = ([x, y], [x, y]);
            a[j] += h;
            b[j] -= h;
            let (ga, gb) = (gx(a[0], a[1]), gx(b[0], b[1]));
            for i in 0..2 {
                assert!((hh[i][j] - (ga[i] - gb[i]) / (2.0 * h)).abs() < 1e-8, "H[{i}][{j}]");
            }
        }
    }
}
