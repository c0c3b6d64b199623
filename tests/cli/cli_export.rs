//! `robocal export` through the real binary: same bytes as the library's
//! golden files, errors on stderr with the exit code of their kind.

use crate::support;
use support::robocal;

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/exports");

#[test]
fn export_writes_the_golden_bytes_to_stdout_and_files() {
    let camera = format!("{FIXTURES}/camera.json");
    let (code, out, err) = robocal(&["export", &camera, "--format", "ros-yaml"]);
    assert_eq!((code, err.as_str()), (0, ""));
    // camera.json is itself an export (name cam0, rms 0.123): exporting it again gives the golden ROS file.
    assert_eq!(
        out,
        std::fs::read_to_string(format!("{FIXTURES}/camera.ros.yaml")).unwrap()
    );
    let dir = std::env::temp_dir().join(format!("robocal-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let target = dir.join("k.txt");
    let (code, out, _) = robocal(&[
        "export",
        &camera,
        "--format=text",
        "-o",
        target.to_str().unwrap(),
    ]);
    assert_eq!((code, out.as_str()), (0, ""));
    // The matrix, then its image size and the lens model it leaves out as
    // comments (the golden file).
    let written = std::fs::read_to_string(&target).unwrap();
    assert!(written.starts_with(
        "1000.5 0.0 640.25\n0.0 1001.75 479.5\n0.0 0.0 1.0\n# image_size_px: 1280 960\n"
    ));
    assert_eq!(
        written,
        std::fs::read_to_string(format!("{FIXTURES}/camera.K.txt")).unwrap()
    );
}

#[test]
fn export_errors_say_what_to_fix() {
    let camera = format!("{FIXTURES}/camera.json");
    let (code, _, err) = robocal(&["export", &camera]);
    assert_eq!(
        (code, err.as_str()),
        (
            2,
            "robocal: export: --format is required (see 'robocal export --help')\n"
        )
    );
    let (code, _, err) = robocal(&["export", "/nonexistent/r.json", "--format", "json"]);
    assert_eq!(code, 1);
    assert!(
        err.starts_with("robocal: cannot read '/nonexistent/r.json': "),
        "{err}"
    );
    let (code, _, err) = robocal(&["export", &camera, "--format", "urdf"]);
    assert_eq!(code, 1);
    assert_eq!(err, "robocal: report: format 'urdf' needs a transform, and this report has none of gripper_from_camera, base_from_camera, right_from_left, base_from_target\n");
    let (code, out, _) = robocal(&["export", "--help"]);
    assert_eq!(code, 0);
    assert!(
        out.contains("Examples:\n  robocal export camera.json --format opencv-yaml -o camera.yaml")
    );
    let (code, _, err) = robocal(&["frobnicate"]);
    assert_eq!(
        (code, err.as_str()),
        (
            2,
            "error: unrecognized subcommand 'frobnicate'\n\nUsage: robocal [COMMAND]\n\nFor more information, try '--help'.\n"
        )
    );
}

#[test]
fn export_names_frames_with_the_frame_flag() {
    let dir = std::env::temp_dir().join(format!("robocal-export-frames-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let report = dir.join("handeye.json");
    std::fs::write(
        &report,
        r#"{"gripper_from_camera": {"translation_m": [0.03, -0.02, 0.1], "quaternion_xyzw": [0.0, 0.0, 0.0, 1.0]}, "frame_names": {"camera": "cam"}}"#,
    )
    .unwrap();
    let path = report.to_str().unwrap();
    let (code, out, err) = robocal(&[
        "export",
        path,
        "--format",
        "ros1-static-tf",
        "--frame",
        "gripper=tool0",
        "--frame",
        "camera=camera_optical_frame",
    ]);
    assert_eq!((code, err.as_str()), (0, ""));
    assert!(
        out.ends_with("rosrun tf2_ros static_transform_publisher 0.03 -0.02 0.1 0.0 0.0 0.0 1.0 tool0 camera_optical_frame\n"),
        "{out}"
    );
    // Without the flag, the report's frame_names.
    let (_, out, _) = robocal(&["export", path, "--format", "ros2-static-tf"]);
    assert!(
        out.ends_with("--frame-id gripper --child-frame-id cam\n"),
        "{out}"
    );
    let (code, _, err) = robocal(&["export", path, "--format", "urdf", "--frame", "tool0"]);
    assert_eq!(
        (code, err.as_str()),
        (2, "robocal: export: --frame takes ROLE=NAME (e.g. gripper=tool0), got 'tool0' (see 'robocal export --help')\n")
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_rig_report_exports_to_a_folder_of_files_or_to_stdout() {
    let rig = format!("{FIXTURES}/rig.json");
    let dir = std::env::temp_dir().join(format!("robocal-export-rig-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let (code, out, err) = robocal(&[
        "export",
        &rig,
        "--format",
        "ros",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert_eq!((code, out.as_str()), (0, ""), "{err}");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "left.yaml",
            "middle.yaml",
            "rig_tf.launch",
            "rig_tf.launch.py",
            "right.yaml"
        ]
    );
    assert_eq!(err.lines().count(), 5, "{err}");
    for name in &names {
        let golden = std::fs::read_to_string(format!("{FIXTURES}/rig.ros.{name}")).unwrap();
        let written = std::fs::read_to_string(dir.join(name)).unwrap();
        assert_eq!(
            written.replace(robocal::VERSION, "VERSION"),
            golden,
            "{name}"
        );
    }
    // Without -o: every file after a '# ==> NAME <==' line.
    let (code, out, _) = robocal(&["export", &rig, "--format", "ros"]);
    assert_eq!(code, 0);
    assert_eq!(out.matches("# ==> ").count(), 5);
    assert!(
        out.starts_with("# ==> left.yaml <==\nimage_width: 1280\n"),
        "{out}"
    );
    // One-file formats still write one file.
    let (code, out, _) = robocal(&["export", &rig, "--format", "kalibr"]);
    assert_eq!(code, 0);
    assert_eq!(
        out.replace(robocal::VERSION, "VERSION"),
        std::fs::read_to_string(format!("{FIXTURES}/rig.kalibr.camchain.yaml")).unwrap()
    );
    let (code, _, err) = robocal(&["export", &rig, "--format", "matrix4"]);
    assert_eq!(
        (code, err.as_str()),
        (1, "robocal: format: format 'matrix4' is not a rig format: a rig report exports as kalibr, opencv-yaml, ros, urdf, mrcal (or report)\n")
    );
    let _ = std::fs::remove_dir_all(&dir);
}
