//! Golden files for every export format: the exact bytes robocal writes for
//! a fixed camera and a fixed transform. A change in any writer shows up
//! here; regenerate on purpose with `UPDATE_FIXTURES=1 cargo test --test calib exports::`.
//! The same `export()` runs in the CLI, node and the browser, so these files
//! are also what those hosts produce (checked by their own tests).

use robocal::io::export::export;
use std::path::PathBuf;

const CAMERA_REPORT: &str = r#"{
  "name": "cam0",
  "image_size_px": [1280, 960],
  "model": "brown",
  "camera_matrix": [[1000.5, 0.0, 640.25], [0.0, 1001.75, 479.5], [0.0, 0.0, 1.0]],
  "distortion": {"k1": -0.125, "k2": 0.0625, "p1": 0.001, "p2": -0.0005, "k3": 0.0},
  "rms_px": 0.123,
  "gripper_from_camera": {
    "matrix_row_major": [[0.0, -1.0, 0.0, 0.05], [1.0, 0.0, 0.0, -0.02], [0.0, 0.0, 1.0, 0.1], [0.0, 0.0, 0.0, 1.0]]
  }
}"#;

fn golden(name: &str, actual: &str) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/exports")
        .join(name);
    if std::env::var_os("UPDATE_FIXTURES").is_some() {
        std::fs::write(&path, actual).unwrap();
        return;
    }
    let expected = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (run with UPDATE_FIXTURES=1 to create it)",
            path.display()
        )
    });
    assert_eq!(actual, expected, "{name} differs from its golden file");
}

#[test]
fn every_camera_format_matches_its_golden_file() {
    for (format, file) in [
        ("json", "camera.json"),
        ("opencv-yaml", "camera.opencv.yaml"),
        ("opencv-xml", "camera.opencv.xml"),
        ("ros-yaml", "camera.ros.yaml"),
        ("mrcal", "camera.cameramodel"),
        ("halcon", "camera.halcon.txt"),
        ("matlab", "camera.m"),
        ("text", "camera.K.txt"),
    ] {
        let out = export(CAMERA_REPORT, format, None)
            .unwrap()
            .replace(robocal::VERSION, "VERSION");
        golden(file, &out);
    }
    // Kalibr's radtan has no k3: with k3 = 0 it exports.
    golden(
        "camera.kalibr.yaml",
        &export(CAMERA_REPORT, "kalibr", None).unwrap(),
    );
}

#[test]
fn every_transform_format_matches_its_golden_file() {
    for format in [
        "matrix4",
        "xyz-quat-xyzw",
        "xyz-quat-wxyz",
        "euler-extrinsic-xyz-deg",
        "euler-intrinsic-zyx-rad",
        "urdf",
        "urdf-robot",
        "ros2-static-tf",
        "ros1-static-tf",
        "ros1-launch",
        "ros2-launch",
        "ur",
        "kuka",
        "abb-tooldata",
        "abb-wobjdata",
        "fanuc",
    ] {
        golden(
            &format!("gripper_from_camera.{format}.txt"),
            &export(CAMERA_REPORT, format, None).unwrap(),
        );
    }
}

#[test]
fn bad_requests_say_what_to_fix() {
    let err = export(CAMERA_REPORT, "png", None).unwrap_err().to_string();
    assert!(
        err.starts_with("format: unknown export format 'png' (known: json, opencv-yaml,"),
        "{err}"
    );
    let err = export(r#"{"rms_px": 1.0}"#, "opencv-yaml", None)
        .unwrap_err()
        .to_string();
    assert_eq!(
        err,
        "report: format 'opencv-yaml' needs a camera, and this report has none (no image_size_px)"
    );
    let err = export(r#"{"rms_px": 1.0}"#, "urdf", None)
        .unwrap_err()
        .to_string();
    assert_eq!(err, "report: format 'urdf' needs a transform, and this report has none of gripper_from_camera, base_from_camera, right_from_left, base_from_target");
    // Flat 16-number matrices are read too.
    let flat = r#"{"base_from_camera": {"matrix_row_major": [1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}}"#;
    assert_eq!(
        export(flat, "xyz-quat-xyzw", None).unwrap(),
        "# base_from_camera: x y z (m) qx qy qz qw\n0.5 0.0 0.0 0.0 0.0 0.0 1.0\n"
    );
    let err = export(
        r#"{"base_from_camera": {"matrix_row_major": [1, 2]}}"#,
        "urdf",
        None,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        err,
        "base_from_camera: expected matrix_row_major with 4 rows of 4 numbers (or 16 numbers), got 2 numbers"
    );
    let err = export("{", "json", None).unwrap_err().to_string();
    assert!(
        err.starts_with("line 1, column 1: the report is not valid JSON"),
        "{err}"
    );
}

/// The rig of fixtures/exports/rig.json (three cameras: Brown, Kannala-Brandt,
/// pinhole; written by the library's export_rig_tests) in every rig format;
/// several files (ros) are golden one by one.
#[test]
fn every_rig_format_matches_its_golden_files() {
    let rig = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/exports/rig.json"),
    )
    .unwrap();
    let options = robocal::io::export::ExportOptions::default();
    for format in ["kalibr", "opencv-yaml", "ros", "urdf"] {
        let files = robocal::io::export::export_files(&rig, format, &options).unwrap();
        for f in files {
            golden(
                &format!("rig.{format}.{}", f.name),
                &f.text.replace(robocal::VERSION, "VERSION"),
            );
        }
    }
    // mrcal has no Kannala-Brandt model: the rig with a pinhole middle camera.
    let pinhole = rig.replacen(
        "\"model\": \"kannala_brandt\",\n            \"k1\": 0.01,\n            \"k2\": -0.002,\n            \"k3\": 0.0003,\n            \"k4\": -0.00004",
        "\"model\": \"none\"",
        1,
    );
    assert_ne!(pinhole, rig, "the fixture's middle camera changed");
    for f in robocal::io::export::export_files(&pinhole, "mrcal", &options).unwrap() {
        golden(
            &format!("rig.mrcal.{}", f.name),
            &f.text.replace(robocal::VERSION, "VERSION"),
        );
    }
}
