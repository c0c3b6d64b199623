//! Round trips of the rig exports: a rig built by hand from known cameras
//! and poses is written in every rig format, the numbers are read back from
//! the text and compared with the truth. The reading here is by line and
//! key (no YAML crate); benches/check_exports.py reads the same files with
//! cv2.FileStorage and PyYAML. Tolerance: 1e-12 (the writers print the
//! shortest round-trip decimal; only the pose conversions — matrix, quaternion,
//! rotation vector, Euler angles — add rounding).

use super::export::{export_files, export_with, ExportOptions};
use super::export_rig::{export_rig, RigFormat};
use super::import_camera::{import_camera, CameraSource};
use crate::calib::multi::rig_report::{CoObservation, RigCalibration, RigCamera, RigFrame};
use crate::calib::{CalibrationOptions, CameraCalibration, Correlation, ProjectionUncertainty};
use crate::camera::{Camera, Distortion};
use crate::geometry::{
    pose_from_params, rotation_from_euler, rotation_from_rotvec, EulerKind, EulerOrder, Pose,
    PoseJson,
};
use crate::optim::Termination;
use nalgebra::{Matrix3, Quaternion, Translation3, UnitQuaternion, Vector3};
use std::collections::BTreeMap;
use wasm_bindgen_test::wasm_bindgen_test;

const TOL: f64 = 1e-12;

fn calibration_of(camera: Camera, rms_px: f64) -> CameraCalibration {
    let mut distortion = BTreeMap::new();
    for (n, v) in camera
        .distortion
        .coefficient_names()
        .iter()
        .zip(camera.distortion.coefficients())
    {
        distortion.insert(n.to_string(), v);
    }
    CameraCalibration {
        kind: crate::report_kind::ReportKind::Camera,
        robocal_version: crate::VERSION.into(),
        image_size_px: [camera.width, camera.height],
        model: camera.distortion.model_name().into(),
        camera_matrix: [
            [camera.fx, camera.skew, camera.cx],
            [0.0, camera.fy, camera.cy],
            [0.0, 0.0, 1.0],
        ],
        camera,
        distortion,
        rms_px,
        std: BTreeMap::new(),
        views: Vec::new(),
        correlation: Correlation {
            names: Vec::new(),
            matrix: Vec::new(),
        },
        board_warp: None,
        spline_support: None,
        cross_validation: None,
        projection_uncertainty: ProjectionUncertainty {
            reference_depth_m: 1.0,
            x_px: Vec::new(),
            y_px: Vec::new(),
            std_px: Vec::new(),
            max_std_px: 0.0,
        },
        distortion_field: Default::default(),
        warnings: Vec::new(),
        iterations: 0,
        termination: Termination::CostTolerance,
        n_points: 0,
        options: CalibrationOptions::default(),
        rejected: None,
        severity: Default::default(),
        start: None,
        starts: Vec::new(),
    }
}

fn camera(fx: f64, distortion: Distortion) -> Camera {
    Camera {
        fx,
        fy: fx + 1.25,
        cx: 639.5,
        cy: 479.75,
        skew: 0.0,
        width: 1280,
        height: 960,
        distortion,
    }
}

