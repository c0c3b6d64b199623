//! Advice on the lens model, from fitting the same views with the others.
//!
//! Two mistakes a report alone does not name:
//!
//! - **The model does not fit the lens** (a fisheye through Brown-Conrady):
//!   when the RMS residual is above [`RESIDUAL_ALERT_PX`], far above what
//!   detection noise gives (about 0.02-0.2 px for the project's detectors),
//!   every other model is fitted to the same views; one that halves the RMS
//!   or better is named, with both figures and the switch to make. The same
//!   when the residuals grow with the distance from the principal point
//!   (RMS in the outer third of the radius more than [`RADIAL_GROWTH`] times
//!   the inner third's and above [`RADIAL_ALERT_PX`]): the signature of a
//!   radial model that cannot follow the lens, even when the overall RMS
//!   looks small.
//! - **Too many parameters for the views** (the rational model on a dozen
//!   views): when the chosen model has more coefficients than another that
//!   fits the same views as well (RMS within [`SAME_FIT_RATIO`] plus
//!   [`SAME_FIT_PX`]), the extra coefficients fit noise; the model with the
//!   fewest coefficients among those is suggested.
//!
//! - **A model no export holds** (division or EUCM where OpenCV and ROS
//!   are wanted): when a model OpenCV can read fits the same views as well,
//!   it is named.
//!
//! Only a model fitted to the same views is ever recommended; among those
//! that fit about equally (within [`SAME_FIT_RATIO`]), the one more export
//! formats hold ([`export_formats`]), so a fisheye gets kannala_brandt
//! (OpenCV's fisheye, ROS equidistant, Kalibr) before division (JSON and
//! Halcon only). A wide-angle lens (half the diagonal field of view above
//! [`WIDE_ANGLE_HALF_DIAGONAL_DEG`]) always has kannala_brandt and EUCM in
//! the comparison. Every piece of advice names the formats that hold the
//! recommended model; [`advise`] also gives the comparison and a summary
//! line (shown per camera by `robocal stereo`).
//!
//! The alternatives are fitted with the user's options except held
//! coefficients (whose names belong to the chosen model); a model that fails
//! to solve is left out. For the warnings alone ([`advise_model`], the
//! `intrinsics` report) a fit that is fine first screens each alternative
//! ([`super::model_advice_screen`]) and refits only those the screen cannot
//! rule out: the comparison's figures are not shown there, and every model
//! a warning names is still refitted in full.

use super::compare::{calibrate_with, Method};
use super::model_advice_screen::screened_out;
use super::report::CameraCalibration;
use super::zhang::CalibrationOptions;
use super::View;
use crate::camera::{Camera, Distortion, LensModel, MODEL_NAMES};
use nalgebra::Point2;
use serde::{Deserialize, Serialize};

/// RMS residual (px) above which the other models are tried.
pub const RESIDUAL_ALERT_PX: f64 = 0.5;
/// Outer-third RMS (px) above which growth with the radius counts.
pub const RADIAL_ALERT_PX: f64 = 0.3;
/// Outer-third RMS over inner-third RMS that counts as growth.
pub const RADIAL_GROWTH: f64 = 3.0;
/// Points needed in each third to judge growth.
const RADIAL_MIN_POINTS: usize = 20;

/// The RMS residual (px) of the points in the inner and the outer third of
/// the radius from the principal point, when the outer one is over
/// [`RADIAL_ALERT_PX`] and [`RADIAL_GROWTH`] times the inner one.
pub fn residuals_grow_with_radius(report: &CameraCalibration) -> Option<(f64, f64)> {
    let (cx, cy) = (report.camera_matrix[0][2], report.camera_matrix[1][2]);
    let points: Vec<(f64, f64)> = report
        .views
        .iter()
        .flat_map(|v| v.residuals_px.iter())
        .map(|r| ((r.x - cx).hypot(r.y - cy), r.dx * r.dx + r.dy * r.dy))
        .filter(|(radius, sq)| radius.is_finite() && sq.is_finite())
        .collect();
    let r_max = points.iter().map(|p| p.0).fold(0.0, f64::max);
    if !(r_max > 0.0) {
        return None;
    }
    let rms = |lo: f64, hi: f64| {
        let sel: Vec<f64> = points
            .iter()
            .filter(|p| p.0 >= lo * r_max && p.0 <= hi * r_max)
            .map(|p| p.1)
            .collect();
        (sel.len() >= RADIAL_MIN_POINTS)
            .then(|| (sel.iter().sum::<f64>() / sel.len() as f64).sqrt())
    };
    let (inner, outer) = (rms(0.0, 1.0 / 3.0)?, rms(2.0 / 3.0, 1.0)?);
    (outer > RADIAL_ALERT_PX && outer > RADIAL_GROWTH * inner).then_some((inner, outer))
}

