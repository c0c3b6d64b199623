//! `robocal stereo` through the real binary on rendered image pairs (two
//! cameras, known right_from_left), the export of its report, bad
//! arguments, and the public OpenCV/Bouguet 9x6 pairs against Bouguet's
//! published stereo result.

use crate::support;
use support::{dataset, robocal, temp_dir};

use nalgebra::{Translation3, Vector3};
use robocal::calib::View;
use robocal::camera::Distortion;
use robocal::geometry::{rotation_from_rotvec, Pose};
use robocal::image::{encode_png, GrayImage};
use robocal::synth::{render, RenderOptions, Scene};
use robocal::target::Target;
use robocal::Camera;
use serde::Deserialize;
use serde_json::Value;
use std::path::Path;

fn camera(fx: f64, cx: f64, k1: f64) -> Camera {
    Camera {
        fx,
        fy: fx,
        cx,
        cy: 239.5,
        skew: 0.0,
        width: 640,
        height: 480,
        distortion: Distortion::Brown {
            k1,
            k2: 0.0,
            k3: 0.0,
            p1: 0.0,
            p2: 0.0,
        },
    }
}

fn inside(c: &Camera, v: &View, pose: &Pose) -> bool {
    v.object_m.iter().all(|p| {
        c.project(&(pose * p)).is_ok_and(|q| {
            q.x > 40.0 && q.y > 40.0 && q.x < c.width as f64 - 41.0 && q.y < c.height as f64 - 41.0
        })
    })
}

/// Writes paired images of a 9x6 board (plus one pair whose right image is
/// blank) and returns (left files, right files, right_from_left).
fn rendered_pairs(dir: &Path) -> (Vec<String>, Vec<String>, Pose) {
    let left = camera(620.0, 319.5, -0.08);
    let right = camera(640.0, 326.0, -0.05);
    let right_from_left = Pose::from_parts(
        Translation3::new(-0.05, 0.001, 0.002),
        rotation_from_rotvec(&Vector3::new(0.005, -0.03, 0.01)),
    );
    let (mut lf, mut rf) = render_pairs(dir, &left, &right, &right_from_left, 7);
    let blank = GrayImage::new(640, 480, vec![120; 640 * 480]).expect("image");
    // Pair 99: a good left image with a blank right one (pairing is by the
    // number in the file names, as in the page).
    let path = dir.join("right99_blank.png");
    std::fs::write(&path, encode_png(&blank).expect("png")).expect("write");
    let left99 = dir.join("left99.png");
    std::fs::copy(&lf[0], &left99).expect("copy");
    lf.push(left99.to_string_lossy().into_owned());
    rf.push(path.to_string_lossy().into_owned());
    (lf, rf, right_from_left)
}

/// Up to `max_pairs` pairs of a 9x6 board seen whole by both cameras,
/// written as leftNN.png and rightNN.png.
fn render_pairs(
    dir: &Path,
    left: &Camera,
    right: &Camera,
    right_from_left: &Pose,
    max_pairs: usize,
) -> (Vec<String>, Vec<String>) {
    let (left, right, right_from_left) = (left.clone(), right.clone(), *right_from_left);
    let target = Target::parse_spec("chessboard:9x6:30mm").expect("target");
    // The scene's points are the inner corners of the board.
    let scene = Scene::calibration(5, &left, (9, 6), 0.03, 24, 0.0).expect("scene");
    let options = RenderOptions {
        supersample: 4,
        ..RenderOptions::default()
    };
    let (mut lf, mut rf) = (vec![], vec![]);
    for (i, (v, pose)) in scene
        .views
        .iter()
        .zip(&scene.camera_from_target)
        .enumerate()
    {
        let right_pose = right_from_left * pose;
        if !inside(&left, v, pose) || !inside(&right, v, &right_pose) || lf.len() == max_pairs {
            continue;
        }
        for (cam, p, list, side) in [
            (&left, pose, &mut lf, "left"),
            (&right, &right_pose, &mut rf, "right"),
        ] {
            let r = render(
                cam,
                &target,
                p,
                &RenderOptions {
                    seed: i as u64,
                    ..options.clone()
                },
            )
            .expect("render");
            let path = dir.join(format!("{side}{i:02}.png"));
            std::fs::write(&path, encode_png(&r.image).expect("png")).expect("write");
            list.push(path.to_string_lossy().into_owned());
        }
    }
    assert!(lf.len() >= 6, "only {} usable pairs", lf.len());
    (lf, rf)
}

