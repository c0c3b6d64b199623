//! Public calibration sets reproduce their published results:
//! - OpenCV's `left_intrinsics.yml` (13 left images of the OpenCV/Bouguet
//!   9x6 stereo set, fixed aspect ratio fx = fy), from OpenCV's own corners
//!   (fixtures/opencv-left-right-9x6.json);
//! - Bouguet's result on OpenCV's `calib1.dat` points (fc, cc, kc with the
//!   uncertainty block the file carries);
//! - Bouguet's stereo result of his 5th example (right_from_left) from the
//!   same OpenCV corners.
//!
//! The data sit in ../shared/datasets (beside the crate root; see
//! tests/support); each test is skipped with a message when absent.

use crate::support;
use support::dataset;

use nalgebra::{Point2, Point3, Vector3};
use robocal::calib::multi::stereo::calibrate_stereo;
use robocal::calib::{calibrate, CalibrationOptions, View};
use robocal::camera::Distortion;
use serde_json::Value;

fn brown() -> Distortion {
    Distortion::Brown {
        k1: 0.0,
        k2: 0.0,
        k3: 0.0,
        p1: 0.0,
        p2: 0.0,
    }
}

/// The numbers of the `data: [...]` list after `key:` in an OpenCV YAML file.
fn yaml_matrix(text: &str, key: &str) -> Vec<f64> {
    let start = text.find(&format!("{key}:")).expect("key in the YAML");
    let rest = &text[start..];
    let open = rest.find('[').expect("[");
    let close = rest.find(']').expect("]");
    rest[open + 1..close]
        .split(',')
        .map(|s| s.trim().parse().expect("number"))
        .collect()
}

/// OpenCV's refined corners of one image of the 9x6 set as a view: corner
/// k at ((k mod 9), (k div 9)) squares, in OpenCV's order (as OpenCV's
/// calibration sample assigns them).
fn fixture_view(fixture: &Value, image: &str, square_m: f64) -> View {
    let corners = fixture["images"][image].as_array().expect("corners");
    assert_eq!(corners.len(), 54, "{image}");
    View {
        name: image.to_string(),
        object_m: (0..54)
            .map(|k| Point3::new((k % 9) as f64 * square_m, (k / 9) as f64 * square_m, 0.0))
            .collect(),
        image_px: corners
            .iter()
            .map(|c| Point2::new(c[0].as_f64().expect("x"), c[1].as_f64().expect("y")))
            .collect(),
        point_ids: Vec::new(),
    }
}

fn opencv_corners() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/opencv-left-right-9x6.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).expect("fixture")).expect("JSON")
}

/// The 13 image numbers of the set (OpenCV ships no pair 10).
const PAIRS: [u32; 13] = [1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14];