/// Three cameras in a row looking outwards: left (the rig frame), middle
/// (about 30 degrees about y, 12 cm right) and right (-65 degrees, 25 cm right,
/// a little up); left and right never saw the board together.
pub(super) fn example_rig() -> (RigCalibration, Vec<Pose>) {
    let cameras = [
        (
            "left",
            camera(
                1000.5,
                Distortion::Brown {
                    k1: -0.125,
                    k2: 0.0625,
                    k3: 0.0,
                    p1: 0.001,
                    p2: -0.0005,
                },
            ),
            pose_from_params(&[0.0; 6]),
        ),
        (
            "middle",
            camera(
                812.25,
                Distortion::KannalaBrandt {
                    k1: 0.01,
                    k2: -0.002,
                    k3: 0.0003,
                    k4: -0.00004,
                },
            ),
            pose_from_params(&[0.01, 0.52, -0.02, -0.12, 0.003, 0.01]),
        ),
        (
            "right",
            camera(1101.0, Distortion::None),
            pose_from_params(&[-0.03, -1.1345, 0.05, -0.25, -0.04, 0.06]),
        ),
    ];
    let truth: Vec<Pose> = cameras.iter().map(|c| c.2).collect();
    let frames_seen = [vec![0, 1, 2], vec![1, 2, 3, 4], vec![3, 4]];
    let names: Vec<String> = cameras.iter().map(|c| c.0.to_string()).collect();
    let rig = RigCalibration {
        kind: crate::report_kind::ReportKind::Rig,
        robocal_version: crate::VERSION.into(),
        rig_frame: "left".into(),
        target: "chessboard:9x6:30mm".into(),
        grouping: "number".into(),
        cameras: cameras
            .iter()
            .zip(&frames_seen)
            .enumerate()
            .map(|(k, ((name, c, pose), seen))| RigCamera {
                name: name.to_string(),
                calibration: calibration_of(c.clone(), 0.25 + k as f64 * 0.125),
                intrinsics_held: false,
                camera_from_rig: PoseJson::from(pose),
                camera_from_rig_std: None,
                rms_px: 0.25 + k as f64 * 0.125,
                frames_seen: seen.clone(),
            })
            .collect(),
        frames: (0..5)
            .map(|f| RigFrame {
                key: format!("{:02}", f + 1),
                rig_from_target: Some(PoseJson::from(&pose_from_params(&[
                    0.1, 0.2, 0.0, 0.0, 0.0, 0.8,
                ]))),
                cameras: names
                    .iter()
                    .zip(&frames_seen)
                    .filter(|(_, s)| s.contains(&f))
                    .map(|(n, _)| n.clone())
                    .collect(),
                rms_px: 0.3,
            })
            .collect(),
        co_observation: CoObservation {
            cameras: names,
            frames: vec![vec![3, 2, 0], vec![2, 4, 2], vec![0, 2, 2]],
            spanning_tree: vec![[0, 1], [1, 2]],
        },
        rms_px: 0.33,
        iterations: 7,
        termination: Termination::CostTolerance,
        warnings: Vec::new(),
        covariance: None,
    };
    (rig, truth)
}

/// The numbers of a text (lists, matrices, key: value), in order.
fn numbers(text: &str) -> Vec<f64> {
    text.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter_map(|s| s.parse().ok())
        .collect()
}

/// The text after `key` up to the next line that starts with no space
/// (the block of that key).
fn block<'a>(text: &'a str, key: &str) -> &'a str {
    let start = text
        .find(key)
        .unwrap_or_else(|| panic!("no {key} in\n{text}"))
        + key.len();
    let rest = &text[start..];
    let end = rest
        .match_indices('\n')
        .map(|(i, _)| i + 1)
        .find(|i| {
            rest[*i..]
                .chars()
                .next()
                .is_some_and(|c| !c.is_whitespace() && c != '-')
        })
        .unwrap_or(rest.len());
    &rest[..end]
}

fn assert_pose_eq(a: &Pose, b: &Pose, what: &str) {
    let d = (a.to_homogeneous() - b.to_homogeneous()).abs().max();
    assert!(
        d < TOL,
        "{what}: matrices differ by {d:e} (unitless/metres)"
    );
}

fn pose_from_r_t(r: &[f64], t: &[f64]) -> Pose {
    let m = Matrix3::from_row_slice(r);
    let rotation = UnitQuaternion::from_matrix(&m);
    Pose::from_parts(Translation3::new(t[0], t[1], t[2]), rotation)
}

