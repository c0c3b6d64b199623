//! Detection on public image sets in ../shared/datasets (skipped with a
//! message when absent).
//!
//! OpenCV left/right 9x6 (Bouguet's stereo example, 640x480 JPEG): every
//! board OpenCV finds must be found (all 26), and the corners must agree
//! with OpenCV's refined corners (fixture
//! tests/fixtures/opencv-left-right-9x6.json, written by
//! bench/opencv_reference.py; OpenCV 4.14, cornerSubPix 11x11).
//!
//! Tolerances (measured 2026-11-22): over all 1404 corners the median
//! distance to OpenCV is 0.092 px, asserted <= 0.1 px (the bound,
//! met in the median); per image the median is 0.06-0.131 px, asserted
//! <= 0.14 px. The disagreement is per-corner scatter (std 0.08-0.09 px
//! per axis, per-image mean offsets below 0.1 px), and the evidence says
//! it is not a bias of ours: (1) after undistorting both corner sets with
//! OpenCV's own calibration (left_intrinsics.yml) a homography fits
//! robocal's corners better than OpenCV's (median RMS 0.166 vs 0.186 px
//! over the 13 left images, BENCHMARKS.md); (2) on renders degraded like
//! these photos (blur, noise, JPEG; bench/detect_jpeg_truth.py) robocal is
//! closer to the truth than OpenCV in every case. Single corners differ
//! by up to 6 px where the board's thin outer row meets its frame:
//! OpenCV's 23x23 window is pulled by the frame edge, while the saddle of
//! the image stays put for windows of 2.5 to 8 px. OpenCV's order may run
//! from the other end of the board: the comparison keeps the direction
//! that fits.
//!
//! Zhang 1998: the target is a grid of separate black squares, not a
//! chessboard (no X-junctions); the chessboard detector must refuse it
//! cleanly instead of inventing a board.

mod support;
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
            "/tests/fixtures/opencv-left-right-9x6.json"
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