#[test]
fn opencv_left_intrinsics_yml_is_reproduced_with_fx_equal_fy() {
    let Some(dir) = dataset("opencv-left-right-9x6") else {
        eprintln!("skipped: opencv-left-right-9x6 dataset not found");
        return;
    };
    let yml = std::fs::read_to_string(dir.join("left_intrinsics.yml")).expect("yml");
    let k = yaml_matrix(&yml, "camera_matrix");
    let d = yaml_matrix(&yml, "distortion_coefficients");
    let published_rms = yml
        .lines()
        .find_map(|l| l.strip_prefix("avg_reprojection_error:"))
        .and_then(|v| v.trim().parse::<f64>().ok())
        .expect("avg_reprojection_error");
    let fixture = opencv_corners();
    // The file's square size (0.025, unit-free); it scales only the poses.
    let views: Vec<View> = PAIRS
        .iter()
        .map(|i| fixture_view(&fixture, &format!("left{i:02}.jpg"), 0.025))
        .collect();
    // flags = 2 (CALIB_FIX_ASPECT_RATIO) with aspectRatio 1, 5 coefficients.
    let options = CalibrationOptions {
        model: brown(),
        fix_aspect_ratio: true,
        aspect_ratio: Some(1.0),
        ..CalibrationOptions::default()
    };
    let report = calibrate(&views, (640, 480), &options).expect("calibration");
    let c = &report.camera;
    assert_eq!(c.fx, c.fy, "fx = fy exactly");
    eprintln!(
        "left_intrinsics: {c:?} rms {} px, std {:?}",
        report.rms_px, report.std
    );
    assert_eq!(report.std["fx"], report.std["fy"]);
    // The published file came from an older OpenCV's corners; OpenCV 4.14
    // finds slightly different ones (the fixture; any findChessboardCorners
    // flags and 30 or 100 cornerSubPix iterations give the same), on which
    // its own calibrateCamera gives fx = fy 536.1088, cx 342.3736, cy
    // 235.5954, rms 0.40879 (benches/.venv, FIX_ASPECT_RATIO), as we do to
    // 1e-3 px (benches/compare_calibration.py shows the solvers agree to
    // 1e-3 std on equal points). The published values then lie within one
    // of our standard deviations (fx: 0.19 px of 0.92 px).
    let got = [c.fx, c.cx, c.cy];
    let want = [k[0], k[2], k[5]];
    for ((name, g), w) in ["fx", "cx", "cy"].iter().zip(got).zip(want) {
        let std = report.std[*name];
        assert!((g - w).abs() < std, "{name}: {g} vs {w} px (std {std} px)");
    }
    let coeffs = c.distortion.coefficients();
    for (i, name) in ["k1", "k2", "p1", "p2", "k3"].iter().enumerate() {
        let std = report.std[*name];
        assert!(
            (coeffs[i] - d[i]).abs() < std,
            "{name}: {} vs {} (std {std})",
            coeffs[i],
            d[i]
        );
    }
    // Same corners as OpenCV 4.14: its fx (see above) to 1e-3 px.
    assert!((c.fx - 536.1088).abs() < 1e-3, "fx {} px", c.fx);
    // OpenCV's avg_reprojection_error is its RMS over points, as ours; the
    // corners differ (above), OpenCV 4.14's give 0.4088 px vs 0.3926.
    assert!(
        (report.rms_px - published_rms).abs() < 0.02,
        "rms {} vs {published_rms} px",
        report.rms_px
    );
}

/// OpenCV's `calib1.dat` (opencv_extra testdata/cv/cameracalibration): the
/// points of 7 views of a 7x5 grid and Bouguet's toolbox result on them.
struct Calib1 {
    size: (u32, u32),
    views: Vec<View>,
    /// fc (2), cc (2), kc (k1 k2 p1 p2).
    fc: [f64; 2],
    cc: [f64; 2],
    kc: [f64; 4],
    /// Per view: target-to-camera translation, cm.
    translations_cm: Vec<Vector3<f64>>,
    /// The uncertainty block: 18 intrinsic entries in OpenCV's order (fx fy
    /// cx cy k1 k2 p1 p2 k3 ... tauY) and 6 per view (rvec, tvec in cm).
    uncertainty: Vec<f64>,
}

