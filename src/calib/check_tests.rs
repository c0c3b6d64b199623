//! The check on synthetic scenes: the same camera reads ok, a focal or
//! principal-point change drifted (naming the parameter), another camera
//! broken.

use super::check::*;
use super::{calibrate, CalibrationOptions};
use crate::camera::{Camera, Distortion};
use crate::synth::Scene;

/// A Brown camera calibrated from 15 views with 0.1 px noise, as saved.
fn saved() -> SavedCalibration {
    let truth = Camera::example_brown();
    let scene = Scene::calibration(3, &truth, (9, 6), 0.03, 15, 0.1).expect("scene");
    let report = calibrate(
        &scene.views,
        (truth.width, truth.height),
        &CalibrationOptions::default(),
    )
    .expect("calibration");
    SavedCalibration {
        camera: report.camera.clone(),
        std: report.std.clone(),
        projection_std_px: Some(report.projection_uncertainty.max_std_px),
        rms_px: Some(report.rms_px),
        camera_from_target: None,
    }
}

fn check(saved: &SavedCalibration, camera: &Camera, seed: u64) -> CheckReport {
    let scene = Scene::calibration(seed, camera, (9, 6), 0.03, 5, 0.1).expect("scene");
    check_calibration(saved, &scene.views, &CheckThresholds::default()).expect("check")
}

#[test]
fn the_same_camera_reimaged_reads_ok() {
    let saved = saved();
    let report = check(&saved, &Camera::example_brown(), 11);
    assert_eq!(report.verdict, Verdict::Ok, "{:?}", report.reasons);
    assert!(report.moved.is_empty());
    let shift = report.projection_shift_px.expect("shift");
    assert!(shift.worst < report.thresholds.shift_px, "{}", shift.worst);
    assert_eq!(report.parameters.len(), 4);
    assert!(report.reprojection_rms_px.expect("rms") < 0.3);
}

#[test]
fn a_focal_or_principal_point_change_reads_drifted_naming_it() {
    let saved = saved();
    let truth = Camera::example_brown();
    let longer = Camera {
        fx: truth.fx * 1.02,
        fy: truth.fy * 1.02,
        ..truth.clone()
    };
    let report = check(&saved, &longer, 11);
    assert_eq!(report.verdict, Verdict::Drifted, "{:?}", report.reasons);
    assert!(
        report.moved.contains(&"fx".to_string()),
        "{:?}",
        report.moved
    );
    let fx = &report.parameters[0];
    assert!(
        (fx.shift_px / (truth.fx * 0.02) - 1.0).abs() < 0.2,
        "{}",
        fx.shift_px
    );
    assert!(fx.shift_std.expect("std") > 3.0);
    assert!(report.projection_shift_px.expect("shift").worst > 5.0);
    let moved = Camera {
        cx: truth.cx + 8.0,
        ..truth.clone()
    };
    let report = check(&saved, &moved, 12);
    assert_eq!(report.verdict, Verdict::Drifted, "{:?}", report.reasons);
    assert!(
        report.moved.contains(&"cx".to_string()),
        "{:?}",
        report.moved
    );
}

#[test]
fn another_camera_or_no_views_reads_broken() {
    let saved = saved();
    let other = Camera {
        distortion: Distortion::Brown {
            k1: 0.3,
            k2: 0.0,
            p1: 0.0,
            p2: 0.0,
            k3: 0.0,
        },
        ..Camera::pinhole(500.0, 500.0, 480.0, 400.0, 1024, 768)
    };
    let report = check(&saved, &other, 13);
    assert_eq!(report.verdict, Verdict::Broken, "{:?}", report.reasons);
    let none = check_calibration(&saved, &[], &CheckThresholds::default()).expect("check");
    assert_eq!(none.verdict, Verdict::Broken);
    assert_eq!(
        none.reasons,
        ["the target was not found in any image: check the target and that it is in view"]
    );
}

#[test]
fn a_saved_pose_gives_the_pose_shift() {
    let mut saved = saved();
    let scene = Scene::calibration(11, &Camera::example_brown(), (9, 6), 0.03, 1, 0.0).unwrap();
    let mut pose = scene.camera_from_target[0];
    saved.camera_from_target = Some(pose);
    let same = check_calibration(&saved, &scene.views, &CheckThresholds::default()).unwrap();
    let shift = same.pose_shift.expect("pose shift");
    assert!(shift.translation_mm < 1.0 && !shift.moved, "{shift:?}");
    pose.translation.vector.x += 0.01;
    saved.camera_from_target = Some(pose);
    let moved = check_calibration(&saved, &scene.views, &CheckThresholds::default()).unwrap();
    let shift = moved.pose_shift.expect("pose shift");
    assert!((shift.translation_mm - 10.0).abs() < 1.5, "{shift:?}");
    assert_eq!(moved.verdict, Verdict::Drifted);
}