#[test]
fn stereo_on_rendered_pairs_recovers_right_from_left_and_exports() {
    let dir = temp_dir("stereo", "pairs");
    let (lf, rf, truth) = rendered_pairs(&dir);
    let out = dir.join("stereo.json");
    let mut args = vec!["stereo", "--target", "chessboard:9x6:30mm", "--left"];
    args.extend(lf.iter().map(String::as_str));
    args.push("--right");
    args.extend(rf.iter().map(String::as_str));
    let out_s = out.to_string_lossy().into_owned();
    args.extend(["-o", &out_s]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("pair dropped") && err.contains("right99_blank.png"),
        "{err}"
    );
    let stereo_err = err.clone();
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&out).expect("read")).expect("json");
    for key in [
        "left",
        "right",
        "right_from_left",
        "initial_right_from_left",
        "rms_px",
    ] {
        assert!(report.get(key).is_some(), "missing {key}");
    }
    assert_eq!(
        report["left"]["views"].as_array().map(Vec::len),
        Some(lf.len() - 1)
    );
    // Rendered corners are found to ~0.05 px (tests/detect/detect_render.rs): the
    // reprojection rms stays well under 0.3 px and, with ~7 pairs at
    // 0.5-1 m, right_from_left is within 2 mm and 2 mrad.
    let rms = report["rms_px"].as_f64().expect("rms");
    assert!(rms < 0.3, "rms {rms}");
    let t = &report["right_from_left"]["translation_m"];
    let got = Vector3::new(
        t[0].as_f64().unwrap(),
        t[1].as_f64().unwrap(),
        t[2].as_f64().unwrap(),
    );
    assert!((got - truth.translation.vector).norm() < 2e-3, "T {got}");
    let q = &report["right_from_left"]["quaternion_xyzw"];
    let qv: Vec<f64> = (0..4).map(|k| q[k].as_f64().unwrap()).collect();
    let rot = robocal::geometry::rotation_from_quaternion_xyzw([qv[0], qv[1], qv[2], qv[3]])
        .expect("quaternion");
    assert!((rot * truth.rotation.inverse()).angle() < 2e-3);
    // The export finds right_from_left.
    let (code, text, err) = robocal(&["export", &out_s, "--format", "xyz-quat-xyzw"]);
    assert_eq!(code, 0, "{err}");
    let numbers: Vec<f64> = text
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter_map(|s| s.parse().ok())
        .collect();
    assert_eq!(numbers.len(), 7, "{text}");
    assert!((numbers[0] - got.x).abs() < 1e-9, "{text}");
    check_stereo_exports(&dir, &out_s, &report);
    // A normal lens: the advice keeps an OpenCV model (Brown-Conrady, or
    // k1 k2 k5 when k3 and the tangential terms fit noise: the truth has k1
    // only), and says OpenCV and ROS hold it.
    for side in ["left", "right"] {
        let advice = &report["model_advice"][side];
        let recommended = advice["recommended"].as_str().unwrap();
        assert!(
            ["brown", "radial_k1_k2_k5"].contains(&recommended),
            "{advice}"
        );
        let formats = export_formats(advice);
        assert!(
            formats.contains(&"opencv-yaml") && formats.contains(&"ros-yaml"),
            "{formats:?}"
        );
        assert!(
            stereo_err.contains(&format!(
                "robocal stereo: {side} camera: lens model: {recommended}"
            )),
            "{stereo_err}"
        );
        assert!(
            advice["half_diagonal_fov_deg"].as_f64().unwrap() < 50.0,
            "{advice}"
        );
    }
}

