//! Hand-eye of a whole camera rig (`robocal::handeye::rig`) on the seeded
//! four-camera rig of `robocal::synth::rig` carried by a robot
//! (`synth::rig::robot_poses`): noise-free exact, noisy within the reported
//! standard deviations, and the errors for poses that do not pair up.

use nalgebra::{Translation3, UnitQuaternion, Vector3};
use robocal::calib::View;
use robocal::geometry::{rotvec_from_rotation, Pose};
use robocal::handeye::rig::pnp::HeldRig;
use robocal::handeye::rig::{calibrate_rig_handeye, rig_handeye_report, RigHandEyeResult};
use robocal::handeye::{HandEyeOptions, Setup};
use robocal::synth::rig::{rig_scene, robot_poses, RigScene, RigSceneConfig};

fn truth(setup: Setup) -> (Pose, Pose) {
    let x = Pose::from_parts(
        Translation3::new(0.05, -0.12, 0.2),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.3, -1.1, 0.4)),
    );
    let y = match setup {
        Setup::EyeInHand => Pose::from_parts(
            Translation3::new(0.8, 0.1, -0.3),
            UnitQuaternion::from_scaled_axis(Vector3::new(2.0, 0.2, -0.5)),
        ),
        Setup::EyeToHand => Pose::from_parts(
            Translation3::new(0.02, 0.03, 0.15),
            UnitQuaternion::from_scaled_axis(Vector3::new(-0.2, 0.1, 0.3)),
        ),
    };
    (x, y)
}

/// The scene's views grouped per frame (camera index, points).
fn frames(scene: &RigScene) -> Vec<Vec<(usize, View)>> {
    let mut out = vec![Vec::new(); scene.frame_keys.len()];
    for (k, views) in scene.views.iter().enumerate() {
        for (f, v) in views {
            out[*f].push((k, v.clone()));
        }
    }
    out
}

fn solve(scene: &RigScene, setup: Setup, options: &HandEyeOptions) -> RigHandEyeResult {
    let (x, y) = truth(setup);
    let rig = HeldRig {
        cameras: scene.cameras.clone(),
        camera_from_rig: scene.camera_from_rig.clone(),
    };
    calibrate_rig_handeye(
        setup,
        &rig,
        &scene.names,
        &scene.frame_keys,
        &frames(scene),
        &robot_poses(scene, setup, &x, &y),
        options,
    )
    .expect("rig hand-eye")
}

/// (rotation error vector in the left frame, rad; translation error, m).
fn error(estimate: &Pose, truth: &Pose) -> (Vector3<f64>, Vector3<f64>) {
    (
        rotvec_from_rotation(&(truth.rotation * estimate.rotation.inverse())),
        estimate.translation.vector - truth.translation.vector,
    )
}

#[test]
fn noise_free_rig_on_a_robot_is_exact_in_both_setups() {
    let scene = rig_scene(&RigSceneConfig::default(), 5);
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        let (x, y) = truth(setup);
        let options = HandEyeOptions {
            bootstrap_samples: 0,
            ..HandEyeOptions::default()
        };
        let solved = solve(&scene, setup, &options);
        let (rx, tx) = error(&solved.result.x, &x);
        let (ry, ty) = error(&solved.result.y, &y);
        assert!(
            rx.norm() < 1e-9 && tx.norm() < 1e-9,
            "{setup:?} x: {rx} {tx}"
        );
        assert!(
            ry.norm() < 1e-9 && ty.norm() < 1e-9,
            "{setup:?} y: {ry} {ty}"
        );
        assert!(solved.frames.iter().all(|f| f.used), "{:?}", solved.frames);
        // Each camera's own transform is the rig's times rig_from_camera.
        let names = &scene.names;
        let rig = HeldRig {
            cameras: scene.cameras.clone(),
            camera_from_rig: scene.camera_from_rig.clone(),
        };
        let report = rig_handeye_report(&solved, &rig, names);
        let (rig_key, camera_key) = match setup {
            Setup::EyeInHand => ("gripper_from_rig", "gripper_from_camera"),
            Setup::EyeToHand => ("base_from_rig", "base_from_camera"),
        };
        assert!(report.get(rig_key).is_some() && report.get(camera_key).is_none());
        assert!(report["methods"][0].get(rig_key).is_some());
        let cam2: robocal::geometry::PoseJson =
            serde_json::from_value(report["cameras"][2][camera_key].clone()).unwrap();
        let expected = x * scene.camera_from_rig[2].inverse();
        let (r2, t2) = error(&cam2.to_pose().unwrap(), &expected);
        assert!(r2.norm() < 1e-9 && t2.norm() < 1e-9, "cam2: {r2} {t2}");
        assert_eq!(
            report["frames"].as_array().unwrap().len(),
            scene.frame_keys.len()
        );
    }
}

