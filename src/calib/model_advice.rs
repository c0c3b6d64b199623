//! Advice on the lens model, from fitting the same views with the others.
//!
//! Two mistakes a report alone does not name:
//!
//! - **The model does not fit the lens** (a fisheye through Brown-Conrady):
//!   when the RMS residual is above [`RESIDUAL_ALERT_PX`], far above what
//!   detection noise gives (about 0.02-0.2 px for the project's detectors),
//!   every other model is fitted to the same views; one that halves the RMS
//!   or better is named, with both figures and the switch to make. The same
//!   when the residuals grow with the distance from the principal point
//!   (RMS in the outer third of the radius more than [`RADIAL_GROWTH`] times
//!   the inner third's and above [`RADIAL_ALERT_PX`]): the signature of a
//!   radial model that cannot follow the lens, even when the overall RMS
//!   looks small.
//! - **Too many parameters for the views** (the rational model on a dozen
//!   views): when the chosen model has more coefficients than another that
//!   fits the same views as well (RMS within [`SAME_FIT_RATIO`] plus
//!   [`SAME_FIT_PX`]), the extra coefficients fit noise; the model with the
//!   fewest coefficients among those is suggested.
//!
//! The alternatives are fitted with the user's options except held
//! coefficients (whose names belong to the chosen model); a model that fails
//! to solve is left out.

use super::compare::{calibrate_with, Method};
use super::json_api::model_from_name;
use super::report::CameraCalibration;
use super::zhang::CalibrationOptions;
use super::View;

/// RMS residual (px) above which the other models are tried.
pub const RESIDUAL_ALERT_PX: f64 = 0.5;
/// Outer-third RMS (px) above which growth with the radius counts.
pub const RADIAL_ALERT_PX: f64 = 0.3;
/// Outer-third RMS over inner-third RMS that counts as growth.
pub const RADIAL_GROWTH: f64 = 3.0;
/// Points needed in each third to judge growth.
const RADIAL_MIN_POINTS: usize = 20;

/// The RMS residual (px) of the points in the inner and the outer third of
/// the radius from the principal point, when the outer one is over
/// [`RADIAL_ALERT_PX`] and [`RADIAL_GROWTH`] times the inner one.
pub fn residuals_grow_with_radius(report: &CameraCalibration) -> Option<(f64, f64)> {
    let (cx, cy) = (report.camera_matrix[0][2], report.camera_matrix[1][2]);
    let points: Vec<(f64, f64)> = report
        .views
        .iter()
        .flat_map(|v| v.residuals_px.iter())
        .map(|r| ((r.x - cx).hypot(r.y - cy), r.dx * r.dx + r.dy * r.dy))
        .filter(|(radius, sq)| radius.is_finite() && sq.is_finite())
        .collect();
    let r_max = points.iter().map(|p| p.0).fold(0.0, f64::max);
    if !(r_max > 0.0) {
        return None;
    }
    let rms = |lo: f64, hi: f64| {
        let sel: Vec<f64> = points
            .iter()
            .filter(|p| p.0 >= lo * r_max && p.0 <= hi * r_max)
            .map(|p| p.1)
            .collect();
        (sel.len() >= RADIAL_MIN_POINTS)
            .then(|| (sel.iter().sum::<f64>() / sel.len() as f64).sqrt())
    };
    let (inner, outer) = (rms(0.0, 1.0 / 3.0)?, rms(2.0 / 3.0, 1.0)?);
    (outer > RADIAL_ALERT_PX && outer > RADIAL_GROWTH * inner).then_some((inner, outer))
}

/// Another model "fits as well" when its RMS is at most this times the
/// chosen model's, plus [`SAME_FIT_PX`].
pub const SAME_FIT_RATIO: f64 = 1.02;
/// See [`SAME_FIT_RATIO`].
pub const SAME_FIT_PX: f64 = 0.002;

/// The models tried, with the names people know them by.
const MODELS: [(&str, &str); 6] = [
    ("brown", "Brown-Conrady"),
    ("radial_k1_k2_k5", "radial k1 k2 k5"),
    ("rational", "rational"),
    ("division", "division"),
    ("kannala_brandt", "Kannala-Brandt (fisheye)"),
    ("eucm", "EUCM"),
];

fn label(model: &str) -> &str {
    MODELS
        .iter()
        .find(|(n, _)| *n == model)
        .map_or(model, |(_, l)| l)
}