/// The model advice's `export_formats` (one camera's `model_advice`).
fn export_formats(advice: &Value) -> Vec<&str> {
    advice["export_formats"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect()
}

/// The stereo exports of a `robocal stereo` report: OpenCV's numbers
/// (E = [T]x R, F = K2^-T E K1^-1, the epipolar constraint to 1e-9 on the
/// board corners projected by the calibrated cameras, rectified rows
/// aligned to 1e-9 px for those and within 0.5 px for the detected corners,
/// whose noise is ~0.05 px), ROS's two files, and what Kalibr refuses.
fn check_stereo_exports(dir: &Path, report_path: &str, report: &Value) {
    use nalgebra::{Matrix3, Matrix3x4, Point2, Point3};
    let (code, text, err) = robocal(&["export", report_path, "--format", "opencv-yaml"]);
    assert_eq!(code, 0, "{err}");
    let matrix = |key: &str| -> Vec<f64> {
        let start = text
            .find(&format!("\n{key}: !!opencv-matrix"))
            .unwrap_or_else(|| panic!("{key}: {text}"));
        let data = &text[start..];
        let open = data.find("data: [").unwrap() + 7;
        let close = open + data[open..].find(']').unwrap();
        data[open..close]
            .split(',')
            .map(|v| v.trim().parse().unwrap())
            .collect()
    };
    let m3 = |key: &str| Matrix3::from_row_slice(&matrix(key));
    let (k1, k2, r, e, f, r1, r2) = (
        m3("K1"),
        m3("K2"),
        m3("R"),
        m3("E"),
        m3("F"),
        m3("R1"),
        m3("R2"),
    );
    let t = Vector3::from_row_slice(&matrix("T"));
    let p1 = Matrix3x4::from_row_slice(&matrix("P1"));
    assert!((e - t.cross_matrix() * r).norm() < 1e-12, "E = [T]x R");
    let f_expected = k2.try_inverse().unwrap().transpose() * e * k1.try_inverse().unwrap();
    assert!(
        (f - f_expected).norm() < 1e-12 * f.norm(),
        "F = K2^-T E K1^-1"
    );
    // The report's right_from_left is R, T.
    let q = &report["right_from_left"]["translation_m"];
    assert_eq!(t.x, q[0].as_f64().unwrap());
    let read = |side: &str| -> Camera {
        let (c, _) = robocal::io::import_camera::import_camera(&report[side].to_string()).unwrap();
        c
    };
    let (left, right) = (read("left"), read("right"));
    let target = Target::parse_spec("chessboard:9x6:30mm").unwrap();
    let board: Vec<Point3<f64>> = (0..6)
        .flat_map(|row| {
            (0..9).map(move |col| Point3::new(0.03 * col as f64, 0.03 * row as f64, 0.0))
        })
        .collect();
    let _ = target;
    let mut worst_detected: f64 = 0.0;
    for (vl, vr) in report["left"]["views"]
        .as_array()
        .unwrap()
        .iter()
        .zip(report["right"]["views"].as_array().unwrap())
    {
        let pose = robocal::geometry::PoseInput::deserialize(&vl["camera_from_target"])
            .unwrap()
            .to_pose()
            .unwrap();
        for p in &board {
            let x_left = pose * p;
            let x_right = r * x_left.coords + t;
            let (pl, pr) = (k1 * (x_left.coords / x_left.z), k2 * (x_right / x_right.z));
            let c = pr.dot(&(f * pl)) / (pr.norm() * pl.norm());
            assert!(c.abs() < 1e-9, "epipolar {c}");
            let (yl, yr) = (
                p1 * (r1 * x_left.coords).push(1.0),
                p1 * (r2 * x_right).push(1.0),
            );
            assert!((yl.y / yl.z - yr.y / yr.z).abs() < 1e-9);
        }
        // Detected corners (the report's residual rows: x, y of each point),
        // undistorted and rectified: rows agree point by point.
        let corners = |v: &Value| -> Vec<Point2<f64>> {
            v["residuals_px"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| Point2::new(r["x"].as_f64().unwrap(), r["y"].as_f64().unwrap()))
                .collect()
        };
        let (cl, cr) = (corners(vl), corners(vr));
        assert_eq!(cl.len(), 54);
        for (a, b) in cl.iter().zip(&cr) {
            let (ra, rb) = (
                r1 * left.unproject(a).unwrap(),
                r2 * right.unproject(b).unwrap(),
            );
            let (ya, yb) = (p1 * ra.push(1.0), p1 * rb.push(1.0));
            worst_detected = worst_detected.max((ya.y / ya.z - yb.y / yb.z).abs());
        }
    }
    assert!(
        worst_detected < 0.5,
        "detected rows differ by up to {worst_detected} px"
    );
    // ROS: two camera_info files, P2's Tx = -fx' * baseline.
    let ros = dir.join("ros");
    let (code, _, err) = robocal(&[
        "export",
        report_path,
        "--format",
        "ros",
        "-o",
        ros.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let right_yaml = std::fs::read_to_string(ros.join("right.yaml")).unwrap();
    assert!(right_yaml.contains("camera_name: right\n"), "{right_yaml}");
    let p2 = Matrix3x4::from_row_slice(&matrix("P2"));
    let tx = p2[(0, 3)] / p2[(0, 0)];
    assert!(
        (tx + report["baseline_m"].as_f64().unwrap()).abs() < 1e-12,
        "Tx {tx}"
    );
    assert!(std::fs::read_to_string(ros.join("left.yaml"))
        .unwrap()
        .contains("rectification_matrix:"));
    // Kalibr's radtan has no k3, and this calibration fitted one.
    let (code, _, err) = robocal(&["export", report_path, "--format", "kalibr"]);
    assert_eq!(
        (code, err.as_str()),
        (1, "robocal: format: left camera: Kalibr's radtan model has no k3: calibrate with k3 fixed at 0 to export to Kalibr\n")
    );
    let (code, _, err) = robocal(&["export", report_path, "--format", "mrcal"]);
    assert_eq!(
        (code, err.as_str()),
        (1, "robocal: format: format 'mrcal' cannot hold a stereo pair: a stereo report exports as opencv-yaml, ros, kalibr (both cameras), as a transform format (right_from_left, e.g. matrix4) or as report\n")
    );
}

/// A wide-angle fisheye pair (Kannala-Brandt, about 70 degrees from the
/// axis to the image corners): the advice of each camera compares
/// kannala_brandt and EUCM and names one of them with its export formats.
#[test]
fn a_fisheye_pair_gets_fisheye_model_advice_with_its_export_formats() {
    let dir = temp_dir("stereo", "fisheye");
    let fisheye = |fx: f64, cx: f64| Camera {
        fx,
        fy: fx,
        cx,
        cy: 239.5,
        skew: 0.0,
        width: 640,
        height: 480,
        distortion: Distortion::KannalaBrandt {
            k1: 0.02,
            k2: -0.005,
            k3: 0.001,
            k4: -0.0002,
        },
    };
    let right_from_left = Pose::from_parts(
        Translation3::new(-0.06, 0.001, 0.0),
        rotation_from_rotvec(&Vector3::new(0.0, -0.02, 0.005)),
    );
    let (lf, rf) = render_pairs(
        &dir,
        &fisheye(330.0, 319.5),
        &fisheye(335.0, 322.0),
        &right_from_left,
        8,
    );
    let out = dir.join("stereo.json");
    let out_s = out.to_string_lossy().into_owned();
    let mut args = vec![
        "stereo",
        "--target",
        "chessboard:9x6:30mm",
        "--model",
        "kannala_brandt",
        "--left",
    ];
    args.extend(lf.iter().map(String::as_str));
    args.push("--right");
    args.extend(rf.iter().map(String::as_str));
    args.extend(["-o", &out_s]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    for side in ["left", "right"] {
        let advice = &report["model_advice"][side];
        let recommended = advice["recommended"].as_str().unwrap();
        assert!(
            ["kannala_brandt", "eucm"].contains(&recommended),
            "{advice}"
        );
        let compared: Vec<&str> = advice["compared"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["model"].as_str().unwrap())
            .collect();
        assert!(
            compared.contains(&"kannala_brandt") && compared.contains(&"eucm"),
            "{compared:?}"
        );
        assert!(
            advice["half_diagonal_fov_deg"].as_f64().unwrap() > 50.0,
            "{advice}"
        );
        let formats = export_formats(advice);
        assert!(
            formats.iter().any(|f| f.starts_with("kalibr")),
            "{formats:?}"
        );
        let line = err
            .lines()
            .find(|l| {
                l.starts_with(&format!(
                    "robocal stereo: {side} camera: lens model: {recommended}"
                ))
            })
            .unwrap_or_else(|| panic!("{err}"));
        assert!(
            line.contains(&format!("; {recommended} exports to json, ")),
            "{line}"
        );
    }
    // The pair exports to OpenCV (fisheye) and Kalibr (equidistant).
    let (code, text, err) = robocal(&["export", &out_s, "--format", "kalibr"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        text.matches("distortion_model: equidistant").count(),
        2,
        "{text}"
    );
    let (code, text, err) = robocal(&["export", &out_s, "--format", "opencv-yaml"]);
    assert_eq!(code, 0, "{err}");
    assert!(text.contains("(read D1, D2 with cv2.fisheye)"), "{text}");
}

#[test]
fn bad_arguments_say_what_to_change() {
    let (code, _, err) = robocal(&[
        "stereo",
        "--target",
        "chessboard:9x6:30mm",
        "--left",
        "a.png",
        "b.png",
        "--right",
        "c.png",
    ]);
    assert_eq!(code, 2);
    assert_eq!(
        err.trim(),
        "robocal: stereo: images are paired by order: 2 left but 1 right (see 'robocal stereo --help')"
    );
    let (code, _, err) = robocal(&[
        "stereo",
        "--target",
        "chessboard:9x6:30mm",
        "--left",
        "a.png",
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("give --left IMAGES... and --right IMAGES... once each"),
        "{err}"
    );
    let (code, help, _) = robocal(&["stereo", "--help"]);
    assert_eq!(code, 0);
    assert!(help.contains("robocal stereo --target chessboard:9x6:25mm --left left*.jpg"));
}

#[test]
fn opencv_9x6_pairs_give_bouguets_right_from_left() {
    let Some(dir) = dataset("opencv-left-right-9x6") else {
        eprintln!("skipped: opencv-left-right-9x6 dataset not found");
        return;
    };
    let pairs = [1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14];
    let side = |s: &str| -> Vec<String> {
        pairs
            .iter()
            .map(|i| {
                dir.join(format!("{s}{i:02}.jpg"))
                    .to_string_lossy()
                    .into_owned()
            })
            .collect()
    };
    let mut args = vec!["stereo", "--target", "chessboard:9x6:30mm", "--left"];
    let (left, right) = (side("left"), side("right"));
    args.extend(left.iter().map(|s| s.as_str()));
    args.push("--right");
    args.extend(right.iter().map(|s| s.as_str()));
    let (code, stdout, stderr) = robocal(&args);
    assert_eq!(code, 0, "{stderr}");
    let report: Value = serde_json::from_str(&stdout).expect("report");
    let f = |v: &Value| v.as_f64().expect("number");
    let q = &report["right_from_left"]["quaternion_xyzw"];
    let t = &report["right_from_left"]["translation_m"];
    // Small rotation: the rotation vector is 2 q_xyz (to ~1e-9 rad here).
    let om = Vector3::new(2.0 * f(&q[0]), 2.0 * f(&q[1]), 2.0 * f(&q[2])) * f(&q[3]).signum();
    let t_mm = Vector3::new(f(&t[0]), f(&t[1]), f(&t[2])) * 1e3;
    // Bouguet's example 5 after his stereo optimisation, with his
    // uncertainties (about 3 standard deviations; SOURCE.md (3)). Our
    // corners (robocal's detector, 13 pairs, rms ~0.18 px) land within them.
    let om_ref = [0.00669, 0.00452, -0.00350];
    let om_unc = [0.0027, 0.00308, 0.00029];
    let t_ref = [-99.80198, 1.12443, 0.05041];
    let t_unc = [0.142, 0.11352, 0.49773];
    for k in 0..3 {
        assert!(
            (om[k] - om_ref[k]).abs() < om_unc[k],
            "om[{k}] {} vs {} rad",
            om[k],
            om_ref[k]
        );
        assert!(
            (t_mm[k] - t_ref[k]).abs() < t_unc[k],
            "T[{k}] {} vs {} mm",
            t_mm[k],
            t_ref[k]
        );
    }
    let baseline_mm = f(&report["baseline_m"]) * 1e3;
    assert!(
        (baseline_mm - 99.81).abs() < 0.142,
        "baseline {baseline_mm} mm"
    );
}
