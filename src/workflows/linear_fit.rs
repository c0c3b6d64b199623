//! Straight-line fit `y = intercept + slope * x` by ordinary least squares,
//! with the statistics the seed-001 article reports (Origin's "Linear Fit"
//! table: residual sum of squares, Pearson's r, R^2 (COD), adjusted R^2),
//! the standard errors needed to predict with an error estimate, and an
//! optional rejection of points of high dispersion followed by a refit.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Minimum number of points for a line fit.
pub const MIN_POINTS: usize = 2;

/// Relative tolerance below which the x values count as all equal.
const SPREAD_TOLERANCE: f64 = 1e-12;

/// A fitted line and its statistics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearFit {
    /// Value at x = 0.
    pub intercept: f64,
    /// Change of y per unit of x.
    pub slope: f64,
    /// Coefficient of determination 1 - RSS/TSS; `None` when y is constant
    /// (TSS = 0), where it is undefined.
    pub r2: Option<f64>,
    /// Pearson's correlation coefficient of x and y; `None` when y is constant.
    pub pearson_r: Option<f64>,
    /// Adjusted R^2 = 1 - (1 - R^2)(n - 1)/(n - 2); `None` for n < 3 or constant y.
    pub adj_r2: Option<f64>,
    /// Residual sum of squares.
    pub rss: f64,
    /// Number of points used.
    pub n: usize,
    /// Standard error of the intercept (0 when n = 2: an exact fit).
    pub intercept_std: f64,
    /// Standard error of the slope (0 when n = 2).
    pub slope_std: f64,
    /// Covariance of intercept and slope (0 when n = 2).
    pub intercept_slope_cov: f64,
}

impl LinearFit {
    /// The fitted value at `x`.
    pub fn value(&self, x: f64) -> f64 {
        self.intercept + self.slope * x
    }

    /// Standard error of the fitted value at `x` (uncertainty of the line
    /// itself, from the scatter of the fitted points).
    pub fn value_std(&self, x: f64) -> f64 {
        let var = self.intercept_std.powi(2)
            + x * x * self.slope_std.powi(2)
            + 2.0 * x * self.intercept_slope_cov;
        var.max(0.0).sqrt()
    }
}

/// Fit a line through `(x[i], y[i])`.
pub fn fit_line(x: &[f64], y: &[f64]) -> Result<LinearFit> {
    if x.len() != y.len() {
        return Err(Error::invalid(
            "y",
            format!("{} x values but {} y values", x.len(), y.len()),
        ));
    }
    let n = x.len();
    if n < MIN_POINTS {
        return Err(Error::too_few("points for a line fit", MIN_POINTS, n));
    }
    let nf = n as f64;
    let mx = x.iter().sum::<f64>() / nf;
    let my = y.iter().sum::<f64>() / nf;
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let syy: f64 = y.iter().map(|v| (v - my).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let scale = x.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1.0);
    if sxx <= (SPREAD_TOLERANCE * scale).powi(2) * nf {
        return Err(Error::degenerate(format!(
            "all {n} x values are equal ({mx}): a line needs at least two different x values"
        )));
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let rss: f64 = x
        .iter()
        .zip(y)
        .map(|(a, b)| (b - intercept - slope * a).powi(2))
        .sum();
    let y_scale = y
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    let constant_y = syy <= (1e-15 * y_scale).powi(2) * nf;
    let r2 = (!constant_y).then(|| 1.0 - rss / syy);
    let pearson_r = (!constant_y).then(|| sxy / (sxx * syy).sqrt());
    let adj_r2 = r2
        .filter(|_| n > 2)
        .map(|r2| 1.0 - (1.0 - r2) * (nf - 1.0) / (nf - 2.0));
    let sigma2 = if n > 2 { rss / (nf - 2.0) } else { 0.0 };
    Ok(LinearFit {
        intercept,
        slope,
        r2,
        pearson_r,
        adj_r2,
        rss,
        n,
        intercept_std: (sigma2 * (1.0 / nf + mx * mx / sxx)).sqrt(),
        slope_std: (sigma2 / sxx).sqrt(),
        intercept_slope_cov: -mx * sigma2 / sxx,
    })
}

/// A line fit after rejecting points of high dispersion.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobustLinearFit {
    /// The fit on the kept points.
    pub fit: LinearFit,
    /// Indices (into the input) of the rejected points, in rejection order.
    pub rejected: Vec<usize>,
}

