//! Zhang calibration end to end on seeded synthetic scenes (noise-free:
//! exact; noisy: bounds from the injected sigma; the reported std checked
//! against the scatter over repetitions) and on Zhang's 1998 data.

use robocal::calib::{calibrate, CalibrationOptions, Severity, View};
use robocal::optim::Termination;
use robocal::synth::Scene;
use robocal::{Camera, Distortion};

fn zeros(model: &Distortion) -> Distortion {
    model
        .with_coefficients(&vec![0.0; model.coefficients().len()])
        .expect("zero coefficients")
}

fn options_for(camera: &Camera) -> CalibrationOptions {
    CalibrationOptions {
        model: zeros(&camera.distortion),
        ..CalibrationOptions::default()
    }
}

#[test]
fn noise_free_scenes_are_recovered_exactly() {
    for truth in [
        Camera::example_brown(),
        Camera::example_rational(),
        Camera::example_kannala_brandt(),
        Camera::example_radial_k1_k2_k5(),
        Camera::example_division(),
    ] {
        let name = truth.distortion.model_name();
        let mut truth = truth;
        truth.skew = 0.0;
        let scene = Scene::calibration(7, &truth, (9, 6), 0.03, 15, 0.0).expect("scene");
        let report = calibrate(
            &scene.views,
            (truth.width, truth.height),
            &options_for(&truth),
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        // Exact data: the optimum reprojects to rounding level.
        assert!(report.rms_px < 1e-9, "{name}: rms {} px", report.rms_px);
        for ((n, got), want) in report
            .camera
            .param_names()
            .iter()
            .zip(report.camera.params())
            .zip(truth.params())
        {
            // 1e-9 relative, with 1e-9 absolute for coefficients near 0.
            assert!(
                (got - want).abs() < 1e-9 * want.abs().max(1.0),
                "{name} {n}: {got} vs {want}"
            );
        }
        for (pose, view) in scene.camera_from_target.iter().zip(&report.views) {
            let t = pose.translation.vector;
            let got = view.camera_from_target.translation_m;
            assert!(
                (t.x - got[0]).abs() + (t.y - got[1]).abs() + (t.z - got[2]).abs() < 1e-9,
                "{name} pose m"
            );
        }
    }
}

#[test]
fn noisy_scene_is_within_bounds_from_sigma() {
    let truth = Camera::example_brown();
    let sigma = 0.25;
    let scene = Scene::calibration(8, &truth, (9, 6), 0.03, 20, sigma).expect("scene");
    let report = calibrate(&scene.views, (1280, 960), &options_for(&truth)).expect("calibration");
    // E|r|^2 = 2 sigma^2 (1 - p / (2N)) for N points, p parameters: rms within 5 %
    // of sigma sqrt(2) (its relative standard error with 1080 points is ~2 %).
    let n = report.n_points as f64;
    let expected = sigma * (2.0 * (1.0 - (9.0 + 6.0 * 20.0) / (2.0 * n))).sqrt();
    assert!(
        (report.rms_px / expected - 1.0).abs() < 0.05,
        "rms {} px vs {expected} px",
        report.rms_px
    );
    // Every parameter within 4 reported standard deviations of the truth.
    for ((name, got), want) in report
        .camera
        .param_names()
        .iter()
        .zip(report.camera.params())
        .zip(truth.params())
    {
        let std = report.std[*name];
        if *name == "skew" {
            assert_eq!(std, 0.0);
            continue;
        }
        assert!(
            (got - want).abs() < 4.0 * std,
            "{name}: {got} vs {want} (std {std})"
        );
    }
    // And the standard deviations are physically sensible for 0.25 px noise
    // (here the views' check, docs/camera-uncertainty.md, widens cx's std
    // to the views' disagreement, 1.25 px: each of fx, fy, cx, cy passes
    // its 2-std level by chance in 2.3 % of scenes whose views agree).
    assert!(
        report.std["fx"] < 2.0 && report.std["cx"] < 1.5,
        "{:?}",
        report.std
    );
    // Projection uncertainty (camera-frame point held fixed): at the image
    // centre it is set by the principal point's std; in the unobserved
    // corners the distortion is extrapolated and it grows.
    let grid = &report.projection_uncertainty;
    let centre = grid.std_px[3][4].expect("centre");
    let pp = report.std["cx"].hypot(report.std["cy"]);
    assert!(
        centre >= 0.9 * report.std["cx"].max(report.std["cy"]) && centre <= 1.5 * pp,
        "{centre} px vs {pp} px"
    );
    assert!(grid.std_px[0][0].expect("corner") > centre);
}

#[test]
fn reported_std_matches_the_scatter_over_repetitions() {
    let truth = Camera::example_brown();
    let sigma = 0.5;
    let trials = 100;
    let mut inside = 0;
    let mut total = 0;
    let (mut sum_sq, mut sum_std) = (0.0, 0.0);
    for seed in 0..trials {
        let scene = Scene::calibration(100 + seed, &truth, (8, 6), 0.03, 12, sigma).expect("scene");
        let report =
            calibrate(&scene.views, (1280, 960), &options_for(&truth)).expect("calibration");
        for ((name, got), want) in report
            .camera
            .param_names()
            .iter()
            .zip(report.camera.params())
            .zip(truth.params())
        {
            if *name == "skew" {
                continue;
            }
            total += 1;
            if (got - want).abs() < 3.0 * report.std[*name] {
                inside += 1;
            }
        }
        sum_sq += (report.camera.fx - truth.fx).powi(2);
        sum_std += report.std["fx"];
    }
    eprintln!("Zhang: {inside} of {total} within 3 std");
    // Gaussian: 99.73 % within 3 sigma; issue 5 asks >= 99 %.
    assert!(
        inside as f64 >= 0.99 * total as f64,
        "{inside} of {total} within 3 std"
    );
    // The observed scatter of fx and the mean reported std agree to ~7 %
    // (std of a 100-sample std); allow 35 % (5 of those).
    let observed = (sum_sq / trials as f64).sqrt();
    let reported = sum_std / trials as f64;
    assert!(
        (observed / reported - 1.0).abs() < 0.35,
        "fx scatter {observed} px vs reported {reported} px"
    );
}

#[test]
fn bad_input_is_reported() {
    let truth = Camera::example_brown();
    let scene = Scene::calibration(9, &truth, (5, 4), 0.03, 3, 0.0).expect("scene");
    let err = calibrate(
        &scene.views[..1],
        (1280, 960),
        &CalibrationOptions::default(),
    )
    .map(|_| ());
    assert_eq!(
        err.map_err(|e| e.to_string()),
        Err("requires at least 2 views, got 1".to_string())
    );
    let mut views: Vec<View> = scene.views.clone();
    views[1].image_px.pop();
    let err = calibrate(&views, (1280, 960), &CalibrationOptions::default()).map(|_| ());
    assert_eq!(
        err.map_err(|e| e.to_string()),
        Err("views[view_001].image_px: 20 target points but 19 image points".to_string())
    );
    let options = CalibrationOptions {
        fixed_coefficients: vec!["k9".into()],
        ..CalibrationOptions::default()
    };
    let err = calibrate(&scene.views, (1280, 960), &options).map(|_| ());
    assert_eq!(
        err.map_err(|e| e.to_string()),
        Err("fixed_coefficients: the brown model has no coefficient 'k9' (it has k1, k2, p1, p2, k3)".to_string())
    );
}

#[test]
fn gross_outliers_are_dropped_and_reported() {
    let truth = Camera::example_brown();
    let sigma = 0.2;
    let mut scene = Scene::calibration(21, &truth, (9, 6), 0.03, 12, sigma).expect("scene");
    let corrupt = [(0, 3), (2, 17), (5, 40), (5, 41), (11, 0)];
    for (v, i) in corrupt {
        scene.views[v].image_px[i].x += 15.0;
    }
    let options = CalibrationOptions {
        outlier_sigma: Some(5.0),
        ..options_for(&truth)
    };
    let report = calibrate(&scene.views, (1280, 960), &options).expect("calibration");
    let dropped: Vec<(usize, usize)> = report
        .views
        .iter()
        .enumerate()
        .flat_map(|(v, r)| r.outliers.iter().map(move |o| (v, o.index)))
        .collect();
    // P(|r| > 5 sigma) for an inlier is exp(-12.5) = 4e-6: none of the 643 go.
    assert_eq!(dropped, corrupt.to_vec());
    assert!(
        report.views[0].outliers[0]
            .reason
            .contains("x robust sigma"),
        "{}",
        report.views[0].outliers[0].reason
    );
    assert_eq!(report.n_points, 9 * 6 * 12 - 5);
    assert!((report.camera.fx - truth.fx).abs() < 4.0 * report.std["fx"]);
}

#[test]
fn fixed_principal_point_and_aspect_ratio_hold() {
    let mut truth = Camera::example_brown();
    truth.fy = truth.fx;
    truth.cx = 639.5;
    truth.cy = 479.5;
    let scene = Scene::calibration(22, &truth, (9, 6), 0.03, 10, 0.0).expect("scene");
    let options = CalibrationOptions {
        fix_principal_point: true,
        fix_aspect_ratio: true,
        fixed_coefficients: vec!["k3".into()],
        model: Distortion::Brown {
            k1: 0.0,
            k2: 0.0,
            k3: -0.012,
            p1: 0.0,
            p2: 0.0,
        },
        ..CalibrationOptions::default()
    };
    let report = calibrate(&scene.views, (1280, 960), &options).expect("calibration");
    let c = &report.camera;
    assert_eq!((c.cx, c.cy), (639.5, 479.5));
    assert_eq!(report.std["cx"], 0.0);
    assert_eq!(report.std["k3"], 0.0);
    // fy follows fx exactly at the initial (closed-form) ratio; the truth
    // has ratio 1, which the noise-free closed form reproduces only
    // approximately (distortion is ignored there), so fx absorbs the rest.
    let ratio = c.fy / c.fx;
    assert!((report.std["fy"] - ratio * report.std["fx"]).abs() < 1e-12);
    assert!((c.fx - truth.fx).abs() < 0.05 * truth.fx, "fx {}", c.fx);
}

#[test]
fn an_explicit_aspect_ratio_is_held_exactly_and_recovers_the_truth() {
    // The truth has fx / fy = r exactly; held at r, the noise-free optimum
    // is the truth (~1e-9 relative), unlike the closed-form ratio above.
    let truth = Camera::example_brown();
    let r = truth.fx / truth.fy;
    let scene = Scene::calibration(23, &truth, (9, 6), 0.03, 10, 0.0).expect("scene");
    let options = CalibrationOptions {
        fix_aspect_ratio: true,
        aspect_ratio: Some(r),
        ..options_for(&truth)
    };
    let report = calibrate(&scene.views, (1280, 960), &options).expect("calibration");
    let c = &report.camera;
    assert!((c.fx / c.fy - r).abs() < 1e-15, "fx/fy {}", c.fx / c.fy);
    assert!((c.fx - truth.fx).abs() < 1e-9 * truth.fx, "fx {} px", c.fx);
    assert!((c.cy - truth.cy).abs() < 1e-7, "cy {} px", c.cy);
    // Without fix_aspect_ratio the value is refused; so is a ratio <= 0.
    for (fix, ratio, message) in [
        (
            false,
            1.0,
            "aspect_ratio: is the held fx / fy: set fix_aspect_ratio too",
        ),
        (
            true,
            -1.0,
            "aspect_ratio: fx / fy must be finite and > 0, got -1",
        ),
    ] {
        let bad = CalibrationOptions {
            fix_aspect_ratio: fix,
            aspect_ratio: Some(ratio),
            ..options_for(&truth)
        };
        let err = calibrate(&scene.views, (1280, 960), &bad).expect_err("refused");
        assert_eq!(err.to_string(), message);
    }
}

#[test]
fn undetermined_parameters_give_a_warning_not_a_failure() {
    // The rational model on distortion-free data: (1 + k1 r^2) / (1 + k4 r^2)
    // is 1 for every k1 = k4, an exact null direction of J^T J.
    let truth = Camera::example_pinhole();
    let scene = Scene::calibration(23, &truth, (9, 6), 0.03, 8, 0.0).expect("scene");
    let options = options_for(&Camera::example_rational());
    let report = calibrate(&scene.views, (1280, 960), &options).expect("calibration");
    assert!(report.rms_px < 1e-9, "rms {} px", report.rms_px);
    assert!((report.camera.fx - truth.fx).abs() < 1e-9 * truth.fx);
    assert!(report.std.is_empty() && report.correlation.matrix.is_empty());
    assert!(report
        .projection_uncertainty
        .std_px
        .iter()
        .flatten()
        .all(Option::is_none));
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.starts_with("the views do not determine every camera parameter")),
        "{:?}",
        report.warnings
    );
}

