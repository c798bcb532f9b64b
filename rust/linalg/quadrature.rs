//! Quadrature rules of the element integrals.

/// 1D Gauss-Legendre rule on [0, 1] with 4 points: exact for polynomials of degree <= 7,
/// which covers every product of the cubic element shape functions.
pub const GAUSS4: [(f64, f64); 4] = {
    // nodes on [-1, 1]
    const A: f64 = 0.339_981_043_584_856_26;
    const B: f64 = 0.861_136_311_594_052_6;
    const WA: f64 = 0.652_145_154_862_546_1;
    const WB: f64 = 0.347_854_845_137_453_85;
    [
        (0.5 * (1.0 - B), 0.5 * WB),
        (0.5 * (1.0 - A), 0.5 * WA),
        (0.5 * (1.0 + A), 0.5 * WA),
        (0.5 * (1.0 + B), 0.5 * WB),
    ]
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss4_integrates_degree_7() {
        for p in 0..=7 {
            let s: f64 = GAUSS4.iter().map(|(x, w)| w * x.powi(p)).sum();
            assert!((s - 1.0 / (p as f64 + 1.0)).abs() < 1e-15, "degree {p}");
        }
    }
}