/// Fit a line, then repeatedly drop the point with the largest externally
/// studentized residual while it exceeds `threshold` (in standard deviations;
/// 3 is a common choice), and refit. At most a quarter of the points are
/// rejected and at least four kept: on the short series of a calibration
/// (8 heights in the article) each rejection shrinks the scatter estimate, and
/// without a cap the good points would be peeled off one after the other.
///
/// The externally studentized residual `e_i / (s_(i) sqrt(1 - h_ii))` uses
/// the scatter of the *other* points, so one wild point cannot hide itself
/// by inflating the standard deviation.
pub fn fit_line_rejecting(x: &[f64], y: &[f64], threshold: f64) -> Result<RobustLinearFit> {
    /// Fewest points kept: below four, a studentized residual is not meaningful.
    const MIN_KEPT: usize = 4;
    if !(threshold > 0.0) {
        return Err(Error::invalid(
            "reject_threshold",
            format!("expected a positive number of standard deviations, got {threshold}"),
        ));
    }
    let max_rejected = x.len() / 4;
    let mut kept: Vec<usize> = (0..x.len()).collect();
    let mut rejected = Vec::new();
    loop {
        let kx: Vec<f64> = kept.iter().map(|&i| x[i]).collect();
        let ky: Vec<f64> = kept.iter().map(|&i| y[i]).collect();
        let fit = fit_line(&kx, &ky)?;
        if kept.len() <= MIN_KEPT || rejected.len() >= max_rejected {
            return Ok(RobustLinearFit { fit, rejected });
        }
        match worst_studentized(&kx, &ky, &fit) {
            Some((k, t)) if t > threshold => rejected.push(kept.remove(k)),
            _ => return Ok(RobustLinearFit { fit, rejected }),
        }
    }
}

/// Index and absolute value of the largest externally studentized residual.
fn worst_studentized(x: &[f64], y: &[f64], fit: &LinearFit) -> Option<(usize, f64)> {
    let nf = x.len() as f64;
    let mx = x.iter().sum::<f64>() / nf;
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let mut worst: Option<(usize, f64)> = None;
    for i in 0..x.len() {
        let e = y[i] - fit.value(x[i]);
        let h = 1.0 / nf + (x[i] - mx).powi(2) / sxx;
        // RSS without point i, from the leave-one-out identity.
        let rss_i = fit.rss - e * e / (1.0 - h);
        let s_i2 = rss_i / (nf - 3.0);
        let t = if s_i2 > 0.0 {
            (e / (s_i2 * (1.0 - h)).sqrt()).abs()
        } else if e.abs() > 0.0 {
            f64::INFINITY
        } else {
            0.0
        };
        if worst.map_or(true, |(_, w)| t > w) {
            worst = Some((i, t));
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn exact_line_and_textbook_statistics() {
        let x = [1.0, 2.0, 3.0, 4.0];
        let y: Vec<f64> = x.iter().map(|v| 2.0 - 0.5 * v).collect();
        let f = fit_line(&x, &y).unwrap();
        assert!((f.intercept - 2.0).abs() < 1e-12 && (f.slope + 0.5).abs() < 1e-12);
        assert_eq!(f.r2, Some(1.0));
        assert!((f.pearson_r.unwrap() + 1.0).abs() < 1e-12);
        // y = 1, 3, 2, 4 at x = 1..4: slope 0.8, intercept 0.5, RSS 1.8, TSS 5.
        let f = fit_line(&x, &[1.0, 3.0, 2.0, 4.0]).unwrap();
        assert!((f.slope - 0.8).abs() < 1e-12 && (f.intercept - 0.5).abs() < 1e-12);
        assert!((f.rss - 1.8).abs() < 1e-12);
        assert!((f.r2.unwrap() - 0.64).abs() < 1e-12);
        assert!((f.pearson_r.unwrap() - 0.8).abs() < 1e-12);
        assert!((f.adj_r2.unwrap() - 0.46).abs() < 1e-12);
        // slope std = sqrt(RSS/(n-2)/Sxx) = sqrt(0.9/5).
        assert!((f.slope_std - (0.18_f64).sqrt()).abs() < 1e-12);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn bad_input_is_refused_clearly() {
        assert_eq!(
            fit_line(&[15.0], &[1.0]).unwrap_err().to_string(),
            "requires at least 2 points for a line fit, got 1"
        );
        assert_eq!(
            fit_line(&[15.0, 15.0], &[1.0, 2.0])
                .unwrap_err()
                .to_string(),
            "all 2 x values are equal (15): a line needs at least two different x values"
        );
        let f = fit_line(&[1.0, 2.0, 3.0], &[5.0, 5.0, 5.0]).unwrap();
        assert_eq!((f.r2, f.pearson_r, f.slope), (None, None, 0.0));
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn rejection_drops_the_wild_point_only() {
        let x: Vec<f64> = (0..8).map(|i| i as f64 * 10.0).collect();
        // Small alternating scatter of +-0.01 plus one point off by 1.
        let mut y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, v)| 3.0 + 0.1 * v + if i % 2 == 0 { 0.01 } else { -0.01 })
            .collect();
        y[5] += 1.0;
        let r = fit_line_rejecting(&x, &y, 3.0).unwrap();
        assert_eq!(r.rejected, vec![5]);
        assert!((r.fit.slope - 0.1).abs() < 1e-3, "slope {}", r.fit.slope);
    }
}
