//! The stripe centres' variances for the plane fit and the joint
//! refinement: a non-decreasing function of the std the extractor
//! reports, its values measured from the residuals.
//!
//! The extractor's std is the image noise through its estimator; the
//! centres' error is mostly what it does not see (speckle, the sub-pixel
//! bias over the board's squares and the pixel grid). On the renders
//! (BENCHMARKS.md section 18, s28) the centres reported at 0.02-0.05 px
//! err 0.31 px RMS, those at 0.10-0.20 px 0.14 px, those at 0.5 px (the
//! fallbacks) 0.48 px: the std does not give the error's scale, and at the
//! low end not even its order, while at the high end it does mark the
//! poor centres. So the std is trusted for its order only: each centre's
//! variance is `v(std)`, `v` non-decreasing, fitted to the squared
//! residuals of a fit with every centre alike by isotonic regression (for
//! Gaussian errors of known zero mean this is the maximum-likelihood
//! variance under that order). Where the low stds err as much as the rest,
//! `v` pools them (the centres weigh alike); a stretch whose std marks it
//! poor and whose residuals say so keeps a lower weight.

/// A centre's variance (px^2 along the scan) as a step function of its
/// reported std: `steps` are `(largest std of the step, variance)`, both
/// non-decreasing.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CentreVariance {
    steps: Vec<(f64, f64)>,
}

/// No variance below this (px^2): noise-free residuals give weights that
/// are alike rather than infinite.
const MIN_VARIANCE: f64 = 1e-12;

impl CentreVariance {
    /// Every centre alike at `variance`.
    pub fn alike(variance: f64) -> CentreVariance {
        CentreVariance {
            steps: vec![(f64::INFINITY, variance.max(MIN_VARIANCE))],
        }
    }

    /// Fit `v(std)` to centres' `(std, squared residual)`; `dof_lost`
    /// parameters were fitted to those residuals (their squares are scaled
    /// by `m / (m - dof_lost)` so their mean is not short by what the fit
    /// absorbed). Consecutive centres in the std's order are pooled in
    /// groups of at least `max(20, m / 40)` (ties kept together) before the
    /// isotonic regression, so no step rests on a few residuals.
    pub fn fit(centres: &[(f64, f64)], dof_lost: usize) -> CentreVariance {
        let m = centres.len();
        if m <= dof_lost || m == 0 {
            return CentreVariance::alike(1.0);
        }
        let scale = m as f64 / (m - dof_lost) as f64;
        let mut sorted: Vec<(f64, f64)> = centres.to_vec();
        sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
        let group = (m / 40).max(20);
        // Blocks: (largest std, sum of r^2, count).
        let mut blocks: Vec<(f64, f64, usize)> = Vec::new();
        for &(s, r2) in &sorted {
            match blocks.last_mut() {
                Some(b) if b.2 < group || b.0 == s => {
                    b.0 = s;
                    b.1 += r2 * scale;
                    b.2 += 1;
                }
                _ => blocks.push((s, r2 * scale, 1)),
            }
        }
        // A short last group joins the one before it.
        if blocks.len() >= 2 && blocks[blocks.len() - 1].2 < group {
            let last = blocks.pop().unwrap_or_default();
            if let Some(b) = blocks.last_mut() {
                *b = (last.0, b.1 + last.1, b.2 + last.2);
            }
        }
        // Pool adjacent violators: merge while a block's mean is below its
        // predecessor's.
        let mut pooled: Vec<(f64, f64, usize)> = Vec::with_capacity(blocks.len());
        for b in blocks {
            pooled.push(b);
            while pooled.len() >= 2 {
                let k = pooled.len();
                let (a, c) = (pooled[k - 2], pooled[k - 1]);
                if a.1 / a.2 as f64 <= c.1 / c.2 as f64 {
                    break;
                }
                pooled[k - 2] = (c.0, a.1 + c.1, a.2 + c.2);
                pooled.pop();
            }
        }
        CentreVariance {
            steps: pooled
                .into_iter()
                .map(|(s, sum, n)| (s, (sum / n as f64).max(MIN_VARIANCE)))
                .collect(),
        }
    }

    /// The variance (px^2) of a centre reported at `std_px`: the step
    /// holding it (above the largest std seen, the last).
    pub fn variance(&self, std_px: f64) -> f64 {
        self.steps
            .iter()
            .find(|(s, _)| std_px <= *s)
            .or(self.steps.last())
            .map_or(1.0, |(_, v)| *v)
    }

    /// The smallest variance: the error scale every centre has.
    pub fn floor(&self) -> f64 {
        self.steps.first().map_or(0.0, |(_, v)| *v)
    }
}