/// Parse the text of `calib1.dat` (format in the dataset's SOURCE.md):
/// whitespace-separated numbers up to the first `#`.
fn parse_calib1(text: &str) -> Result<Calib1, String> {
    let body = text.split('#').next().unwrap_or("");
    let numbers = body
        .split_whitespace()
        .map(|t| t.parse::<f64>().map_err(|e| format!("'{t}': {e}")))
        .collect::<Result<Vec<f64>, String>>()?;
    let mut it = numbers.into_iter();
    let mut take = |n: usize| -> Result<Vec<f64>, String> {
        let v: Vec<f64> = it.by_ref().take(n).collect();
        if v.len() == n {
            Ok(v)
        } else {
            Err(format!("expected {n} more numbers, got {}", v.len()))
        }
    };
    let head = take(6)?;
    let (w, h, cols, rows, n_views) = (head[0], head[1], head[2], head[3], head[4]);
    let n_points = (cols * rows) as usize;
    let n_views = n_views as usize;
    let objects = take(n_views * n_points * 3)?;
    let images = take(n_views * n_points * 2)?;
    let views = (0..n_views)
        .map(|v| View {
            name: format!("view{}", v + 1),
            // cm -> m
            object_m: (0..n_points)
                .map(|i| {
                    let o = &objects[(v * n_points + i) * 3..][..3];
                    Point3::new(o[0] * 0.01, o[1] * 0.01, o[2] * 0.01)
                })
                .collect(),
            image_px: (0..n_points)
                .map(|i| {
                    let p = &images[(v * n_points + i) * 2..][..2];
                    Point2::new(p[0], p[1])
                })
                .collect(),
            point_ids: Vec::new(),
        })
        .collect();
    let intrinsics = take(8)?;
    let _rotations = take(n_views * 9)?;
    let t = take(n_views * 3)?;
    let uncertainty = take(18 + 6 * n_views)?;
    let pixel_error = take(2)?;
    if take(1).is_ok() {
        return Err("numbers after the pixel error".into());
    }
    assert!(pixel_error.iter().all(|e| *e > 0.0));
    Ok(Calib1 {
        size: (w as u32, h as u32),
        views,
        fc: [intrinsics[0], intrinsics[1]],
        cc: [intrinsics[2], intrinsics[3]],
        kc: [intrinsics[4], intrinsics[5], intrinsics[6], intrinsics[7]],
        translations_cm: t
            .chunks(3)
            .map(|c| Vector3::new(c[0], c[1], c[2]))
            .collect(),
        uncertainty,
    })
}

#[test]
fn calib1_parser_reports_short_files() {
    assert_eq!(
        parse_calib1("640 480 7 5 7 14464 0 0").err().as_deref(),
        Some("expected 735 more numbers, got 2")
    );
    assert_eq!(
        parse_calib1("640 480 x").err().as_deref(),
        Some("'x': invalid float literal")
    );
}

#[test]
fn bouguet_calib1_result_is_reproduced_within_its_uncertainty() {
    let Some(dir) = dataset("opencv-calib1-dat") else {
        eprintln!("skipped: opencv-calib1-dat dataset not found");
        return;
    };
    let text = std::fs::read_to_string(dir.join("calib1.dat")).expect("calib1.dat");
    let data = parse_calib1(&text).expect("parse");
    assert_eq!((data.size, data.views.len()), ((640, 480), 7));
    // Bouguet's model: fc, cc, kc = k1 k2 p1 p2 (no k3), no skew.
    let options = CalibrationOptions {
        model: brown(),
        fixed_coefficients: vec!["k3".into()],
        ..CalibrationOptions::default()
    };
    let report = calibrate(&data.views, data.size, &options).expect("calibration");
    let c = &report.camera;
    let coeffs = c.distortion.coefficients();
    let got = [
        c.fx, c.fy, c.cx, c.cy, coeffs[0], coeffs[1], coeffs[2], coeffs[3],
    ];
    let want = [
        data.fc[0], data.fc[1], data.cc[0], data.cc[1], data.kc[0], data.kc[1], data.kc[2],
        data.kc[3],
    ];
    let names = ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"];
    eprintln!("calib1: {got:?}, rms {} px", report.rms_px);
    for (i, name) in names.iter().enumerate() {
        // The published uncertainty (Bouguet: about 3 standard deviations)
        // bounds the difference; the same data and model make it far smaller.
        let bound = data.uncertainty[i];
        assert!(
            (got[i] - want[i]).abs() < bound,
            "{name}: {} vs published {} (uncertainty {bound})",
            got[i],
            want[i]
        );
    }
    for (v, (pose, t)) in report.views.iter().zip(&data.translations_cm).enumerate() {
        let ours = Vector3::from(pose.camera_from_target.translation_m) * 100.0;
        let bound = Vector3::new(
            data.uncertainty[18 + 6 * v + 3],
            data.uncertainty[18 + 6 * v + 4],
            data.uncertainty[18 + 6 * v + 5],
        );
        for k in 0..3 {
            assert!(
                (ours[k] - t[k]).abs() < bound[k],
                "view {v} translation[{k}]: {} vs {} cm (uncertainty {})",
                ours[k],
                t[k],
                bound[k]
            );
        }
    }
}

