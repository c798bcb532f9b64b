//! Forward-mode automatic differentiation for small generic energies: a scalar trait [`Real`]
//! implemented by `f64`, by [`Dual<N>`] (value and gradient in `N` seeded directions) and by
//! [`HyperDual<N>`] (value, gradient and Hessian). A function written once over `T: Real`
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
    ($t:ident) => {
        impl<const N: usize> Neg for $t<N> {
            type Output = Self;
            #[inline]
            fn neg(self) -> Self {
                self.scale(-1.0)
            }
        }

        impl<const N: usize> Div for $t<N> {
            type Output = Self;
            #[inline]
            #[allow(clippy::suspicious_arithmetic_impl)] // a / b = a * (1 / b), the chain rule of 1 / b
            fn div(self, o: Self) -> Self {
                self * o.recip()
            }
        }
    };
}

neg_and_div!(Dual);
neg_and_div!(HyperDual);

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

/// Value, gradient and Hessian (full, symmetric) in `N` directions.
#[derive(Debug, Clone, Copy)]
pub struct HyperDual<const N: usize> {
    pub v: f64,
    pub g: [f64; N],
    pub h: [[f64; N]; N],
}

impl<const N: usize> HyperDual<N> {
    /// The `i`-th independent variable at `x`.
    pub fn var(x: f64, i: usize) -> Self {
        let mut g = [0.0; N];
        g[i] = 1.0;
        HyperDual { v: x, g, h: [[0.0; N]; N] }
    }
}

impl<const N: usize> Add for HyperDual<N> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        for i in 0..N {
            self.g[i] += o.g[i];
            for j in 0..N {
                self.h[i][j] += o.h[i][j];
            }
        }
        self
    }
}

impl<const N: usize> Sub for HyperDual<N> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        self + o.scale(-1.0)
    }
}

impl<const N: usize> Mul for HyperDual<N> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let mut r = HyperDual { v: self.v * o.v, g: [0.0; N], h: [[0.0; N]; N] };
        for i in 0..N {
            r.g[i] = self.v * o.g[i] + o.v * self.g[i];
            for j in 0..N {
                r.h[i][j] = self.v * o.h[i][j] + o.v * self.h[i][j] + self.g[i] * o.g[j] + o.g[i] * self.g[j];
            }
        }
        r
    }
}

impl<const N: usize> Real for HyperDual<N> {
    #[inline]
    fn cst(x: f64) -> Self {
        HyperDual { v: x, g: [0.0; N], h: [[0.0; N]; N] }
    }
    #[inline]
    fn val(&self) -> f64 {
        self.v
    }
    #[inline]
    fn unary(self, f: f64, df: f64, d2f: f64) -> Self {
        let mut r = HyperDual { v: f, g: self.g.map(|x| df * x), h: [[0.0; N]; N] };
        for i in 0..N {
            for j in 0..N {
                r.h[i][j] = df * self.h[i][j] + d2f * self.g[i] * self.g[j];
            }
        }
        r
    }
    #[inline]
    fn scale(self, s: f64) -> Self {
        HyperDual { v: self.v * s, g: self.g.map(|x| s * x), h: self.h.map(|row| row.map(|x| s * x)) }
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
        let hd = f(HyperDual::<2>::var(x, 0), HyperDual::<2>::var(y, 1));
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
                assert!((hd.h[i][j] - (ga[i] - gb[i]) / (2.0 * h)).abs() < 1e-8, "H[{i}][{j}]");
            }
        }
    }
}
