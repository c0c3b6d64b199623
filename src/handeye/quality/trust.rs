//! Can the reported uncertainty be trusted? The pose refinement's
//! covariance is right when its noise model is: white robot and camera pose
//! noise. Real cells add what it leaves out (robot kinematic error that
//! depends on the pose, slightly wrong intrinsics, timing), and weak
//! geometry lets those move the answer far more than the model says. Two
//! checks, both on the data at hand:
//!
//! 1. **Internal consistency.** The leave-one-out solutions (the
//!    repeatability's jackknife, each a full refinement without one view)
//!    spread as the covariance predicts when the model is right: their
//!    jackknife std over `n` views has a relative spread of about
//!    `1 / sqrt(2 (n - 1))` per axis. When their spread (root-sum-square
//!    over the three axes, translation and rotation apart) exceeds the
//!    covariance's by more than [`WIDEN_RATIO`], the covariance is scaled
//!    by the square of the larger ratio (the std by the ratio) and a warning
//!    says so.
//!    Few poses ([`widen_for_few_poses`]): below
//!    [`crate::handeye::refine::pose_noise::MIN_POSES_FOR_NOISE_ESTIMATE`]
//!    poses the noise levels are the documented defaults times one scale
//!    fitted to the residuals, `6 n - 12` degrees of freedom for `n` inlier
//!    poses (six residuals a pose, twelve unknowns). A std resting on so
//!    few degrees of freedom is itself uncertain: the error over it
//!    follows Student's t, whose 3-std interval covers 98.9 % with 12 (4
//!    poses) instead of 99.73 %. The covariance is scaled by the square
//!    of [`coverage_factor`] of those degrees of freedom (1.25 at 4 poses,
//!    1.11 at 6) before the leave-one-out comparison, which cannot run
//!    below [`MIN_LOO_VIEWS`] poses; the "only n poses" warning stays.
//! 2. **Weak geometry, named**: fewer than [`FEW_POSES`] poses, a largest
//!    robot rotation under [`SMALL_ROTATION_DEG`], and the target at one
//!    distance in every view (spread under [`ONE_DISTANCE_SPREAD`] of the
//!    median: a focal-length error then moves the camera along its optical
//!    axis without leaving a residual).
//!
//! Finally the error that matters to a user: the std at the default work
//! point (the target's centre where the views see it, at their mean
//! distance: [`crate::handeye::quality::work_point::target_centre_camera`]),
//! from the (widened) covariance of the camera transform.

use crate::handeye::closed_form::motion::MotionStats;
use crate::handeye::quality::checks::consistency;
use crate::handeye::quality::repeat::Repeatability;
use crate::handeye::quality::residuals::pose_difference;
use crate::handeye::quality::work_point::{target_centre_camera, DefaultWorkPoint, Placement};
use crate::handeye::refine::pose_noise::NoiseModel;
use crate::handeye::refine::pose_problem::{refine, PoseRefineOptions};
use crate::handeye::refine::pose_residual::PoseMeasurement;
use crate::handeye::refine::pose_summary::{transform_std, PoseRefinementSummary};
use crate::handeye::{HandEyeInput, Pose, Setup};
use crate::optim::student_t::coverage_factor;
use nalgebra::{Matrix3, Point3, SMatrix, Vector3};

/// The covariance is widened when the leave-one-out spread exceeds it by
/// more than this factor ...
pub const WIDEN_RATIO: f64 = 1.0;
/// ... and a warning says so beyond this one.
pub const WARN_RATIO: f64 = 2.0;
/// Leave-one-out spreads below these (mm, degrees) are rounding, not data.
pub const LOO_FLOOR_MM: f64 = 1e-4;
/// See [`LOO_FLOOR_MM`].
pub const LOO_FLOOR_DEG: f64 = 1e-6;
/// Fewest views for the leave-one-out comparison.
pub const MIN_LOO_VIEWS: usize = 6;
/// Fewer poses than this are named as too few.
pub const FEW_POSES: usize = 8;
/// Poses recommended.
pub const RECOMMENDED_POSES: usize = 12;
/// A largest robot rotation below this (degrees) is named as small.
pub const SMALL_ROTATION_DEG: f64 = 25.0;
/// A camera-target distance range below this fraction of the median is
/// named as one distance.
pub const ONE_DISTANCE_SPREAD: f64 = 0.1;

