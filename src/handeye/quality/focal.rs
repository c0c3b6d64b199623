//! Does the camera's focal length agree with the robot's motion?
//!
//! The image path takes each view's camera pose from PnP with the given
//! intrinsics. A focal length 1 % off puts every target about 1 % too far
//! along the optical axis and turns the poses of tilted views; the robot's
//! metric motions disagree with that, and the hand-eye solve with the
//! intrinsics held is biased while its covariance (built on those
//! intrinsics) says it is exact. Because the robot gives metric scale, the
//! focal length is observable in the joint problem over the pixels and the
//! robot poses: the reprojection least squares of
//! [`crate::handeye::refine::pixel_problem`] with one common scale `s` of fx
//! and fy free (`focal_scale`), the robot poses as given.
//!
//! The check ([`check_focal`]): `s` and its jackknife std over the views
//! (leave one out, or one of [`FOCAL_GROUPS`] groups out on larger sets),
//! which measures the robot's noise and kinematic error as well as the
//! pixels' (the point-wise covariance of that problem would take the robot
//! as exact). When `|s - 1|` exceeds [`FOCAL_ALERT_STD`] of that std, the
//! camera poses are computed again by PnP with fx and fy scaled by `s` and
//! the pose refinement runs on them: the freed solution. The orchestrator
//! adds the shift between the held (reported) and the freed solutions to
//! the covariance, and gives the warning, which says how far the focal
//! length is off and what to do, when `|s - 1|` exceeds [`FOCAL_MIN`] or
//! the shift exceeds the held std on some axis of the camera transform.
//!
//! Below [`FOCAL_ALERT_STD`] std the scale is not named, but a bias can
//! still hide there: kinematic error inflates the jackknife std of `s` and
//! can pull `s` itself (a smooth kinematic error is common to the views,
//! which the jackknife cannot see), so a real 1 % focal error can land
//! within one std of 1 while its shift lies beyond the held std. The held
//! solution takes the focal length as exact; the robot's motion confirms
//! it only to `std`, and with the camera's own std (`fx_std`, when the
//! camera came with it) to `known` ([`known_scale_std`], both together).
//! So the covariance always carries the focal length's uncertainty: the
//! shift to the freed solution joins it with its outer product scaled to
//! `(max(0, (s-1)^2 - std^2) + known^2) / (s-1)^2` ([`focal_share`]; the
//! first term is the unbiased estimate of the squared true offset,
//! `E[(s-1)^2] = (s_true-1)^2 + std^2`, the second what is not known of
//! the scale), and within one std of 1 the shift of a refit at `1 +- std`
//! joins it scaled by `known / std`: the covariance of the solution with
//! the focal length free. Without the camera's std, `known = std` and the
//! whole shift joins from one std on. Measured (`handeye_coverage 400`,
//! BENCHMARKS.md section 9): the 30-pose cell with kinematic error and a
//! 1 % focal error went from 1.2 % of trials beyond 4 std without a warning
//! to 0 %; with the right focal length and no camera std the std is wider
//! (mean abs(error) / std 0.60 -> 0.46), with the camera's fx std given
//! (0.5 px) 0.56.
//!
//! Why the shift, not `|s - 1|`, decides the warning: how far a focal
//! error moves the answer grows with the working distance. On RWHE-Calib's
//! CS_synthetic_1 (board 7-8 m away, 15 poses) fx 0.05 % short (1079.5 px
//! for 1080) moves gripper_from_camera 2.5 mm along the optical axis, 3.3
//! of its held std, and the scale is 17 of its std from 1: a fixed 0.1 %
//! floor let that through silently (tests/cli/cli_handeye_focal.rs).

use crate::calib::pnp::camera_from_target_with_covariance;
use crate::calib::View;
use crate::camera::Camera;
use crate::handeye::quality::residuals::pose_difference;
use crate::handeye::quality::trust::{pose_shift, MIN_LOO_VIEWS};
use crate::handeye::refine::over_poses::refine_over_poses;
use crate::handeye::refine::pixel_problem::{refine, RefineOptions};
use crate::handeye::refine::pose_noise::CameraNoise;
use crate::handeye::refine::pose_summary::{FocalCheck, TransformStd};
use crate::handeye::{HandEyeInput, HandEyeResult};
use crate::handeye::{MotionPairs, Pose, Setup};

