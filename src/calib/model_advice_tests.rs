use super::*;
use crate::api::camera::calibrate_json;
use crate::api::camera_tests::point_views;
use crate::calib::model_advice_screen::{screened_rms, FIRST_LOOK_ITERATIONS, SCREEN_ITERATIONS};
use crate::camera::Camera;
use crate::synth::Scene;
use serde_json::{json, Value};

/// The report's warnings for `n` views of `truth` (0.1 px noise) fitted
/// with `model`, and its rms.
fn warnings(truth: &Camera, model: &str, n: usize) -> (Vec<String>, f64) {
    let scene = Scene::calibration(7, truth, (9, 6), 0.03, n, 0.1).expect("scene");
    let views = point_views(&scene);
    let [w, h] = [truth.width, truth.height];
    let input = json!({"model": model, "views": views, "image_size_px": [w, h]});
    let out: Value =
        serde_json::from_str(&calibrate_json(&input.to_string()).expect("solve")).unwrap();
    let report = &out["report"];
    let list = report["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap().to_string())
        .collect();
    (list, report["rms_px"].as_f64().unwrap())
}

#[test]
fn growth_with_the_radius_is_measured_from_the_principal_point() {
    let scene = Scene::calibration(7, &Camera::example_brown(), (9, 6), 0.03, 6, 0.0).unwrap();
    let views = point_views(&scene);
    let input = json!({"model": "brown", "views": views, "image_size_px": [1024, 768]});
    let out: Value = serde_json::from_str(&calibrate_json(&input.to_string()).unwrap()).unwrap();
    let mut report: CameraCalibration = serde_json::from_value(out["report"].clone()).unwrap();
    // Noise-free: no growth.
    assert_eq!(residuals_grow_with_radius(&report), None);
    // Residuals of 0.1 px inside, 1 px outside (radius from cx, cy).
    let (cx, cy) = (report.camera_matrix[0][2], report.camera_matrix[1][2]);
    let r_max = report
        .views
        .iter()
        .flat_map(|v| v.residuals_px.iter())
        .map(|r| (r.x - cx).hypot(r.y - cy))
        .fold(0.0, f64::max);
    for v in &mut report.views {
        for r in &mut v.residuals_px {
            let radius = (r.x - cx).hypot(r.y - cy);
            (r.dx, r.dy) = if radius > 2.0 / 3.0 * r_max {
                (1.0, 0.0)
            } else {
                (0.1, 0.0)
            };
        }
    }
    let (inner, outer) = residuals_grow_with_radius(&report).expect("growth");
    assert!(
        (inner - 0.1).abs() < 1e-12 && (outer - 1.0).abs() < 1e-12,
        "{inner} {outer}"
    );
}

#[test]
fn a_model_with_coefficients_to_spare_is_called_out() {
    // Brown-Conrady truth fitted with the rational model's 12 coefficients.
    let (w, _) = warnings(&Camera::example_brown(), "rational", 10);
    let too_many: Vec<&String> = w
        .iter()
        .filter(|w| w.starts_with("too many parameters"))
        .collect();
    assert_eq!(too_many.len(), 1, "{w:?}");
    assert!(
        too_many[0].contains("the rational model's 12 coefficients"),
        "{}",
        too_many[0]
    );
    // The model of the truth gives no advice.
    let (w, rms) = warnings(&Camera::example_brown(), "brown", 10);
    assert!(rms < 0.2, "rms {rms}");
    assert!(
        !w.iter()
            .any(|w| w.starts_with("too many parameters") || w.starts_with("the residuals")),
        "{w:?}"
    );
}

#[test]
fn held_coefficients_are_not_counted() {
    // The rational model with all but k1 k2 held has 2 free coefficients:
    // not "12", and no model with fewer than 2 but the 1-coefficient division
    // can be called simpler.
    let scene = Scene::calibration(7, &Camera::example_brown(), (9, 6), 0.03, 10, 0.1).unwrap();
    let views = point_views(&scene);
    let held = ["p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4"];
    let input = json!({"model": "rational", "views": views, "image_size_px": [1024, 768],
        "options": {"fixed_coefficients": held}});
    let out: Value = serde_json::from_str(&calibrate_json(&input.to_string()).unwrap()).unwrap();
    for w in out["report"]["warnings"].as_array().unwrap() {
        let w = w.as_str().unwrap();
        assert!(!w.contains("12 coefficients"), "{w}");
        if w.starts_with("too many parameters") {
            assert!(
                w.contains("the rational model's 2 free coefficients"),
                "{w}"
            );
        }
    }
}

#[test]
fn a_fisheye_through_a_pinhole_model_is_named_with_the_model_that_fits() {
    let (w, rms) = warnings(&Camera::example_kannala_brandt(), "division", 10);
    if rms <= RESIDUAL_ALERT_PX {
        // The division model absorbed this lens: then no alarm is due.
        assert!(!w.iter().any(|w| w.starts_with("the residuals")), "{w:?}");
        return;
    }
    let alarm = w
        .iter()
        .find(|w| w.starts_with("the residuals"))
        .unwrap_or_else(|| panic!("{w:?}"));
    assert!(
        alarm.contains("the division model does not fit this lens"),
        "{alarm}"
    );
}

/// `n` views (`v0`, `v1`, ...) of a 9x6 grid of 30 mm seen by `truth`,
/// 0.1 px noise, seed 7.
fn named_views(truth: &Camera, n: usize) -> Vec<View> {
    let scene = Scene::calibration(7, truth, (9, 6), 0.03, n, 0.1).expect("scene");
    scene
        .views
        .iter()
        .enumerate()
        .map(|(i, v)| View {
            name: format!("v{i}"),
            ..v.clone()
        })
        .collect()
}

/// The advice of `n` views of `truth` (0.1 px noise) fitted with `model`.
fn advice_of(truth: &Camera, model: &str, n: usize) -> ModelAdvice {
    let views = named_views(truth, n);
    let options = CalibrationOptions {
        model: Distortion::named(model).unwrap(),
        ..CalibrationOptions::default()
    };
    let size = (truth.width, truth.height);
    let report = calibrate_with(Method::Zhang, &views, size, &options).expect("solve");
    advise(&views, size, &options, &report)
}

#[test]
fn a_fisheye_lens_is_advised_a_fisheye_model_with_its_export_formats() {
    // The 190-degree Kannala-Brandt example, calibrated with its own model:
    // the comparison has EUCM and the simpler models, and the advice keeps
    // kannala_brandt (division may fit about as well, but only JSON and
    // Halcon hold it, and it is not simpler than what OpenCV reads).
    let a = advice_of(&Camera::example_kannala_brandt(), "kannala_brandt", 10);
    assert!(
        a.half_diagonal_fov_deg > 80.0,
        "{}",
        a.half_diagonal_fov_deg
    );
    let compared: Vec<&str> = a.compared.iter().map(|f| f.model.as_str()).collect();
    assert_eq!(compared[0], "kannala_brandt");
    assert!(compared.contains(&"eucm"), "{compared:?}");
    assert_eq!(a.recommended, "kannala_brandt", "{}", a.summary);
    assert!(a.warnings.is_empty(), "{:?}", a.warnings);
    assert_eq!(
        a.export_formats,
        [
            "json",
            "opencv-yaml (cv2.fisheye)",
            "opencv-xml (cv2.fisheye)",
            "ros-yaml (equidistant)",
            "kalibr (equidistant)"
        ]
    );
    assert!(
        a.summary.starts_with("lens model: kannala_brandt (kannala_brandt fits at ")
            && a.summary.ends_with("; kannala_brandt exports to json, opencv-yaml (cv2.fisheye), opencv-xml (cv2.fisheye), ros-yaml (equidistant), kalibr (equidistant)"),
        "{}",
        a.summary
    );
    // Through Brown-Conrady the lens does not fit: the model named is a
    // fisheye one that was fitted, with its formats.
    let a = advice_of(&Camera::example_kannala_brandt(), "brown", 10);
    assert!(
        ["kannala_brandt", "eucm"].contains(&a.recommended.as_str()),
        "{}",
        a.summary
    );
    assert!(a.compared.iter().any(|f| f.model == a.recommended));
    let w = a
        .warnings
        .first()
        .unwrap_or_else(|| panic!("{}", a.summary));
    assert!(
        w.contains(&format!(
            "switch the model to {m} (CLI: --model {m}); {m} exports to json, ",
            m = a.recommended
        )),
        "{w}"
    );
}

#[test]
fn a_normal_lens_keeps_brown_conrady_which_opencv_holds() {
    let a = advice_of(&Camera::example_brown(), "brown", 10);
    assert!(
        a.half_diagonal_fov_deg < WIDE_ANGLE_HALF_DIAGONAL_DEG,
        "{}",
        a.half_diagonal_fov_deg
    );
    assert_eq!(a.recommended, "brown", "{}", a.summary);
    assert!(
        a.export_formats.iter().any(|f| f == "opencv-yaml"),
        "{:?}",
        a.export_formats
    );
    assert!(a.summary.ends_with("; brown exports to json, opencv-yaml, opencv-xml, ros-yaml, kalibr (with k3 held at 0), mrcal, halcon, matlab"), "{}", a.summary);
    // No fisheye model was fitted for a normal lens unless it has fewer
    // coefficients than Brown-Conrady's five (all the others do).
    assert!(a
        .compared
        .iter()
        .all(|f| f.model == "brown" || f.coefficients < 5));
}

#[test]
fn of_models_that_fit_alike_the_one_more_formats_hold_is_picked() {
    let fit = |model: &str, rms_px: f64, coefficients: usize| ModelFit {
        model: model.into(),
        rms_px,
        coefficients,
    };
    let (division, eucm, kb) = (
        fit("division", 0.100, 1),
        fit("eucm", 0.1005, 2),
        fit("kannala_brandt", 0.101, 4),
    );
    // Within 2 % of the best: Kannala-Brandt (OpenCV, ROS, Kalibr) over
    // EUCM (Kalibr) and division (Halcon).
    assert_eq!(
        pick(&[&division, &eucm, &kb]).unwrap().model,
        "kannala_brandt"
    );
    // A clearly worse fit is not picked for its formats; between two that
    // two formats each hold, the fewer coefficients.
    let kb_worse = fit("kannala_brandt", 0.2, 4);
    assert_eq!(
        pick(&[&division, &eucm, &kb_worse]).unwrap().model,
        "division"
    );
    assert_eq!(pick(&[]), None);
}

#[test]
fn the_screen_never_leaves_out_a_model_that_fits_as_well() {
    // Every truth of the examples fitted with every model, 10 views at 0.1
    // px: for each alternative the screen's prediction against its full
    // refit. A model whose refit is within the advice's limit must never be
    // screened out; the prediction must not be far below the refit either
    // (it would then keep refits for nothing).
    let truths = [
        Camera::example_brown(),
        Camera::example_division(),
        Camera::example_radial_k1_k2_k5(),
        Camera::example_kannala_brandt(),
        Camera::example_eucm(),
        Camera::example_rational(),
    ];
    let models = [
        "brown",
        "division",
        "radial_k1_k2_k5",
        "kannala_brandt",
        "eucm",
    ];
    let mut failed = Vec::new();
    for truth in &truths {
        let views = named_views(truth, 10);
        let size = (truth.width, truth.height);
        for chosen in models {
            let options = CalibrationOptions {
                model: Distortion::named(chosen).unwrap(),
                ..CalibrationOptions::default()
            };
            let Ok(report) = calibrate_with(Method::Zhang, &views, size, &options) else {
                continue;
            };
            let limit = SAME_FIT_RATIO * report.rms_px + SAME_FIT_PX;
            for other in models.iter().filter(|m| **m != chosen) {
                let alternative = CalibrationOptions {
                    model: Distortion::named(other).unwrap(),
                    ..options.clone()
                };
                let full = calibrate_with(Method::Zhang, &views, size, &alternative)
                    .map(|r| r.rms_px)
                    .unwrap_or(f64::INFINITY);
                let screened = screened_rms(&views, &alternative, &report, SCREEN_ITERATIONS);
                let first = screened_rms(&views, &alternative, &report, FIRST_LOOK_ITERATIONS);
                eprintln!(
                    "{} via {chosen} ({:.4} px): {other} full {full:.4}, screen {screened:.4?}, \
                     first look {first:.4?}",
                    truth.distortion.model_name(),
                    report.rms_px
                );
                if full <= limit && screened_out(&views, &alternative, &report, limit) {
                    failed.push(format!(
                        "{} via {chosen}: {other} fits at {full} but the screen ({screened:?}, \
                         first look {first:?}) leaves it out",
                        truth.distortion.model_name()
                    ));
                }
            }
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}
