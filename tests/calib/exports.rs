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

fn stereo_fixture() -> String {
    std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/exports/stereo.json"),
    )
    .unwrap()
}

/// The pair of fixtures/exports/stereo.json (two Brown-Conrady cameras with
/// k3 = 0, right_from_left of rotation vector [0.01, -0.04, 0.015] rad and
/// T [-0.06, 0.002, -0.001] m: the pair of src/calib/stereo_rectify_tests.rs,
/// whose rectification matches cv2.stereoRectify) in every stereo format.
#[test]
fn every_stereo_format_matches_its_golden_files() {
    let stereo = stereo_fixture();
    let options = robocal::io::export::ExportOptions::default();
    let mut names = Vec::new();
    for format in ["opencv-yaml", "ros", "kalibr"] {
        for f in robocal::io::export::export_files(&stereo, format, &options).unwrap() {
            names.push(f.name.clone());
            golden(
                &format!("stereo.{format}.{}", f.name),
                &f.text.replace(robocal::VERSION, "VERSION"),
            );
        }
    }
    assert_eq!(
        names,
        [
            "stereo.opencv.yaml",
            "left.yaml",
            "right.yaml",
            "camchain.yaml"
        ]
    );
    // A transform format writes right_from_left, as before.
    let text = export(&stereo, "xyz-quat-xyzw", None).unwrap();
    assert!(text.contains("-0.06 0.002 -0.001"), "{text}");
}

/// The numbers of the OpenCV file, read back as cv::FileStorage would:
/// E = [T]x R, F = K2^-T E K1^-1, and the epipolar constraint of projected
/// points to 1e-9 (noise-free, so only rounding remains).
#[test]
fn the_stereo_opencv_file_holds_e_f_and_a_rectification_that_aligns_rows() {
    use nalgebra::{Matrix3, Matrix3x4, Point3, Vector3};
    let text = export(&stereo_fixture(), "opencv-yaml", None).unwrap();
    let matrix = |key: &str| -> Vec<f64> {
        let start = text
            .find(&format!("\n{key}: !!opencv-matrix"))
            .unwrap_or_else(|| panic!("no {key} in {text}"));
        let data = &text[start..];
        let open = data.find("data: [").unwrap() + 7;
        let close = open + data[open..].find(']').unwrap();
        data[open..close]
            .split(',')
            .map(|v| v.trim().parse().unwrap())
            .collect()
    };
    let m3 = |key: &str| Matrix3::from_row_slice(&matrix(key));
    let (k1, k2, r, e, f) = (m3("K1"), m3("K2"), m3("R"), m3("E"), m3("F"));
    let t = Vector3::from_row_slice(&matrix("T"));
    assert_eq!(matrix("T"), [-0.06, 0.002, -0.001]);
    assert_eq!(matrix("D1"), [-0.12, 0.01, 0.0005, -0.0003, 0.0]);
    assert!(
        text.contains("\nimage_width: 640\nimage_height: 480\n"),
        "{text}"
    );
    assert!((e - t.cross_matrix() * r).norm() < 1e-15, "E = [T]x R");
    let f_expected = k2.try_inverse().unwrap().transpose() * e * k1.try_inverse().unwrap();
    assert!((f - f_expected).norm() < 1e-15, "F = K2^-T E K1^-1");
    assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-15);
    let (r1, r2) = (m3("R1"), m3("R2"));
    let p1 = Matrix3x4::from_row_slice(&matrix("P1"));
    let p2 = Matrix3x4::from_row_slice(&matrix("P2"));
    for i in 0..30 {
        let i = i as f64;
        let x_left = Point3::new(-0.3 + 0.02 * i, 0.2 - 0.013 * i, 0.8 + 0.05 * (i % 7.0));
        let x_right = r * x_left.coords + t;
        // Undistorted pixels of both cameras satisfy the epipolar constraint.
        let (pl, pr) = (k1 * (x_left.coords / x_left.z), k2 * (x_right / x_right.z));
        let c = pr.dot(&(f * pl));
        assert!(c.abs() < 1e-9, "p_r^T F p_l = {c}");
        // Rectified: the same row in both images.
        let rl = p1 * (r1 * x_left.coords).push(1.0);
        let rr = p1 * (r2 * x_right).push(1.0);
        let rr2 = p2 * (r1 * x_left.coords).push(1.0);
        assert!(
            (rl.y / rl.z - rr.y / rr.z).abs() < 1e-9,
            "rows differ by {} px",
            rl.y / rl.z - rr.y / rr.z
        );
        assert!((rr.x / rr.z - rr2.x / rr2.z).abs() < 1e-9);
    }
}

#[test]
fn what_a_stereo_report_cannot_be_exported_as_is_named() {
    let stereo = stereo_fixture();
    let err = |report: &str, format: &str| export(report, format, None).unwrap_err().to_string();
    assert_eq!(
        err(&stereo, "mrcal"),
        "format: format 'mrcal' cannot hold a stereo pair: a stereo report exports as opencv-yaml, ros, kalibr (both cameras), as a transform format (right_from_left, e.g. matrix4) or as report"
    );
    assert_eq!(
        err(&stereo, "ros-yaml"),
        "format: format 'ros-yaml' cannot hold a stereo pair: a stereo report exports as opencv-yaml, ros, kalibr (both cameras), as a transform format (right_from_left, e.g. matrix4) or as report"
    );
    let two_sizes = stereo.replacen(
        "\"image_size_px\": [640, 480]",
        "\"image_size_px\": [1280, 960]",
        1,
    );
    assert_eq!(
        err(&two_sizes, "opencv-yaml"),
        "format: format 'opencv-yaml' holds one image size for both cameras (as cv2.stereoRectify takes one), but the left camera is 1280x960 and the right 640x480: export as kalibr, or each camera alone"
    );
    assert!(export(&two_sizes, "kalibr", None)
        .unwrap()
        .contains("resolution: [1280, 960]"));
    let division = stereo
        .replacen(
            "\"model\": \"brown\",\n    \"camera_matrix\": [[640.0",
            "\"model\": \"division\",\n    \"camera_matrix\": [[640.0",
            1,
        )
        .replacen("\"k1\": -0.05, \"k2\"", "\"kappa\": -0.05, \"k2\"", 1);
    assert_eq!(
        err(&division, "ros"),
        "format: right camera: the division lens model cannot be written for OpenCV (use robocal JSON, Halcon for division, Kalibr for EUCM)"
    );
    let with_k3 = stereo.replacen("\"k3\": 0.0", "\"k3\": 0.001", 1);
    assert_eq!(
        err(&with_k3, "kalibr"),
        "format: left camera: Kalibr's radtan model has no k3: calibrate with k3 fixed at 0 to export to Kalibr"
    );
    let no_left = stereo.replacen("\"image_size_px\": [640, 480],", "", 1);
    assert!(
        err(&no_left, "opencv-yaml").starts_with("left.image_size_px: "),
        "{}",
        err(&no_left, "opencv-yaml")
    );
    let options = robocal::io::export::ExportOptions {
        frames: vec![("left".into(), "cam 0".into())],
        ..Default::default()
    };
    assert_eq!(
        robocal::io::export::export_with(&stereo, "ros", &options).unwrap_err().to_string(),
        "frame_names: the left camera name 'cam 0' is not a ROS name: use letters, digits, _ and / (starting with a letter, _ or /), e.g. --frame left=cam0"
    );
}