/// The focal length is named as off when its fitted scale is more than
/// this many of its jackknife std from 1 ...
pub const FOCAL_ALERT_STD: f64 = 3.0;
/// ... and warned when more than this (relative) from 1, or when the
/// shift it causes exceeds the held std (module docs): a smaller
/// difference whose shift stays within the std widens the std silently.
pub const FOCAL_MIN: f64 = 1e-3;
/// Most jackknife groups (each a refit without its views): larger sets
/// leave out one group of every `n / FOCAL_GROUPS`-th view at a time.
pub const FOCAL_GROUPS: usize = 30;

/// The focal scale that fits the pixels through the robot poses: fx and fy
/// times `scale` (about 1 when the intrinsics and the robot agree).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FocalScale {
    /// The fitted scale of fx and fy.
    pub scale: f64,
    /// Its jackknife std over the views.
    pub std: f64,
}

/// The finding of [`check_focal`], for the orchestrator to write.
#[derive(Debug, Clone)]
pub struct FocalFinding {
    /// The report's object: none when the scale is within
    /// [`FOCAL_ALERT_STD`] of its std from 1 (the shift then only widens
    /// the std, scaled by [`focal_share`]).
    pub check: Option<FocalCheck>,
    /// The freed solution `(x, y)`, when its refit ran.
    pub freed: Option<(Pose, Pose)>,
    /// What joins the covariance: the shift from the reported to the freed
    /// camera and target transforms (`[rotation (rad, left frame);
    /// translation (m)]` each), scaled as the module docs say.
    pub shift: Option<([f64; 6], [f64; 6])>,
    /// The warning: none when the focal length is within [`FOCAL_MIN`]
    /// and the shift within the held std.
    pub warning: Option<String>,
}

/// The focal scale of the joint pixel problem and its jackknife std,
/// started from `(x, y)`; `None` with fewer than [`MIN_LOO_VIEWS`] views or
/// when the fits fail.
pub fn focal_scale(
    setup: Setup,
    base_from_gripper: &[Pose],
    views: &[View],
    camera: &Camera,
    (x, y): (&Pose, &Pose),
) -> Option<FocalScale> {
    let n = views.len();
    if n < MIN_LOO_VIEWS || base_from_gripper.len() != n {
        return None;
    }
    let options = RefineOptions {
        focal_scale: true,
        ..Default::default()
    };
    let full = refine(setup, base_from_gripper, views, camera, x, y, &options).ok()?;
    let scale = full.camera.fx / camera.fx;
    let groups = n.min(FOCAL_GROUPS);
    let runs: Vec<f64> = (0..groups)
        .filter_map(|g| {
            let keep: Vec<usize> = (0..n).filter(|i| i % groups != g).collect();
            let robots: Vec<Pose> = keep.iter().map(|&i| base_from_gripper[i]).collect();
            let kept: Vec<View> = keep.iter().map(|&i| views[i].clone()).collect();
            refine(
                setup,
                &robots,
                &kept,
                &full.camera,
                &full.x,
                &full.y,
                &options,
            )
            .ok()
            .map(|r| r.camera.fx / camera.fx)
            .filter(|s| s.is_finite())
        })
        .collect();
    if runs.len() + 1 < groups || runs.len() < 2 {
        return None;
    }
    let m = runs.len() as f64;
    let mean = runs.iter().sum::<f64>() / m;
    let var = (m - 1.0) / m * runs.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
    (scale.is_finite() && var.is_finite()).then(|| FocalScale {
        scale,
        std: var.sqrt(),
    })
}

