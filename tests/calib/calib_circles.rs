//! Intrinsics from circle grids against intrinsics from chessboards of the
//! same views (issue 20): the same twelve board poses (tilts 20-49 degrees)
//! rendered at 1280x960 with noise sigma 2, detected, and calibrated with
//! the same model (Brown k1 k2 k3 p1 p2). The error is the distance of (fx,
//! fy, cx, cy) from the truth, px, averaged over several noise draws.
//!
//! Two comparisons:
//! - **Same points** (asserted against the goal): a 9x6 chessboard
//!   of 30 mm squares and a 9x6 circle grid of 30 mm pitch (15 mm circles),
//!   so both targets put the same 54 points at the same board positions in
//!   every view and only the detectors differ. The perspective-correct
//!   circle centres must calibrate at least as accurately as the chessboard
//!   corners, and the uncorrected ellipse centres worse than they.
//! - **The usual asymmetric grid**: OpenCV's 4x11 asymmetric grid at 20 mm
//!   (44 points over 140x200 mm, against the chessboard's 54 over 240x150
//!   mm), reported and bounded, not held to the chessboard: it is a smaller
//!   board with fewer points, weaker geometry even without noise (noise-free
//!   renders through the strongly distorted camera, one draw: 0.060 px
//!   against the chessboard's 0.031; docs/benchmark-history.md, session 16).
//!
//! Why averaged, and why twelve views: one noise draw of six views moved
//! the error by 0.1-0.2 px from seed to seed on the strongly distorted
//! camera, several times the differences between the centre models, and
//! flipped their ranking (docs/benchmark-history.md, sessions 12 and 13).
//! The test is to measure the centres, not one draw.
//!
//! History: the circles led the chessboard (session 13) until the
//! chessboard's saddle fit lost its pixel-phase bias (session 14); the edge
//! points of the circles then left a systematic floor of about 0.007 px
//! under their centres, which bent the calibration, until the edges became
//! gradient centroids (session 16, src/detect/blobs.rs).

use robocal::calib::{calibrate, CalibrationOptions, View};
use robocal::camera::Camera;
use robocal::detect::{detect, CentreModel, DetectOptions};
use robocal::synth::{board_pose, render, RenderOptions};
use robocal::target::Target;

/// Three numbers: a roll-pitch-yaw (rad) or a position (m).
type Triple = (f64, f64, f64);

/// Board poses: roll-pitch-yaw (rad) and position (m) of the board centre.
const POSES: [(Triple, Triple); 12] = [
    ((0.63, -0.63, 0.2), (0.0, 0.0, 0.55)),
    ((-0.35, 0.5, -0.4), (0.06, -0.04, 0.5)),
    ((0.55, 0.25, 0.9), (-0.07, 0.05, 0.55)),
    ((-0.6, -0.3, 0.1), (0.05, 0.05, 0.6)),
    ((0.2, 0.65, -0.2), (-0.05, -0.03, 0.5)),
    ((-0.3, -0.55, 1.4), (0.0, 0.06, 0.6)),
    ((0.4, 0.4, -0.6), (0.08, 0.05, 0.6)),
    ((-0.5, 0.2, 0.5), (-0.08, -0.05, 0.55)),
    ((0.1, -0.5, -1.0), (0.07, -0.06, 0.6)),
    ((0.5, -0.1, 0.3), (-0.06, 0.07, 0.5)),
    ((-0.2, 0.3, 1.0), (0.0, 0.0, 0.45)),
    ((-0.45, -0.45, -0.3), (-0.05, 0.06, 0.6)),
];

/// Noise seeds of the draws of the same-points comparison (view k of a
/// draw uses seed + k).
const SEEDS: [u64; 8] = [70, 170, 270, 370, 470, 570, 670, 770];
/// Noise seeds of the draws of the asymmetric grid (reported and bounded).
const SEEDS_ASYMMETRIC: [u64; 3] = [70, 170, 270];

