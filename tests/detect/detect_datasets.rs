//! Detection on public image sets in ../shared/datasets (skipped with a
//! message when absent).
//!
//! OpenCV left/right 9x6 (Bouguet's stereo example, 640x480 JPEG): every
//! board OpenCV finds must be found (all 26), and the corners must agree
//! with OpenCV's refined corners (fixture
//! fixtures/opencv-left-right-9x6.json, written by
//! benches/opencv_reference.py; OpenCV 4.14, cornerSubPix 11x11).
//!
//! Tolerances (measured 2026-11-22): over all 1404 corners the median
//! distance to OpenCV is 0.092 px, asserted <= 0.1 px (the bound,
//! met in the median); per image the median is 0.06-0.131 px, asserted
//! <= 0.14 px. The disagreement is per-corner scatter (std 0.08-0.09 px
//! per axis, per-image mean offsets below 0.1 px), and the evidence says
//! it is not a bias of ours: (1) after undistorting both corner sets with
//! OpenCV's own calibration (left_intrinsics.yml) a homography fits
//! robocal's corners better than OpenCV's (median RMS 0.166 vs 0.186 px
//! over the 13 left images, docs/benchmark-history.md); (2) on renders degraded like
//! these photos (blur, noise, JPEG; benches/detect_jpeg_truth.py) robocal is
//! closer to the truth than OpenCV in every case. Single corners differ
//! by up to 6 px where the board's thin outer row meets its frame:
//! OpenCV's 23x23 window is pulled by the frame edge, while the saddle of
//! the image stays put for windows of 2.5 to 8 px. OpenCV's order may run
//! from the other end of the board: the comparison keeps the direction
//! that fits.
//!
//! Zhang 1998: the target is a grid of separate black squares, not a
//! chessboard (no X-junctions); the chessboard detector must refuse it
//! cleanly instead of inventing a board, and the square-grid detector
//! (`squares:8x8:12.7mm:22.5778mm`) must find all five boards.

use crate::support;
use support::dataset;

use robocal::detect::{detect, DetectOptions};
use robocal::target::Target;

#[test]
fn opencv_left_right_9x6_agrees_with_opencv() {
    let Some(root) = dataset("") else {
        eprintln!("skipped: ../shared/datasets not found");
        return;
    };
    let dir = root.join("opencv-left-right-9x6");
    if !dir.is_dir() {
        eprintln!("skipped: {} not found", dir.display());
        return;
    }
    let fixture: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/fixtures/opencv-left-right-9x6.json"
        ))
        .unwrap(),
    )
    .unwrap();
    let target = Target::parse_spec("chessboard:9x6:30mm").unwrap();
    let mut checked = 0;
    let mut worst_median: f64 = 0.0;
    let mut all: Vec<f64> = Vec::new();
    for (name, reference) in fixture["images"].as_object().unwrap() {
        let Some(reference) = reference.as_array() else {
            continue;
        };
        let r: Vec<(f64, f64)> = reference
            .iter()
            .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
            .collect();
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let img = robocal::image::decode_gray(&bytes).unwrap();
        let det = detect(&img, &target, &DetectOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(det.points.len(), 54, "{name}");
        let dist = |reverse: bool| -> Vec<f64> {
            det.points
                .iter()
                .map(|p| {
                    let q = r[if reverse { 53 - p.id } else { p.id }];
                    ((p.x_px - q.0).powi(2) + (p.y_px - q.1).powi(2)).sqrt()
                })
                .collect()
        };
        let (a, b) = (dist(false), dist(true));
        let d = if a.iter().sum::<f64>() < b.iter().sum::<f64>() {
            a
        } else {
            b
        };
        let mut sorted = d.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[sorted.len() / 2];
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let max = d.iter().cloned().fold(0.0, f64::max);
        eprintln!("{name}: median {median:.4} px, mean {mean:.4} px, max {max:.4} px from OpenCV");
        assert!(median <= 0.14, "{name}: median {median} px from OpenCV");
        all.extend(d.iter().copied());
        worst_median = worst_median.max(median);
        checked += 1;
    }
    assert_eq!(checked, 26);
    all.sort_by(f64::total_cmp);
    let overall = all[all.len() / 2];
    eprintln!(
        "worst per-image median distance to OpenCV: {worst_median:.4} px; median over all {} corners {overall:.4} px",
        all.len()
    );
    assert!(overall <= 0.1, "median over all corners {overall} px");
}

