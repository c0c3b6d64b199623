//! Stereo calibration (seed 000): two cameras that saw the same board
//! poses. Each camera is first calibrated alone ([`calibrate`]); the seed's
//! per-view relation `R = R_R R_L^-1`, `T = T_R - R T_L` gives one
//! right_from_left per view, averaged (rotations by the quaternion mean,
//! translations arithmetically); then one Levenberg-Marquardt refines both
//! cameras' intrinsics and distortion, the left camera's board poses and
//! right_from_left jointly (the right camera sees the board at
//! `right_from_left * left_from_target`).

use super::stereo_jackknife::{leave_pairs_out, WARN_FACTOR};
use crate::calib::model_advice::{advise, ModelAdvice};
use crate::calib::multi::same_images::{refuse_identical_views, refuse_zero_baseline};
use crate::calib::multi::stereo_problem::StereoProblem;
use crate::calib::refine::{block_from_pose, CalibProblem};
use crate::calib::report::{build_report, SpreadCheck};
use crate::calib::usable::{usable_views, LeftOut};
use crate::calib::zhang::lm_options;
use crate::calib::{calibrate, CalibrationOptions, CameraCalibration, View};
use crate::error::{Error, Result};
use crate::geometry::{average_rotations_quaternion, Pose, PoseJson};
use crate::optim::{solve, BlockParams, BlockProblem, LmOptions, Termination};
use nalgebra::{Translation3, Vector3};
use serde::{Deserialize, Serialize};

/// Standard deviations of right_from_left from the joint covariance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TransformStd {
    /// Of the rotation (small-angle vector, left perturbation), radians.
    pub rotation_rad: [f64; 3],
    /// Of the translation, metres.
    pub translation_m: [f64; 3],
}

/// The result of [`calibrate_stereo`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StereoCalibration {
    /// What the report is: `stereo` (absent from reports written before
    /// the key existed).
    #[serde(default = "crate::report_kind::ReportKind::stereo")]
    pub kind: crate::report_kind::ReportKind,
    /// The left camera at the joint optimum (its `std` and correlations are
    /// from its own observations, with the right camera held).
    pub left: CameraCalibration,
    /// The right camera at the joint optimum; its views' `camera_from_target`
    /// is `right_from_left * left camera_from_target`.
    pub right: CameraCalibration,
    /// The refined transform: `p_right = right_from_left * p_left`.
    pub right_from_left: PoseJson,
    /// The averaged single-camera estimate the refinement started from.
    pub initial_right_from_left: PoseJson,
    /// Distance between the camera centres, metres.
    pub baseline_m: f64,
    /// Standard deviations of right_from_left (`None` when singular): the
    /// joint fit's, widened axis by axis to the leave-pairs-out spread
    /// where that is larger ([`super::stereo_jackknife`]).
    pub right_from_left_std: Option<TransformStd>,
    /// RMS reprojection error over every point of both cameras, px.
    pub rms_px: f64,
    /// Joint solver iterations.
    pub iterations: usize,
    /// Why the joint solver stopped.
    pub termination: Termination,
    /// Pairs left out (a side whose points cannot fix a homography), with
    /// the reason, and the lens-model advice of each camera; empty when
    /// every pair was used and both models fit.
    #[serde(default)]
    pub warnings: Vec<String>,
    /// The lens-model advice of each camera ([`crate::calib::model_advice::advise`]);
    /// absent in reports written before it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_advice: Option<PairModelAdvice>,
}

/// The lens-model advice of both cameras of a pair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairModelAdvice {
    /// The left camera's.
    pub left: ModelAdvice,
    /// The right camera's.
    pub right: ModelAdvice,
}