/// A 1280x720 webcam with strong barrel distortion (the failure class of
/// issue 35: a Zhang fit that stopped at its iteration limit far from the
/// minimum Tsai's start finds).
fn webcam() -> Camera {
    Camera {
        fx: 910.0,
        fy: 910.0,
        cx: 645.0,
        cy: 352.0,
        skew: 0.0,
        width: 1280,
        height: 720,
        distortion: Distortion::Brown {
            k1: -0.38,
            k2: 0.18,
            k3: -0.04,
            p1: 0.0005,
            p2: -0.0003,
        },
    }
}

/// Starts perturbed over a grid (fx and fy 0.5x to 2x, independently;
/// cx 500 px and cy 300 px off) on four noisy views (0.2 px) of the
/// webcam, with the default budget of 200 iterations and a short one of
/// 25: some first starts settle in a wrong minimum (the 1.4x / 0.6x start
/// stops at 11.8 px) or hit the limit. Whatever the first start does, the
/// result reaches the cost the best start reaches (the minimum found from
/// the truth with a long budget), within 1e-6 relative in RMS, and is no
/// worse than any start it tried; or it carries the error-level warning
/// first. The tolerance: equal minima agree to the solver's cost tolerance
/// (1e-12 relative), far below 1e-6.
#[test]
fn the_best_start_wins_or_the_report_says_error() {
    let truth = webcam();
    let size = (truth.width, truth.height);
    let scene = Scene::calibration(11, &truth, (9, 6), 0.03, 4, 0.2).expect("scene");
    let options = options_for(&truth);
    let reference = calibrate(
        &scene.views,
        size,
        &CalibrationOptions {
            initial_camera: Some(truth.clone()),
            max_iterations: 5000,
            ..options.clone()
        },
    )
    .expect("from the truth");
    for budget in [200, 25] {
        let (mut failed_first, mut errors) = (0, 0);
        for (sx, sy) in [(0.5, 0.5), (0.6, 1.4), (1.4, 0.6), (2.0, 2.0), (0.8, 1.06)] {
            for (cx_off, cy_off) in [(-500.0, -300.0), (0.0, 300.0), (500.0, 300.0)] {
                let start = Camera {
                    fx: truth.fx * sx,
                    fy: truth.fy * sy,
                    cx: truth.cx + cx_off,
                    cy: truth.cy + cy_off,
                    distortion: zeros(&truth.distortion),
                    ..truth.clone()
                };
                let what = format!(
                    "budget {budget}, start fx x{sx} fy x{sy}, cx {cx_off:+} cy {cy_off:+} px"
                );
                let report = calibrate(
                    &scene.views,
                    size,
                    &CalibrationOptions {
                        initial_camera: Some(start),
                        max_iterations: budget,
                        ..options.clone()
                    },
                )
                .unwrap_or_else(|e| panic!("{what}: {e}"));
                if let Some(first) = report.starts.first() {
                    let stalled = first.rms_px > 1.01 * reference.rms_px;
                    if stalled || first.termination == Termination::MaxIterations {
                        failed_first += 1;
                    }
                    let lowest = report
                        .starts
                        .iter()
                        .map(|s| s.rms_px)
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        report.rms_px <= lowest * (1.0 + 1e-9),
                        "{what}: rms {} px above the best start's {lowest} px",
                        report.rms_px
                    );
                }
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
                    (report.rms_px - reference.rms_px).abs() <= 1e-6 * reference.rms_px,
                    "{what}: rms {} px, the best start reaches {} px (start {:?}, starts {:?})",
                    report.rms_px,
                    reference.rms_px,
                    report.start,
                    report.starts
                );
            }
        }
        eprintln!(
            "budget {budget}: {failed_first} of 15 first starts stalled or hit the limit, \
             {errors} reports at error level; minimum {:.4} px",
            reference.rms_px
        );
        assert!(
            failed_first >= 1,
            "budget {budget}: no first start failed: the test shows nothing"
        );
    }
}

/// With a budget of 2 iterations no start converges: the report says so at
/// error level, first, naming every start tried.
#[test]
fn a_fit_that_converges_from_no_start_is_an_error_level_report() {
    let truth = webcam();
    let scene = Scene::calibration(11, &truth, (9, 6), 0.03, 4, 0.2).expect("scene");
    let report = calibrate(
        &scene.views,
        (truth.width, truth.height),
        &CalibrationOptions {
            max_iterations: 2,
            ..options_for(&truth)
        },
    )
    .expect("a report");
    assert_eq!(report.severity, Severity::Error);
    assert_eq!(report.termination, Termination::MaxIterations);
    assert_eq!(report.starts.len(), 6, "{:?}", report.starts);
    assert!(
        report.warnings[0].starts_with(
            "error: the fit did not converge: from the best of 6 starts (closed_form, tsai, \
             square_pixels, centred_principal_point, square_pixels_centred, \
             distortion_held_then_freed) the solver stopped at its iteration limit ("
        ),
        "{}",
        report.warnings[0]
    );
    assert!(report.warnings[1..]
        .iter()
        .all(|w| !w.starts_with("error: ")));
}
