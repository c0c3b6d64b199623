//! The report's repeatability re-solves every resample the way the main
//! estimate was solved: with the pose refinement on (the default), each
//! leave-one-out run and bootstrap resample is the closed form the
//! refinement started from, then refined (issue 19's leftover).
//!
//! Tolerances: noise-free resamples reproduce X to rounding (1e-6 mm,
//! 1e-6 deg). With noise (robot 0.1 mm / 0.02 deg, camera 0.05 deg tilt,
//! 0.4 mm depth, 20 views), the bootstrap spread of the refined X estimates
//! the refinement's own uncertainty: its total std (root sum of the three
//! axes' variances, frame-independent) must lie within a factor 1.5 of the
//! std from the refinement's covariance (100 resamples: the bootstrap std
//! is good to ~10 %, the covariance is estimated from 20 poses).

use robocal::handeye::{calibrate, HandEyeInput, HandEyeOptions, Setup};
use robocal::synth::handeye_looking::{looking_scene, perturbed, LookingConfig};
use robocal::synth::Rng;

fn config(setup: Setup) -> LookingConfig {
    LookingConfig {
        setup,
        views: 20,
        distance_m: 0.5,
        grid: (9, 6, 0.03),
        max_tilt_deg: 30.0,
        max_roll_deg: 60.0,
    }
}

fn input(setup: Setup, seed: u64, noisy: bool) -> HandEyeInput {
    let scene = looking_scene(&config(setup), seed);
    let mut rng = Rng::new(seed + 1);
    let k = if noisy { 1.0 } else { 0.0 };
    let r = 0.02f64.to_radians() * k;
    let c = 0.05f64.to_radians() * k;
    HandEyeInput {
        setup,
        base_from_gripper: scene
            .base_from_gripper
            .iter()
            .map(|p| perturbed(&mut rng, p, [r; 3], [0.1e-3 * k; 3]))
            .collect(),
        camera_from_target: scene
            .camera_from_target
            .iter()
            .map(|p| {
                perturbed(
                    &mut rng,
                    p,
                    [c, c, 0.1 * c],
                    [0.05e-3 * k, 0.05e-3 * k, 0.4e-3 * k],
                )
            })
            .collect(),
    }
}

fn norm(v: [f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

#[test]
fn noise_free_resamples_reproduce_the_refined_x() {
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        let options = HandEyeOptions {
            bootstrap_samples: 20,
            ..Default::default()
        };
        let result = calibrate(&input(setup, 3, false), &options).expect("solve");
        let rep = result.repeatability.expect("repeatability");
        assert!(
            rep.method.starts_with("refined from "),
            "{setup:?}: {}",
            rep.method
        );
        assert_eq!(rep.method, result.method, "{setup:?}");
        assert_eq!(
            (rep.leave_one_out.runs, rep.bootstrap.runs),
            (20, 20),
            "{setup:?}"
        );
        let worst_mm = rep
            .leave_one_out
            .camera_translation_deviation_mm_samples
            .iter()
            .chain(&rep.bootstrap.camera_translation_deviation_mm_samples)
            .fold(0.0f64, |a, &b| a.max(b));
        let worst_deg = rep
            .leave_one_out
            .camera_rotation_deviation_deg_samples
            .iter()
            .chain(&rep.bootstrap.camera_rotation_deviation_deg_samples)
            .fold(0.0f64, |a, &b| a.max(b));
        assert!(
            worst_mm < 1e-6 && worst_deg < 1e-6,
            "{setup:?}: {worst_mm} mm, {worst_deg} deg"
        );
    }
}

#[test]
fn the_bootstrap_spread_of_the_refined_x_matches_its_reported_std() {
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        let data = input(setup, 11, true);
        let refined = calibrate(&data, &HandEyeOptions::default()).expect("refined");
        let closed = calibrate(
            &data,
            &HandEyeOptions {
                refine_poses: false,
                ..Default::default()
            },
        )
        .expect("closed form");
        let rep = refined.repeatability.expect("repeatability");
        let old = closed.repeatability.expect("closed-form repeatability");
        let summary = refined.pose_refinement.expect("pose refinement");
        let reported_mm = norm(summary.camera_transform_std.translation_mm);
        let reported_deg = norm(summary.camera_transform_std.rotation_deg);
        let boot_mm = norm(rep.bootstrap.camera_std.translation_mm);
        let boot_deg = norm(rep.bootstrap.camera_std.rotation_deg);
        let old_mm = norm(old.bootstrap.camera_std.translation_mm);
        let old_deg = norm(old.bootstrap.camera_std.rotation_deg);
        eprintln!(
            "{setup:?}: X std translation {boot_mm:.4} mm bootstrap of '{}' ({} runs, {} failed), \
             {reported_mm:.4} mm reported, {old_mm:.4} mm bootstrap of '{}'; rotation \
             {boot_deg:.5} / {reported_deg:.5} / {old_deg:.5} deg",
            rep.method, rep.bootstrap.runs, rep.bootstrap.failed, old.method
        );
        assert_eq!(rep.bootstrap.failed, 0, "{setup:?}");
        for (what, boot, reported) in [
            ("mm", boot_mm, reported_mm),
            ("deg", boot_deg, reported_deg),
        ] {
            assert!(
                boot < 1.5 * reported && reported < 1.5 * boot,
                "{setup:?}: bootstrap std {boot} {what} vs reported {reported} {what}"
            );
        }
    }
}