#[wasm_bindgen_test(unsupported = test)]
fn kalibr_chain_composes_back_to_every_camera_from_rig() {
    let (rig, truth) = example_rig();
    let files = export_rig(&rig, RigFormat::Kalibr, &[]).unwrap();
    let text = &files[0].text;
    assert_eq!(files[0].name, "camchain.yaml");
    let mut camera_from_rig = pose_from_params(&[0.0; 6]);
    for (n, want) in truth.iter().enumerate() {
        let cam = block(text, &format!("cam{n}:\n"));
        if n > 0 {
            let rows: String = block(cam, "T_cn_cnm1:\n").lines().take(4).collect();
            let m = numbers(&rows);
            assert_eq!(&m[12..], &[0.0, 0.0, 0.0, 1.0], "{cam}");
            let cn_from_cnm1 = pose_from_r_t(
                &[m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]],
                &[m[3], m[7], m[11]],
            );
            camera_from_rig = cn_from_cnm1 * camera_from_rig;
        } else {
            assert!(!cam.contains("T_cn_cnm1"), "{cam}");
        }
        assert_pose_eq(&camera_from_rig, want, &format!("cam{n} from rig"));
        let c = &rig.cameras[n].calibration.camera;
        let intrinsics = numbers(cam.lines().find(|l| l.contains("intrinsics")).unwrap());
        assert_eq!(intrinsics, vec![c.fx, c.fy, c.cx, c.cy], "{cam}");
    }
    assert!(text.contains("cam0:\n  cam_overlaps: [1]\n  camera_model: pinhole\n"));
    assert!(text.contains("  cam_overlaps: [0, 2]\n"), "{text}");
    assert!(text.contains(
        "  distortion_model: equidistant\n  distortion_coeffs: [0.01, -0.002, 0.0003, -0.00004]\n"
    ));
    assert!(text.contains("  distortion_model: none\n  distortion_coeffs: []\n  resolution: [1280, 960]\n  rostopic: /right/image_raw\n"));
}

#[wasm_bindgen_test(unsupported = test)]
fn kalibr_names_the_camera_and_the_models_it_takes() {
    let (mut rig, _) = example_rig();
    rig.cameras[1].calibration.camera.distortion = Distortion::Division { kappa: -0.1 };
    let err = export_rig(&rig, RigFormat::Kalibr, &[]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "format: camera 'middle': the division lens model cannot be written for Kalibr (it takes none, brown with k3 = 0 (radtan), radial_k1_k2_k5 with k5 = 0 (radtan), kannala_brandt (equidistant), eucm)"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn opencv_r_t_map_rig_into_each_camera() {
    let (rig, truth) = example_rig();
    let text = &export_rig(&rig, RigFormat::OpencvYaml, &[]).unwrap()[0].text;
    assert!(text.starts_with("%YAML:1.0\n---\n"));
    assert!(text.contains("camera_count: 3\n"));
    for (k, want) in truth.iter().enumerate() {
        let data = |key: &str| numbers(block(text, &format!("{key}_{k}: !!opencv-matrix")));
        // rows, cols, then the data.
        let r = data("R");
        let t = data("T");
        assert_eq!((r[0], r[1], t[0], t[1]), (3.0, 3.0, 3.0, 1.0));
        assert_pose_eq(
            &pose_from_r_t(&r[2..], &t[2..]),
            want,
            &format!("R_{k}, T_{k}"),
        );
        let c = &rig.cameras[k].calibration.camera;
        let kmat = data("camera_matrix");
        assert_eq!(kmat[2..], [c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0]);
        let d = data("distortion_coefficients");
        let want_d = match c.distortion {
            Distortion::None => vec![0.0; 5],
            _ => c.distortion.coefficients(),
        };
        let want_d = if matches!(c.distortion, Distortion::Brown { .. }) {
            // OpenCV's order: k1 k2 p1 p2 k3.
            let v = c.distortion.coefficients();
            let names = c.distortion.coefficient_names();
            ["k1", "k2", "p1", "p2", "k3"]
                .iter()
                .map(|n| v[names.iter().position(|m| m == n).unwrap()])
                .collect()
        } else {
            want_d
        };
        assert_eq!(d[2..], want_d[..], "camera {k}");
    }
    assert!(text.contains("name_1: \"middle\"\nmodel_1: \"kannala_brandt\"\n"));
    assert!(text.contains("# camera 1: read with cv2.fisheye\n"));
}

#[wasm_bindgen_test(unsupported = test)]
fn ros_camera_infos_read_back_and_the_launch_files_place_each_camera() {
    let (rig, truth) = example_rig();
    let files = export_rig(&rig, RigFormat::Ros, &[]).unwrap();
    let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "left.yaml",
            "middle.yaml",
            "right.yaml",
            "rig_tf.launch",
            "rig_tf.launch.py"
        ]
    );
    for (k, rc) in rig.cameras.iter().enumerate() {
        let (back, source) = import_camera(&files[k].text).unwrap();
        assert_eq!(source, CameraSource::RosYaml);
        let want = match rc.calibration.camera.distortion {
            // camera_info has no "none": plumb_bob with zeros.
            Distortion::None => Camera {
                distortion: Distortion::Brown {
                    k1: 0.0,
                    k2: 0.0,
                    k3: 0.0,
                    p1: 0.0,
                    p2: 0.0,
                },
                ..rc.calibration.camera.clone()
            },
            _ => rc.calibration.camera.clone(),
        };
        assert_eq!(back, want, "{}", files[k].text);
        assert!(files[k]
            .text
            .contains(&format!("camera_name: {}\n", rc.name)));
    }
    // ROS 1: args="x y z qx qy qz qw rig camera".
    let launch = &files[3].text;
    for (rc, want) in rig.cameras.iter().zip(&truth) {
        let line = launch
            .lines()
            .find(|l| l.ends_with(&format!(" rig {}\"/>", rc.name)))
            .unwrap_or_else(|| panic!("no node for {} in\n{launch}", rc.name));
        let args = line.split("args=\"").nth(1).unwrap();
        let v = numbers(args.split(" rig ").next().unwrap());
        let q = UnitQuaternion::from_quaternion(Quaternion::new(v[6], v[3], v[4], v[5]));
        let rig_from_camera = Pose::from_parts(Translation3::new(v[0], v[1], v[2]), q);
        assert_pose_eq(
            &rig_from_camera,
            &want.inverse(),
            &format!("rig_from_{}", rc.name),
        );
    }
    let py = &files[4].text;
    assert_eq!(
        py.matches("executable='static_transform_publisher'")
            .count(),
        3
    );
    assert!(py.contains("'--frame-id', 'rig', '--child-frame-id', 'right'"));
}