/// Rotation vector of a quaternion x y z w (small angles, the sign of w fixed).
fn rotvec(q: [f64; 4]) -> Vector3<f64> {
    let s = if q[3] < 0.0 { -1.0 } else { 1.0 };
    let v = Vector3::new(q[0], q[1], q[2]) * s;
    let angle = 2.0 * v.norm().atan2(q[3] * s);
    if v.norm() > 0.0 {
        v.normalize() * angle
    } else {
        v
    }
}

#[test]
fn stereo_9x6_matches_bouguets_published_right_from_left() {
    let Some(_) = dataset("opencv-left-right-9x6") else {
        eprintln!("skipped: opencv-left-right-9x6 dataset not found");
        return;
    };
    let fixture = opencv_corners();
    // Bouguet's squares: 30 mm (his example-5 page).
    let side = |s: &str| -> Vec<View> {
        PAIRS
            .iter()
            .map(|i| fixture_view(&fixture, &format!("{s}{i:02}.jpg"), 0.030))
            .collect()
    };
    // Bouguet's stereo model: k1 k2 p1 p2 (kc(5) = 0).
    let options = CalibrationOptions {
        model: brown(),
        fixed_coefficients: vec!["k3".into()],
        ..CalibrationOptions::default()
    };
    let stereo = calibrate_stereo(
        &side("left"),
        &side("right"),
        (640, 480),
        (640, 480),
        &options,
    )
    .expect("stereo");
    let om = rotvec(stereo.right_from_left.quaternion_xyzw);
    let t_mm = Vector3::from(stereo.right_from_left.translation_m) * 1e3;
    // Bouguet's example 5 after the stereo optimisation (SOURCE.md (3)):
    // om and T with his uncertainties (about 3 standard deviations). He had
    // 14 pairs and his own corners, we have OpenCV 4.14's on 13 pairs: two
    // independent estimates, so their difference is bounded by
    // sqrt(his_3sigma^2 + (3 our_sigma)^2), our sigma from the joint
    // covariance (T x: 0.11 mm, the difference is 0.34 mm of 0.36).
    let om_ref: Vector3<f64> = Vector3::new(0.00669, 0.00452, -0.00350);
    let om_unc: Vector3<f64> = Vector3::new(0.0027, 0.00308, 0.00029);
    let t_ref: Vector3<f64> = Vector3::new(-99.80198, 1.12443, 0.05041);
    let t_unc: Vector3<f64> = Vector3::new(0.142, 0.11352, 0.49773);
    let std = stereo.right_from_left_std.clone().expect("std");
    eprintln!("stereo: om {om:?} rad, T {t_mm:?} mm, std {std:?}");
    for k in 0..3 {
        let om_tol = om_unc[k].hypot(3.0 * std.rotation_rad[k]);
        assert!(
            (om[k] - om_ref[k]).abs() < om_tol,
            "om[{k}]: {} vs {} rad (tolerance {om_tol})",
            om[k],
            om_ref[k],
        );
        let t_tol = t_unc[k].hypot(3.0 * std.translation_m[k] * 1e3);
        assert!(
            (t_mm[k] - t_ref[k]).abs() < t_tol,
            "T[{k}]: {} vs {} mm (tolerance {t_tol})",
            t_mm[k],
            t_ref[k],
        );
    }
    // The baseline: within the x tolerance (it is almost all x).
    let tol = t_unc[0].hypot(3.0 * std.translation_m[0] * 1e3);
    assert!(
        (stereo.baseline_m * 1e3 - t_ref.norm()).abs() < tol,
        "baseline {} mm",
        stereo.baseline_m * 1e3
    );
}
