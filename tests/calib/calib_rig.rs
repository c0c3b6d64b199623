//! Rig calibration (issue 22) against seeded synthetic rigs
//! (`robocal::synth::rig`: four cameras in two pairs facing each other,
//! linked only by "side" frames seen by cam1 and cam2, partial views) and
//! against stereo on OpenCV's left/right 9x6 corners.
//!
//! Tolerances: noise-free points give the truth to solver precision (1e-9
//! rad and m, the solver stops at a relative cost change of 1e-12); with
//! Gaussian pixel noise the errors are compared with the reported standard
//! deviations: each component of every camera_from_rig within 3 std holds
//! with probability 0.9973 when the covariance is right, so over many
//! (trial, component) samples at least 99 % must hold.

use crate::support;
use support::dataset;

use nalgebra::{Point2, Point3};
use robocal::calib::multi::rig::{calibrate_rig, RigCameraViews, RigOptions};
use robocal::calib::multi::rig_report::RigCalibration;
use robocal::calib::multi::stereo::calibrate_stereo;
use robocal::calib::{CalibrationOptions, View};
use robocal::camera::Distortion;
use robocal::geometry::{rotvec_from_rotation, Pose};
use robocal::synth::rig::{rig_scene, RigScene, RigSceneConfig};
use serde_json::Value;

fn solve(scene: &RigScene, held: &[usize], rig_frame: Option<&str>) -> RigCalibration {
    calibrate_rig(
        &scene.camera_views(held),
        &scene.frame_keys,
        &RigScene::rig_options(rig_frame),
    )
    .expect("rig")
}

/// Rotation (left perturbation, rad) and translation (m) errors of a pose.
fn errors(got: &Pose, truth: &Pose) -> [f64; 6] {
    let r = rotvec_from_rotation(&(got.rotation * truth.rotation.inverse()));
    let t = got.translation.vector - truth.translation.vector;
    [r.x, r.y, r.z, t.x, t.y, t.z]
}

#[test]
fn noise_free_rig_is_recovered_exactly() {
    let scene = rig_scene(&RigSceneConfig::default(), 1);
    let rig = solve(&scene, &[], None);
    assert_eq!(rig.rig_frame, "cam0");
    for (k, camera) in rig.cameras.iter().enumerate() {
        let got = camera.camera_from_rig.to_pose().expect("pose");
        let e = errors(&got, &scene.camera_from_rig[k]);
        assert!(
            e.iter().all(|v| v.abs() < 1e-9),
            "cam{k}: errors {e:?} (rad, m)"
        );
        let c = &camera.calibration.camera;
        assert!(
            (c.fx - scene.cameras[k].fx).abs() < 1e-6,
            "cam{k} fx {} px",
            c.fx
        );
        assert!(
            (c.cy - scene.cameras[k].cy).abs() < 1e-6,
            "cam{k} cy {} px",
            c.cy
        );
    }
    for (f, frame) in rig.frames.iter().enumerate() {
        let got = frame
            .rig_from_target
            .as_ref()
            .expect("seen")
            .to_pose()
            .expect("pose");
        let e = errors(&got, &scene.rig_from_target[f]);
        assert!(e.iter().all(|v| v.abs() < 1e-9), "frame {f}: {e:?}");
    }
    assert!(rig.rms_px < 1e-6, "rms {} px", rig.rms_px);
    // The graph: the pairs never see a frame together; only cam1-cam2 links them.
    let counts = &rig.co_observation.frames;
    assert_eq!(counts[0][2], 0);
    assert_eq!(counts[0][3], 0);
    assert_eq!(counts[1][3], 0);
    assert!(counts[1][2] > 0 && counts[1][2] <= 4, "{counts:?}");
    assert!(rig.co_observation.spanning_tree.contains(&[1, 2]));
    assert!(rig.cameras[0].camera_from_rig_std.is_none());
}

#[test]
fn held_intrinsics_and_another_rig_frame() {
    let scene = rig_scene(&RigSceneConfig::default(), 2);
    let rig = solve(&scene, &[2, 3], Some("cam2"));
    assert_eq!(rig.rig_frame, "cam2");
    let rig_from_cam2 = scene.camera_from_rig[2].inverse();
    for (k, camera) in rig.cameras.iter().enumerate() {
        assert_eq!(camera.intrinsics_held, k >= 2);
        let got = camera.camera_from_rig.to_pose().expect("pose");
        let e = errors(&got, &(scene.camera_from_rig[k] * rig_from_cam2));
        assert!(
            e.iter().all(|v| v.abs() < 1e-9),
            "cam{k}: errors {e:?} (rad, m)"
        );
    }
    assert_eq!(rig.cameras[3].calibration.camera, scene.cameras[3]);
}

