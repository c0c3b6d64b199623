//! A focal length that disagrees with the robot's motion
//! (`robocal::handeye::quality::focal`), through the JSON API every host
//! calls: the image path (views and a camera, no `refine`), whose PnP poses
//! take the camera as given.
//!
//! Scene: `synth::handeye_looking::observe_looking`, eye-in-hand, 20 views
//! of a 9x6 grid (30 mm) at 0.5 m +-10 %, 1280x960 at f = 1100 px, pixel
//! noise 0.2 px, robot noise 0.1 mm / 0.02 deg per axis (the cells of
//! examples/handeye_coverage.rs). Given a camera with fx = fy = 1111 px
//! (1 % long), the report must name the focal length and its std must
//! cover the truth (3 std on every component); given the right camera, no
//! focal warning.

use robocal::api::handeye::solve_handeye_json;
use robocal::camera::Camera;
use robocal::geometry::PoseJson;
use robocal::handeye::{Pose, Setup};
use robocal::synth::handeye_looking::{observe_looking, LookingConfig, LookingNoise};
use serde_json::{json, Value};

/// The report of one solve, the camera's focal length `f` (px).
fn solve(f: f64, seed: u64) -> (Value, Pose) {
    let truth = Camera::pinhole(1100.0, 1100.0, 639.5, 479.5, 1280, 960);
    let config = LookingConfig::half_metre(Setup::EyeInHand, 20);
    let noise = LookingNoise {
        pixel_sigma: 0.2,
        robot_sigma: (0.02f64.to_radians(), 0.1e-3),
        kinematic: None,
    };
    let seen = observe_looking(&config, seed, &truth, &noise, seed ^ 0xc0ffee);
    let robots: Vec<Value> = seen
        .base_from_gripper
        .iter()
        .map(|p| serde_json::to_value(PoseJson::from(p)))
        .collect::<Result<_, _>>()
        .unwrap();
    let views: Vec<Value> = seen
        .views
        .iter()
        .map(|v| {
            json!({
                "object_m": v.object_m.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
                "image_px": v.image_px.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>(),
            })
        })
        .collect();
    let input = json!({
        "setup": "eye-in-hand",
        "base_from_gripper": robots,
        "camera": Camera::pinhole(f, f, 639.5, 479.5, 1280, 960),
        "views": views,
        "bootstrap_samples": 0,
        "strict_checks": false,
    });
    let out = solve_handeye_json(&input.to_string()).unwrap_or_else(|e| panic!("{e}"));
    (serde_json::from_str(&out).unwrap(), seen.scene.x_true)
}

fn focal_warnings(report: &Value) -> Vec<String> {
    report["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|w| w.as_str())
        .filter(|w| w.starts_with("focal length:"))
        .map(str::to_string)
        .collect()
}

/// Error of the reported `gripper_from_camera` over its reported std, per
/// component (rotation x, y, z about the gripper axes, translation x, y, z).
fn errors_in_std(report: &Value, truth: &Pose) -> [f64; 6] {
    let x = pose_of(&report["gripper_from_camera"]);
    let std = &report["pose_refinement"]["camera_transform_std"];
    let dr = (x.rotation * truth.rotation.inverse()).scaled_axis();
    let dt = (x.translation.vector - truth.translation.vector) * 1e3;
    std::array::from_fn(|k| {
        if k < 3 {
            dr[k].to_degrees().abs() / std["rotation_deg"][k].as_f64().unwrap()
        } else {
            dt[k - 3].abs() / std["translation_mm"][k - 3].as_f64().unwrap()
        }
    })
}

fn pose_of(v: &Value) -> Pose {
    serde_json::from_value::<PoseJson>(v.clone())
        .unwrap()
        .to_pose()
        .unwrap()
}

#[test]
fn a_focal_length_one_percent_off_is_named_and_the_std_covers_the_truth() {
    let seed = 9003;
    let (off, truth) = solve(1111.0, seed);
    let named = focal_warnings(&off);
    assert_eq!(named.len(), 1, "{:?}", off["warnings"]);
    // "... by 0.89 % (4.2 std)": about the 1 % put in.
    let percent: f64 = named[0]
        .split("motion by ")
        .nth(1)
        .and_then(|t| t.split(" %").next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{}", named[0]));
    assert!((0.7..1.3).contains(&percent), "{}", named[0]);
    assert!(named[0].contains("want fx and fy shorter"), "{}", named[0]);
    assert!(named[0].contains("Recalibrate the camera's intrinsics"));
    let check = &off["pose_refinement"]["focal_check"];
    let scale = check["scale"].as_f64().unwrap();
    // The fitted scale brings fx back near 1100 px.
    assert!(
        (1111.0 * scale - 1100.0).abs() < 2.0,
        "fx {}",
        1111.0 * scale
    );
    let within = errors_in_std(&off, &truth);
    assert!(within.iter().all(|k| *k <= 3.0), "errors in std {within:?}");

    let (right, truth) = solve(1100.0, seed);
    assert!(focal_warnings(&right).is_empty(), "{:?}", right["warnings"]);
    assert!(right["pose_refinement"].get("focal_check").is_none());
    let within = errors_in_std(&right, &truth);
    assert!(within.iter().all(|k| *k <= 3.0), "errors in std {within:?}");
}