#[test]
fn zhang1998_square_grid_is_not_mistaken_for_a_chessboard() {
    let Some(root) = dataset("") else {
        eprintln!("skipped: ../shared/datasets not found");
        return;
    };
    let dir = root.join("zhang1998");
    if !dir.is_dir() {
        eprintln!("skipped: {} not found", dir.display());
        return;
    }
    let target = Target::parse_spec("chessboard:8x8:20mm").unwrap();
    for k in 1..=5 {
        let bytes = std::fs::read(dir.join(format!("image{k}.gif"))).unwrap();
        let img = robocal::image::decode_gray(&bytes).unwrap();
        assert_eq!((img.width, img.height), (640, 480));
        let e = detect(&img, &target, &DetectOptions::default()).unwrap_err();
        assert!(
            matches!(e, robocal::Error::NotFound { .. }),
            "image{k}: {e}"
        );
    }
}

/// Zhang's `dataK.txt` as 256 points, rows of 8 numbers (4 corners).
fn zhang_points(text: &str) -> Vec<(f64, f64)> {
    let v: Vec<f64> = text
        .split_whitespace()
        .map(|t| t.parse().expect("number"))
        .collect();
    v.chunks(2).map(|c| (c[0], c[1])).collect()
}

/// Our id of Zhang's point `p` (line `p / 4`, corner `p % 4`): his rows of
/// squares run from the bottom of the image (src/target.rs).
fn zhang_to_robocal_id(p: usize) -> usize {
    let (n, k) = (p / 4, p % 4);
    4 * (n % 8 + 8 * (7 - n / 8)) + k
}

