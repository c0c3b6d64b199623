//! A calibration report at a given estimate, without refining it: how the
//! linear and filter methods (DLT, EKF) are reported in the same form as
//! Zhang's bundle adjustment, with the parameter covariance from the
//! Jacobian at that estimate scaled by its residual variance.

use super::refine::{block_from_pose, CalibProblem};
use super::report::{build_report, SpreadCheck};
use super::{CalibrationOptions, CameraCalibration, View};
use crate::camera::Camera;
use crate::error::Result;
use crate::geometry::Pose;
use crate::optim::{solve, BlockParams, LmOptions};
use nalgebra::DMatrix;

/// The report of `camera` and one pose per view, as they are. `fixed`
/// flags the camera parameters (layout of [`Camera::params`]) the method
/// did not estimate: they get a standard deviation of 0.
pub(crate) fn report_at(
    views: &[View],
    camera: &Camera,
    poses: &[Pose],
    fixed: Vec<bool>,
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    refine_from(views, camera, poses, fixed, None, 0, options)
}

/// Bundle adjustment from a method's own start (camera and poses) for at
/// most `iterations` solver iterations, then the report. With `aspect`,
/// fy is held at `aspect * fx`.
pub(crate) fn refine_from(
    views: &[View],
    camera: &Camera,
    poses: &[Pose],
    fixed: Vec<bool>,
    aspect: Option<f64>,
    iterations: usize,
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    refine_with(
        views, camera, poses, fixed, aspect, iterations, None, options,
    )
}

/// The report of `camera` and the poses as they are, with the camera
/// parameters' covariance given (layout of [`Camera::params`]) instead of
/// the one of the Jacobian: for the filter, whose own covariance is its
/// uncertainty.
pub(crate) fn report_with_covariance(
    views: &[View],
    camera: &Camera,
    poses: &[Pose],
    covariance: DMatrix<f64>,
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    let fixed = vec![true; camera.params().len()];
    refine_with(
        views,
        camera,
        poses,
        fixed,
        None,
        0,
        Some(covariance),
        options,
    )
}

#[allow(clippy::too_many_arguments)]
fn refine_with(
    views: &[View],
    camera: &Camera,
    poses: &[Pose],
    fixed: Vec<bool>,
    aspect: Option<f64>,
    iterations: usize,
    covariance: Option<DMatrix<f64>>,
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    let used: Vec<Vec<bool>> = views.iter().map(|v| vec![true; v.object_m.len()]).collect();
    let problem = CalibProblem {
        template: camera,
        views,
        used: &used,
        aspect,
        warp: None,
    };
    let params = BlockParams {
        global: camera.params(),
        blocks: poses.iter().map(block_from_pose).collect(),
    };
    // With 0 iterations the solver only evaluates the cost and the covariance.
    let lm = LmOptions {
        max_iterations: iterations,
        fixed_global: fixed,
        ..LmOptions::default()
    };
    let mut result = solve(&problem, &params, &lm)?;
    // A covariance given from elsewhere (the filter's) is its own
    // uncertainty: the views' spread is not checked against it.
    let spread = if covariance.is_some() {
        SpreadCheck::Skip
    } else {
        SpreadCheck::Check
    };
    if covariance.is_some() {
        result.covariance_global = covariance;
    }
    let options = CalibrationOptions {
        model: camera.distortion.clone(),
        ..options.clone()
    };
    build_report(
        &problem,
        &result,
        vec![vec![]; views.len()],
        (camera.width, camera.height),
        &options,
        spread,
    )
}