#[test]
fn noisy_rig_hand_eye_lies_within_its_reported_deviations() {
    // 0.3 px pixel noise, robot poses exact: the error of every component of
    // both transforms within 4 reported standard deviations (the std come
    // from each frame's multi-camera PnP covariance, its scale estimated),
    // and the translation within 2 mm, the rotation within 0.1 deg.
    let config = RigSceneConfig {
        noise_px: 0.3,
        ..RigSceneConfig::default()
    };
    for seed in [1, 2, 3] {
        let scene = rig_scene(&config, seed);
        for setup in [Setup::EyeInHand, Setup::EyeToHand] {
            let (x, _) = truth(setup);
            let options = HandEyeOptions {
                bootstrap_samples: 0,
                ..HandEyeOptions::default()
            };
            let solved = solve(&scene, setup, &options);
            let summary = solved
                .result
                .pose_refinement
                .as_ref()
                .expect("pose refinement ran");
            assert_eq!(summary.camera_noise_model, "per_view");
            let std = &summary.camera_transform_std;
            let (r, t) = error(&solved.result.x, &x);
            for i in 0..3 {
                let (er, sr) = (r[i].to_degrees().abs(), std.rotation_deg[i]);
                let (et, st) = (t[i].abs() * 1e3, std.translation_mm[i]);
                assert!(
                    er < 4.0 * sr,
                    "seed {seed} {setup:?} rot {i}: {er} deg, std {sr}"
                );
                assert!(
                    et < 4.0 * st,
                    "seed {seed} {setup:?} t {i}: {et} mm, std {st}"
                );
            }
            assert!(t.norm() < 2e-3 && r.norm().to_degrees() < 0.1, "{t} {r}");
        }
    }
}

#[test]
fn poses_that_do_not_pair_with_the_frames_are_refused() {
    let scene = rig_scene(&RigSceneConfig::default(), 5);
    let (x, y) = truth(Setup::EyeInHand);
    let rig = HeldRig {
        cameras: scene.cameras.clone(),
        camera_from_rig: scene.camera_from_rig.clone(),
    };
    let mut poses = robot_poses(&scene, Setup::EyeInHand, &x, &y);
    poses.pop();
    let err = calibrate_rig_handeye(
        Setup::EyeInHand,
        &rig,
        &scene.names,
        &scene.frame_keys,
        &frames(&scene),
        &poses,
        &HandEyeOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "poses: 19 robot poses but 20 frames: give one robot pose per frame, in frame order"
    );
    // Frames no camera saw are left out with their pose and say so; with
    // too few left the error lists them.
    let mut few = frames(&scene);
    for f in few.iter_mut().skip(2) {
        f.clear();
    }
    let err = calibrate_rig_handeye(
        Setup::EyeInHand,
        &rig,
        &scene.names,
        &scene.frame_keys,
        &few,
        &robot_poses(&scene, Setup::EyeInHand, &x, &y),
        &HandEyeOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.starts_with(
            "frames: requires at least 3 pose pairs, got 2; left out with their pose: \
             frame 2 (no camera saw the board), frame 3 (no camera saw the board)"
        ),
        "{err}"
    );
}