/// Calibrate a stereo pair from views paired by index (`left[i]` and
/// `right[i]` saw the same board pose; their point sets may differ: each
/// camera's residuals are over its own points, through the shared board
/// pose, so no point needs to be seen by both). A pair with a side whose
/// points cannot fix a homography ([`crate::calib::usable`]) is left out, with a
/// warning. `options` apply to both cameras; points a single-camera
/// calibration rejected as outliers stay out of the joint refinement.
pub fn calibrate_stereo(
    left: &[View],
    right: &[View],
    left_size_px: (u32, u32),
    right_size_px: (u32, u32),
    options: &CalibrationOptions,
) -> Result<StereoCalibration> {
    if left.len() != right.len() {
        return Err(Error::invalid(
            "right",
            format!(
                "views are paired by order: {} left views but {} right views",
                left.len(),
                right.len()
            ),
        ));
    }
    let pairs: Vec<(&View, &View)> = left.iter().zip(right).collect();
    refuse_identical_views("right", "the left and right images", "pairs", &pairs)?;
    let (left, right, warnings) = usable_pairs(left, right, options)?;
    let (left, right) = (&left[..], &right[..]);
    let single_left = calibrate(left, left_size_px, options)?;
    let single_right = calibrate(right, right_size_px, options)?;
    let left_poses = report_poses(&single_left)?;
    let right_poses = report_poses(&single_right)?;
    let initial = initial_right_from_left(&left_poses, &right_poses)?;
    let used_left = used_masks(left, &single_left);
    let used_right = used_masks(right, &single_right);
    let problem = StereoProblem {
        left: CalibProblem {
            template: &single_left.camera,
            views: left,
            used: &used_left,
            aspect: aspect(&single_left.camera, options),
            warp: None,
        },
        right: CalibProblem {
            template: &single_right.camera,
            views: right,
            used: &used_right,
            aspect: aspect(&single_right.camera, options),
            warp: None,
        },
        n_left: single_left.camera.params().len(),
        n_right: single_right.camera.params().len(),
    };
    let lm_left = lm_options(&single_left.camera, options)?;
    let lm_right = lm_options(&single_right.camera, options)?;
    let mut fixed_global = lm_left.fixed_global.clone();
    fixed_global.extend(&lm_right.fixed_global);
    fixed_global.extend([false; 6]);
    let mut global = single_left.camera.params();
    global.extend(single_right.camera.params());
    global.extend(block_from_pose(&initial));
    let start = BlockParams {
        global,
        blocks: left_poses.iter().map(block_from_pose).collect(),
    };
    let lm = LmOptions {
        fixed_global,
        ..lm_left
    };
    let result = solve(&problem, &start, &lm)?;
    let g = &result.params.global;
    let (nl, nr) = (problem.n_left, problem.n_right);
    let rfl = problem.right_from_left(g);
    let right_blocks: Vec<Vec<f64>> = result
        .params
        .blocks
        .iter()
        .map(|b| block_from_pose(&(rfl * crate::calib::refine::pose_from_block(b))))
        .collect();
    let left_report = camera_report(
        &problem.left,
        &g[..nl],
        &result.params.blocks,
        &single_left,
        left_size_px,
        options,
    )?;
    let right_report = camera_report(
        &problem.right,
        &g[nl..nl + nr],
        &right_blocks,
        &single_right,
        right_size_px,
        options,
    )?;
    let blocks = problem.residuals_and_jacobian(&result.params, false)?;
    let squared: f64 = blocks.iter().map(|b| b.residuals.norm_squared()).sum();
    let o = problem.rfl_offset();
    let mut warnings = warnings;
    let right_from_left_std = result.std_global().map(|s| {
        let mut std: [f64; 6] = std::array::from_fn(|i| s[o + i]);
        // Checked against the spread of leave-pairs-out refits and widened
        // to it axis by axis ([`super::stereo_jackknife`]).
        if let Some(spread) = leave_pairs_out(&problem, &result, &lm) {
            let runs = spread.runs;
            let mut worst: f64 = 1.0;
            for ((model, data), covering) in std.iter_mut().zip(spread.std).zip(spread.covering) {
                if *model > 0.0 {
                    // Warned on the plain spread, widened to the t-scaled one.
                    worst = worst.max(data / *model);
                    *model = model.max(covering);
                }
            }
            if worst > WARN_FACTOR {
                warnings.push(format!(
                    "right_from_left: leaving pairs out moves it {worst:.1}x more than the joint \
                     fit's std says ({runs} refits): the pairs disagree beyond the pixel noise \
                     (the two images of a pair not taken at one moment while the board moved, a \
                     board that bends, a camera that moved between pairs); its std is widened to \
                     that spread. Hold the board still for each pair or trigger the cameras \
                     together"
                ));
            }
        }
        TransformStd {
            rotation_rad: [std[0], std[1], std[2]],
            translation_m: [std[3], std[4], std[5]],
        }
    });
    let baseline_m = rfl.inverse().translation.vector.norm();
    refuse_zero_baseline(
        "right_from_left",
        "the left and right cameras",
        baseline_m,
        right_from_left_std.as_ref().map(|s| s.translation_m),
    )?;
    // Each camera's lens model, judged on its views at the joint optimum.
    let advice = PairModelAdvice {
        left: advise(left, left_size_px, options, &left_report),
        right: advise(right, right_size_px, options, &right_report),
    };
    for (side, a) in [("left", &advice.left), ("right", &advice.right)] {
        warnings.extend(a.warnings.iter().map(|w| format!("{side} camera: {w}")));
    }
    Ok(StereoCalibration {
        kind: crate::report_kind::ReportKind::Stereo,
        model_advice: Some(advice),
        left: left_report,
        right: right_report,
        right_from_left: PoseJson::from(&rfl),
        initial_right_from_left: PoseJson::from(&initial),
        baseline_m,
        right_from_left_std,
        rms_px: (squared / blocks.len().max(1) as f64).sqrt(),
        iterations: result.iterations,
        termination: result.termination,
        warnings,
    })
}

