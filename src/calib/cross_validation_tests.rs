//! Cross-validation on synthetic scenes: the halves of the right model
//! agree within their predicted uncertainty, a wrong model's do not.

use super::*;
use crate::calib::calibrate;
use crate::camera::Camera;
use crate::synth::Scene;

/// The cross-validation of `truth` seen in `n_views` views at 0.1 px,
/// calibrated with `model`.
fn cross_validated(truth: &Camera, model: &str, n_views: usize) -> CrossValidation {
    let scene = Scene::calibration(11, truth, (10, 8), 0.03, n_views, 0.1).expect("scene");
    let options = CalibrationOptions {
        model: Distortion::named(model).expect("model"),
        ..CalibrationOptions::default()
    };
    let size = (truth.width, truth.height);
    let report = calibrate(&scene.views, size, &options).expect("fit");
    cross_validate(&scene.views, size, &options, &report).expect("cross-validation")
}

fn row<'a>(cv: &'a CrossValidation, model: &str) -> &'a HalvesDiff {
    cv.models.iter().find(|r| r.model == model).expect("row")
}

#[test]
fn a_fisheye_s_halves_agree_with_kannala_brandt_and_not_with_brown() {
    let cv = cross_validated(&Camera::example_kannala_brandt(), "brown", 24);
    let kb = row(&cv, "kannala_brandt");
    let brown = row(&cv, "brown");
    println!("{}", cv.summary);
    assert!(brown.chosen && !kb.chosen);
    assert!(kb.agree, "{kb:?}");
    assert!(kb.grid_points >= 10, "{kb:?}");
    assert!(!brown.agree, "{brown:?}");
    assert!(brown.error.is_some() || brown.ratio_median > 3.0 * kb.ratio_median);
    assert_eq!(cv.recommended.as_deref(), Some("kannala_brandt"));
    let warning = cross_validation_warning(&cv).expect("warning");
    assert!(warning.contains("--model kannala_brandt"), "{warning}");
    assert_eq!(cv.views, [12, 12]);
}

#[test]
fn a_brown_lens_s_halves_agree_with_brown_and_no_warning() {
    let cv = cross_validated(&Camera::example_brown(), "brown", 20);
    let brown = row(&cv, "brown");
    println!("{}", cv.summary);
    assert!(brown.agree, "{brown:?}");
    assert!(brown.diff_median_px < 3.0 * brown.predicted_median_px);
    assert_eq!(cv.recommended.as_deref(), Some("brown"));
    assert!(cross_validation_warning(&cv).is_none());
    // The maps are the uncertainty map's grid.
    assert_eq!(brown.diff_map_px.len(), cv.y_px.len());
    assert_eq!(brown.diff_map_px[0].len(), cv.x_px.len());
}

#[test]
fn too_few_views_are_refused_with_the_count() {
    let truth = Camera::example_brown();
    let scene = Scene::calibration(3, &truth, (10, 8), 0.03, 5, 0.1).expect("scene");
    let options = CalibrationOptions::default();
    let size = (truth.width, truth.height);
    let report = calibrate(&scene.views, size, &options).expect("fit");
    let err = cross_validate(&scene.views, size, &options, &report).unwrap_err();
    assert!(err.to_string().contains("at least 6 views, got 5"), "{err}");
}
