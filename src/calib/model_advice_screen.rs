//! A cheap first look at an alternative model for the model advice
//! (issue 38): most alternatives of a fit that is fine fit far worse, and
//! then their refit, the advice's cost, decides nothing.
//!
//! The alternative starts from the calibrated camera's intrinsics and view
//! poses with its own starting coefficients, takes [`SCREEN_ITERATIONS`]
//! solver iterations and the Gauss-Newton model there predicts the cost at
//! its minimum ([`crate::optim::gauss_newton_floor`]). When the RMS of that prediction is
//! more than [`SCREEN_MARGIN`] times the RMS the advice would act on, the
//! model is left out without a refit; otherwise (and whenever the screen
//! does not apply) the model is refitted in full, so every figure the
//! advice prints comes from a full fit as before.

use super::refine::{block_from_pose, CalibProblem};
use super::report::CameraCalibration;
use super::zhang::{held_aspect, lm_options, CalibrationOptions};
use super::View;
use crate::camera::{Camera, Distortion};
use crate::optim::{solve_with_floor, BlockParams, Loss};

/// Solver iterations of the screen before its prediction.
pub const SCREEN_ITERATIONS: usize = 3;

/// How far (as a factor on the RMS) the screen's prediction must be past
/// the advice's limit to leave a model out without its refit. From a
/// close start the Gauss-Newton prediction after a few iterations is the
/// minimum to a small fraction of a per cent (model_advice_tests prints
/// both); 2 % leaves room for a full fit that ends in a slightly lower
/// minimum, and still screens out the OpenCV sample's alternatives, which
/// fit 2.3-3.1 % past the limit.
pub const SCREEN_MARGIN: f64 = 1.02;

/// The RMS (px) the screen predicts for the views fitted with `options`
/// (an alternative model), from the camera and poses of `report`. `None`
/// when the screen does not apply (outlier rounds, a robust loss, the board
/// warp, a given start, a splined lens, views the
/// report does not hold one to one) or the solve fails: the full refit
/// decides then.
pub(crate) fn screened_rms(
    views: &[View],
    options: &CalibrationOptions,
    report: &CameraCalibration,
) -> Option<f64> {
    let plain = options.outlier_sigma.is_none()
        && options.loss == Loss::Squared
        && !options.board_warp
        && options.initial_camera.is_none()
        && !matches!(options.model, Distortion::Splined(_));
    let same_views = report.views.len() == views.len()
        && report
            .views
            .iter()
            .zip(views)
            .all(|(r, v)| r.name == v.name && r.n_points == v.object_m.len());
    if !plain || !same_views {
        return None;
    }
    let template = Camera {
        distortion: options.model.clone(),
        ..report.camera.clone()
    };
    let blocks = report
        .views
        .iter()
        .map(|v| {
            v.camera_from_target
                .to_pose()
                .ok()
                .map(|p| block_from_pose(&p))
        })
        .collect::<Option<Vec<_>>>()?;
    let used: Vec<Vec<bool>> = views.iter().map(|v| vec![true; v.object_m.len()]).collect();
    let problem = CalibProblem {
        template: &template,
        views,
        used: &used,
        // A held aspect ratio: the chosen fit's fy / fx (the closed form's
        // that the alternative's own fit would hold, to round-off), or the
        // one given.
        aspect: held_aspect(&report.camera, options),
        warp: None,
    };
    let start = BlockParams {
        global: template.params(),
        blocks,
    };
    let mut lm = lm_options(&template, options).ok()?;
    lm.max_iterations = SCREEN_ITERATIONS;
    // The floor at the solver's last point, from the normal equations it
    // built there (the same figure as `gauss_newton_floor` at
    // `result.params`, without evaluating the problem again).
    let (_, floor) = solve_with_floor(&problem, &start, &lm).ok()?;
    let n_points: usize = views.iter().map(|v| v.object_m.len()).sum();
    let rms = (2.0 * floor / n_points.max(1) as f64).sqrt();
    rms.is_finite().then_some(rms)
}
