//! Model choice by cross-validation (mrcal's test of a lens model): the
//! views are split into two disjoint halves (even and odd positions, so
//! both see the same mix of poses), each half is calibrated with each
//! model, and the projection difference of the two halves
//! ([`super::projection_diff`], implied rotation fitted where the points
//! fall) is set beside the uncertainty the halves predict for it. A model
//! that fits the lens gives halves that differ by about their uncertainty;
//! a model that does not gives halves that differ by much more, because
//! each half bends the wrong model its own way.
//!
//! The predicted uncertainty of the difference is `sqrt(sa^2 + sb^2)` of
//! the halves' projection-uncertainty maps (same 9 x 7 grid), each rescaled
//! to one noise level: the lowest RMS residual of all the fits (a model
//! that does not fit inflates its own residual, and with it an uncertainty
//! scaled by that residual; the noise is what the best model leaves).
//! Only grid points where both halves have points nearby are compared (the
//! valid region): elsewhere every model extrapolates.

use super::compare::{calibrate_with, Method};
use super::projection_diff::{projection_diff, DiffOptions};
use super::report::CameraCalibration;
use super::zhang::CalibrationOptions;
use super::View;
use crate::camera::Distortion;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Fewest views: 3 per half (a calibration's minimum).
pub const MIN_VIEWS: usize = 6;
/// The halves of a model agree when the median, over the valid region, of
/// their difference over its predicted uncertainty is at most this (two
/// independent estimates differ by about 1.2 sigma at the median).
pub const AGREE_RATIO: f64 = 2.0;
/// The models compared beside the chosen one (the parametric models of the
/// model advice that follow narrow and fisheye lenses).
pub const CANDIDATES: [&str; 4] = ["brown", "rational", "kannala_brandt", "eucm"];

/// One model's two halves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HalvesDiff {
    /// The model.
    pub model: String,
    /// The model the report is calibrated with.
    pub chosen: bool,
    /// The RMS residual of each half, px (`[0, 0]` when a half failed).
    pub rms_px: [f64; 2],
    /// Grid points compared (in the valid region, both halves defined).
    pub grid_points: usize,
    /// The median projection difference of the halves there, px.
    pub diff_median_px: f64,
    /// The largest one, px.
    pub diff_worst_px: f64,
    /// The median predicted uncertainty of the difference there, px.
    pub predicted_median_px: f64,
    /// The median of difference over predicted uncertainty, point by point.
    pub ratio_median: f64,
    /// `ratio_median` at most [`AGREE_RATIO`].
    pub agree: bool,
    /// Per grid row, per column: the difference, px; `None` outside the
    /// valid region or where a half cannot project.
    pub diff_map_px: Vec<Vec<Option<f64>>>,
    /// Per grid row, per column: the predicted uncertainty, px.
    pub predicted_map_px: Vec<Vec<Option<f64>>>,
    /// Why the model could not be compared (a half did not calibrate);
    /// the figures are then 0 and `agree` false.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The cross-validation of a calibration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CrossValidation {
    /// Views in each half (even and odd positions).
    pub views: [usize; 2],
    /// Grid pixel x coordinates (the projection-uncertainty map's).
    pub x_px: Vec<f64>,
    /// Grid pixel y coordinates.
    pub y_px: Vec<f64>,
    /// The noise level the predictions are scaled to: the lowest RMS
    /// residual of all the fits, px.
    pub noise_px: f64,
    /// The chosen model first, then the others.
    pub models: Vec<HalvesDiff>,
    /// The model whose halves agree: the chosen one when they do, else
    /// the one with the smallest median difference among those that do;
    /// `None` when no model's halves agree.
    pub recommended: Option<String>,
    /// One line: each model's median difference against its prediction.
    pub summary: String,
}

/// A model's two fits, or why it has none.
type Fits = std::result::Result<[CameraCalibration; 2], String>;