fn rss(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Compare the refinement's covariance with the leave-one-out spread and
/// widen it when the spread is larger (module docs). The leave-one-out std
/// are per axis of `x^-1 * x_run` (the transform's own frame), so the
/// covariance is turned into that frame (`R^T Sigma R` per block, `R` the
/// camera transform's rotation) and compared axis by axis; the largest
/// ratio scales it. Returns the warning (ratio above [`WARN_RATIO`]).
pub fn widen_to_leave_one_out(
    summary: &mut PoseRefinementSummary,
    repeatability: &Repeatability,
    x_rotation: &Matrix3<f64>,
    views: usize,
) -> Option<String> {
    let loo = &repeatability.leave_one_out;
    if views < MIN_LOO_VIEWS || loo.runs + 1 < views {
        return None;
    }
    let block = |offset: usize| {
        let m = Matrix3::from_fn(|r, c| summary.covariance[offset + r][offset + c]);
        let own = x_rotation.transpose() * m * x_rotation;
        [0, 1, 2].map(|k| own[(k, k)].max(0.0).sqrt())
    };
    let model_r = block(0).map(f64::to_degrees);
    let model_t = block(3).map(|v| v * 1e3);
    let (loo_r, loo_t) = (&loo.camera_std.rotation_deg, &loo.camera_std.translation_mm);
    // Spreads at rounding level (noise-free data) say nothing.
    let mut ratio: f64 = 0.0;
    for k in 0..3 {
        if loo_t[k] > LOO_FLOOR_MM && model_t[k] > 0.0 {
            ratio = ratio.max(loo_t[k] / model_t[k]);
        }
        if loo_r[k] > LOO_FLOOR_DEG && model_r[k] > 0.0 {
            ratio = ratio.max(loo_r[k] / model_r[k]);
        }
    }
    if !ratio.is_finite() || ratio <= WIDEN_RATIO {
        return None;
    }
    scale_covariance(summary, ratio);
    if ratio <= WARN_RATIO {
        return None;
    }
    Some(format!(
        "uncertainty: the leave-one-out solutions spread {ratio:.1} times wider than the noise \
         model predicts (translation {:.3} mm against {:.3} mm, rotation {:.4} deg against \
         {:.4} deg, root-sum-square over the axes): something the model leaves out (robot \
         kinematic error, wrong intrinsics, timing, a bad pose) moves the result, so the std \
         and covariance are widened by {ratio:.1}; check the views' residuals, the robot's \
         accuracy and the camera calibration, and add poses",
        rss(loo_t),
        rss(&model_t),
        rss(loo_r),
        rss(&model_r)
    ))
}

/// Scale the covariance by `factor^2` (the std by `factor`), recompute the
/// std and record the factor in `std_widened_by` (times any earlier one).
fn scale_covariance(summary: &mut PoseRefinementSummary, factor: f64) {
    let scale = factor * factor;
    let mut cov = SMatrix::<f64, 12, 12>::zeros();
    for (r, row) in summary.covariance.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v *= scale;
            cov[(r, c)] = *v;
        }
    }
    summary.camera_transform_std = transform_std(&cov, 0);
    summary.target_transform_std = transform_std(&cov, 6);
    summary.std_widened_by = Some(summary.std_widened_by.unwrap_or(1.0) * factor);
}

/// Widen the covariance for the few degrees of freedom its noise scale
/// rests on (module docs): with the noise levels scaled by one common
/// factor (fewer than 8 inlier poses), the std times [`coverage_factor`]
/// of `6 n - 12` for `n` inlier poses. Returns the factor (none when the
/// levels were estimated per component or nothing is left to fit them).
pub fn widen_for_few_poses(summary: &mut PoseRefinementSummary) -> Option<f64> {
    if summary.noise_estimated_per_component {
        return None;
    }
    let inliers = summary
        .whitened_residual_norms
        .len()
        .saturating_sub(summary.outlier_views.len());
    let dof = 6.0 * inliers as f64 - 12.0;
    let factor = coverage_factor(dof);
    if dof <= 0.0 || factor <= 1.0 {
        return None;
    }
    scale_covariance(summary, factor);
    Some(factor)
}

