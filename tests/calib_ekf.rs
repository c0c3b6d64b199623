//! The EKF calibration's uncertainty: the report's standard deviations are
//! the filter's own covariance, and over seeded repetitions that covariance
//! is measured against the truth (it is optimistic, as the report warns;
//! Zhang's is checked in tests/calib_zhang.rs).

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
    let report = calibrate_ekf(&scene.views, (1280, 960), &options(), &ekf).expect("ekf");
    let mut filter = EkfCalibrator::new((1280, 960), &options(), &ekf).expect("filter");
    for v in &scene.views {
        filter.add_view(v).expect("view");
    }
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
    assert!(report
        .warnings
        .iter()
        .any(|w| w.starts_with("EKF: the standard deviations are the filter's covariance")));
}

/// Measured, not wished: one pass of the filter linearises each point at
/// the estimate of its time and never revisits it, and the covariance
/// accounts for the pixel noise only. Over 20 seeded scenes (10 views,
/// 0.5 px noise, the filter told 0.5 px) the truth lies within 3 filter
/// std far less often than the 99.7 % a consistent estimator gives
/// (measured: 19 of 80 checks of fx fy cx cy, 24 %). This test pins that finding, which the
/// report's warning states; it fails once the filter becomes consistent,
/// and the warning must go then.
#[test]
fn the_filter_covariance_is_optimistic_over_seeded_repetitions() {
    let truth = Camera::example_radial_k1_k2_k5();
    let want = [truth.fx, truth.fy, truth.cx, truth.cy, -0.25, 0.11, -0.015];
    let ekf = EkfOptions::default();
    let (mut inside, mut total) = (0, 0);
    for seed in 0..20 {
        let scene = Scene::calibration(700 + seed, &truth, (9, 6), 0.03, 10, 0.5).expect("scene");
        let mut filter = EkfCalibrator::new((1280, 960), &options(), &ekf).expect("filter");
        // A diverged filter (a point beyond the lens fold) counts as a miss.
        let ok = scene.views.iter().try_for_each(|v| filter.add_view(v));
        let c = filter.camera().expect("camera");
        let p = filter.intrinsics_covariance();
        let k = c.distortion.coefficients();
        let got = [c.fx, c.fy, c.cx, c.cy, k[0], k[1], k[2]];
        for i in 0..4 {
            total += 1;
            if ok.is_ok() && (got[i] - want[i]).abs() < 3.0 * p[(i, i)].sqrt() {
                inside += 1;
            }
        }
    }
    let coverage = inside as f64 / total as f64;
    eprintln!("EKF: {inside} of {total} within 3 filter std");
    assert!(coverage < 0.9, "{inside} of {total} within 3 std");
}
