//! The EKF calibration's uncertainty: the report's standard deviations are
//! the filter's own covariance (after re-linearisation), and over seeded
//! repetitions that covariance is measured against the truth (Zhang's is
//! checked in tests/calib/calib_zhang.rs).

use robocal::calib::ekf::{calibrate_ekf, EkfCalibrator, EkfOptions};
use robocal::calib::CalibrationOptions;
use robocal::camera::Distortion;
use robocal::synth::Scene;
use robocal::Camera;

fn options() -> CalibrationOptions {
    CalibrationOptions {
        model: Distortion::RadialK1K2K5 {
            k1: 0.0,
            k2: 0.0,
            k5: 0.0,
        },
        ..CalibrationOptions::default()
    }
}

const NAMES: [&str; 7] = ["fx", "fy", "cx", "cy", "k1", "k2", "k5"];

#[test]
fn report_std_is_the_filters_covariance() {
    let truth = Camera::example_radial_k1_k2_k5();
    let scene = Scene::calibration(41, &truth, (9, 6), 0.03, 8, 0.5).expect("scene");
    let ekf = EkfOptions::default();
    // A given start, so the filter below starts where calibrate_ekf does.
    let opts = CalibrationOptions {
        initial_camera: Some(Camera {
            fx: 1.05 * truth.fx,
            fy: 1.05 * truth.fy,
            ..truth.clone()
        }),
        ..options()
    };
    let report = calibrate_ekf(&scene.views, (1280, 960), &opts, &ekf).expect("ekf");
    let mut filter = EkfCalibrator::new((1280, 960), &opts, &ekf).expect("filter");
    for v in &scene.views {
        filter.add_view(v).expect("view");
    }
    let sigma = filter
        .relinearize_until_converged(ekf.relinearize_passes)
        .expect("relinearize");
    // The residual sigma estimates the injected 0.5 px (2 x 8 x 54 - 55
    // degrees of freedom: relative std ~ 1 / sqrt(2 x 809) = 2.5 %; 4x that).
    assert!((sigma - 0.5).abs() < 0.05, "sigma {sigma} px");
    let p = filter.intrinsics_covariance();
    for (i, name) in NAMES.iter().enumerate() {
        assert_eq!(report.std[*name], p[(i, i)].sqrt(), "{name}");
    }
    assert_eq!(report.std["skew"], 0.0);
    let r = report.correlation.names.iter().position(|n| n == "fx");
    let c = report.correlation.names.iter().position(|n| n == "cx");
    let (r, c) = (r.expect("fx"), c.expect("cx"));
    let want = p[(0, 2)] / (p[(0, 0)] * p[(2, 2)]).sqrt();
    assert!((report.correlation.matrix[r][c] - want).abs() < 1e-12);
    assert!(!report.warnings.iter().any(|w| w.starts_with("EKF:")));
    // Without re-linearisation the plain filter's covariance is reported,
    // with the warning that it is optimistic.
    let plain = EkfOptions {
        relinearize_passes: 0,
        ..EkfOptions::default()
    };
    let report = calibrate_ekf(&scene.views, (1280, 960), &opts, &plain).expect("ekf");
    assert!(report
        .warnings
        .iter()
        .any(|w| w.starts_with("EKF: the standard deviations are the filter's covariance")));
}

/// Measured, not wished. The plain filter (one pass, each point linearised
/// at the estimate of its time, told 0.5 px) had the truth within 3 filter
/// std in only 19 of 80 checks of fx fy cx cy (24 %) over these 20 scenes
/// (10 views, 0.5 px noise), and some runs diverged past the lens fold.
/// With the closed-form start, the filter pass told 1 px and
/// re-linearisation (module docs of robocal::calib::ekf) all 20 runs
/// converge and the truth lies within 3 std in 139 of 140 checks of fx fy
/// cx cy k1 k2 k5 (99.3 %; a consistent estimator gives 99.7 %); the one
/// miss is 3.13 std (k1 of seed 718). With the filter pass told 0.5 px
/// seed 705 still diverged (132 of 133 in the other runs). The bounds:
/// no diverged run, every check but one within 3 std, the largest |z|
/// below 3.5.
#[test]
fn the_filter_covariance_is_consistent_over_seeded_repetitions() {
    let truth = Camera::example_radial_k1_k2_k5();
    let want = [truth.fx, truth.fy, truth.cx, truth.cy, -0.25, 0.11, -0.015];
    let ekf = EkfOptions::default();
    let (mut inside, mut checks, mut diverged, mut worst) = (0, 0, 0, 0.0f64);
    for seed in 0..20 {
        let scene = Scene::calibration(700 + seed, &truth, (9, 6), 0.03, 10, 0.5).expect("scene");
        let Ok(report) = calibrate_ekf(&scene.views, (1280, 960), &options(), &ekf) else {
            diverged += 1;
            continue;
        };
        let c = &report.camera;
        let k = c.distortion.coefficients();
        let got = [c.fx, c.fy, c.cx, c.cy, k[0], k[1], k[2]];
        for (i, name) in NAMES.iter().enumerate() {
            let z = (got[i] - want[i]) / report.std[*name];
            checks += 1;
            worst = worst.max(z.abs());
            if z.abs() < 3.0 {
                inside += 1;
            }
        }
    }
    eprintln!("EKF: {inside} of {checks} within 3 std (worst {worst:.2}), {diverged} diverged");
    assert_eq!(diverged, 0, "{diverged} of 20 runs diverged");
    assert!(inside + 1 >= checks, "{inside} of {checks} within 3 std");
    assert!(worst < 3.5, "worst |z| {worst}");
}