/// Views of `spec` for each of `options`, from one rendering per pose.
fn views(cam: &Camera, spec: &str, options: &[&DetectOptions], seed: u64) -> Vec<Vec<View>> {
    let target = Target::parse_spec(spec).expect("spec");
    let mut out = vec![Vec::new(); options.len()];
    for (k, (rpy, at)) in POSES.iter().enumerate() {
        let o = RenderOptions {
            seed: seed + k as u64,
            ..RenderOptions::default()
        };
        let r = render(cam, &target, &board_pose(&target, *rpy, *at), &o).expect("render");
        assert_eq!(r.points.len(), target.point_count(), "{spec} view {k}");
        for (views, opt) in out.iter_mut().zip(options) {
            let det =
                detect(&r.image, &target, opt).unwrap_or_else(|e| panic!("{spec} view {k}: {e}"));
            views.push(View::from_detection(format!("view{k}"), &det));
        }
    }
    out
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

/// Mean intrinsics error over `seeds` of the 9x6 chessboard, of the
/// circle grid `spec` with perspective-correct centres, and of the same
/// detections' uncorrected ellipse centres, px.
fn mean_errors(cam: &Camera, name: &str, spec: &str, seeds: &[u64]) -> [f64; 3] {
    let default = DetectOptions::default();
    let ellipse = DetectOptions {
        circle_centres: CentreModel::EllipseCentre,
        ..DetectOptions::default()
    };
    let mut mean = [0.0; 3];
    for &seed in seeds {
        let board = views(cam, "chessboard:9x6:30mm", &[&default], seed);
        let circles = views(cam, spec, &[&default, &ellipse], seed);
        let e = [
            intrinsics_error(cam, &board[0]),
            intrinsics_error(cam, &circles[0]),
            intrinsics_error(cam, &circles[1]),
        ];
        eprintln!(
            "{name} {spec}, seed {seed}: intrinsics error, px: chessboard {:.4}, circles perspective_pole {:.4}, circles ellipse_centre {:.4}",
            e[0], e[1], e[2]
        );
        for (m, e) in mean.iter_mut().zip(e) {
            *m += e / seeds.len() as f64;
        }
    }
    eprintln!(
        "{name} {spec}, mean of {} draws: chessboard {:.4}, circles perspective_pole {:.4}, circles ellipse_centre {:.4}",
        seeds.len(),
        mean[0],
        mean[1],
        mean[2]
    );
    mean
}

/// The same-points comparison: circle centres at least as accurate as the
/// chessboard corners, ellipse centres worse.
fn same_points(cam: &Camera, name: &str) {
    let [chess, pole, uncorrected] = mean_errors(cam, name, "circles:9x6:30mm", &SEEDS);
    assert!(
        pole <= chess,
        "{name}: circles {pole} px, chessboard of the same views {chess} px"
    );
    assert!(
        uncorrected > pole,
        "{name}: ellipse centres {uncorrected} px vs corrected {pole} px"
    );
}

/// The asymmetric grid: its error at most `bound` px (1.3x what session 16
/// measured).
fn asymmetric(cam: &Camera, name: &str, bound: f64) {
    let [_, pole, _] = mean_errors(cam, name, "circles:4x11:20mm:asymmetric", &SEEDS_ASYMMETRIC);
    assert!(pole <= bound, "{name}: circles {pole} px, bound {bound} px");
}

#[test]
fn circle_grid_and_chessboard_of_the_same_points_std_camera() {
    // Measured: chessboard 0.1026, circles 0.0676, ellipse centres 0.3390 px.
    same_points(&Camera::example_pinhole(), "std");
}

#[test]
fn circle_grid_and_chessboard_of_the_same_points_strong_distortion() {
    // Measured: chessboard 0.0974, circles 0.0582, ellipse centres 0.0937 px.
    same_points(&Camera::example_brown(), "brown");
}

#[test]
fn asymmetric_circle_grid_std_camera() {
    // Measured: 0.0750 px (the 9x6 chessboard of the same poses: 0.0944).
    asymmetric(&Camera::example_pinhole(), "std", 0.098);
}

#[test]
fn asymmetric_circle_grid_strong_distortion() {
    // Measured: 0.1125 px (the 9x6 chessboard of the same poses: 0.1075).
    asymmetric(&Camera::example_brown(), "brown", 0.146);
}