/// Cross-validate `report` (calibrated from `views` with `options`): its
/// model and the [`CANDIDATES`].
pub fn cross_validate(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
    report: &CameraCalibration,
) -> Result<CrossValidation> {
    if views.len() < MIN_VIEWS {
        return Err(Error::invalid(
            "cross_validate",
            format!(
                "cross-validation splits the views into two halves of at least 3: it needs at \
                 least {MIN_VIEWS} views, got {}",
                views.len()
            ),
        ));
    }
    let halves: [Vec<View>; 2] = [0, 1].map(|parity| {
        views
            .iter()
            .enumerate()
            .filter(|(i, _)| i % 2 == parity)
            .map(|(_, v)| v.clone())
            .collect()
    });
    let chosen = report.model.clone();
    let mut models: Vec<(String, Distortion, Vec<String>)> = vec![(
        chosen.clone(),
        options.model.clone(),
        options.fixed_coefficients.clone(),
    )];
    for name in CANDIDATES.into_iter().filter(|n| *n != chosen) {
        if let Some(d) = Distortion::named(name) {
            models.push((name.to_string(), d, Vec::new()));
        }
    }
    let fits: Vec<(String, Fits)> = models
        .into_iter()
        .map(|(name, model, fixed)| {
            let o = CalibrationOptions {
                model,
                fixed_coefficients: fixed,
                ..options.clone()
            };
            let fit = |h: &[View]| {
                calibrate_with(Method::Zhang, h, image_size_px, &o).map_err(|e| e.to_string())
            };
            let both = fit(&halves[0]).and_then(|a| fit(&halves[1]).map(|b| [a, b]));
            (name, both)
        })
        .collect();
    let noise_px = fits
        .iter()
        .filter_map(|(_, f)| f.as_ref().ok())
        .flat_map(|[a, b]| [a.rms_px, b.rms_px])
        .filter(|r| r.is_finite() && *r > 0.0)
        .fold(f64::INFINITY, f64::min);
    let fit_px: Vec<[f64; 2]> = views
        .iter()
        .flat_map(|v| v.image_px.iter().map(|p| [p.x, p.y]))
        .collect();
    let grid = &report.projection_uncertainty;
    let (x_px, y_px) = (grid.x_px.clone(), grid.y_px.clone());
    let near = near_points(&halves, &x_px, &y_px);
    let rows: Vec<HalvesDiff> = fits
        .into_iter()
        .enumerate()
        .map(|(i, (model, fits))| match fits {
            Ok(pair) => compare_halves(model, i == 0, &pair, noise_px, &fit_px, &near),
            Err(e) => failed(model, i == 0, e),
        })
        .collect();
    let recommended = match rows.first() {
        Some(r) if r.agree => Some(r.model.clone()),
        _ => rows
            .iter()
            .filter(|r| r.agree)
            .min_by(|a, b| a.diff_median_px.total_cmp(&b.diff_median_px))
            .map(|r| r.model.clone()),
    };
    let summary = summary(&rows, recommended.as_deref());
    Ok(CrossValidation {
        views: [halves[0].len(), halves[1].len()],
        x_px,
        y_px,
        noise_px: if noise_px.is_finite() { noise_px } else { 0.0 },
        models: rows,
        recommended,
        summary,
    })
}

/// Per grid row, per column: whether both halves have a point within half
/// a grid spacing (the grid point's cell).
fn near_points(halves: &[Vec<View>; 2], x_px: &[f64], y_px: &[f64]) -> Vec<Vec<bool>> {
    let spacing = |v: &[f64]| match v {
        [a, b, ..] => 0.5 * (b - a),
        _ => f64::INFINITY,
    };
    let (hx, hy) = (spacing(x_px), spacing(y_px));
    let cell_of = |x: f64, y: f64| -> Option<(usize, usize)> {
        let c = x_px.iter().position(|gx| (x - gx).abs() <= hx)?;
        let r = y_px.iter().position(|gy| (y - gy).abs() <= hy)?;
        Some((r, c))
    };
    let mut seen = [0, 1].map(|_| vec![vec![false; x_px.len()]; y_px.len()]);
    for (half, views) in halves.iter().enumerate() {
        for p in views.iter().flat_map(|v| v.image_px.iter()) {
            if let Some((r, c)) = cell_of(p.x, p.y) {
                seen[half][r][c] = true;
            }
        }
    }
    (0..y_px.len())
        .map(|r| {
            (0..x_px.len())
                .map(|c| seen[0][r][c] && seen[1][r][c])
                .collect()
        })
        .collect()
}