/// The pairs whose two views each fix a homography, and a warning per pair
/// left out; fewer usable pairs than Zhang's closed form needs is an error
/// naming the pairs left out and why.
fn usable_pairs(
    left: &[View],
    right: &[View],
    options: &CalibrationOptions,
) -> Result<(Vec<View>, Vec<View>, Vec<String>)> {
    let (_, left_out_l) = usable_views(left);
    let (_, left_out_r) = usable_views(right);
    let reason =
        |list: &[LeftOut], i: usize| list.iter().find(|l| l.index == i).map(|l| l.reason.clone());
    let (mut kept_l, mut kept_r, mut left_out) = (Vec::new(), Vec::new(), Vec::new());
    for (i, (l, r)) in left.iter().zip(right).enumerate() {
        let why: Vec<String> = [
            ("left", &l.name, reason(&left_out_l, i)),
            ("right", &r.name, reason(&left_out_r, i)),
        ]
        .into_iter()
        .filter_map(|(side, name, why)| why.map(|w| format!("{side} {name}: {w}")))
        .collect();
        if why.is_empty() {
            kept_l.push(l.clone());
            kept_r.push(r.clone());
        } else {
            left_out.push(format!("pair {i} left out: {}", why.join("; ")));
        }
    }
    let required = crate::calib::zhang::required_views(options);
    if kept_l.len() < required && !left_out.is_empty() {
        return Err(Error::invalid(
            "pairs",
            format!(
                "requires at least {required} pairs whose views fix a homography, got {}; {}",
                kept_l.len(),
                left_out.join(", ")
            ),
        ));
    }
    Ok((kept_l, kept_r, left_out))
}

/// The seed's closed form per view, averaged: `R_i = R_R R_L^-1`,
/// `T_i = T_R - R_i T_L`; R = quaternion mean of the R_i, T = mean of the
/// `T_R - R T_L` (recomputed with the averaged R so that T matches it).
pub fn initial_right_from_left(
    left_from_target: &[Pose],
    right_from_target: &[Pose],
) -> Result<Pose> {
    let (l, r) = (left_from_target, right_from_target);
    if l.is_empty() || l.len() != r.len() {
        return Err(Error::invalid(
            "views",
            format!(
                "need paired views, got {} left and {} right",
                l.len(),
                r.len()
            ),
        ));
    }
    let rotations: Vec<_> = l
        .iter()
        .zip(r)
        .map(|(pl, pr)| pr.rotation * pl.rotation.inverse())
        .collect();
    let rotation = average_rotations_quaternion(&rotations, None)?;
    let mut t = Vector3::zeros();
    for (pl, pr) in l.iter().zip(r) {
        t += pr.translation.vector - rotation * pl.translation.vector;
    }
    t /= l.len() as f64;
    Ok(Pose::from_parts(Translation3::from(t), rotation))
}

fn aspect(camera: &crate::camera::Camera, options: &CalibrationOptions) -> Option<f64> {
    crate::calib::zhang::held_aspect(camera, options)
}

/// The camera_from_target of every view of a report.
pub(crate) fn report_poses(report: &CameraCalibration) -> Result<Vec<Pose>> {
    report
        .views
        .iter()
        .map(|v| v.camera_from_target.to_pose())
        .collect()
}

/// Per view, per point: not rejected by the single-camera calibration.
pub(crate) fn used_masks(views: &[View], report: &CameraCalibration) -> Vec<Vec<bool>> {
    views
        .iter()
        .zip(&report.views)
        .map(|(v, r)| {
            let mut used = vec![true; v.object_m.len()];
            for o in &r.outliers {
                if let Some(u) = used.get_mut(o.index) {
                    *u = false;
                }
            }
            used
        })
        .collect()
}

/// A camera report at the joint optimum: the solver evaluated (no
/// iterations) at the given camera and poses, then the usual report.
fn camera_report(
    problem: &CalibProblem,
    params: &[f64],
    blocks: &[Vec<f64>],
    single: &CameraCalibration,
    size: (u32, u32),
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    let lm = lm_options(problem.template, options)?;
    let outliers = single.views.iter().map(|v| v.outliers.clone()).collect();
    camera_report_with(problem, params, blocks, outliers, size, options, lm)
}

/// [`camera_report`] with the solver options given (e.g. every parameter
/// held) and the outliers of each view.
pub(crate) fn camera_report_with(
    problem: &CalibProblem,
    params: &[f64],
    blocks: &[Vec<f64>],
    outliers: Vec<Vec<crate::calib::Outlier>>,
    size: (u32, u32),
    options: &CalibrationOptions,
    lm: LmOptions,
) -> Result<CameraCalibration> {
    let start = BlockParams {
        global: params.to_vec(),
        blocks: blocks.to_vec(),
    };
    let result = solve(
        problem,
        &start,
        &LmOptions {
            max_iterations: 0,
            ..lm
        },
    )?;
    build_report(
        problem,
        &result,
        outliers,
        size,
        options,
        SpreadCheck::Check,
    )
}