#[test]
fn zhang1998_square_grid_found_and_calibrated() {
    // Zhang 1998: all 5 boards found as 8x8 grids of separate squares. The
    // corners are compared with Zhang's own (data1..5.txt, lines fitted to
    // the square edges and intersected) and the camera calibrated from
    // robocal's detections is compared with his published result
    // (completecalibration.txt).
    //
    // Measured (session 14): per image the median distance to Zhang's
    // corners is 0.062, 0.124, 0.069, 0.110, 0.127 px (images 1-5), the max
    // 0.19-0.79 px. Bounds: median <= 0.15 px, max <= 0.85 px. Zhang's
    // corners are estimates too (lines fitted to whole sides and
    // intersected, a different edge operator), so this is agreement, not
    // error; the largest difference (0.79 px, image2 at (390, 110)) lies in
    // the reflection that crosses that photo. The calibration from
    // robocal's corners lands within 0.7 of its std of every published
    // value (fx -0.49, fy -0.51, cx +0.54, cy +0.67, skew -0.09, k1 -0.19,
    // k2 +0.22; bound: 0.7 std, the goal) with RMS 0.3621 px
    // (Zhang's corners: 0.3364 px). Most of cy's offset is image5, whose
    // corners sit 0.049 px lower than Zhang's on average. The side model
    // is also best here: parabolas per side gave RMS 0.407 px, half-side
    // segments 0.385 px (session 8, src/detect/squares/mod.rs).
    use robocal::calib::{calibrate, CalibrationOptions, View};
    let Some(dir) = dataset("zhang1998") else {
        eprintln!(
            "skipped: zhang1998 dataset not found beside the crate or in /work/shared/datasets"
        );
        return;
    };
    let target = Target::parse_spec("squares:8x8:12.7mm:22.5778mm").unwrap();
    let mut views = Vec::new();
    let mut zhang_views = Vec::new();
    for k in 1..=5 {
        let bytes = std::fs::read(dir.join(format!("image{k}.gif"))).unwrap();
        let img = robocal::image::decode_gray(&bytes).unwrap();
        let det = detect(&img, &target, &DetectOptions::default())
            .unwrap_or_else(|e| panic!("image{k}: {e}"));
        assert_eq!(det.points.len(), 256, "image{k}");
        let zhang =
            zhang_points(&std::fs::read_to_string(dir.join(format!("data{k}.txt"))).unwrap());
        assert_eq!(zhang.len(), 256);
        let dist: Vec<(f64, (f64, f64))> = zhang
            .iter()
            .enumerate()
            .map(|(p, z)| {
                let q = &det.points[zhang_to_robocal_id(p)];
                (((q.x_px - z.0).powi(2) + (q.y_px - z.1).powi(2)).sqrt(), *z)
            })
            .collect();
        let mut d: Vec<f64> = dist.iter().map(|e| e.0).collect();
        d.sort_by(f64::total_cmp);
        let (median, max) = (d[128], d[255]);
        let mean = d.iter().sum::<f64>() / 256.0;
        let worst = dist
            .iter()
            .fold(dist[0], |a, b| if b.0 > a.0 { *b } else { a });
        eprintln!(
            "image{k}: distance to Zhang's corners median {median:.4} px, mean {mean:.4} px, max {max:.4} px (at {:.0}, {:.0})",
            worst.1 .0, worst.1 .1
        );
        assert!(
            median <= 0.15,
            "image{k}: median {median} px from Zhang's corners"
        );
        assert!(max <= 0.85, "image{k}: max {max} px from Zhang's corners");
        // Mean signed offset of robocal's corners from Zhang's (a shared
        // shift would move the principal point).
        let mut theirs = det.clone();
        let mut offset = (0.0, 0.0);
        for (p, z) in zhang.iter().enumerate() {
            let q = &mut theirs.points[zhang_to_robocal_id(p)];
            offset.0 += (q.x_px - z.0) / 256.0;
            offset.1 += (q.y_px - z.1) / 256.0;
            (q.x_px, q.y_px) = *z;
        }
        eprintln!(
            "image{k}: mean offset from Zhang's corners ({:+.4}, {:+.4}) px",
            offset.0, offset.1
        );
        views.push(View::from_detection(format!("image{k}"), &det));
        zhang_views.push(View::from_detection(format!("image{k}"), &theirs));
    }
    // Zhang's model: radial k1 k2, no tangential terms, skew estimated.
    let options = CalibrationOptions {
        model: robocal::Distortion::Brown {
            k1: 0.0,
            k2: 0.0,
            k3: 0.0,
            p1: 0.0,
            p2: 0.0,
        },
        fixed_coefficients: vec!["p1".into(), "p2".into(), "k3".into()],
        zero_skew: false,
        ..CalibrationOptions::default()
    };
    let report = calibrate(&views, (640, 480), &options).expect("calibration");
    // The same calibration from Zhang's own corners: how far the method
    // itself lands from the published values (not asserted).
    let his = calibrate(&zhang_views, (640, 480), &options).expect("calibration");
    let c = &report.camera;
    let rows = [
        ("fx", c.fx, 832.5),
        ("fy", c.fy, 832.53),
        ("cx", c.cx, 303.959),
        ("cy", c.cy, 206.585),
        ("skew", c.skew, 0.204494),
        ("k1", report.distortion["k1"], -0.228601),
        ("k2", report.distortion["k2"], 0.190353),
    ];
    for (name, got, want) in rows {
        let z = (got - want) / report.std[name];
        let his_value = match name {
            "fx" => his.camera.fx,
            "fy" => his.camera.fy,
            "cx" => his.camera.cx,
            "cy" => his.camera.cy,
            "skew" => his.camera.skew,
            _ => his.distortion[name],
        };
        eprintln!(
            "{name}: {got:.5} from robocal's detections vs published {want} (std {:.5}, {z:.2} std); from Zhang's corners {:.2} std",
            report.std[name],
            (his_value - want) / report.std[name]
        );
        assert!(
            z.abs() <= 0.7,
            "{name}: {got} vs published {want} ({z:.2} std)"
        );
    }
    eprintln!(
        "rms {:.4} px (Zhang's corners: {:.4} px)",
        report.rms_px, his.rms_px
    );
    // Zhang's own corners give 0.337 px (OpenCV, SOURCE.md).
    assert!(report.rms_px < 0.4, "rms {} px", report.rms_px);
}