/// Warnings that name weak geometry (module docs): `views` poses used,
/// the motion statistics, and each view's camera-target distance (m).
pub fn geometry_warnings(views: usize, motion: &MotionStats, distances_m: &[f64]) -> Vec<String> {
    let mut out = Vec::new();
    if views < FEW_POSES {
        out.push(format!(
            "weak geometry: only {views} poses: the result and its uncertainty rest on too few; \
             add {} more (at least {RECOMMENDED_POSES} in all), rotating the gripper by 30 deg \
             or more about different axes between them",
            RECOMMENDED_POSES - views
        ));
    }
    if motion.angle_max_deg < SMALL_ROTATION_DEG {
        out.push(format!(
            "weak geometry: the largest rotation between two poses is {:.1} deg: with small \
             rotations the hand-eye translation is poorly determined (its error grows as the \
             rotations shrink); rotate the gripper by 30 deg or more about at least two axes",
            motion.angle_max_deg
        ));
    }
    let mut d: Vec<f64> = distances_m
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    if d.len() >= 3 {
        d.sort_by(f64::total_cmp);
        let median = d[d.len() / 2];
        let range = d[d.len() - 1] - d[0];
        if median > 0.0 && range < ONE_DISTANCE_SPREAD * median {
            out.push(format!(
                "weak geometry: the target is at one distance in every view ({:.3} to {:.3} m): \
                 an error in the focal length then moves the camera along its optical axis \
                 without showing in any residual; vary the distance to the target by 20 % or \
                 more (poses at several heights)",
                d[0],
                d[d.len() - 1]
            ));
        }
    }
    out
}

/// The std (mm, root-sum-square over the axes) of a point `point_camera`
/// (camera frame, m), in the frame of the camera transform's left side,
/// from the refinement's covariance; `x_rotation` is the camera
/// transform's rotation (`gripper_from_camera` or `base_from_camera`).
/// Rotation errors are in the left frame: `d(point) = d(t) - [R p]x d(theta)`.
pub fn work_point_std_mm(
    summary: &PoseRefinementSummary,
    x_rotation: &Matrix3<f64>,
    point_camera: &Vector3<f64>,
) -> f64 {
    let p = x_rotation * point_camera;
    let skew = Matrix3::new(0.0, -p.z, p.y, p.z, 0.0, -p.x, -p.y, p.x, 0.0);
    let mut j = SMatrix::<f64, 3, 6>::zeros();
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-skew));
    j.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&Matrix3::identity());
    let cov6 = SMatrix::<f64, 6, 6>::from_fn(|r, c| summary.covariance[r][c]);
    let point = j * cov6 * j.transpose();
    point.trace().max(0.0).sqrt() * 1e3
}

/// A scale mismatch of the camera translations below this (relative) is
/// not reported, whatever its spread.
pub const SCALE_MIN: f64 = 1e-3;
/// Views used for the scale's jackknife (evenly spread over larger sets).
const SCALE_VIEWS: usize = 40;

/// The scale `k` that makes the robot translations fit the camera motion
/// (`(R_A - I) t + k t_A = R_X t_B`, [`consistency`]) and its jackknife std
/// over the views. `k` is 1 when the camera poses are metric; a focal
/// length off by 1 % (PnP then puts the target 1 % too far) or a target
/// square size off by 1 % gives `k` 1 % from 1. `None` when too few views
/// or motions.
pub fn translation_scale(
    setup: Setup,
    base_from_gripper: &[Pose],
    camera_from_target: &[Pose],
) -> Option<(f64, f64)> {
    let n = base_from_gripper.len().min(camera_from_target.len());
    if n < MIN_LOO_VIEWS {
        return None;
    }
    let picked: Vec<usize> = if n > SCALE_VIEWS {
        (0..SCALE_VIEWS).map(|i| i * n / SCALE_VIEWS).collect()
    } else {
        (0..n).collect()
    };
    let scale_of = |idx: &[usize]| -> Option<f64> {
        let r: Vec<Pose> = idx.iter().map(|&i| base_from_gripper[i]).collect();
        let c: Vec<Pose> = idx.iter().map(|&i| camera_from_target[i]).collect();
        consistency(setup, &r, &c)
            .ok()
            .map(|c| c.robot_translation_scale)
            .filter(|k| k.is_finite() && *k > 0.0)
    };
    let k = scale_of(&picked)?;
    let runs: Vec<f64> = (0..picked.len())
        .filter_map(|skip| {
            let idx: Vec<usize> = picked
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != skip)
                .map(|(_, &i)| i)
                .collect();
            scale_of(&idx)
        })
        .collect();
    if runs.len() + 1 < picked.len() {
        return None;
    }
    let m = runs.len() as f64;
    let mean = runs.iter().sum::<f64>() / m;
    let var = (m - 1.0) / m * runs.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
    Some((k, var.sqrt()))
}

