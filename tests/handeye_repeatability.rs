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