#[wasm_bindgen_test(unsupported = test)]
fn urdf_joints_place_each_camera_in_the_rig() {
    let (rig, truth) = example_rig();
    let frames = [("rig".to_string(), "camera_rig".to_string())];
    let text = &export_rig(&rig, RigFormat::Urdf, &frames).unwrap()[0].text;
    assert_eq!(text.matches("<link name=").count(), 4);
    for (rc, want) in rig.cameras.iter().zip(&truth) {
        let joint = block(text, &format!("<joint name=\"camera_rig_to_{}\"", rc.name));
        assert!(
            joint.contains(&format!("<child link=\"{}\"/>", rc.name)),
            "{joint}"
        );
        let origin = joint.lines().find(|l| l.contains("<origin")).unwrap();
        let v = numbers(origin);
        let r = rotation_from_euler(EulerOrder::XYZ, EulerKind::Extrinsic, [v[3], v[4], v[5]]);
        let pose = Pose::from_parts(Translation3::new(v[0], v[1], v[2]), r);
        assert_pose_eq(&pose, &want.inverse(), &format!("joint to {}", rc.name));
    }
    let bad = [("right".to_string(), "right camera".to_string())];
    assert_eq!(
        export_rig(&rig, RigFormat::Urdf, &bad).unwrap_err().to_string(),
        "frame_names: the right frame name 'right camera' is not a ROS frame name: use letters, digits, _ and / (starting with a letter, _ or /), or rename it with --frame right=NAME"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn mrcal_extrinsics_are_rt_cam_ref_with_the_rig_as_reference() {
    let (rig, truth) = example_rig();
    let files = export_rig(&rig, RigFormat::Mrcal, &[]);
    // The middle camera is Kannala-Brandt: mrcal has no such model.
    assert_eq!(
        files.unwrap_err().to_string(),
        "format: camera 'middle': the kannala_brandt lens model cannot be written for mrcal (it has no equivalent model)"
    );
    let mut rig = rig;
    rig.cameras[1].calibration.camera.distortion = Distortion::None;
    let files = export_rig(&rig, RigFormat::Mrcal, &[]).unwrap();
    assert_eq!(files.len(), 3);
    for ((file, rc), want) in files.iter().zip(&rig.cameras).zip(&truth) {
        assert_eq!(file.name, format!("{}.cameramodel", rc.name));
        let rt = numbers(block(&file.text, "'extrinsics':"));
        let rt = &rt[..6];
        let r = rotation_from_rotvec(&Vector3::new(rt[0], rt[1], rt[2]));
        let pose = Pose::from_parts(Translation3::new(rt[3], rt[4], rt[5]), r);
        assert_pose_eq(&pose, want, &format!("{} rt_cam_ref", rc.name));
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn the_one_entry_detects_a_rig_report_and_joins_multi_file_formats() {
    let (rig, _) = example_rig();
    let json = serde_json::to_string(&rig).unwrap();
    let options = ExportOptions::default();
    let files = export_files(&json, "ros", &options).unwrap();
    assert_eq!(files.len(), 5);
    let joined = export_with(&json, "ros", &options).unwrap();
    assert!(joined.starts_with("# ==> left.yaml <==\nimage_width: 1280\n"));
    assert!(joined.contains("# ==> rig_tf.launch.py <==\n# rig_from_camera"));
    assert_eq!(
        export_with(&json, "kalibr", &options).unwrap(),
        files_text(&json, "kalibr")
    );
    assert_eq!(
        export_with(&json, "ros-yaml", &options)
            .unwrap_err()
            .to_string(),
        "format: format 'ros-yaml' is not a rig format: a rig report exports as kalibr, opencv-yaml, ros, urdf, mrcal (or report)"
    );
    // A report written before `kind` existed, with `crate_version`: known by
    // its keys, exported the same.
    assert!(
        json.starts_with("{\"kind\":\"rig\",\"robocal_version\":"),
        "{json}"
    );
    let old = json
        .replacen("\"kind\":\"rig\",", "", 1)
        .replacen("\"robocal_version\"", "\"crate_version\"", 1)
        .replace("\"kind\":\"camera\",", "")
        .replace("\"robocal_version\"", "\"crate_version\"");
    assert_eq!(files_text(&old, "kalibr"), files_text(&json, "kalibr"));
    assert_eq!(files_text(&old, "ros"), files_text(&json, "ros"));
    // With `kind`, the kind decides; an unknown one names the known ones.
    let unknown = json.replacen("\"kind\":\"rig\"", "\"kind\":\"mono\"", 1);
    assert_eq!(
        export_with(&unknown, "kalibr", &options)
            .unwrap_err()
            .to_string(),
        "kind: unknown report kind 'mono' (expected one of camera, stereo, rig, handeye, rig_handeye, check, diff, laser_plane, laser_points, laser_sphere)"
    );
    let broken = json.replacen("\"rig_frame\"", "\"rig_frame_x\"", 1);
    assert_eq!(
        export_with(&broken, "urdf", &options)
            .unwrap_err()
            .to_string(),
        "report: not a readable rig report: missing field `rig_frame`"
    );
}

fn files_text(json: &str, format: &str) -> String {
    export_files(json, format, &ExportOptions::default()).unwrap()[0]
        .text
        .clone()
}

/// The example rig as JSON, for the golden files of tests/calib/exports.rs and
/// the CLI tests (regenerate with UPDATE_FIXTURES=1).
#[cfg(not(target_arch = "wasm32"))]
#[test]
fn the_example_rig_fixture_is_current() {
    let (rig, _) = example_rig();
    let json = serde_json::to_string_pretty(&rig)
        .unwrap()
        .replace(crate::VERSION, "VERSION")
        + "\n";
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/exports/rig.json");
    if std::env::var_os("UPDATE_FIXTURES").is_some() {
        std::fs::write(&path, &json).unwrap();
    }
    let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
    assert_eq!(
        on_disk, json,
        "fixtures/exports/rig.json is stale: UPDATE_FIXTURES=1"
    );
}