fn failed(model: String, chosen: bool, error: String) -> HalvesDiff {
    HalvesDiff {
        model,
        chosen,
        rms_px: [0.0, 0.0],
        grid_points: 0,
        diff_median_px: 0.0,
        diff_worst_px: 0.0,
        predicted_median_px: 0.0,
        ratio_median: 0.0,
        agree: false,
        diff_map_px: Vec::new(),
        predicted_map_px: Vec::new(),
        error: Some(error),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => 0.0,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

fn compare_halves(
    model: String,
    chosen: bool,
    [a, b]: &[CameraCalibration; 2],
    noise_px: f64,
    fit_px: &[[f64; 2]],
    near: &[Vec<bool>],
) -> HalvesDiff {
    let ua = &a.projection_uncertainty;
    let options = DiffOptions {
        grid: [ua.x_px.len(), ua.y_px.len()],
        fit_px: fit_px.to_vec(),
        focus_radius_px: None,
    };
    let diff = match projection_diff(&a.camera, &b.camera, &options) {
        Ok(d) => d,
        Err(e) => return failed(model, chosen, e.to_string()),
    };
    let scale = |r: &CameraCalibration| {
        if r.rms_px > 0.0 && noise_px.is_finite() {
            noise_px / r.rms_px
        } else {
            1.0
        }
    };
    let (sa, sb) = (scale(a), scale(b));
    let ub = &b.projection_uncertainty;
    let mut diff_map = vec![vec![None; options.grid[0]]; options.grid[1]];
    let mut predicted_map = diff_map.clone();
    let (mut diffs, mut predicted, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    for (r, row) in near.iter().enumerate() {
        for (c, &valid) in row.iter().enumerate() {
            let at = |m: &[Vec<Option<f64>>]| m.get(r).and_then(|row| row.get(c)).copied();
            let (Some(Some(d)), Some(Some(pa)), Some(Some(pb))) =
                (at(&diff.map), at(&ua.std_px), at(&ub.std_px))
            else {
                continue;
            };
            let p = ((pa * sa).powi(2) + (pb * sb).powi(2)).sqrt();
            if !valid || p.is_nan() || p <= 0.0 {
                continue;
            }
            diff_map[r][c] = Some(d);
            predicted_map[r][c] = Some(p);
            diffs.push(d);
            predicted.push(p);
            ratios.push(d / p);
        }
    }
    let ratio_median = median(ratios);
    HalvesDiff {
        model,
        chosen,
        rms_px: [a.rms_px, b.rms_px],
        grid_points: diffs.len(),
        diff_worst_px: diffs.iter().copied().fold(0.0, f64::max),
        diff_median_px: median(diffs.clone()),
        predicted_median_px: median(predicted),
        agree: !diffs.is_empty() && ratio_median <= AGREE_RATIO,
        ratio_median,
        diff_map_px: diff_map,
        predicted_map_px: predicted_map,
        error: None,
    }
}

fn summary(rows: &[HalvesDiff], recommended: Option<&str>) -> String {
    let parts: Vec<String> = rows
        .iter()
        .map(|r| match &r.error {
            Some(_) => format!("{} not fitted", r.model),
            None => format!(
                "{} {:.3} px ({:.1}x, {})",
                r.model,
                r.diff_median_px,
                r.ratio_median,
                if r.agree { "agree" } else { "disagree" }
            ),
        })
        .collect();
    format!(
        "cross-validation (median difference of two halves of the views, over its predicted \
         uncertainty): {}; {}",
        parts.join(", "),
        match recommended {
            Some(m) => format!("{m} recommended"),
            None => "no model's halves agree".to_string(),
        }
    )
}

/// The warning of a cross-validation whose chosen model's halves disagree.
pub fn cross_validation_warning(cv: &CrossValidation) -> Option<String> {
    let chosen = cv.models.first()?;
    if chosen.agree {
        return None;
    }
    let what = match &chosen.error {
        Some(e) => format!(
            "a half of the views did not calibrate with {} ({e})",
            chosen.model
        ),
        None => format!(
            "the two halves of the views calibrated with {} differ by {:.3} px (median over \
             the image where the points fall), {:.1}x their predicted uncertainty of {:.3} px",
            chosen.model, chosen.diff_median_px, chosen.ratio_median, chosen.predicted_median_px
        ),
    };
    Some(match &cv.recommended {
        Some(m) => {
            let other = cv.models.iter().find(|r| &r.model == m)?;
            format!(
                "cross-validation: {what}: the model does not fit this lens (or the views do not \
                 determine it); {m}'s halves agree ({:.3} px, {:.1}x): switch the model to {m} \
                 (CLI: --model {m})",
                other.diff_median_px, other.ratio_median
            )
        }
        None => format!(
            "cross-validation: {what}, and no model's halves agree: add views that cover the \
             image, or try --model splined with many views"
        ),
    })
}

#[cfg(test)]
#[path = "cross_validation_tests.rs"]
mod tests;
