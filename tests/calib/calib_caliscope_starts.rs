//! Convergence from perturbed starts on real frames (issue 35, "Measured:
//! convergence"): caliscope's free-running 1280x720 webcams
//! (../shared/datasets/caliscope-4cam-charuco-video, SOURCE.md), the
//! inverted ChArUco `charuco:4x5:54mm:40.5mm:DICT_4X4_1000`, every third
//! frame from frame 21 extracted with ffmpeg and detected without a print
//! option. Issue 35's failure class came from these webcams: a Zhang fit
//! stopped at its iteration limit far from the minimum (fx 733 / fy 967 at
//! 0.319 px where fx 907 / fy 912 reach 0.156 px).
//!
//! For cameras 0 and 1 (15 and 9 usable views), every start of a grid (fx
//! and fy 0.5x to 2x of 900 px independently, the principal point up to
//! 300 px off the centre, distortion zero) gives a report that either
//! reaches the lowest cost any start reaches or says at error level that
//! it did not converge. "Reaches": within [`CLEARLY_LOWER`] in cost, the
//! bar at which the multi-start (src/calib/starts.rs) lets one minimum
//! replace another. Camera 1's 9 weak views have three minima: 0.1958 px
//! (cy 299), 0.1964 px (cy 362, where the closed form and every start of
//! the project go) and 0.2047 px (cx 766, k2 6.8, where a guess 300 px off
//! settled, converged and plausible-looking, until a given guess was
//! checked against the closed form). Skipped with a
//! message when the dataset or ffmpeg is absent.

use crate::support;

use robocal::calib::{calibrate, CalibrationOptions, Severity, View};
use robocal::camera::{Camera, Distortion};
use robocal::detect::{detect, DetectOptions};
use robocal::target::Target;

/// The multi-start's bar: a minimum replaces an earlier one only when its
/// cost is this much lower (1 %, about 0.5 % in RMS).
const CLEARLY_LOWER: f64 = 0.01;

fn brown() -> Distortion {
    Distortion::Brown {
        k1: 0.0,
        k2: 0.0,
        k3: 0.0,
        p1: 0.0,
        p2: 0.0,
    }
}

#[test]
fn caliscope_fits_reach_the_best_cost_from_every_start_or_say_so() {
    let dir = support::temp_dir("calib", "caliscope-starts");
    let target = Target::parse_spec(support::CALISCOPE_TARGET).expect("spec");
    for camera in [0, 1] {
        let Some(files) = support::caliscope_frames(&dir, camera) else {
            return;
        };
        let views: Vec<View> = files
            .iter()
            .filter_map(|f| {
                let image = robocal::image::decode_gray(&std::fs::read(f).ok()?).ok()?;
                let det = detect(&image, &target, &DetectOptions::default()).ok()?;
                (det.points.len() >= 5).then(|| View::from_detection(f.display().to_string(), &det))
            })
            .collect();
        assert!(views.len() >= 8, "camera {camera}: {} views", views.len());
        let options = CalibrationOptions {
            model: brown(),
            fixed_coefficients: vec!["k3".into()],
            ..CalibrationOptions::default()
        };
        let size = (1280, 720);
        let mut reports = Vec::new();
        for (sx, sy) in [(0.5, 0.5), (0.6, 1.4), (1.4, 0.6), (2.0, 2.0), (1.0, 1.0)] {
            for (dx, dy) in [(-300.0, -200.0), (0.0, 0.0), (300.0, 200.0)] {
                let start = Camera {
                    fx: 900.0 * sx,
                    fy: 900.0 * sy,
                    cx: 640.0 + dx,
                    cy: 360.0 + dy,
                    skew: 0.0,
                    width: 1280,
                    height: 720,
                    distortion: brown(),
                };
                let what = format!("camera {camera}, start fx x{sx} fy x{sy}, c {dx:+} {dy:+} px");
                let report = calibrate(
                    &views,
                    size,
                    &CalibrationOptions {
                        initial_camera: Some(start),
                        ..options.clone()
                    },
                )
                .unwrap_or_else(|e| panic!("{what}: {e}"));
                reports.push((what, report));
            }
        }
        let best = reports
            .iter()
            .flat_map(|(_, r)| std::iter::once(r.rms_px).chain(r.starts.iter().map(|s| s.rms_px)))
            .fold(f64::INFINITY, f64::min);
        let mut errors = 0;
        for (what, report) in &reports {
            if report.severity == Severity::Error {
                errors += 1;
                assert!(
                    report.warnings[0].starts_with("error: the fit did not converge"),
                    "{what}: {:?}",
                    report.warnings
                );
                continue;
            }
            assert!(
                report.rms_px.powi(2) * (1.0 - CLEARLY_LOWER) <= best.powi(2),
                "{what}: rms {} px, the best start reaches {best} px (start {:?}, starts {:?})",
                report.rms_px,
                report.start,
                report.starts
            );
        }
        let c = &reports[13].1.camera;
        eprintln!(
            "camera {camera}: {} views, best rms {best:.4} px, {errors} of {} reports at error \
             level; fx {:.1} fy {:.1} cx {:.1} cy {:.1}",
            views.len(),
            reports.len(),
            c.fx,
            c.fy,
            c.cx,
            c.cy
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