/// The image path of `robocal handeye` on a scene whose model is not exactly
/// right: a robot error that depends on the pose (0.3 mm / 0.02 deg, a
/// smooth function of the pose like a kinematic model error) or a focal
/// length 1 % off for the PnP. Returns the result and the truth.
fn misspecified(
    seed: u64,
    views: usize,
    max_tilt_deg: f64,
    max_roll_deg: f64,
    kinematic: bool,
    focal_error: f64,
) -> (robocal::handeye::HandEyeResult, robocal::handeye::Pose) {
    use robocal::camera::Camera;
    use robocal::handeye::solve::apply_pose_refinement_from_views;
    use robocal::handeye::MotionPairs;
    use robocal::synth::handeye_looking::{observe_looking, LookingNoise};
    let camera = Camera::pinhole(1100.0, 1100.0, 639.5, 479.5, 1280, 960);
    let config = LookingConfig {
        setup: Setup::EyeInHand,
        views,
        distance_m: 0.5,
        grid: (9, 6, 0.03),
        max_tilt_deg,
        max_roll_deg,
    };
    let noise = LookingNoise {
        pixel_sigma: 0.2,
        robot_sigma: (0.02f64.to_radians(), 0.1e-3),
        kinematic: Some(if kinematic { (0.3, 0.02) } else { (0.0, 0.0) }),
    };
    let seen = observe_looking(&config, seed, &camera, &noise, seed ^ 0xc0ffee);
    let f = 1100.0 * (1.0 + focal_error);
    let used = Camera::pinhole(f, f, 639.5, 479.5, 1280, 960);
    let input = seen.handeye_input(&used).unwrap();
    let options = HandEyeOptions {
        bootstrap_samples: 1,
        refine_poses: false,
        strict_checks: false,
        ..Default::default()
    };
    let mut result = calibrate(&input, &options).unwrap();
    apply_pose_refinement_from_views(
        &mut result,
        &input,
        &seen.views,
        (&used, None),
        MotionPairs::All,
    )
    .unwrap();
    (result, seen.scene.x_true)
}

/// The truth within 3 reported std on all six components of X.
fn covered(result: &robocal::handeye::HandEyeResult, truth: &robocal::handeye::Pose) -> bool {
    let std = &result
        .pose_refinement
        .as_ref()
        .unwrap()
        .camera_transform_std;
    let dt = (result.x.translation.vector - truth.translation.vector) * 1e3;
    let dr = (result.x.rotation * truth.rotation.inverse()).scaled_axis();
    (0..3).all(|k| {
        dt[k].abs() <= 3.0 * std.translation_mm[k]
            && dr[k].to_degrees().abs() <= 3.0 * std.rotation_deg[k]
    })
}

/// Issue 35, item 3: small rotations (tilts and rolls to 8 deg) and a robot
/// error the noise model leaves out. Before the leave-one-out check 90 % of
/// such trials (tilts to 10 deg) were covered by 3 std
/// (examples/handeye_coverage.rs, 100 trials); with it 100 %. Here 16 trials: at least 15 covered, and every trial not
/// covered carries a warning; the weak geometry is named in every trial.
#[test]
fn weak_geometry_and_robot_error_are_named_and_the_std_covers_the_truth() {
    let mut hits = 0;
    for seed in 0..16 {
        let (result, truth) = misspecified(500 + seed, 12, 8.0, 8.0, true, 0.0);
        let ok = covered(&result, &truth);
        hits += usize::from(ok);
        assert!(
            result
                .warnings
                .iter()
                .any(|w| w.starts_with("weak geometry: the largest rotation between two poses is")),
            "seed {seed}: {:?}",
            result.warnings
        );
        let summary = result.pose_refinement.as_ref().unwrap();
        assert!(summary.work_point_std_mm.unwrap() > 0.0);
        assert!((summary.work_distance_m.unwrap() - 0.5).abs() < 0.06);
    }
    assert!(hits >= 15, "{hits} of 16 covered");
}

/// Issue 35, item 3: a focal length 1 % off for the PnP puts every target
/// 1 % too far. The scale that fits the robot translations to the camera
/// motion says so (a warning naming about 1 %), and the std includes what a
/// refit with the translations rescaled moves: before, 0 of 40 trials were
/// covered by 3 std; with the check 90 of 100 (examples/handeye_coverage.rs).
/// Here 12 trials: the warning in at least 10 (it names 0.5-1.5 %), at
/// least 9 covered.
#[test]
fn a_focal_length_one_percent_off_is_named_and_in_the_std() {
    let (mut named, mut hits) = (0, 0);
    for seed in 0..12 {
        let (result, truth) = misspecified(700 + seed, 20, 30.0, 60.0, false, 0.01);
        hits += usize::from(covered(&result, &truth));
        if let Some(w) = result.warnings.iter().find(|w| w.starts_with("scale: ")) {
            let pct: f64 = w
                .split("is about ")
                .nth(1)
                .and_then(|s| s.split(" %").next())
                .and_then(|s| s.parse().ok())
                .unwrap();
            assert!((0.5..1.5).contains(&pct), "seed {seed}: {w}");
            named += 1;
        }
    }
    assert!(named >= 10, "{named} of 12 named the scale");
    assert!(hits >= 9, "{hits} of 12 covered");
}