/// Check the focal length of `camera` against the robot's motion (module
/// docs) for an image-path result whose pose refinement ran; `None` when
/// it agrees or cannot be checked (too few views, parallel rotation axes).
///
/// `fx_std` is the std of the camera's calibrated fx (px), when the camera
/// came with its standard deviations: a disagreement within it and the
/// scale's own std together ([`within_camera_std`]) widens the std but
/// writes no warning.
pub fn check_focal(
    result: &HandEyeResult,
    input: &HandEyeInput,
    views: &[View],
    (camera, fx_std): (&Camera, Option<f64>),
    motion_pairs: MotionPairs,
) -> Option<FocalFinding> {
    if result.pose_refinement.is_none() || !result.unobservable_translation.is_empty() {
        return None;
    }
    let fit = focal_scale(
        input.setup,
        &input.base_from_gripper,
        views,
        camera,
        (&result.x, &result.y),
    )?;
    let off = fit.scale - 1.0;
    let prior = fx_std.map(|s| s / camera.fx);
    let known = known_scale_std(fit.std, prior);
    let shift_to = |scale: f64, part: f64| {
        freed_solution(result, input, views, camera, scale, motion_pairs).map(|(x, y)| {
            let scaled = |d: [f64; 6]| d.map(|v| v * part);
            let shift = (
                scaled(pose_shift(&result.x, &x)),
                scaled(pose_shift(&result.y, &y)),
            );
            ((x, y), shift)
        })
    };
    if !(off.abs() > fit.std) {
        // Within its std of 1: the shift of one std of the scale, scaled to
        // what is known of the focal length.
        if !(known > 0.0) {
            return None;
        }
        let probe = 1.0 + fit.std.copysign(off);
        let found = shift_to(probe, known / fit.std)?;
        return Some(FocalFinding {
            check: None,
            freed: None,
            shift: Some(found.1),
            warning: None,
        });
    }
    let part = focal_share(off, fit.std, known).sqrt();
    let found = shift_to(fit.scale, part);
    let freed = found.map(|f| f.0);
    if !(off.abs() > FOCAL_ALERT_STD * fit.std) {
        // Not named: the shift joins the covariance silently.
        return Some(FocalFinding {
            check: None,
            freed,
            shift: found.map(|f| f.1),
            warning: None,
        });
    }
    let moves = freed.map(|(x, _)| pose_difference(&result.x, &x));
    let shift = found.map(|f| f.1);
    let beyond_std = shift.as_ref().is_some_and(|(dx, _)| {
        result
            .pose_refinement
            .as_ref()
            .is_some_and(|p| shift_beyond_std(dx, &p.camera_transform_std))
    });
    if off.abs() <= FOCAL_MIN && shift.is_none() {
        return None;
    }
    let key = input.setup.camera_key();
    let what = match moves {
        Some((mm, deg)) => format!(
            "with the focal length scaled by {:.4} (fx {:.1} px, fy {:.1} px) {key} moves by \
             {mm:.2} mm and {deg:.3} deg, which its std now includes",
            fit.scale,
            camera.fx * fit.scale,
            camera.fy * fit.scale
        ),
        None => format!(
            "the refit with the focal length scaled by {:.4} failed, so the std do not include \
             its effect",
            fit.scale
        ),
    };
    let explained = within_camera_std(&fit, camera.fx, fx_std);
    let warning = ((off.abs() > FOCAL_MIN || beyond_std) && !explained).then(|| {
        format!(
            "focal length: the camera's focal length disagrees with the robot's motion by {:.2} % \
         ({:.1} std): fitted through the robot poses, the image points want fx and fy {} by \
         that much; {what}. Recalibrate the camera's intrinsics (with the focus and zoom of \
         these images), or check the target's square size and the robot's accuracy",
            100.0 * off.abs(),
            off.abs() / fit.std.max(f64::MIN_POSITIVE),
            if off > 0.0 { "longer" } else { "shorter" },
        )
    });
    Some(FocalFinding {
        check: Some(FocalCheck {
            scale: fit.scale,
            scale_std: fit.std,
            freed_moves: moves.map(|(mm, deg)| [mm, deg]),
        }),
        freed,
        shift,
        warning,
    })
}

/// Whether a focal disagreement lies within what the camera's own
/// calibration allows: the focal scale's std over the views and the
/// calibrated fx's relative std (`fx_std / fx`, when the camera came with
/// its standard deviations) taken together. The check alone judges the
/// scale against its own std, as if the intrinsics were exact; on clean
/// data both are tiny (the page's demo: fx 899.985 +- 0.055 px, the robot's
/// motion wants 0.0028 % more: 3.1 std of the check, 0.4 of both), and such a
/// disagreement is not worth a warning. The covariance keeps the shift.
pub(crate) fn within_camera_std(fit: &FocalScale, fx: f64, fx_std: Option<f64>) -> bool {
    let Some(fx_std) = fx_std.filter(|s| s.is_finite() && *s > 0.0 && fx > 0.0) else {
        return false;
    };
    let off = (fit.scale - 1.0).abs();
    let both = fit.std.hypot(fx_std / fx);
    off <= FOCAL_MIN && off <= FOCAL_ALERT_STD * both
}