/// Another model "fits as well" when its RMS is at most this times the
/// chosen model's, plus [`SAME_FIT_PX`].
pub const SAME_FIT_RATIO: f64 = 1.02;
/// See [`SAME_FIT_RATIO`].
pub const SAME_FIT_PX: f64 = 0.002;

/// The row of `model` in the lens-model table.
fn row(model: &str) -> Option<&'static LensModel> {
    LensModel::named(model)
}

/// The short name of `model` for a message (its name when unknown).
fn label(model: &str) -> &str {
    row(model).map_or(model, |m| m.label)
}

fn coefficient_count(model: &str) -> usize {
    row(model).map_or(0, |m| m.coefficients.len())
}

/// What `robocal export` can write a camera of `model` to: the table's
/// `export_formats` (camera formats; `text` holds no lens model and is left
/// out). A condition in parentheses says what the coefficients must be. The
/// io tests check every entry against `io::export_camera`.
pub fn export_formats(model: &str) -> &'static [&'static str] {
    row(model).map_or(&[], |m| m.export_formats)
}

/// The format names of `model`, without conditions.
fn format_names(model: &str) -> Vec<&'static str> {
    row(model).map_or_else(Vec::new, |m| m.format_names().collect())
}

/// The models for lenses past 90 degrees (the table's `wide_angle`:
/// Kannala-Brandt and EUCM).
fn is_fisheye(model: &str) -> bool {
    row(model).is_some_and(|m| m.wide_angle)
}

fn can_go_to_opencv(model: &str) -> bool {
    format_names(model).contains(&"opencv-yaml")
}

/// Half the diagonal field of view (degrees) above which a lens counts as
/// wide-angle: kannala_brandt and eucm are then always in the comparison.
pub const WIDE_ANGLE_HALF_DIAGONAL_DEG: f64 = 50.0;

/// The largest angle (degrees) between the optical axis and the ray of an
/// image corner, by the camera's own model (the pinhole's when the model
/// cannot unproject a corner).
pub fn half_diagonal_fov_deg(camera: &Camera) -> f64 {
    let (w, h) = (camera.width as f64 - 1.0, camera.height as f64 - 1.0);
    [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)]
        .iter()
        .map(|&(u, v)| match camera.unproject(&Point2::new(u, v)) {
            Ok(ray) => ray.x.hypot(ray.y).atan2(ray.z),
            Err(_) => ((u - camera.cx) / camera.fx)
                .hypot((v - camera.cy) / camera.fy)
                .atan(),
        })
        .fold(0.0, f64::max)
        .to_degrees()
}

/// One model fitted to the views.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelFit {
    /// The model's name.
    pub model: String,
    /// Its RMS residual on the same views, px.
    pub rms_px: f64,
    /// Its free distortion coefficients.
    pub coefficients: usize,
}

/// The advice on a camera's lens model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelAdvice {
    /// The model to use: the calibrated one, unless another model fitted to
    /// the same views (one of `compared`) is named instead.
    pub recommended: String,
    /// Every model fitted, the calibrated one first.
    pub compared: Vec<ModelFit>,
    /// The camera export formats that hold the recommended model.
    pub export_formats: Vec<String>,
    /// Half the diagonal field of view of the calibrated camera, degrees.
    pub half_diagonal_fov_deg: f64,
    /// One line: the recommendation, the comparison and the formats.
    pub summary: String,
    /// The warnings of [`advise_model`] (empty when the model is fine).
    pub warnings: Vec<String>,
}

/// Warnings about the lens model of `report`, fitted from `views` with
/// `options`; empty when the model fits and is not over-parameterised.
pub fn advise_model(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
    report: &CameraCalibration,
) -> Vec<String> {
    advise_with(views, image_size_px, options, report, Screen::Yes).warnings
}

/// Whether the advice may leave out, without a refit, a model the screen
/// ([`super::model_advice_screen`]) finds far from the decision: only when
/// the comparison's figures are not shown (the warnings alone).
#[derive(Clone, Copy, PartialEq)]
enum Screen {
    Yes,
    No,
}

