//! Round trips of the camera and transform exports (golden files live in
//! tests/calib/exports.rs, natively, with the UPDATE_FIXTURES switch).

use super::export_camera::{export_camera, float, CameraExportInfo, CameraFormat};
use super::export_transform::{export_transform, FrameNames, TransformFormat};
use super::import_camera::{import_camera, CameraSource};
use crate::camera::{Camera, Distortion};
use crate::geometry::{rotation_from_euler, EulerKind, EulerOrder, Pose};
use nalgebra::{Translation3, Vector3};
use wasm_bindgen_test::wasm_bindgen_test;

fn brown() -> Camera {
    Camera {
        fx: 812.3456789,
        fy: 815.25,
        cx: 319.75,
        cy: 241.125,
        skew: 0.0,
        width: 640,
        height: 480,
        distortion: Distortion::Brown {
            k1: -0.2286,
            k2: 0.1904,
            k3: -0.0123,
            p1: 0.00123,
            p2: -0.000456,
        },
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn floats_read_back_exactly_and_never_use_exponents() {
    for x in [0.1, 1.0, -2.5e-9, 123456.789, 1e-20, f64::MAX / 3.0] {
        let s = float(x);
        assert!(!s.contains('e'), "{s}");
        assert_eq!(s.parse::<f64>().unwrap(), x);
    }
    assert_eq!(float(3.0), "3.0");
}

#[wasm_bindgen_test(unsupported = test)]
fn cameras_round_trip_through_every_readable_format() {
    let kb = Camera {
        distortion: Distortion::KannalaBrandt {
            k1: 0.01,
            k2: -0.002,
            k3: 0.0003,
            k4: -0.00004,
        },
        ..brown()
    };
    let rational = Camera {
        distortion: Distortion::Rational {
            k1: 0.1,
            k2: 0.01,
            k3: 0.001,
            k4: 0.2,
            k5: 0.02,
            k6: 0.002,
            p1: 0.001,
            p2: -0.001,
            s1: 0.0001,
            s2: 0.0002,
            s3: -0.0001,
            s4: 0.00005,
        },
        skew: 0.25,
        ..brown()
    };
    let info = CameraExportInfo::default();
    for camera in [brown(), kb, rational] {
        for (format, source) in [
            (CameraFormat::Json, CameraSource::Json),
            (CameraFormat::OpencvYaml, CameraSource::OpencvYaml),
            (CameraFormat::OpencvXml, CameraSource::OpencvXml),
            (CameraFormat::RosYaml, CameraSource::RosYaml),
            (CameraFormat::Kalibr, CameraSource::Kalibr),
            (CameraFormat::Mrcal, CameraSource::Mrcal),
        ] {
            // Kalibr holds no skew, no k3 and no rational model; mrcal no
            // skew and no fisheye: their round trip is of what they hold.
            let camera = match format {
                CameraFormat::Kalibr | CameraFormat::Mrcal => Camera {
                    skew: 0.0,
                    distortion: match (&camera.distortion, format) {
                        (Distortion::Brown { k1, k2, p1, p2, .. }, CameraFormat::Kalibr) => {
                            Distortion::Brown {
                                k1: *k1,
                                k2: *k2,
                                p1: *p1,
                                p2: *p2,
                                k3: 0.0,
                            }
                        }
                        (Distortion::Rational { .. }, CameraFormat::Kalibr)
                        | (Distortion::KannalaBrandt { .. }, CameraFormat::Mrcal) => continue,
                        (d, _) => d.clone(),
                    },
                    ..camera.clone()
                },
                _ => camera.clone(),
            };
            let text = export_camera(&camera, &info, format).unwrap();
            let (back, seen) = import_camera(&text).unwrap();
            assert_eq!(seen, source, "{format:?}");
            assert_eq!(
                back,
                camera,
                "{format:?} of {}:\n{text}",
                camera.distortion.model_name()
            );
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn matlab_is_one_based_and_halcon_is_metric() {
    let c = brown();
    let m = export_camera(&c, &CameraExportInfo::default(), CameraFormat::Matlab).unwrap();
    assert!(m.contains("principalPoint = [320.75, 242.125];"), "{m}");
    assert!(m.contains("imageSize = [480, 640];"), "{m}");
    let h = export_camera(&c, &CameraExportInfo::default(), CameraFormat::Halcon).unwrap();
    // Focus = fx * 5 µm; HALCON's K1 undistorts: about -k1 / Focus^2.
    let focus = 812.3456789 * 5e-6;
    let start = format!("['area_scan_polynomial', {}, ", float(focus));
    let at = h.find(&start).unwrap_or_else(|| panic!("{h}")) + start.len();
    let big_k1: f64 = h[at..].split(',').next().unwrap().trim().parse().unwrap();
    let first_order = 0.2286 / (focus * focus);
    assert!(
        (big_k1 - first_order).abs() < 0.3 * first_order,
        "K1 {big_k1} vs {first_order}\n{h}"
    );
    assert!(
        h.contains("maps distorted to undistorted image-plane points"),
        "{h}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn formats_without_the_model_say_why() {
    let c = Camera {
        distortion: Distortion::Division { kappa: -0.1 },
        ..brown()
    };
    let err =
        export_camera(&c, &CameraExportInfo::default(), CameraFormat::OpencvYaml).unwrap_err();
    assert_eq!(
        err.to_string(),
        "format: the division lens model cannot be written for OpenCV (use robocal JSON, Halcon for division, Kalibr for EUCM)"
    );
    let err =
        export_camera(&brown(), &CameraExportInfo::default(), CameraFormat::Kalibr).unwrap_err();
    assert_eq!(
        err.to_string(),
        "format: Kalibr's radtan model has no k3: calibrate with k3 fixed at 0 to export to Kalibr"
    );
    assert_eq!(
        CameraFormat::from_name("yml").unwrap_err().to_string(),
        "format: unknown camera format 'yml' (known: json, opencv-yaml, opencv-xml, ros-yaml, kalibr, mrcal, halcon, matlab, text)"
    );
}

fn pose() -> Pose {
    let r = rotation_from_euler(EulerOrder::ZYX, EulerKind::Intrinsic, [0.3, -0.2, 1.1]);
    Pose::from_parts(Translation3::from(Vector3::new(0.1, -0.05, 0.3)), r)
}

fn numbers(line: &str) -> Vec<f64> {
    line.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter_map(|s| s.parse().ok())
        .collect()
}

#[wasm_bindgen_test(unsupported = test)]
fn transforms_read_back_to_the_same_pose() {
    let names = FrameNames::from_transform_name("gripper_from_camera").unwrap();
    let p = pose();
    // Every Euler order and kind, in radians: the printed angles rebuild the rotation.
    for order in EulerOrder::ALL {
        for kind in [EulerKind::Intrinsic, EulerKind::Extrinsic] {
            let text = export_transform(
                &p,
                &names,
                TransformFormat::Euler {
                    order,
                    kind,
                    degrees: false,
                },
            );
            let v = numbers(text.lines().nth(1).unwrap());
            let r = rotation_from_euler(order, kind, [v[3], v[4], v[5]]);
            assert!(r.angle_to(&p.rotation) < 1e-12, "{order:?} {kind:?}");
        }
    }
    // KUKA ABC (intrinsic ZYX, deg) and FANUC WPR (extrinsic XYZ, deg), mm.
    let k = export_transform(&p, &names, TransformFormat::KukaFrame);
    let v = numbers(k.lines().nth(1).unwrap());
    assert_eq!(&v[..3], &[100.0, -50.0, 300.0]);
    let r = rotation_from_euler(
        EulerOrder::ZYX,
        EulerKind::Intrinsic,
        [v[3], v[4], v[5]].map(f64::to_radians),
    );
    // Each angle is rounded to 1e-4 deg (8.7e-7 rad): three of them stay under 2.7e-6 rad.
    assert!(
        r.angle_to(&p.rotation) < 2.7e-6,
        "KUKA angles rounded to 1e-4 deg"
    );
    let f = export_transform(&p, &names, TransformFormat::FanucFrame);
    let v = numbers(f.lines().nth(1).unwrap());
    let r = rotation_from_euler(
        EulerOrder::XYZ,
        EulerKind::Extrinsic,
        [v[3], v[4], v[5]].map(f64::to_radians),
    );
    // 1e-3 deg (8.7e-6 rad) per angle: under 2.7e-5 rad.
    assert!(
        r.angle_to(&p.rotation) < 2.7e-5,
        "FANUC angles rounded to 1e-3 deg"
    );
    let ros = export_transform(&p, &names, TransformFormat::Ros2StaticTransform);
    assert!(
        ros.ends_with("--frame-id gripper --child-frame-id camera\n"),
        "{ros}"
    );
    assert_eq!(
        TransformFormat::from_name("euler-sideways-xyz-deg").unwrap_err().to_string(),
        "format: unknown transform format 'euler-sideways-xyz-deg' (known: matrix4, xyz-quat-xyzw, xyz-quat-wxyz, urdf, urdf-robot, ros2-static-tf, ros1-static-tf, ros1-launch, ros2-launch, ur, kuka, abb-tooldata, abb-wobjdata, fanuc, euler-<intrinsic|extrinsic>-<order>-<deg|rad>)"
    );
}

/// A hand-eye report with frame names, as the page writes it.
fn named_report(frame_names: &str) -> String {
    format!(
        r#"{{"gripper_from_camera": {{"translation_m": [0.03, -0.02, 0.1], "quaternion_xyzw": [0.0, 0.0, 0.6, 0.8]}}{frame_names}}}"#
    )
}

#[wasm_bindgen_test(unsupported = test)]
fn ros_exports_put_the_arguments_in_each_versions_order() {
    use super::export::export;
    let report =
        named_report(r#", "frame_names": {"gripper": "tool0", "camera": "camera_optical_frame"}"#);
    // quaternion (0, 0, 0.6, 0.8): 73.74 deg about z; ROS 1 positional
    // x y z qx qy qz qw frame_id child_frame_id, ROS 2 named.
    assert_eq!(
        export(&report, "ros1-static-tf", None).unwrap(),
        "# gripper_from_camera (ROS 1): x y z (m) qx qy qz qw parent child\nrosrun tf2_ros static_transform_publisher 0.03 -0.02 0.1 0.0 0.0 0.6 0.8 tool0 camera_optical_frame\n"
    );
    assert_eq!(
        export(&report, "ros2-static-tf", None).unwrap(),
        "ros2 run tf2_ros static_transform_publisher --x 0.03 --y -0.02 --z 0.1 --qx 0.0 --qy 0.0 --qz 0.6 --qw 0.8 --frame-id tool0 --child-frame-id camera_optical_frame\n"
    );
    assert_eq!(
        export(&report, "ros1-launch", None).unwrap(),
        "<!-- gripper_from_camera: x y z (m) qx qy qz qw parent child (ROS 1 tf2_ros) -->\n<launch>\n  <node pkg=\"tf2_ros\" type=\"static_transform_publisher\" name=\"tool0_to_camera_optical_frame\" args=\"0.03 -0.02 0.1 0.0 0.0 0.6 0.8 tool0 camera_optical_frame\"/>\n</launch>\n"
    );
    let py = export(&report, "ros2-launch", None).unwrap();
    assert!(py.contains("            arguments=['--x', '0.03', '--y', '-0.02', '--z', '0.1', '--qx', '0.0', '--qy', '0.0', '--qz', '0.6', '--qw', '0.8', '--frame-id', 'tool0', '--child-frame-id', 'camera_optical_frame'],\n"), "{py}");
    assert!(
        py.contains("executable='static_transform_publisher'"),
        "{py}"
    );
    let urdf = export(&report, "urdf-robot", None).unwrap();
    assert!(urdf.starts_with("<?xml version=\"1.0\"?>\n<robot name=\"robocal_calibration\">\n  <link name=\"tool0\"/>\n  <link name=\"camera_optical_frame\"/>\n  <joint name=\"tool0_to_camera_optical_frame\" type=\"fixed\">\n    <parent link=\"tool0\"/>\n"), "{urdf}");
    assert!(urdf.ends_with("  </joint>\n</robot>\n"), "{urdf}");
}

#[wasm_bindgen_test(unsupported = test)]
fn frame_names_come_from_the_options_then_the_report_then_the_key() {
    use super::export::{export, export_with, ExportOptions};
    // No names: the roles of the key, as before.
    let plain = export(&named_report(""), "urdf", None).unwrap();
    assert!(plain.starts_with("<joint name=\"gripper_to_camera\" type=\"fixed\">\n  <parent link=\"gripper\"/>\n  <child link=\"camera\"/>"), "{plain}");
    // The options win over the report; a role named by neither keeps its name.
    let report = named_report(r#", "frame_names": {"gripper": "tool0", "camera": "cam"}"#);
    let options = ExportOptions {
        transform: None,
        frames: vec![("camera".into(), "camera_optical_frame".into())],
    };
    let out = export_with(&report, "ros2-static-tf", &options).unwrap();
    assert!(
        out.ends_with("--frame-id tool0 --child-frame-id camera_optical_frame\n"),
        "{out}"
    );
    let only_base = export(
        &named_report(r#", "frame_names": {"base": "base_link"}"#),
        "ros2-static-tf",
        None,
    )
    .unwrap();
    assert!(
        only_base.ends_with("--frame-id gripper --child-frame-id camera\n"),
        "{only_base}"
    );
    // Names that would break the XML, shell or Python text are refused.
    assert_eq!(
        export(&named_report(r#", "frame_names": {"gripper": "tool 0"}"#), "urdf", None).unwrap_err().to_string(),
        "frame_names: the gripper frame name 'tool 0' is not a ROS frame name: use letters, digits, _ and / (starting with a letter, _ or /), e.g. tool0"
    );
    assert_eq!(
        export(
            &named_report(r#", "frame_names": {"camera": 3}"#),
            "urdf",
            None
        )
        .unwrap_err()
        .to_string(),
        "frame_names: 'camera' should name a frame as a string, got 3"
    );
}

/// The top-level keys of a block YAML text (lines that start a mapping key
/// at column 0).
fn top_level_keys(yaml: &str) -> Vec<&str> {
    yaml.lines()
        .filter(|l| !l.starts_with([' ', '#', '%', '-']) && !l.is_empty())
        .filter_map(|l| l.split_once(':').map(|(k, _)| k))
        .collect()
}

#[wasm_bindgen_test(unsupported = test)]
fn camera_names_are_quoted_for_yaml_or_refused_when_they_break_lines() {
    use super::export::export;
    let camera = export_camera(&brown(), &CameraExportInfo::default(), CameraFormat::Json).unwrap();
    let named = |name: &str| {
        let mut v: serde_json::Value = serde_json::from_str(&camera).unwrap();
        v["name"] = name.into();
        v.to_string()
    };
    let ros = export(&named("cam: x # y"), "ros-yaml", None).unwrap();
    assert!(ros.contains("\ncamera_name: \"cam: x # y\"\n"), "{ros}");
    assert_eq!(
        top_level_keys(&ros),
        [
            "image_width",
            "image_height",
            "camera_name",
            "camera_matrix",
            "distortion_model",
            "distortion_coefficients",
            "rectification_matrix",
            "projection_matrix"
        ]
    );
    let plain = export(&named("left_cam"), "ros-yaml", None).unwrap();
    assert!(plain.contains("\ncamera_name: left_cam\n"), "{plain}");
    let err = export(&named("cam\ncamera_matrix: {rows: 3}"), "ros-yaml", None).unwrap_err();
    assert_eq!(
        err.to_string(),
        r"name: the camera name 'cam\ncamera_matrix: {rows: 3}' holds a control character (\n): a name is one line of printable text"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn transform_names_that_are_not_frame_names_are_refused() {
    use super::export::export;
    let report = r#"{"a_from_b\"/><node name=\"x": {"translation_m": [0, 0, 0], "quaternion_xyzw": [0, 0, 0, 1]}}"#;
    for format in ["ros1-launch", "urdf", "matrix4"] {
        let err = export(report, format, Some("a_from_b\"/><node name=\"x")).unwrap_err();
        assert!(
            err.to_string()
                .ends_with("as in gripper_from_camera; 'b\"/><node name=\"x' is not one"),
            "{format}: {err}"
        );
    }
}

/// The lens-model table's formats per model ([`crate::camera::LENS_MODELS`],
/// `export_formats`: what the model advice names) are what the writers do:
/// every camera format but `text` (no lens model) is listed for a model
/// exactly when it writes the example camera of that model (zero skew, and
/// the coefficient a condition names held at 0); every model of the table
/// has its example.
#[test]
#[wasm_bindgen_test]
fn the_lens_model_table_names_the_formats_the_writers_accept() {
    use crate::camera::{LensModel, LENS_MODELS};
    let examples = Camera::examples();
    for row in &LENS_MODELS {
        assert!(
            examples
                .iter()
                .any(|c| c.distortion.model_name() == row.name),
            "{} has no example camera",
            row.name
        );
    }
    for example in examples {
        let mut camera = Camera {
            skew: 0.0,
            ..example
        };
        let model = camera.distortion.model_name();
        let listed = LensModel::named(model).map_or(&[][..], |m| m.export_formats);
        assert_eq!(
            listed,
            crate::calib::model_advice::export_formats(model),
            "the model advice names the table's formats"
        );
        assert!(!listed.is_empty(), "{model} is not in the table");
        for format in CameraFormat::ALL {
            if format == CameraFormat::Text {
                continue;
            }
            let entry = listed
                .iter()
                .find(|f| f.split(" (").next() == Some(format.name()));
            if let Some(condition) = entry.and_then(|e| e.strip_suffix(" held at 0)")) {
                let coefficient = condition.rsplit(' ').next().unwrap_or_default();
                let names = camera.distortion.coefficient_names();
                let mut values = camera.distortion.coefficients();
                let k = names.iter().position(|n| *n == coefficient).unwrap();
                values[k] = 0.0;
                camera.distortion = camera.distortion.with_coefficients(&values).unwrap();
            }
            super::import_camera_tests::milder_for_halcon(entry.copied(), &mut camera);
            let written = export_camera(&camera, &CameraExportInfo::default(), format).is_ok();
            assert_eq!(
                written,
                entry.is_some(),
                "{model} to {}: listed {entry:?}",
                format.name()
            );
        }
    }
}

/// The tilted (Scheimpflug) model: OpenCV's 14 coefficients in YAML and
/// XML (`tau_x tau_y` last), read back to the same camera; the formats
/// without a tilted sensor name those with one.
#[wasm_bindgen_test(unsupported = test)]
fn the_tilted_model_goes_to_opencv_with_14_coefficients_and_back() {
    let camera = Camera {
        skew: 0.0,
        ..Camera::example_tilted()
    };
    let info = CameraExportInfo::default();
    for (format, source) in [
        (CameraFormat::Json, CameraSource::Json),
        (CameraFormat::OpencvYaml, CameraSource::OpencvYaml),
        (CameraFormat::OpencvXml, CameraSource::OpencvXml),
    ] {
        let text = export_camera(&camera, &info, format).unwrap();
        let (back, seen) = import_camera(&text).unwrap();
        assert_eq!(seen, source, "{format:?}");
        assert_eq!(back, camera, "{format:?}:\n{text}");
    }
    let yaml = export_camera(&camera, &info, CameraFormat::OpencvYaml).unwrap();
    assert!(
        yaml.contains(
            "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 14\n   dt: d\n   \
             data: [ -0.21, 0.07, 0.0008, -0.0005, -0.008, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, \
             0.052, -0.035 ]\n"
        ),
        "{yaml}"
    );
    for format in [
        CameraFormat::RosYaml,
        CameraFormat::Kalibr,
        CameraFormat::Mrcal,
        CameraFormat::Halcon,
        CameraFormat::Matlab,
    ] {
        let err = export_camera(&camera, &info, format)
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("format: the tilted lens model cannot be written for ")
                && err.ends_with(": export it as json, opencv-yaml, opencv-xml"),
            "{format:?}: {err}"
        );
    }
}