/// The share of the squared focal offset `off^2` that is real rather than
/// noise of its std `std`: `max(0, off^2 - std^2) / off^2` (module docs).
pub(crate) fn real_share(off: f64, std: f64) -> f64 {
    if !(off.abs() > 0.0) {
        return 0.0;
    }
    ((off * off - std * std) / (off * off)).clamp(0.0, 1.0)
}

/// How well the focal scale is known (module docs): the robot's check
/// alone (`std`, the scale's jackknife std) when the camera came without
/// its own, else both together, `1 / sqrt(1 / std^2 + 1 / prior^2)` with
/// `prior` the calibrated fx's relative std.
pub(crate) fn known_scale_std(std: f64, prior: Option<f64>) -> f64 {
    match prior.filter(|p| p.is_finite() && *p > 0.0) {
        Some(p) if std > 0.0 => 1.0 / (1.0 / (std * std) + 1.0 / (p * p)).sqrt(),
        Some(_) => 0.0,
        None => std,
    }
}

/// The share of the shift to the freed solution (its square, of the
/// squared offset `off^2`) that joins the covariance: the part of the
/// offset that is real ([`real_share`]) plus what is not known of the
/// scale (`known`, [`known_scale_std`]), at most the whole shift.
pub(crate) fn focal_share(off: f64, std: f64, known: f64) -> f64 {
    if !(off.abs() > 0.0) {
        return 0.0;
    }
    (real_share(off, std) + (known * known) / (off * off)).clamp(0.0, 1.0)
}

/// Whether a shift of the camera transform (`[rotation (rad, left frame);
/// translation (m)]`) exceeds its std on some axis.
pub(crate) fn shift_beyond_std(shift: &[f64; 6], std: &TransformStd) -> bool {
    (0..3).any(|k| {
        shift[k].abs().to_degrees() > std.rotation_deg[k]
            || shift[k + 3].abs() * 1e3 > std.translation_mm[k]
    })
}

