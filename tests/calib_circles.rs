//! Intrinsics from circle grids against intrinsics from chessboards of the
//! same views (issue 20): the same six board poses (tilts 20-49 degrees)
//! rendered at 1280x960 with noise sigma 2 as a 9x6 chessboard and as a 4x11
//! asymmetric circle grid, detected, and calibrated with the same model
//! (Brown k1 k2 k3 p1 p2). The error is the distance of
//! (fx, fy, cx, cy) from the truth, px.
//!
//! Bounds: the perspective-correct circle centres must calibrate at least
//! as accurately as the chessboard corners (both are noise-limited: centre
//! and corner sd ~0.01-0.02 px, which over ~300 points gives intrinsics
//! within a few tenths of a pixel), while the uncorrected ellipse centres,
//! biased by up to 0.3 px in the tilted views, must do visibly worse (so the
//! comparison can fail).

use robocal::calib::{calibrate, CalibrationOptions, View};
use robocal::camera::Camera;
use robocal::detect::{detect, CentreModel, DetectOptions};
use robocal::synth::{board_pose, render, RenderOptions};
use robocal::target::Target;

const POSES: [((f64, f64, f64), (f64, f64, f64)); 6] = [
    ((0.63, -0.63, 0.2), (0.0, 0.0, 0.55)),
    ((-0.35, 0.5, -0.4), (0.06, -0.04, 0.5)),
    ((0.55, 0.25, 0.9), (-0.07, 0.05, 0.55)),
    ((-0.6, -0.3, 0.1), (0.05, 0.05, 0.6)),
    ((0.2, 0.65, -0.2), (-0.05, -0.03, 0.5)),
    ((-0.3, -0.55, 1.4), (0.0, 0.06, 0.6)),
];

fn views(cam: &Camera, spec: &str, options: &DetectOptions) -> Vec<View> {
    let target = Target::parse_spec(spec).expect("spec");
    POSES
        .iter()
        .enumerate()
        .map(|(k, (rpy, at))| {
            let o = RenderOptions {
                seed: 70 + k as u64,
                ..RenderOptions::default()
            };
            let r = render(cam, &target, &board_pose(&target, *rpy, *at), &o).expect("render");
            assert_eq!(r.points.len(), target.point_count(), "{spec} view {k}");
            let det = detect(&r.image, &target, options)
                .unwrap_or_else(|e| panic!("{spec} view {k}: {e}"));
            View::from_detection(format!("view{k}"), &det)
        })
        .collect()
}

/// Distance of (fx, fy, cx, cy) from the truth, px.
fn intrinsics_error(cam: &Camera, views: &[View]) -> f64 {
    // The full Brown model: the strong-distortion camera has k3, p1, p2.
    let options = CalibrationOptions::default();
    let report = calibrate(views, (cam.width, cam.height), &options).expect("calibration");
    let c = &report.camera;
    ((c.fx - cam.fx).powi(2)
        + (c.fy - cam.fy).powi(2)
        + (c.cx - cam.cx).powi(2)
        + (c.cy - cam.cy).powi(2))
    .sqrt()
}

fn compare(cam: &Camera, name: &str) {
    let default = DetectOptions::default();
    let ellipse = DetectOptions {
        circle_centres: CentreModel::EllipseCentre,
        ..DetectOptions::default()
    };
    let chess = intrinsics_error(cam, &views(cam, "chessboard:9x6:30mm", &default));
    let circles = "circles:4x11:20mm:asymmetric";
    let pole = intrinsics_error(cam, &views(cam, circles, &default));
    let uncorrected = intrinsics_error(cam, &views(cam, circles, &ellipse));
    eprintln!(
        "{name}: intrinsics error, px: chessboard {chess:.4}, circles perspective_pole {pole:.4}, circles ellipse_centre {uncorrected:.4}"
    );
    assert!(
        pole <= chess,
        "{name}: circles {pole} px vs chessboard {chess} px"
    );
    assert!(
        uncorrected > pole,
        "{name}: ellipse centres {uncorrected} px vs corrected {pole} px"
    );
}

#[test]
fn circle_grid_intrinsics_at_least_as_accurate_as_chessboard_std_camera() {
    compare(&Camera::example_pinhole(), "std");
}

#[test]
fn circle_grid_intrinsics_at_least_as_accurate_as_chessboard_strong_distortion() {
    compare(&Camera::example_brown(), "brown");
}