#[test]
fn cameras_without_shared_frames_name_the_groups() {
    let config = RigSceneConfig {
        side_frames: 0,
        ..RigSceneConfig::default()
    };
    let scene = rig_scene(&config, 3);
    let err = calibrate_rig(
        &scene.camera_views(&[]),
        &scene.frame_keys,
        &RigScene::rig_options(None),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "cameras are not connected by shared board views: {cam0, cam1} and {cam2, cam3}; add \
         frames where a camera of each group sees the board"
    );
}

/// Over `trials` seeded noisy rigs: (samples within 3 std, samples).
fn coverage(trials: u64, noise_px: f64) -> (usize, usize) {
    let (mut inside, mut total) = (0, 0);
    for seed in 0..trials {
        let config = RigSceneConfig {
            noise_px,
            ..RigSceneConfig::default()
        };
        let scene = rig_scene(&config, 100 + seed);
        let rig = solve(&scene, &[], None);
        for (k, camera) in rig.cameras.iter().enumerate().skip(1) {
            let got = camera.camera_from_rig.to_pose().expect("pose");
            let e = errors(&got, &scene.camera_from_rig[k]);
            let s = camera.camera_from_rig_std.as_ref().expect("std");
            let std = [s.rotation_rad, s.translation_m].concat();
            for (err, sd) in e.iter().zip(&std) {
                total += 1;
                if err.abs() <= 3.0 * sd {
                    inside += 1;
                }
            }
        }
    }
    (inside, total)
}

#[test]
fn noisy_extrinsics_are_within_three_reported_std() {
    // 20 trials x 18 components: expected ~1 outside; 98 % allows 7.
    let (inside, total) = coverage(20, 0.3);
    eprintln!("within 3 std: {inside} of {total}");
    assert!(
        inside as f64 >= 0.98 * total as f64,
        "{inside} of {total} within 3 std"
    );
}

#[test]
#[ignore = "200 seeded trials (about a minute in release): cargo test --release --test calib calib_rig:: -- --ignored"]
fn noisy_extrinsics_are_within_three_reported_std_in_200_trials() {
    let (inside, total) = coverage(200, 0.3);
    eprintln!("within 3 std: {inside} of {total}");
    assert!(
        inside as f64 >= 0.99 * total as f64,
        "{inside} of {total} within 3 std"
    );
}

/// OpenCV's refined corners of one image of the 9x6 set (30 mm squares).
fn fixture_view(fixture: &Value, image: &str) -> View {
    let corners = fixture["images"][image].as_array().expect("corners");
    View::new(
        image,
        (0..54)
            .map(|k| Point3::new((k % 9) as f64 * 0.03, (k / 9) as f64 * 0.03, 0.0))
            .collect(),
        corners
            .iter()
            .map(|c| Point2::new(c[0].as_f64().expect("x"), c[1].as_f64().expect("y")))
            .collect(),
    )
}

