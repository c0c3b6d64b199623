//! Robot pose files from public datasets, parsed with the `io` presets.
//! Skipped (with a message) when ../shared/datasets is not present.

use crate::support;
use std::path::PathBuf;

use robocal::geometry::{pose_from_matrix4, rotation_angle_between};
use robocal::io::{parse_pose_candidates, parse_poses, PoseFileOptions, PoseFormat};

fn dataset(rel: &str) -> Option<PathBuf> {
    let found = support::dataset(rel);
    if found.is_none() {
        eprintln!("skipping: dataset file {rel} not found");
    }
    found
}

/// RWHE-Calib CS_synthetic_1: 15 tab-separated row-major 4x4 matrices,
/// T_base_gripper in metres (SOURCE.md). Printed with 9 decimals, so values
/// agree to 1e-9.
#[test]
fn rwhe_robot_poses_vec_reads_as_matrix4() {
    let Some(path) = dataset("rwhe-calib-cs-synthetic-1/RobotPosesVec.txt") else {
        return;
    };
    let text = std::fs::read_to_string(path).unwrap();
    let parsed = parse_poses(&text, &PoseFileOptions::default()).unwrap();
    assert_eq!(parsed.format, PoseFormat::Matrix4);
    assert_eq!(parsed.poses.len(), 15);
    let p1 = parsed.poses[0].base_from_gripper;
    assert!((p1.translation.vector - nalgebra::Vector3::new(1.2, 0.0, 2.5)).norm() < 1e-9);
    // Row 1 of pose 1: [0 0 -1 | 1.2], so the gripper z axis is base -x.
    let r = p1.rotation.to_rotation_matrix().into_inner();
    assert!((r.column(2) - nalgebra::Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-9);
    let p15 = &parsed.poses[14];
    assert_eq!(p15.line, 15);
    assert!(
        (p15.base_from_gripper.translation.vector - nalgebra::Vector3::new(6.0, 0.134267, 3.5))
            .norm()
            < 1e-9
    );
    // No other reading: 16 values are a matrix; metres rank above millimetres.
    let c = parse_pose_candidates(&text, &PoseFileOptions::default()).unwrap();
    assert_eq!(c.len(), 2);
    assert_eq!(c[0].length_unit, robocal::io::LengthUnit::Metre);
}

/// MoveIt calibration samples: 50 [eef_wrt_world, obj_wrt_sensor] pairs of
/// 4x4 matrices (metres). The robot poses are the first matrix of each pair.
#[test]
fn moveit_pose_samples_robot_matrices_read_as_matrix4() {
    let Some(path) = dataset("moveit-handeye-pose-samples/pose_samples.json") else {
        return;
    };
    let text = std::fs::read_to_string(path).unwrap();
    // The pair layout is not a pose file by itself: the error says what to do.
    let err = parse_poses(&text, &PoseFileOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("for [robot, camera] pairs, pass the robot matrices alone"),
        "{err}"
    );
    let samples: Vec<Vec<serde_json::Value>> = serde_json::from_str(&text).unwrap();
    let robot: Vec<&serde_json::Value> = samples.iter().map(|s| &s[0]).collect();
    let robot_json = serde_json::to_string(&robot).unwrap();
    let parsed = parse_poses(&robot_json, &PoseFileOptions::default()).unwrap();
    assert_eq!(parsed.format, PoseFormat::Matrix4);
    assert_eq!(parsed.poses.len(), 50);
    let p1 = parsed.poses[0].base_from_gripper;
    let t = p1.translation.vector;
    assert!(
        (t - nalgebra::Vector3::new(0.263275187959874, 0.11594185945790944, 0.03908420968284165))
            .norm()
            < 1e-15
    );
    let r = p1.rotation.to_rotation_matrix().into_inner();
    assert!((r[(0, 0)] + 0.7577318022980202).abs() < 1e-9);
    // Same as building the pose directly from the nested JSON matrix.
    let m: Vec<Vec<f64>> = serde_json::from_value(samples[0][0].clone()).unwrap();
    let m4 = nalgebra::Matrix4::from_fn(|r, c| m[r][c]);
    let direct = pose_from_matrix4(&m4).unwrap();
    assert!(rotation_angle_between(&direct.rotation, &p1.rotation) < 1e-15);
}