/// Of the fits within [`SAME_FIT_RATIO`] of the lowest RMS among `fits`,
/// the one more export formats hold, then the one with fewer coefficients.
fn pick<'a>(fits: &[&'a ModelFit]) -> Option<&'a ModelFit> {
    let best = fits.iter().map(|f| f.rms_px).fold(f64::INFINITY, f64::min);
    fits.iter()
        .filter(|f| f.rms_px <= SAME_FIT_RATIO * best + SAME_FIT_PX)
        .min_by(|a, b| {
            format_names(&b.model)
                .len()
                .cmp(&format_names(&a.model).len())
                .then(a.coefficients.cmp(&b.coefficients))
                .then(a.rms_px.total_cmp(&b.rms_px))
        })
        .copied()
}

/// "; kannala_brandt exports to json, ..." for a message.
fn formats_clause(model: &str) -> String {
    format!("; {model} exports to {}", export_formats(model).join(", "))
}

/// The advice on the lens model of `report`, fitted from `views` with
/// `options`: the models compared, the one recommended (never one that was
/// not fitted), the formats that hold it, and warnings when the model does
/// not fit the lens, has coefficients to spare, or cannot be exported to
/// OpenCV while a model that can fits as well.
pub fn advise(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
    report: &CameraCalibration,
) -> ModelAdvice {
    advise_with(views, image_size_px, options, report, Screen::No)
}