#[test]
fn opencv_9x6_pair_as_a_rig_gives_the_stereo_result() {
    let Some(_) = dataset("opencv-left-right-9x6") else {
        eprintln!("skipped: opencv-left-right-9x6 dataset not found");
        return;
    };
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/opencv-left-right-9x6.json"
    );
    let fixture: Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("fixture")).expect("JSON");
    let numbers = [1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14];
    let side = |s: &str| -> Vec<View> {
        numbers
            .iter()
            .map(|i| fixture_view(&fixture, &format!("{s}{i:02}.jpg")))
            .collect()
    };
    let calibration = CalibrationOptions {
        model: Distortion::Brown {
            k1: 0.0,
            k2: 0.0,
            k3: 0.0,
            p1: 0.0,
            p2: 0.0,
        },
        fixed_coefficients: vec!["k3".into()],
        ..CalibrationOptions::default()
    };
    let (left, right) = (side("left"), side("right"));
    let stereo =
        calibrate_stereo(&left, &right, (640, 480), (640, 480), &calibration).expect("stereo");
    let keyed = |views: Vec<View>| views.into_iter().enumerate().collect::<Vec<_>>();
    let cameras = vec![
        RigCameraViews {
            name: "left".into(),
            image_size_px: (640, 480),
            views: keyed(left),
            camera: None,
        },
        RigCameraViews {
            name: "right".into(),
            image_size_px: (640, 480),
            views: keyed(right),
            camera: None,
        },
    ];
    let keys: Vec<String> = numbers.iter().map(|n| n.to_string()).collect();
    let rig = calibrate_rig(
        &cameras,
        &keys,
        &RigOptions {
            calibration,
            ..RigScene::rig_options(None)
        },
    )
    .expect("rig");
    // The same problem, parameterised alike: the same optimum to the
    // solver's precision (1e-9 rad, 1e-9 m ~ 1e-7 of the 0.1 m baseline).
    let want = stereo.right_from_left.to_pose().expect("pose");
    let got = rig.cameras[1].camera_from_rig.to_pose().expect("pose");
    let e = errors(&got, &want);
    eprintln!(
        "rig - stereo: {e:?} (rad, m); rms {} vs {} px",
        rig.rms_px, stereo.rms_px
    );
    assert!(e.iter().all(|v| v.abs() < 1e-9), "{e:?}");
    let (s_rig, s_st) = (
        rig.cameras[1].camera_from_rig_std.as_ref().expect("std"),
        stereo.right_from_left_std.as_ref().expect("std"),
    );
    // The rig widens its std to the leave-frames-out spread where that is
    // larger (calib::rig_jackknife); stereo reports the joint covariance's.
    // On these 13 real frames the spread is about twice the model's (0.22
    // against 0.11 mm in x): never narrower, and within 3x.
    for (a, b) in s_rig.translation_m.iter().zip(&s_st.translation_m) {
        assert!(*a >= b * (1.0 - 1e-6) && *a <= 3.0 * b, "std {a} vs {b} m");
    }
    eprintln!(
        "baseline std: rig {:?} m (widened), stereo {:?} m",
        s_rig.translation_m, s_st.translation_m
    );
    assert!(
        (rig.rms_px - stereo.rms_px).abs() < 1e-9,
        "rms {} vs {}",
        rig.rms_px,
        stereo.rms_px
    );
    assert!((rig.cameras[1].calibration.camera.fx - stereo.right.camera.fx).abs() < 1e-6);
}

/// A camera whose images sit two frames late (its files numbered from 2
/// where the others start at 0) is refused before the joint fit, with the
/// shift and a pair of frames named; the same scene grouped right solves
/// without a grouping warning (issue 35: the rig's frame grouping proven).
#[test]
fn frames_of_one_camera_shifted_are_named_before_the_joint_fit() {
    let config = RigSceneConfig {
        noise_px: 0.3,
        ..RigSceneConfig::default()
    };
    let scene = rig_scene(&config, 5);
    let right = solve(&scene, &[], None);
    assert!(
        !right.warnings.iter().any(|w| w.contains("frames")),
        "{:?}",
        right.warnings
    );
    let mut cameras = scene.camera_views(&[]);
    let n = scene.frame_keys.len();
    cameras[1].views = cameras[1]
        .views
        .iter()
        .filter(|(f, _)| f + 2 < n)
        .map(|(f, v)| (f + 2, v.clone()))
        .collect();
    let err = calibrate_rig(&cameras, &scene.frame_keys, &RigScene::rig_options(None))
        .expect_err("shifted frames")
        .to_string();
    assert!(
        err.contains("the board's motions agree only when cam1's frames are taken 2 frames late"),
        "{err}"
    );
    assert!(
        err.contains("rename them or choose another grouping rule"),
        "{err}"
    );
}

/// Free-running cameras 5 ms apart (std per view) filming a hand-held
/// board (30 deg/s, 0.15 m/s): over 10 seeded rigs every result either
/// holds the true extrinsics within 3 reported std or carries a warning
/// (the grouping check's or the intrinsics drift): never a silent wrong
/// rig. The full table is `cargo run --release --example rig_coverage`.
#[test]
fn timing_error_is_covered_or_warned() {
    let mut silent = Vec::new();
    for seed in 0..10 {
        let config = RigSceneConfig {
            noise_px: 0.3,
            timing_ms: 5.0,
            ..RigSceneConfig::default()
        };
        let scene = rig_scene(&config, 300 + seed);
        let rig = solve(&scene, &[], None);
        let covered = rig.cameras.iter().enumerate().skip(1).all(|(k, camera)| {
            let got = camera.camera_from_rig.to_pose().expect("pose");
            let e = errors(&got, &scene.camera_from_rig[k]);
            let s = camera.camera_from_rig_std.as_ref().expect("std");
            let std = [s.rotation_rad, s.translation_m].concat();
            e.iter().zip(&std).all(|(err, sd)| err.abs() <= 3.0 * sd)
        });
        let warned = rig.warnings.iter().any(|w| {
            w.contains("disagree on how the board moved")
                || w.contains("moved its intrinsics beyond")
                || w.contains("leaving frames out moves")
        });
        if !covered && !warned {
            silent.push(seed);
        }
    }
    assert!(silent.is_empty(), "silent wrong rigs at seeds {silent:?}");
}
