//! Intrinsics from circle grids against intrinsics from chessboards of the
//! same views (issue 20): the same twelve board poses (tilts 20-49 degrees)
//! rendered at 1280x960 with noise sigma 2 as a 9x6 chessboard and as a 4x11
//! asymmetric circle grid, detected, and calibrated with the same model
//! (Brown k1 k2 k3 p1 p2). The error is the distance of (fx, fy, cx, cy)
//! from the truth, px, averaged over three noise draws.
//!
//! Why averaged, and why twelve views: one noise draw of six views moved
//! the error by 0.1-0.2 px from seed to seed on the strongly distorted
//! camera, several times the differences between the centre models, and
//! flipped their ranking (BENCHMARKS.md, issue 20, sessions 12 and 13).
//! The test is to measure the centres, not one draw.
//!
//! Bounds. Issue 20 asks the perspective-correct circle centres to
//! calibrate at least as accurately as the chessboard corners. They did
//! (session 13: strong distortion chessboard 0.239, circles 0.116, ellipse
//! centres 0.137 px; 'std' camera 0.163, 0.126, 0.209 px) until the
//! chessboard's saddle fit lost its pixel-phase bias (session 14,
//! src/detect/refine.rs): the chessboard now gives 0.108 px (strong) and
//! 0.094 px ('std'), ahead of the circles, so that goal is open again
//! (BENCHMARKS.md, "Chessboard corners: the fit points' phase"). Asserted
//! here: the uncorrected ellipse centres, biased by up to 0.3 px in the
//! tilted views, do worse than the corrected ones (so the centre model is
//! measured), and neither target's error exceeds 1.3x what session 14
//! measured (the chessboard's bound fails on the biased fit of before).

use robocal::calib::{calibrate, CalibrationOptions, View};
use robocal::camera::Camera;
use robocal::detect::{detect, CentreModel, DetectOptions};
use robocal::synth::{board_pose, render, RenderOptions};
use robocal::target::Target;

/// Board poses: roll-pitch-yaw (rad) and position (m) of the board centre.
const POSES: [((f64, f64, f64), (f64, f64, f64)); 12] = [
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

/// Noise seeds of the three draws (view k of a draw uses seed + k).
const SEEDS: [u64; 3] = [70, 170, 270];

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

/// `bounds`: the largest accepted mean error of the chessboard and of the
/// perspective-correct circle centres, px.
fn compare(cam: &Camera, name: &str, bounds: (f64, f64)) {
    let default = DetectOptions::default();
    let ellipse = DetectOptions {
        circle_centres: CentreModel::EllipseCentre,
        ..DetectOptions::default()
    };
    let (mut chess, mut pole, mut uncorrected) = (0.0, 0.0, 0.0);
    for seed in SEEDS {
        let board = views(cam, "chessboard:9x6:30mm", &[&default], seed);
        let circles = views(
            cam,
            "circles:4x11:20mm:asymmetric",
            &[&default, &ellipse],
            seed,
        );
        let e = [
            intrinsics_error(cam, &board[0]),
            intrinsics_error(cam, &circles[0]),
            intrinsics_error(cam, &circles[1]),
        ];
        eprintln!(
            "{name}, seed {seed}: intrinsics error, px: chessboard {:.4}, circles perspective_pole {:.4}, circles ellipse_centre {:.4}",
            e[0], e[1], e[2]
        );
        chess += e[0] / SEEDS.len() as f64;
        pole += e[1] / SEEDS.len() as f64;
        uncorrected += e[2] / SEEDS.len() as f64;
    }
    eprintln!(
        "{name}, mean of {} draws: chessboard {chess:.4}, circles perspective_pole {pole:.4}, circles ellipse_centre {uncorrected:.4}",
        SEEDS.len()
    );
    assert!(
        chess <= bounds.0,
        "{name}: chessboard {chess} px, bound {} px",
        bounds.0
    );
    assert!(
        pole <= bounds.1,
        "{name}: circles {pole} px, bound {} px",
        bounds.1
    );
    assert!(
        uncorrected > pole,
        "{name}: ellipse centres {uncorrected} px vs corrected {pole} px"
    );
}

#[test]
fn circle_grid_and_chessboard_intrinsics_std_camera() {
    // Measured: chessboard 0.0944, circles 0.1259, ellipse centres 0.2090 px.
    compare(&Camera::example_pinhole(), "std", (0.123, 0.164));
}

#[test]
fn circle_grid_and_chessboard_intrinsics_strong_distortion() {
    // Measured: chessboard 0.1075, circles 0.1162, ellipse centres 0.1369 px.
    compare(&Camera::example_brown(), "brown", (0.140, 0.151));
}
