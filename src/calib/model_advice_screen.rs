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
//! advice prints comes from a full fit as before. A first look of one
//! iteration ([`FIRST_LOOK_ITERATIONS`]) comes before: a model it predicts
//! clearly past the limit ([`FIRST_LOOK_MARGIN`]) is left out at once, at
//! half the screen's cost ([`screened_out`]).

use super::model_advice::RESIDUAL_ALERT_PX;
use super::refine::{block_from_pose, CalibProblem};
use super::report::CameraCalibration;
use super::zhang::{held_aspect, lm_options, CalibrationOptions};
use super::View;
use crate::camera::{Camera, Distortion};
use crate::optim::{solve_with_floor, BlockParams, Loss};

/// Solver iterations of the screen before its prediction.
pub const SCREEN_ITERATIONS: usize = 3;

/// Solver iterations of the screen's first look: one.
pub const FIRST_LOOK_ITERATIONS: usize = 1;

/// How far (a factor on the RMS) the first look's prediction must be past
/// the advice's limit to leave a model out at once; nearer, the screen of
/// [`SCREEN_ITERATIONS`] decides as before. On the 44 solves of BENCHMARKS
/// 5's report check the prediction after one iteration lay 2.9 % below to
/// 0.4 % above the one after three; a model the first look leaves out
/// predicts at least 5 % past the limit.
pub const FIRST_LOOK_MARGIN: f64 = 1.05;

/// Whether the model advice may leave out the alternative fitted with
/// `options` without its refit: the first look predicts an RMS beyond
/// [`FIRST_LOOK_MARGIN`] times `limit_px`, or the full screen beyond
/// [`SCREEN_MARGIN`] times it. False when the screen does not apply. The
/// first look only follows a fit that is fine (RMS up to
/// [`RESIDUAL_ALERT_PX`], the only fits the advice screens for): from a
/// camera pixels off, one iteration can predict 7x the alternative's
/// minimum (a fisheye fitted with Brown-Conrady, model_advice_tests).
pub(crate) fn screened_out(
    views: &[View],
    options: &CalibrationOptions,
    report: &CameraCalibration,
    limit_px: f64,
) -> bool {
    let first_look = if report.rms_px <= RESIDUAL_ALERT_PX {
        screened_rms(views, options, report, FIRST_LOOK_ITERATIONS)
    } else {
        Some(0.0)
    };
    match first_look {
        None => false,
        Some(rms) if rms > FIRST_LOOK_MARGIN * limit_px => true,
        Some(_) => screened_rms(views, options, report, SCREEN_ITERATIONS)
            .is_some_and(|rms| rms > SCREEN_MARGIN * limit_px),
    }
}

/// How far (as a factor on the RMS) the screen's prediction must be past
/// the advice's limit to leave a model out without its refit. From a
/// close start the Gauss-Newton prediction after a few iterations is the
/// minimum to a small fraction of a per cent (model_advice_tests prints
/// both); 2 % leaves room for a full fit that ends in a slightly lower
/// minimum, and still screens out the OpenCV sample's alternatives, which
/// fit 2.3-3.1 % past the limit.
pub const SCREEN_MARGIN: f64 = 1.02;

/// The RMS (px) the screen predicts, after `iterations` solver
/// iterations, for the views fitted with `options`
/// (an alternative model), from the camera and poses of `report`. `None`
/// when the screen does not apply (outlier rounds, a robust loss, the board
/// warp, a given start, a splined lens, views the
/// report does not hold one to one) or the solve fails: the full refit
/// decides then.
pub(crate) fn screened_rms(
    views: &[View],
    options: &CalibrationOptions,
    report: &CameraCalibration,
    iterations: usize,
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
    lm.max_iterations = iterations;
    // The floor at the solver's last point, from the normal equations it
    // built there (the same figure as `gauss_newton_floor` at
    // `result.params`, without evaluating the problem again).
    let (_, floor) = solve_with_floor(&problem, &start, &lm).ok()?;
    let n_points: usize = views.iter().map(|v| v.object_m.len()).sum();
    let rms = (2.0 * floor / n_points.max(1) as f64).sqrt();
    rms.is_finite().then_some(rms)
}
