//! Tests of stereo calibration on seeded synthetic two-camera scenes.

use crate::calib::multi::stereo::{calibrate_stereo, initial_right_from_left};
use crate::calib::{CalibrationOptions, View};
use crate::camera::Camera;
use crate::error::Error;
use crate::geometry::{rotation_from_rotvec, Pose};
use crate::rng::Rng;
use crate::synth::Scene;
use nalgebra::{Point2, Translation3, Vector3};
use wasm_bindgen_test::wasm_bindgen_test;

struct Pair {
    left: Vec<View>,
    right: Vec<View>,
    right_camera: Camera,
    right_from_left: Pose,
    left_camera: Camera,
}

/// Left views from the synthetic scene; the right camera (other
/// intrinsics, 6 cm baseline, a few degrees of rotation) sees the same
/// board poses, with its own noise.
fn pair(seed: u64, noise_px: f64) -> Pair {
    moving_pair(seed, noise_px, 0.0, 8)
}

/// [`pair`] with `views` board poses, the board moved between the left and
/// the right image of each pair by a seeded random motion of about
/// `move_m` (each translation axis) and `move_m / 0.3 m` rad (each
/// rotation axis): the free-running cameras of issue 35.
fn moving_pair(seed: u64, noise_px: f64, move_m: f64, views: usize) -> Pair {
    let left_camera = Camera::example_brown();
    let scene =
        Scene::calibration(seed, &left_camera, (9, 6), 0.03, views, noise_px).expect("scene");
    let right_camera = Camera {
        fx: left_camera.fx * 1.02,
        fy: left_camera.fy * 1.015,
        cx: left_camera.cx + 7.0,
        cy: left_camera.cy - 4.0,
        ..left_camera.clone()
    };
    let right_from_left = Pose::from_parts(
        Translation3::new(-0.06, 0.002, -0.001),
        rotation_from_rotvec(&Vector3::new(0.01, -0.04, 0.015)),
    );
    let mut rng = Rng::new(seed + 1000);
    let right = scene
        .views
        .iter()
        .zip(&scene.camera_from_target)
        .map(|(v, pose)| {
            if move_m == 0.0 {
                return (v, *pose);
            }
            let mut draw = |scale: f64| Vector3::from_fn(|_, _| rng.gaussian(scale));
            let moved = Pose::from_parts(
                Translation3::from(draw(move_m)),
                rotation_from_rotvec(&draw(move_m / 0.3)),
            );
            (v, moved * pose)
        })
        .collect::<Vec<_>>()
        .into_iter()
        .map(|(v, pose)| View {
            name: format!("right_{}", v.name),
            object_m: v.object_m.clone(),
            image_px: v
                .object_m
                .iter()
                .map(|p| {
                    let px = right_camera
                        .project(&(right_from_left * pose * p))
                        .expect("in front");
                    Point2::new(px.x + rng.gaussian(noise_px), px.y + rng.gaussian(noise_px))
                })
                .collect(),
            point_ids: v.point_ids.clone(),
        })
        .collect();
    Pair {
        left: scene.views,
        right,
        right_camera,
        right_from_left,
        left_camera,
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn noise_free_pair_gives_the_true_cameras_and_transform() {
    let p = pair(7, 0.0);
    let size = (p.left_camera.width, p.left_camera.height);
    let s = calibrate_stereo(
        &p.left,
        &p.right,
        size,
        size,
        &CalibrationOptions::default(),
    )
    .expect("stereo");
    let rfl = s.right_from_left.to_pose().expect("pose");
    let err = p.right_from_left.inverse() * rfl;
    assert!(
        err.rotation.angle() < 1e-9,
        "rotation {}",
        err.rotation.angle()
    );
    assert!(err.translation.vector.norm() < 1e-9);
    let init = s.initial_right_from_left.to_pose().expect("pose");
    // The single-camera solutions are exact too, so the seed's closed form is.
    assert!((p.right_from_left.inverse() * init).rotation.angle() < 1e-8);
    assert!(s.rms_px < 1e-8, "rms {}", s.rms_px);
    assert!((s.left.camera.fx - p.left_camera.fx).abs() < 1e-6);
    assert!((s.right.camera.fx - p.right_camera.fx).abs() < 1e-6);
    assert!((s.right.camera.cx - p.right_camera.cx).abs() < 1e-6);
    assert!((s.baseline_m - p.right_from_left.translation.vector.norm()).abs() < 1e-9);
    // The right view poses are right_from_left * left poses.
    let l0 = s.left.views[0].camera_from_target.to_pose().expect("pose");
    let r0 = s.right.views[0].camera_from_target.to_pose().expect("pose");
    assert!(((rfl * l0).inverse() * r0).translation.vector.norm() < 1e-12);
}

#[wasm_bindgen_test(unsupported = test)]
fn noisy_pair_is_within_bounds_of_the_noise() {
    let sigma = 0.3;
    let p = pair(11, sigma);
    let size = (p.left_camera.width, p.left_camera.height);
    let s = calibrate_stereo(
        &p.left,
        &p.right,
        size,
        size,
        &CalibrationOptions::default(),
    )
    .expect("stereo");
    // 2 x 8 x 54 points: the rms of 2-D residual norms is sqrt(2) sigma
    // (less the fitted dof, ~4 %); 15 % covers that and the sampling spread.
    let expected = std::f64::consts::SQRT_2 * sigma;
    assert!((s.rms_px / expected - 1.0).abs() < 0.15, "rms {}", s.rms_px);
    let std = s.right_from_left_std.clone().expect("std");
    let rfl = s.right_from_left.to_pose().expect("pose");
    let err_t = rfl.translation.vector - p.right_from_left.translation.vector;
    let err_r = (rfl.rotation * p.right_from_left.rotation.inverse()).scaled_axis();
    // Each component within 4 of its reported std (a Gaussian estimate
    // leaves that bound with probability 6e-5 per component) and the std
    // itself small at 0.3 px: below a millimetre and 3 mrad (the rotation
    // about y trades with the right camera's cx, hence its ~1.3 mrad).
    for k in 0..3 {
        assert!(err_t[k].abs() < 4.0 * std.translation_m[k], "t{k} {err_t}");
        assert!(err_r[k].abs() < 4.0 * std.rotation_rad[k], "r{k} {err_r}");
        assert!(
            std.translation_m[k] < 1e-3 && std.rotation_rad[k] < 3e-3,
            "{std:?}"
        );
    }
}

/// Issue 35: with the board moving between the two images of a pair, the
/// joint fit's std alone is far too small; the leave-pairs-out spread
/// widens it to cover the true right_from_left, and the report says so.
/// With the board still the std is the model's and nothing is said.
#[wasm_bindgen_test(unsupported = test)]
fn a_board_moving_between_the_images_of_a_pair_widens_the_std_and_is_said() {
    let still = moving_pair(21, 0.2, 0.0, 16);
    let size = (still.left_camera.width, still.left_camera.height);
    let options = CalibrationOptions::default();
    let s = calibrate_stereo(&still.left, &still.right, size, size, &options).expect("stereo");
    assert!(
        !s.warnings.iter().any(|w| w.contains("leaving pairs out")),
        "{:?}",
        s.warnings
    );
    let mut covered = 0;
    let mut said = 0;
    let seeds = 21..27u64;
    for seed in seeds.clone() {
        // 1 mm and ~3 mrad of motion per pair: far beyond 0.2 px of noise.
        let p = moving_pair(seed, 0.2, 1e-3, 16);
        let s = calibrate_stereo(&p.left, &p.right, size, size, &options).expect("stereo");
        said += usize::from(s.warnings.iter().any(|w| {
            w.starts_with("right_from_left: leaving pairs out moves it")
                && w.ends_with("trigger the cameras together")
        }));
        let std = s.right_from_left_std.clone().expect("std");
        let rfl = s.right_from_left.to_pose().expect("pose");
        let err_t = rfl.translation.vector - p.right_from_left.translation.vector;
        let err_r = (rfl.rotation * p.right_from_left.rotation.inverse()).scaled_axis();
        covered += usize::from((0..3).all(|k| {
            err_t[k].abs() < 4.0 * std.translation_m[k]
                && err_r[k].abs() < 4.0 * std.rotation_rad[k]
        }));
    }
    let n = seeds.count();
    assert_eq!(said, n, "the widening is said in every moving scene");
    // Every component within 4 std in at least 5 of 6 scenes (a jackknife
    // std from 16 pairs is itself uncertain by ~20 %).
    assert!(covered + 1 >= n, "covered {covered} of {n}");
}

#[wasm_bindgen_test(unsupported = test)]
fn mismatched_pairs_are_refused() {
    let p = pair(3, 0.0);
    let size = (p.left_camera.width, p.left_camera.height);
    let e = calibrate_stereo(
        &p.left,
        &p.right[..5],
        size,
        size,
        &CalibrationOptions::default(),
    )
    .expect_err("mismatch");
    assert!(matches!(e, Error::Invalid { .. }));
    assert_eq!(
        e.to_string(),
        "right: views are paired by order: 8 left views but 5 right views"
    );
    assert!(initial_right_from_left(&[], &[]).is_err());
}

/// Issue 35, item 6: the same images on both sides are refused before
/// solving (they would solve to a baseline of 0 m); the same board poses
/// seen from one place with independent noise (0.1 px) are refused after,
/// the baseline being zero within its uncertainty.
#[wasm_bindgen_test(unsupported = test)]
fn the_same_images_on_both_sides_are_refused() {
    let p = pair(5, 0.1);
    let size = (p.left_camera.width, p.left_camera.height);
    let e = calibrate_stereo(&p.left, &p.left, size, size, &CalibrationOptions::default())
        .expect_err("identical");
    assert_eq!(
        e.to_string(),
        "right: the left and right images have identical detections in all 8 pairs: the same \
         images were given for both cameras, which would solve to a baseline of 0 m; give each \
         camera its own images"
    );
    let mut rng = Rng::new(77);
    let again: Vec<View> = p
        .left
        .iter()
        .map(|v| View {
            image_px: v
                .image_px
                .iter()
                .map(|q| Point2::new(q.x + rng.gaussian(0.1), q.y + rng.gaussian(0.1)))
                .collect(),
            ..v.clone()
        })
        .collect();
    let e = calibrate_stereo(&p.left, &again, size, size, &CalibrationOptions::default())
        .expect_err("zero baseline")
        .to_string();
    assert!(
        e.starts_with("right_from_left: the baseline between the left and right cameras is 0.000"),
        "{e}"
    );
    assert!(
        e.ends_with(
            "the two cameras are at the same place, so the images are of one camera (the same \
             scene given for both?); give each camera its own images, taken at the same moments"
        ),
        "{e}"
    );
    // The real pair (6 cm) passes.
    let ok = calibrate_stereo(
        &p.left,
        &p.right,
        size,
        size,
        &CalibrationOptions::default(),
    )
    .expect("a real pair");
    assert!(
        (ok.baseline_m - 0.06).abs() < 2e-3,
        "baseline {} m",
        ok.baseline_m
    );
}