fn coefficient_count(model: &str) -> usize {
    model_from_name(model).map_or(0, |d| d.coefficients().len())
}

/// Warnings about the lens model of `report`, fitted from `views` with
/// `options`; empty when the model fits and is not over-parameterised.
pub fn advise_model(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
    report: &CameraCalibration,
) -> Vec<String> {
    let chosen = report.model.as_str();
    // Coefficients held at 0 are not fitted: they count for nothing.
    let held = model_from_name(chosen).map_or(0, |d| {
        let names = d.coefficient_names();
        let held = &options.fixed_coefficients;
        names
            .iter()
            .filter(|n| held.iter().any(|h| h == *n))
            .count()
    });
    let n_chosen = coefficient_count(chosen) - held;
    let free = if held > 0 { " free" } else { "" };
    let radial = residuals_grow_with_radius(report);
    let far_off = report.rms_px > RESIDUAL_ALERT_PX || radial.is_some();
    let simpler_exists = MODELS.iter().any(|(m, _)| coefficient_count(m) < n_chosen);
    if !far_off && !simpler_exists {
        return Vec::new();
    }
    let mut fits: Vec<(&str, f64, usize)> = Vec::new();
    for (name, _) in MODELS {
        let n = coefficient_count(name);
        if name == chosen || (!far_off && n >= n_chosen) {
            continue;
        }
        let Ok(model) = model_from_name(name) else {
            continue;
        };
        let alternative = CalibrationOptions {
            model,
            fixed_coefficients: Vec::new(),
            ..options.clone()
        };
        if let Ok(r) = calibrate_with(Method::Zhang, views, image_size_px, &alternative) {
            if r.rms_px.is_finite() {
                fits.push((name, r.rms_px, n));
            }
        }
    }
    let mut advice = Vec::new();
    if let (Some((inner, outer)), false) = (radial, report.rms_px > RESIDUAL_ALERT_PX) {
        let best = fits
            .iter()
            .filter(|f| f.1 <= 0.7 * report.rms_px)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some(&(name, rms, _)) = best {
            advice.push(format!(
                "the residuals grow with the distance from the image centre (rms {outer:.3} px \
                 in the outer third against {inner:.3} px in the centre): the {} model does \
                 not follow this lens; {} fits the same views at {rms:.3} px against {:.3} px: \
                 switch the model to {name} (CLI: --model {name})",
                label(chosen),
                label(name),
                report.rms_px
            ));
        }
        return advice;
    }
    if far_off {
        let best = fits
            .iter()
            .filter(|f| f.1 <= 0.5 * report.rms_px)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match best {
            Some(&(name, rms, _)) => advice.push(format!(
                "the residuals (rms {:.3} px) are far above detection noise: the {} model \
                 does not fit this lens; {} fits the same views at {:.3} px ({:.0}x lower): \
                 switch the model to {name} (CLI: --model {name})",
                report.rms_px,
                label(chosen),
                label(name),
                rms,
                report.rms_px / rms
            )),
            None => advice.push(format!(
                "the residuals (rms {:.3} px) are far above detection noise (below {} px \
                 expected) and no other lens model fits much better: check the target spec \
                 and its printed size, and exclude views with wrong detections",
                report.rms_px, RESIDUAL_ALERT_PX
            )),
        }
        return advice;
    }
    let simplest = fits
        .iter()
        .filter(|f| f.2 < n_chosen && f.1 <= SAME_FIT_RATIO * report.rms_px + SAME_FIT_PX)
        .min_by(|a, b| a.2.cmp(&b.2).then(a.1.total_cmp(&b.1)));
    if let Some(&(name, rms, n)) = simplest {
        advice.push(format!(
            "too many parameters for these views: the {} model's {n_chosen}{free} coefficients \
             fit at {:.3} px, and {} with {n} fits as well ({:.3} px), so the extra ones fit \
             noise and their values mean nothing: use {name} (CLI: --model {name}), or add \
             views that fill the image corners",
            label(chosen),
            report.rms_px,
            label(name),
            rms
        ));
    }
    advice
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calib::json_api::calibrate_json;
    use crate::calib::json_api_tests::point_views;
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
        let out: Value =
            serde_json::from_str(&calibrate_json(&input.to_string()).unwrap()).unwrap();
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
        let out: Value =
            serde_json::from_str(&calibrate_json(&input.to_string()).unwrap()).unwrap();
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
}
