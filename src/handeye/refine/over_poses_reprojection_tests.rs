//! The reprojection RMS of the default with image points (the pose ML with
//! each view's PnP covariance, `refine` none): every view's target points
//! projected through `x^-1 * robot[i]^-1 * y` of the refined transforms,
//! through the JSON API (the CLI, page and npm package call it).

use crate::camera::Camera;
use crate::geometry::PoseJson;
use crate::handeye::Setup;
use crate::rng::Rng;
use crate::synth::handeye_looking::{grid_pixels, looking_scene, LookingConfig};
use serde_json::{json, Value};
use wasm_bindgen_test::wasm_bindgen_test;

/// 15 views of a 9x6 board (30 mm) at 0.5 m, 1280x960 camera, exact robot
/// poses, pixel noise `sigma_px` per axis; the report of the default.
fn solve(setup: Setup, sigma_px: f64, seed: u64) -> (Value, usize) {
    let camera = Camera::pinhole(1100.0, 1100.0, 639.5, 479.5, 1280, 960);
    let config = LookingConfig {
        setup,
        views: 15,
        distance_m: 0.5,
        grid: (9, 6, 0.03),
        max_tilt_deg: 30.0,
        max_roll_deg: 60.0,
    };
    let scene = looking_scene(&config, seed);
    let pixels = grid_pixels(&scene, &camera, sigma_px, &mut Rng::new(seed + 1));
    let points: usize = pixels.iter().map(|v| v.image_px.len()).sum();
    let views: Vec<Value> = pixels
        .iter()
        .map(|v| {
            json!({
                "object_m": v.object_m.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
                "image_px": v.image_px.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>(),
            })
        })
        .collect();
    let robots: Vec<Value> = scene
        .base_from_gripper
        .iter()
        .map(|p| serde_json::to_value(PoseJson::from(p)).unwrap())
        .collect();
    let input = json!({
        "setup": setup.name(),
        "base_from_gripper": robots,
        "camera": serde_json::to_value(&camera).unwrap(),
        "views": views,
        "bootstrap_samples": 0,
        "strict_checks": false,
    });
    let out = crate::api::handeye::solve_handeye_json(&input.to_string()).unwrap();
    (serde_json::from_str(&out).unwrap(), points)
}

#[wasm_bindgen_test(unsupported = test)]
fn noise_free_points_reproject_exactly_in_both_setups() {
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        // 1e-9 px: noise-free for every purpose, without a zero pixel
        // variance for the noise estimate to meet.
        let (out, _) = solve(setup, 1e-9, 41);
        assert!(out["method"].as_str().unwrap().starts_with("refined from "));
        let p = &out["pose_refinement"];
        assert_eq!(p["camera_noise_model"], "per_view");
        let rms = out["errors"]["reprojection_rms_px"].as_f64().unwrap();
        assert!(rms < 1e-6, "{}: {rms} px", setup.name());
        assert_eq!(p["reprojection_rms_px"].as_f64().unwrap(), rms);
        let per_view = p["per_view_reprojection_rms_px"].as_array().unwrap();
        assert_eq!(per_view.len(), 15);
        assert!(per_view.iter().all(|v| v.as_f64().unwrap() < 1e-6));
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn noisy_points_reproject_at_the_pixel_noise() {
    // Exact robot poses, 0.2 px per axis: at the maximum-likelihood (x, y)
    // the mean squared 2-D residual is 2 sigma^2 (1 - 12 / (2 n)) over n
    // points (12 parameters). About 800 points: the RMS scatters by about
    // 1.8 %, so 5 % is nearly 3 spreads; the pose ML is not the pixel ML,
    // which can only raise it.
    let sigma = 0.2;
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        let (out, n) = solve(setup, sigma, 43);
        let p = &out["pose_refinement"];
        assert_eq!(p["camera_noise_model"], "per_view");
        let rms = out["errors"]["reprojection_rms_px"].as_f64().unwrap();
        let expected = sigma * (2.0 * (1.0 - 12.0 / (2.0 * n as f64))).sqrt();
        eprintln!(
            "{}: {rms:.4} px, expected {expected:.4} px over {n} points",
            setup.name()
        );
        assert!(
            (rms / expected - 1.0).abs() < 0.05,
            "{}: {rms} px vs {expected} px",
            setup.name()
        );
        assert_eq!(p["reprojection_rms_px"].as_f64().unwrap(), rms);
        // Per view (54 points, 2 x 54 residuals): within 40 % of sigma sqrt(2).
        for v in p["per_view_reprojection_rms_px"].as_array().unwrap() {
            let v = v.as_f64().unwrap();
            assert!(
                (v / (sigma * 2f64.sqrt()) - 1.0).abs() < 0.4,
                "a view at {v} px"
            );
        }
        // The starting closed form's RMS is reported beside it.
        let started = p["started_from"].as_str().unwrap();
        let closed = p["closed_form_reprojection_rms_px"].as_f64().unwrap();
        let listed = out["methods"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["method"] == started)
            .unwrap()["errors"]["reprojection_rms_px"]
            .as_f64()
            .unwrap();
        assert_eq!(closed, listed);
    }
}