/// Add the outer product of a shift of the camera transform (`dx`) and the
/// target transform (`dy`), each `[rotation (rad, left frame); translation
/// (m)]`, to the covariance and recompute the std.
pub fn add_shift_to_covariance(summary: &mut PoseRefinementSummary, dx: &[f64; 6], dy: &[f64; 6]) {
    let d: Vec<f64> = dx.iter().chain(dy.iter()).copied().collect();
    let mut cov = SMatrix::<f64, 12, 12>::zeros();
    for (r, row) in summary.covariance.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v += d[r] * d[c];
            cov[(r, c)] = *v;
        }
    }
    summary.camera_transform_std = transform_std(&cov, 0);
    summary.target_transform_std = transform_std(&cov, 6);
}

/// `b` relative to `a` as `[rotation vector of b a^-1 (rad); b.t - a.t (m)]`.
pub fn pose_shift(a: &Pose, b: &Pose) -> [f64; 6] {
    let w = (b.rotation * a.rotation.inverse()).scaled_axis();
    let t = b.translation.vector - a.translation.vector;
    [w.x, w.y, w.z, t.x, t.y, t.z]
}

/// The camera translations against the robot's
/// ([`translation_scale`]): when they disagree by more than
/// three of their jackknife std (and [`SCALE_MIN`]), a refit
/// with the camera translations rescaled shows how far that moves the
/// transforms; the shift joins the covariance and a warning names the
/// likely causes.
pub(crate) fn check_translation_scale(
    summary: &mut PoseRefinementSummary,
    (x, y): (&Pose, &Pose),
    input: &HandEyeInput,
    views: &[PoseMeasurement],
    (noise, options): (&NoiseModel, &PoseRefineOptions),
) -> Option<String> {
    let (k, sk) = translation_scale(
        input.setup,
        &input.base_from_gripper,
        &input.camera_from_target,
    )?;
    let off = k - 1.0;
    if !(off.abs() > 3.0 * sk && off.abs() > SCALE_MIN) {
        return None;
    }
    let scaled: Vec<PoseMeasurement> = views
        .iter()
        .map(|m| PoseMeasurement {
            base_from_gripper: m.base_from_gripper,
            camera_from_target: Pose::from_parts(
                nalgebra::Translation3::from(m.camera_from_target.translation.vector / k),
                m.camera_from_target.rotation,
            ),
        })
        .collect();
    let refit = refine(input.setup, &scaled, x, y, noise.clone(), options).ok()?;
    let dx = pose_shift(x, &refit.x);
    let dy = pose_shift(y, &refit.y);
    add_shift_to_covariance(summary, &dx, &dy);
    let (moved_mm, moved_deg) = pose_difference(x, &refit.x);
    Some(format!(
        "scale: the camera translations match the robot's only when scaled by {:.4} (+- {:.4}): \
         the camera's focal length or the target's square size is about {:.2} % off; a refit \
         with the camera translations rescaled moves {} by {moved_mm:.2} mm and {moved_deg:.3} \
         deg, which the std now includes; check the camera calibration and the target spec",
        1.0 / k,
        sk / (k * k),
        100.0 * off.abs(),
        input.setup.camera_key()
    ))
}