/// The pose refinement on camera poses from PnP with fx and fy scaled by
/// `scale` (each view's covariance from the same fit), started from the
/// result's solutions; `None` when a PnP or the refinement fails.
fn freed_solution(
    result: &HandEyeResult,
    input: &HandEyeInput,
    views: &[View],
    camera: &Camera,
    scale: f64,
    motion_pairs: MotionPairs,
) -> Option<(Pose, Pose)> {
    let mut scaled = camera.clone();
    (scaled.fx, scaled.fy) = (camera.fx * scale, camera.fy * scale);
    let mut poses = Vec::with_capacity(views.len());
    let mut covariances = Vec::with_capacity(views.len());
    for v in views {
        let (pose, _, cov) = camera_from_target_with_covariance(&scaled, v).ok()?;
        poses.push(pose);
        covariances.push(cov);
    }
    let freed_input = HandEyeInput {
        setup: input.setup,
        base_from_gripper: input.base_from_gripper.clone(),
        camera_from_target: poses,
    };
    let found = refine_over_poses(
        result,
        &freed_input,
        CameraNoise::PerView(covariances),
        motion_pairs,
        true,
        None,
    )
    .ok()?;
    found.refined.map(|r| (r.x, r.y))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_real_share_of_the_offset_grows_from_one_std() {
        assert_eq!(real_share(0.0, 1e-3), 0.0);
        assert_eq!(real_share(-0.8e-3, 1e-3), 0.0);
        assert!((real_share(2e-3, 1e-3) - 0.75).abs() < 1e-12);
        assert!((real_share(-3e-3, 1e-3) - 8.0 / 9.0).abs() < 1e-12);
        assert_eq!(real_share(0.01, 0.0), 1.0);
    }

    /// Twelve eye-in-hand views at 0.5 m through `truth` (seed `seed`), the
    /// PnP poses from `used`, solved and pose-refined without the focal
    /// check: the result, its input and the views.
    fn refined_scene(
        truth: &Camera,
        used: &Camera,
        noise: &crate::synth::handeye_looking::LookingNoise,
        seed: u64,
    ) -> (HandEyeResult, HandEyeInput, Vec<View>) {
        use crate::handeye::refine::over_poses::camera_noise_from_views;
        use crate::handeye::solve::apply_pose_refinement;
        use crate::handeye::{calibrate, HandEyeOptions};
        use crate::synth::handeye_looking::{observe_looking, LookingConfig};
        let config = LookingConfig::half_metre(Setup::EyeInHand, 12);
        let seen = observe_looking(&config, seed, truth, noise, seed);
        let input = seen.handeye_input(used).unwrap();
        let options = HandEyeOptions {
            bootstrap_samples: 1,
            refine_poses: false,
            strict_checks: false,
            ..Default::default()
        };
        let mut result = calibrate(&input, &options).unwrap();
        let levels = camera_noise_from_views(&input, &seen.views, used).0;
        apply_pose_refinement(&mut result, &input, levels, MotionPairs::All).unwrap();
        (result, input, seen.views)
    }

    #[test]
    fn the_known_scale_std_takes_the_cameras_own_with_the_robots() {
        assert_eq!(known_scale_std(2e-3, None), 2e-3);
        assert_eq!(known_scale_std(2e-3, Some(f64::NAN)), 2e-3);
        assert_eq!(known_scale_std(2e-3, Some(0.0)), 2e-3);
        // 1 / sqrt(1 / 4e-6 + 1 / 1e-6) = 1e-3 / sqrt(1.25).
        let both = known_scale_std(2e-3, Some(1e-3));
        assert!((both - 1e-3 / 1.25f64.sqrt()).abs() < 1e-15);
        assert_eq!(known_scale_std(0.0, Some(1e-3)), 0.0);
    }

    #[test]
    fn the_focal_share_is_the_whole_shift_without_the_cameras_std() {
        // Without a prior the known std is the scale's own: the real part
        // plus std^2 / off^2 is the whole shift from one std on.
        for off in [1.2e-3, -2e-3, 5e-3] {
            assert!((focal_share(off, 1e-3, 1e-3) - 1.0).abs() < 1e-12);
        }
        // With a camera std of 0.05 % against the scale's 0.1 %: at 2 std
        // the real part 3/4 plus (0.447e-3)^2 / (2e-3)^2 = 1/20.
        let known = known_scale_std(1e-3, Some(5e-4));
        assert!((focal_share(2e-3, 1e-3, known) - (0.75 + 0.05)).abs() < 1e-12);
        assert_eq!(focal_share(0.0, 1e-3, 1e-3), 0.0);
    }

    /// The right focal length, 0.2 px and the robot's 0.1 mm / 0.02 deg
    /// noise: the robot confirms the focal length only to the scale's std,
    /// and without the camera's own std that uncertainty joins the
    /// covariance (the shift of one std of the scale); with it, the shift
    /// shrinks to what both know together, `known / std` of it.
    #[test]
    fn a_focal_length_confirmed_only_to_its_std_widens_the_std() {
        use crate::synth::handeye_looking::LookingNoise;
        let camera = Camera::pinhole(1100.0, 1100.0, 639.5, 479.5, 1280, 960);
        let noise = LookingNoise {
            pixel_sigma: 0.2,
            robot_sigma: (0.02f64.to_radians(), 1e-4),
            kinematic: None,
        };
        let (result, input, views) = refined_scene(&camera, &camera, &noise, 41);
        let pose = (&result.x, &result.y);
        let fit = focal_scale(input.setup, &input.base_from_gripper, &views, &camera, pose);
        let fit = fit.unwrap();
        assert!((fit.scale - 1.0).abs() <= fit.std, "{fit:?}");
        // The robot's noise limits the check to about 0.1-0.3 % here.
        assert!(fit.std > 5e-4 && fit.std < 5e-3, "{fit:?}");
        let alone = check_focal(&result, &input, &views, (&camera, None), MotionPairs::All);
        let alone = alone.unwrap();
        assert!(alone.check.is_none() && alone.warning.is_none());
        let (dx, _) = alone.shift.unwrap();
        // About 0.5 m x std along the optical axis (z of the camera).
        let along = dx[5].abs();
        assert!(
            along > 0.3 * 0.5 * fit.std && along < 3.0 * 0.5 * fit.std,
            "{dx:?}"
        );
        let fx_std = 0.5;
        let with = check_focal(
            &result,
            &input,
            &views,
            (&camera, Some(fx_std)),
            MotionPairs::All,
        );
        let (dx_with, _) = with.unwrap().shift.unwrap();
        let ratio = known_scale_std(fit.std, Some(fx_std / camera.fx)) / fit.std;
        for k in 0..6 {
            assert!((dx_with[k] - ratio * dx[k]).abs() <= 1e-12 + 1e-9 * dx[k].abs());
        }
    }

    #[test]
    fn the_cameras_own_fx_std_joins_the_scale_std() {
        // The demo's figures: 3.1 std of the scale alone, 0.4 of both.
        let fit = FocalScale {
            scale: 1.000_027_6,
            std: 8.86e-6,
        };
        assert!(within_camera_std(&fit, 899.985, Some(0.055)));
        // Without the camera's std the check stands.
        assert!(!within_camera_std(&fit, 899.985, None));
        assert!(!within_camera_std(&fit, 899.985, Some(0.0)));
        // Beyond 3 std of both (3.09 here), or 0.1 % off, it stands too.
        assert!(!within_camera_std(&fit, 899.985, Some(0.001)));
        let far = FocalScale {
            scale: 1.002,
            std: 1e-3,
        };
        assert!(!within_camera_std(&far, 1000.0, Some(5.0)));
    }

    /// A clean eye-in-hand scene (0.01 px, robot noise 1e-6) whose PnP used
    /// fx and fy 0.05 % long: the check names the scale and, without the
    /// camera's own fx std, warns (the shift exceeds the held std); with an
    /// fx std of 1 px (0.09 %) the disagreement lies within the camera's
    /// calibration and no warning is written, while the check and the
    /// widened std stay.
    #[test]
    fn check_focal_writes_no_warning_within_the_cameras_fx_std() {
        use crate::synth::handeye_looking::LookingNoise;
        let truth = Camera::pinhole(1100.0, 1100.0, 639.5, 479.5, 1280, 960);
        let clean = LookingNoise {
            pixel_sigma: 0.01,
            robot_sigma: (1e-6, 1e-6),
            kinematic: None,
        };
        let used = Camera::pinhole(1100.55, 1100.55, 639.5, 479.5, 1280, 960);
        let (result, input, views) = refined_scene(&truth, &used, &clean, 35);
        let alone = check_focal(&result, &input, &views, (&used, None), MotionPairs::All).unwrap();
        let check = alone.check.clone().unwrap();
        let off = check.scale - 1.0;
        assert!((off + 5e-4).abs() < 1e-4, "scale {}", check.scale);
        assert!(off.abs() > FOCAL_ALERT_STD * check.scale_std);
        assert!(alone
            .warning
            .unwrap()
            .starts_with("focal length: the camera's focal length"));
        let within = check_focal(
            &result,
            &input,
            &views,
            (&used, Some(1.0)),
            MotionPairs::All,
        );
        let within = within.unwrap();
        assert!(within.warning.is_none());
        assert_eq!(within.check, alone.check);
        assert!(within.shift.is_some());
        // 0.1 px is 0.009 %: the 0.05 % stands out of it.
        let tight = check_focal(
            &result,
            &input,
            &views,
            (&used, Some(0.1)),
            MotionPairs::All,
        );
        assert!(tight.unwrap().warning.is_some());
    }

    #[test]
    fn a_shift_is_beyond_the_std_when_one_axis_is() {
        let std = TransformStd {
            rotation_deg: [0.01, 0.02, 0.03],
            translation_mm: [0.5, 0.5, 1.0],
        };
        let within = [
            0.009f64.to_radians(),
            0.0,
            -0.02f64.to_radians(),
            4e-4,
            -4e-4,
            9e-4,
        ];
        assert!(!shift_beyond_std(&within, &std));
        // 1.1 mm along z against a 1 mm std (RWHE's fx 0.05 % short: 2.5 mm
        // against 0.76 mm).
        let along_z = [0.0, 0.0, 0.0, 0.0, 0.0, -1.1e-3];
        assert!(shift_beyond_std(&along_z, &std));
        let turned = [0.0, 0.021f64.to_radians(), 0.0, 0.0, 0.0, 0.0];
        assert!(shift_beyond_std(&turned, &std));
    }
}