/// [`advise`], with the screen or without.
fn advise_with(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
    report: &CameraCalibration,
    screen: Screen,
) -> ModelAdvice {
    let chosen = report.model.as_str();
    // Coefficients held at 0 are not fitted: they count for nothing.
    let held = row(chosen).map_or(0, |m| {
        let held = &options.fixed_coefficients;
        m.coefficients
            .iter()
            .filter(|n| held.iter().any(|h| h == *n))
            .count()
    });
    let n_chosen = coefficient_count(chosen) - held;
    let free = if held > 0 { " free" } else { "" };
    let radial = residuals_grow_with_radius(report);
    let far_off = report.rms_px > RESIDUAL_ALERT_PX || radial.is_some();
    let fov = half_diagonal_fov_deg(&report.camera);
    let wide = fov > WIDE_ANGLE_HALF_DIAGONAL_DEG;
    // 1. The models to fit: all when the model does not fit; else those with
    // fewer coefficients, and the fisheye models for a wide-angle lens.
    let mut fits: Vec<ModelFit> = Vec::new();
    // Every model of the table but the pinhole (no model is simpler) and
    // the splined one (a grid of knots to choose, seconds to fit: chosen
    // by the user, never fitted on the side).
    for name in MODEL_NAMES
        .into_iter()
        .filter(|n| *n != "none" && *n != "splined")
    {
        let n = coefficient_count(name);
        let fisheye = is_fisheye(name);
        if name == chosen || !(far_off || n < n_chosen || (wide && fisheye)) {
            continue;
        }
        let Some(model) = Distortion::named(name) else {
            continue;
        };
        let alternative = CalibrationOptions {
            model,
            fixed_coefficients: Vec::new(),
            ..options.clone()
        };
        // A fine fit acts only on models that fit as well (step 2): one the
        // screen finds far worse changes nothing and is not refitted.
        if screen == Screen::Yes && !far_off {
            let limit = SAME_FIT_RATIO * report.rms_px + SAME_FIT_PX;
            if screened_out(views, &alternative, report, limit) {
                continue;
            }
        }
        if let Ok(r) = calibrate_with(Method::Zhang, views, image_size_px, &alternative) {
            if r.rms_px.is_finite() {
                fits.push(ModelFit {
                    model: name.to_string(),
                    rms_px: r.rms_px,
                    coefficients: n,
                });
            }
        }
    }
    // 2. The recommendation and its warning.
    let mut warnings = Vec::new();
    let mut recommended = chosen.to_string();
    if let (Some((inner, outer)), false) = (radial, report.rms_px > RESIDUAL_ALERT_PX) {
        let better: Vec<&ModelFit> = fits
            .iter()
            .filter(|f| f.rms_px <= 0.7 * report.rms_px)
            .collect();
        if let Some(f) = pick(&better) {
            warnings.push(format!(
                "the residuals grow with the distance from the image centre (rms {outer:.3} px \
                 in the outer third against {inner:.3} px in the centre): the {} model does \
                 not follow this lens; {} fits the same views at {:.3} px against {:.3} px: \
                 switch the model to {name} (CLI: --model {name}){}",
                label(chosen),
                label(&f.model),
                f.rms_px,
                report.rms_px,
                formats_clause(&f.model),
                name = f.model,
            ));
            recommended = f.model.clone();
        }
    } else if far_off {
        let better: Vec<&ModelFit> = fits
            .iter()
            .filter(|f| f.rms_px <= 0.5 * report.rms_px)
            .collect();
        match pick(&better) {
            Some(f) => {
                warnings.push(format!(
                    "the residuals (rms {:.3} px) are far above detection noise: the {} model \
                     does not fit this lens; {} fits the same views at {:.3} px ({:.0}x lower): \
                     switch the model to {name} (CLI: --model {name}){}",
                    report.rms_px,
                    label(chosen),
                    label(&f.model),
                    f.rms_px,
                    report.rms_px / f.rms_px,
                    formats_clause(&f.model),
                    name = f.model,
                ));
                recommended = f.model.clone();
            }
            None => warnings.push(format!(
                "the residuals (rms {:.3} px) are far above detection noise (below {} px \
                 expected) and no other lens model fits much better: check the target spec \
                 and its printed size, and exclude views with wrong detections",
                report.rms_px, RESIDUAL_ALERT_PX
            )),
        }
    } else {
        let as_well = |f: &&ModelFit| f.rms_px <= SAME_FIT_RATIO * report.rms_px + SAME_FIT_PX;
        // A simpler model is named only if it exports wherever the chosen one
        // does, and, for a wide-angle lens fitted with a fisheye model, only
        // another fisheye model: a polynomial's fit inside the views says
        // nothing of the rays beyond them, where a wide lens sees most.
        let mine = format_names(chosen);
        let keeps_fisheye = |m: &str| !(wide && is_fisheye(chosen)) || is_fisheye(m);
        let simplest = fits
            .iter()
            .filter(as_well)
            .filter(|f| f.coefficients < n_chosen)
            .filter(|f| mine.iter().all(|m| format_names(&f.model).contains(m)))
            .filter(|f| keeps_fisheye(&f.model))
            .min_by(|a, b| {
                a.coefficients
                    .cmp(&b.coefficients)
                    .then(a.rms_px.total_cmp(&b.rms_px))
            });
        let exportable = fits
            .iter()
            .filter(as_well)
            .filter(|f| can_go_to_opencv(&f.model))
            .min_by(|a, b| {
                a.coefficients
                    .cmp(&b.coefficients)
                    .then(a.rms_px.total_cmp(&b.rms_px))
            });
        if let Some(f) = simplest {
            warnings.push(format!(
                "too many parameters for these views: the {} model's {n_chosen}{free} coefficients \
                 fit at {:.3} px, and {} with {} fits as well ({:.3} px), so the extra ones fit \
                 noise and their values mean nothing: use {name} (CLI: --model {name}), or add \
                 views that fill the image corners{}",
                label(chosen),
                report.rms_px,
                label(&f.model),
                f.coefficients,
                f.rms_px,
                formats_clause(&f.model),
                name = f.model,
            ));
            recommended = f.model.clone();
        } else if let (false, Some(f)) = (can_go_to_opencv(chosen), exportable) {
            warnings.push(format!(
                "the {} model cannot be exported to OpenCV or ROS, and {} fits the same views as \
                 well ({:.3} px against {:.3} px): use {name} (CLI: --model {name}) to export \
                 there{}",
                label(chosen),
                label(&f.model),
                f.rms_px,
                report.rms_px,
                formats_clause(&f.model),
                name = f.model,
            ));
            recommended = f.model.clone();
        }
    }
    // 3. The summary.
    let mut compared = vec![ModelFit {
        model: chosen.to_string(),
        rms_px: report.rms_px,
        coefficients: n_chosen,
    }];
    compared.extend(fits);
    let others: Vec<String> = compared[1..]
        .iter()
        .map(|f| format!("{} {:.3} px", f.model, f.rms_px))
        .collect();
    let summary = format!(
        "lens model: {recommended}{} ({} fits at {:.3} px{}; half diagonal field of view {fov:.0} deg){}",
        if recommended == chosen { "" } else { " recommended" },
        chosen,
        report.rms_px,
        if others.is_empty() {
            String::new()
        } else {
            format!(", compared with {}", others.join(", "))
        },
        formats_clause(&recommended),
    );
    ModelAdvice {
        export_formats: export_formats(&recommended)
            .iter()
            .map(|f| f.to_string())
            .collect(),
        recommended,
        compared,
        half_diagonal_fov_deg: fov,
        summary,
        warnings,
    }
}

#[cfg(test)]
#[path = "model_advice_tests.rs"]
mod tests;
