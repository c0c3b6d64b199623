//! The Wilson score interval of a share: how sure a measured coverage
//! ("k of n trials had the truth within 3 std") is, for the seeded
//! Monte-Carlo coverage tables (`examples/handeye_coverage.rs`,
//! `examples/rig_coverage.rs`).
//!
//! Unlike the normal-approximation interval `p +- z sqrt(p (1 - p) / n)`,
//! it stays inside [0, 1] and does not shrink to a point at `k = n`
//! (400 of 400 covered is 99.0-100 %, not exactly 100 %).

/// The standard Gaussian's two-sided 95 % quantile.
pub const Z_95: f64 = 1.959_963_984_540_054;

/// The 95 % Wilson score interval `(low, high)` of the share `k / n`;
/// `(0, 1)` when `n` is 0 (nothing measured). `k` above `n` is taken as `n`.
pub fn wilson_interval_95(k: usize, n: usize) -> (f64, f64) {
    if n == 0 {
        return (0.0, 1.0);
    }
    let (n, z) = (n as f64, Z_95);
    let p = k.min(n as usize) as f64 / n;
    let denominator = 1.0 + z * z / n;
    let centre = (p + z * z / (2.0 * n)) / denominator;
    let half = z / denominator * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference values: Wilson (1927)'s formula evaluated by hand for
    /// z = 1.96 (5 of 10: 0.2366-0.7634; 0 of 10: 0-0.2775; 400 of 400:
    /// 0.9905-1).
    #[test]
    fn matches_the_textbook_values() {
        let close = |a: f64, b: f64| (a - b).abs() < 5e-5;
        let (low, high) = wilson_interval_95(5, 10);
        assert!(close(low, 0.2366) && close(high, 0.7634), "{low} {high}");
        let (low, high) = wilson_interval_95(0, 10);
        assert!(close(low, 0.0) && close(high, 0.2775), "{low} {high}");
        let (low, high) = wilson_interval_95(400, 400);
        assert!(close(low, 0.9905) && close(high, 1.0), "{low} {high}");
        assert_eq!(wilson_interval_95(3, 0), (0.0, 1.0));
    }
}