/// The uncertainty checked against the data ([`crate::handeye::quality::trust`]): widened
/// to the leave-one-out spread of `repeatability` when that is larger (the
/// warning returned), and the error at the default work point (the target
/// frame's origin here; [`place_work_point`] moves it to the board centre
/// when the board points are known).
pub(crate) fn check_uncertainty(
    summary: &mut PoseRefinementSummary,
    x: &Pose,
    repeatability: Option<&Repeatability>,
    input: &HandEyeInput,
) -> Option<String> {
    let n = input.camera_from_target.len();
    let rotation = x.rotation.to_rotation_matrix().into_inner();
    widen_for_few_poses(summary);
    let warning = repeatability.and_then(|rep| widen_to_leave_one_out(summary, rep, &rotation, n));
    place_work_point(
        summary,
        x,
        &input.camera_from_target,
        &Point3::origin(),
        Placement::TargetOrigin,
    );
    warning
}

/// Place the summary's default work point at the target point `centre`
/// (target frame) as the views `camera_from_target` see it
/// ([`target_centre_camera`]): `work_distance_m` (its mean distance),
/// `work_point_std_mm` (the error there) and the point itself, which the
/// report's `work_point_error` is computed at. Left unchanged when no view
/// places it.
pub fn place_work_point(
    summary: &mut PoseRefinementSummary,
    x: &Pose,
    camera_from_target: &[Pose],
    centre: &Point3<f64>,
    placement: Placement,
) {
    let Some(q) = target_centre_camera(camera_from_target, centre) else {
        return;
    };
    let rotation = x.rotation.to_rotation_matrix().into_inner();
    summary.work_distance_m = Some(q.norm());
    summary.work_point_std_mm = Some(work_point_std_mm(summary, &rotation, &q));
    summary.work_point = Some(DefaultWorkPoint {
        camera_m: [q.x, q.y, q.z],
        placement,
    });
}

/// The frame name of the camera transform, for messages.
pub fn camera_transform_name(setup: Setup) -> &'static str {
    setup.camera_key()
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn stats(angle_max_deg: f64) -> MotionStats {
        MotionStats {
            motions: 10,
            discarded_small_rotation: 0,
            angle_min_deg: 5.0,
            angle_median_deg: angle_max_deg / 2.0,
            angle_max_deg,
            axis_spread_deg: 60.0,
            dominant_axis: [0.0, 0.0, 1.0],
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn weak_geometry_is_named_and_good_geometry_is_not() {
        let good = geometry_warnings(12, &stats(60.0), &[0.4, 0.5, 0.6, 0.55]);
        assert!(good.is_empty(), "{good:?}");
        let weak = geometry_warnings(5, &stats(12.5), &[0.50, 0.51, 0.52, 0.505, 0.515]);
        assert_eq!(weak.len(), 3, "{weak:?}");
        assert!(
            weak[0].starts_with("weak geometry: only 5 poses: "),
            "{}",
            weak[0]
        );
        assert!(
            weak[0].contains("add 7 more (at least 12 in all)"),
            "{}",
            weak[0]
        );
        assert!(
            weak[1]
                .starts_with("weak geometry: the largest rotation between two poses is 12.5 deg"),
            "{}",
            weak[1]
        );
        assert!(
            weak[2].starts_with(
                "weak geometry: the target is at one distance in every view (0.500 to 0.520 m)"
            ),
            "{}",
            weak[2]
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn the_work_point_std_adds_the_rotation_lever() {
        // Translation std 1 mm per axis, rotation std 1 mrad per axis,
        // uncorrelated: at 0.5 m along z the rotation adds 0.5 mm on x and
        // y: sqrt(3 * 1 + 2 * 0.25) mm.
        let mut cov = vec![[0.0; 12]; 12];
        for (k, row) in cov.iter_mut().enumerate().take(6) {
            row[k] = 1e-6; // (1 mrad)^2 for rotations, (1 mm)^2 for translations
        }
        let summary = PoseRefinementSummary::for_tests(cov);
        let s = work_point_std_mm(&summary, &Matrix3::identity(), &Vector3::new(0.0, 0.0, 0.5));
        assert!((s - (3.0f64 + 0.5).sqrt()).abs() < 1e-9, "{s}");
        // At the transform's origin only the translation counts.
        let s0 = work_point_std_mm(&summary, &Matrix3::identity(), &Vector3::zeros());
        assert!((s0 - 3f64.sqrt()).abs() < 1e-9, "{s0}");
    }
}
