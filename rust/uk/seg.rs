//! The fixed-size products of the Gram path (`gram`): dot products of a segment of `A` (six or
//! seven entries: a rigid3 body's segment, off its unit coordinate or not) and a rigid3 body's
//! `F^-1` block times one, each with a fixed order of evaluation (the rounding bounds of `gram`
//! count the terms, not the order).

/// `seg_dot` of six entries.
#[inline(always)]
pub(super) fn dot6(x: &[f64; 6], y: &[f64; 6]) -> f64 {
    ((x[0] * y[0] + x[2] * y[2]) + (x[1] * y[1] + x[3] * y[3])) + x[4] * y[4] + x[5] * y[5]
}

/// `dot4(x, y)` to the bit, with the six- and seven-entry cases (a rigid3 body off its unit
/// coordinate: most products of `S_22`; a rigid3 body's segment) written out so that they have
/// no loop and no remainder branches.
#[inline(always)]
pub(super) fn seg_dot(x: &[f64], y: &[f64]) -> f64 {
    let head = |x: &[f64], y: &[f64]| (x[0] * y[0] + x[2] * y[2]) + (x[1] * y[1] + x[3] * y[3]);
    if let (Ok(x), Ok(y)) = (<&[f64; 6]>::try_from(x), <&[f64; 6]>::try_from(y)) {
        dot6(x, y)
    } else if let (Ok(x), Ok(y)) = (<&[f64; 7]>::try_from(x), <&[f64; 7]>::try_from(y)) {
        head(x, y) + x[4] * y[4] + x[5] * y[5] + x[6] * y[6]
    } else {
        crate::linalg::dot4(x, y)
    }
}

/// `T a` from `T` by columns (`tc[l][i] = T_il`), each row's sum left to right (the bits of
/// `T_i0 a_0 + T_i1 a_1 + T_i2 a_2 + T_i3 a_3`), two rows at a time (SSE2 on x86_64).
#[inline(always)]
pub(super) fn t_times(tc: &[[f64; 4]; 4], a: [f64; 4]) -> [f64; 4] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is part of every x86_64 target; no pointer is read
        unsafe {
            let col = |l: usize, h: usize| _mm_mul_pd(_mm_set_pd(tc[l][h + 1], tc[l][h]), _mm_set1_pd(a[l]));
            let half = |h: usize| _mm_add_pd(_mm_add_pd(_mm_add_pd(col(0, h), col(1, h)), col(2, h)), col(3, h));
            let (lo, hi) = (half(0), half(2));
            [_mm_cvtsd_f64(lo), _mm_cvtsd_f64(_mm_unpackhi_pd(lo, lo)), _mm_cvtsd_f64(hi), _mm_cvtsd_f64(_mm_unpackhi_pd(hi, hi))]
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        std::array::from_fn(|i| tc[0][i] * a[0] + tc[1][i] * a[1] + tc[2][i] * a[2] + tc[3][i] * a[3])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `t_times` gives the bits of the row-by-row sums, left to right (what `gram` wrote before
    /// it), on awkward values (signs, magnitudes far apart, a subnormal).
    #[test]
    fn t_times_matches_the_rows_to_the_bit() {
        for s in 0..50u32 {
            let v = |k: u32| ((s * 31 + k * 17) as f64 * 0.713).sin() * 10f64.powi((k as i32 * 7 + s as i32) % 13 - 6);
            let t: [[f64; 4]; 4] = std::array::from_fn(|i| std::array::from_fn(|l| v(4 * i as u32 + l as u32)));
            let mut a = [v(16), v(17), v(18), v(19)];
            if s == 7 {
                a[2] = 1e-310;
            }
            let tc = std::array::from_fn(|l| std::array::from_fn(|i| t[i][l]));
            let got = t_times(&tc, a);
            for (i, row) in t.iter().enumerate() {
                let want = row[0] * a[0] + row[1] * a[1] + row[2] * a[2] + row[3] * a[3];
                assert_eq!(got[i].to_bits(), want.to_bits(), "row {i} case {s}");
            }
        }
    }
}
