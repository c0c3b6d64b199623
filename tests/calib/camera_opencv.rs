//! Agreement with OpenCV 4.14 (`cv2.projectPoints`, `cv2.fisheye.projectPoints`)
//! on the recorded fixture `fixtures/opencv_project_points.json`
//! (regenerate with `python3 tools/opencv_reference.py`).
//!
//! Tolerance: 1e-9 relative to the pixel coordinate. Both sides evaluate the
//! same closed-form expressions in double precision, so they differ only by
//! rounding (~1e-13 px); 1e-9 leaves room for a different operation order.

use nalgebra::Point3;
use robocal::{Camera, Distortion};
use serde_json::Value;

const FIXTURE: &str = include_str!("../../fixtures/opencv_project_points.json");

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn camera_of(case: &Value) -> Camera {
    let k = numbers(&case["camera_matrix_row_major"]);
    let d = numbers(&case["opencv_dist_coeffs"]);
    let template = match case["model"].as_str().expect("model") {
        "brown" => Camera::example_brown(),
        "rational" => Camera::example_rational(),
        "kannala_brandt" => Camera::example_kannala_brandt(),
        other => panic!("unknown model {other}"),
    };
    // OpenCV's fisheye skew is alpha = skew / fx; its pinhole model ignores K[0][1].
    let skew = case["fisheye_alpha"]
        .as_f64()
        .map_or(k[1], |alpha| alpha * k[0]);
    let mut params = vec![k[0], k[4], k[2], k[5], skew];
    params.extend(d);
    template.with_params(&params).expect("valid parameters")
}

#[test]
fn projections_match_opencv() {
    let fixture: Value = serde_json::from_str(FIXTURE).expect("fixture JSON");
    let cases = fixture["cases"].as_array().expect("cases");
    assert_eq!(cases.len(), 3);
    for case in cases {
        let camera = camera_of(case);
        let model = camera.distortion.model_name();
        let points = case["points_camera_m"].as_array().expect("points");
        let pixels = case["pixels_px"].as_array().expect("pixels");
        assert_eq!(points.len(), 200);
        let mut worst: f64 = 0.0;
        for (p, px) in points.iter().zip(pixels) {
            let p = numbers(p);
            let expected = numbers(px);
            let got = camera
                .project(&Point3::new(p[0], p[1], p[2]))
                .unwrap_or_else(|e| panic!("{model}: {e}"));
            for (g, e) in [got.x, got.y].iter().zip(&expected) {
                let rel = (g - e).abs() / e.abs().max(1.0);
                worst = worst.max(rel);
                assert!(rel < 1e-9, "{model}: {g} px vs OpenCV {e} px");
            }
        }
        eprintln!("{model}: worst relative difference to OpenCV {worst:.2e}");
    }
    // The fixture covers the models it claims to.
    let models: Vec<_> = cases.iter().map(|c| camera_of(c).distortion).collect();
    assert!(matches!(models[1], Distortion::Rational { s4, .. } if s4 != 0.0));
}
