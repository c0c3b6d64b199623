//! The focal check of `robocal handeye` (src/handeye/quality/focal.rs) on
//! the public hand-eye sets: no false warning where the focal length is
//! right, a named one (and a std that covers the truth) where it is not.
//!
//! - RWHE-Calib CS_synthetic_1 (rendered, ground truth X = diag(1, -1, -1),
//!   t = 0; the board 7-8 m away): its focal length is 1080 px (the joint
//!   refinement of `cli_handeye` finds it within 0.5 px). Given 1080 px the
//!   check must stay quiet; given SOURCE.md's estimate of 1078.88 px (0.10 %
//!   short) it must name the focal length, and given 1079.5 px (0.05 %
//!   short, which moves the answer 2.5 mm at that distance) the std must
//!   still cover the truth.
//! - MoveIt's eye-to-hand pose samples (real camera poses, no images): the
//!   check cannot run, and the pose path's scale check must not fire.
//!
//! Either set absent: skipped with a message.

use crate::support;
use support::{dataset, temp_dir};

use super::cli_handeye::{matrix, ok, read_json, robocal};
use serde_json::Value;

fn warnings(report: &Value, start: &str) -> Vec<String> {
    report["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(Value::as_str)
        .filter(|w| w.starts_with(start))
        .map(str::to_string)
        .collect()
}

/// The RWHE report from the images with the pose refinement (no refinement
/// over pixels: the path the focal check runs on), the camera's focal
/// length `f` px.
fn rwhe_report(dir: &std::path::Path, tmp: &std::path::Path, f: f64) -> Value {
    super::cli_handeye::rwhe_report(dir, tmp, f, [959.5, 539.5], "none")
}

/// The truth within 3 reported std on every component of
/// gripper_from_camera (rotation about the gripper axes, translation).
fn truth_within_3_std(report: &Value) -> Result<(), String> {
    let m = matrix(&report["gripper_from_camera"]);
    let std = &report["pose_refinement"]["camera_transform_std"];
    let s = |key: &str, k: usize| std[key][k].as_f64().unwrap();
    // Truth R = diag(1, -1, -1), t = 0: R R_true^T's small angles.
    let r = [
        [m[0][0], -m[0][1], -m[0][2]],
        [m[1][0], -m[1][1], -m[1][2]],
        [m[2][0], -m[2][1], -m[2][2]],
    ];
    let angle_deg = [
        0.5 * (r[2][1] - r[1][2]),
        0.5 * (r[0][2] - r[2][0]),
        0.5 * (r[1][0] - r[0][1]),
    ]
    .map(f64::to_degrees);
    for k in 0..3 {
        let t_mm = m[k][3] * 1e3;
        if t_mm.abs() > 3.0 * s("translation_mm", k) {
            return Err(format!("t[{k}] {t_mm} mm, std {}", s("translation_mm", k)));
        }
        if angle_deg[k].abs() > 3.0 * s("rotation_deg", k) {
            return Err(format!(
                "r[{k}] {} deg, std {}",
                angle_deg[k],
                s("rotation_deg", k)
            ));
        }
    }
    Ok(())
}

#[test]
fn rwhe_focal_check_is_quiet_at_the_right_focal_length_and_covers_a_wrong_one() {
    let Some(dir) = dataset("rwhe-calib-cs-synthetic-1") else {
        eprintln!("skipped: ../shared/datasets/rwhe-calib-cs-synthetic-1 is absent");
        return;
    };
    let tmp = temp_dir("cli", "rwhe-focal");
    let right = rwhe_report(&dir, &tmp, 1080.0);
    assert!(
        warnings(&right, "focal length:").is_empty(),
        "{:?}",
        right["warnings"]
    );
    assert!(right["pose_refinement"].get("focal_check").is_none());
    truth_within_3_std(&right).unwrap();
    // SOURCE.md's estimate, 0.10 % short: named, the wanted fx is 1080.
    let short = rwhe_report(&dir, &tmp, 1078.88);
    let named = warnings(&short, "focal length:");
    assert_eq!(named.len(), 1, "{:?}", short["warnings"]);
    assert!(
        named[0].contains("(fx 1080.0 px, fy 1080.0 px)"),
        "{}",
        named[0]
    );
    let scale = short["pose_refinement"]["focal_check"]["scale"]
        .as_f64()
        .unwrap();
    assert!((scale - 1080.0 / 1078.88).abs() < 2e-4, "{scale}");
    truth_within_3_std(&short).unwrap();
    // 0.05 % short: the answer moves 2.5 mm along the optical axis, several
    // of the held std; the std must include it.
    let slightly = rwhe_report(&dir, &tmp, 1079.5);
    truth_within_3_std(&slightly).unwrap();
    let _ = std::fs::remove_dir_all(&tmp);
}

#[test]
fn moveit_camera_poses_raise_no_focal_or_scale_warning() {
    let Some(dir) = dataset("moveit-handeye-pose-samples") else {
        eprintln!("skipped: ../shared/datasets/moveit-handeye-pose-samples is absent");
        return;
    };
    let text = std::fs::read_to_string(dir.join("pose_samples.json")).unwrap();
    let samples: Value = serde_json::from_str(&text).unwrap();
    let samples = samples.as_array().unwrap();
    // Each sample: [eef_wrt_world, obj_wrt_sensor], 4x4 row-major, metres.
    let table = |k: usize| -> String {
        samples
            .iter()
            .map(|s| {
                let rows = s[k].as_array().unwrap();
                let line: Vec<String> = rows
                    .iter()
                    .flat_map(|r| r.as_array().unwrap().iter().map(|v| v.to_string()))
                    .collect();
                line.join(" ") + "\n"
            })
            .collect()
    };
    let tmp = temp_dir("cli", "moveit-focal");
    let (robot, cameras, out) = (
        tmp.join("robot.txt"),
        tmp.join("cameras.txt"),
        tmp.join("handeye.json"),
    );
    std::fs::write(&robot, table(0)).unwrap();
    std::fs::write(&cameras, table(1)).unwrap();
    ok(&robocal(&[
        "handeye",
        "--setup",
        "eye-to-hand",
        "--poses",
        robot.to_str().unwrap(),
        "--camera-poses",
        cameras.to_str().unwrap(),
        "--bootstrap",
        "0",
        "-o",
        out.to_str().unwrap(),
    ]));
    let report = read_json(&out);
    for start in ["focal length:", "scale:"] {
        assert!(
            warnings(&report, start).is_empty(),
            "{:?}",
            report["warnings"]
        );
    }
    assert!(report["pose_refinement"].get("focal_check").is_none());
    let _ = std::fs::remove_dir_all(&tmp);
}
