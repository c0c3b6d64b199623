//! Tests of the XY-table workflow on the seeded synthetic scene of
//! `calib::dlt::scene` (camera 0.6 m above an 18-position stage grid).

use super::*;
use crate::calib::dlt::scene;
use crate::rng::Rng;
use wasm_bindgen_test::wasm_bindgen_test;

fn observe(stage_mm: [f64; 3], noise: &mut dyn FnMut() -> f64) -> StageObservation {
    let p = project(&scene::projection(), &metres(stage_mm));
    StageObservation {
        stage_mm,
        image_px: [p.x + noise(), p.y + noise()],
    }
}

fn request(noise: &mut dyn FnMut() -> f64) -> XyTableRequest {
    let observations = scene::stage_points()
        .iter()
        .map(|p| observe([p.x * 1e3, p.y * 1e3, p.z * 1e3], noise))
        .collect();
    let verification = [
        [-50.0, -40.0, 25.0],
        [50.0, -40.0, 25.0],
        [50.0, 40.0, 25.0],
        [-50.0, 40.0, 25.0],
    ]
    .iter()
    .map(|s| observe(*s, noise))
    .collect();
    XyTableRequest {
        observations,
        verification,
        still_target_px: Vec::new(),
        measurement_noise_px2: None,
        kalman_mode: KalmanMode::Extended,
    }
}

fn relative(a: &[f64; 12], b: &Matrix3x4<f64>) -> f64 {
    (Matrix3x4::from_row_slice(a) - b).norm() / b.norm()
}

#[wasm_bindgen_test(unsupported = test)]
fn noise_free_both_methods_are_exact() {
    let r = solve_xytable(&request(&mut || 0.0)).unwrap();
    let truth = to_mm(&scene::projection());
    assert!(relative(&r.batch.projection_matrix, &truth) < 1e-9, "batch");
    assert!(
        relative(&r.kalman.projection_matrix, &truth) < 1e-9,
        "kalman"
    );
    // Depth row in mm: the stage origin is 600 mm in front of the camera
    // (camera_from_world translation z = 0.6 m).
    assert!(
        (r.batch.projection_matrix[11] - 600.0).abs() < 1e-6,
        "{}",
        r.batch.projection_matrix[11]
    );
    let v = r.verification.unwrap();
    assert!(v
        .stage_mm
        .iter()
        .zip([0.0, 0.0, 25.0])
        .all(|(a, b)| (a - b).abs() < 1e-9));
    assert!(v.batch_error_px < 1e-6 && v.kalman_error_px < 1e-6, "{v:?}");
    assert_eq!(r.kalman.history.as_ref().map(|h| h.len()), Some(18));
    assert_eq!(r.noise_source, NoiseSource::BatchResiduals);
}

#[wasm_bindgen_test(unsupported = test)]
fn noisy_estimates_and_verification_within_bounds() {
    let sigma = 0.3;
    let mut rng = Rng::new(11);
    let mut req = request(&mut || rng.gaussian(sigma));
    let centre = [320.0, 240.0];
    req.still_target_px = (0..60)
        .map(|_| {
            [
                centre[0] + rng.gaussian(sigma),
                centre[1] + rng.gaussian(sigma),
            ]
        })
        .collect();
    let r = solve_xytable(&req).unwrap();
    assert_eq!(r.noise_source, NoiseSource::StillTarget);
    // Sample variance of 60 draws: relative std sqrt(2/59) = 0.18; 3 std bound.
    for k in 0..2 {
        let var = r.measurement_noise_px2[k][k];
        assert!(
            (var / (sigma * sigma) - 1.0).abs() < 0.55,
            "R[{k}][{k}] = {var} px^2"
        );
    }
    // Residual RMS of a fit with 11 parameters on 36 scalars: about
    // sigma * sqrt(25/36) = 0.25 px; allow 2 sigma.
    assert!(r.batch.rms_px < 2.0 * sigma && r.kalman.rms_px < 2.0 * sigma);
    // Verification: measured intersection noise about sigma, prediction
    // noise about sigma * sqrt(11/36); 4 sigma covers both.
    let v = r.verification.unwrap();
    assert!(
        v.batch_error_px < 4.0 * sigma && v.kalman_error_px < 4.0 * sigma,
        "{v:?}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn bad_input_is_refused_clearly() {
    let mut req = request(&mut || 0.0);
    req.verification.truncate(3);
    assert_eq!(
        solve_xytable(&req).unwrap_err().to_string(),
        "verification: expected exactly 4 positions (A, B, C, D around a quadrilateral), got 3"
    );
    req.observations.truncate(5);
    assert_eq!(
        solve_xytable(&req).unwrap_err().to_string(),
        "requires at least 6 3-D/2-D point pairs, got 5"
    );
    let mut req = request(&mut || 0.0);
    req.observations.truncate(9);
    assert!(solve_xytable(&req)
        .unwrap_err()
        .to_string()
        .starts_with("the 9 3-D points are coplanar"));
    let mut req = request(&mut || 0.0);
    req.verification.swap(1, 2);
    // A, C, B, D: the "diagonals" are now two opposite sides of the rectangle
    // (parallel on the stage; in the image perspective makes them meet).
    assert_eq!(
        solve_xytable(&req).unwrap_err().to_string(),
        "the stage diagonals AC and BD are parallel: give A, B, C, D in order around the quadrilateral"
    );
    // More positions than the bound: refused before any solving.
    let mut req = request(&mut || 0.0);
    let one = req.observations[0];
    req.observations = vec![one; MAX_POSITIONS + 1];
    assert_eq!(
        solve_xytable(&req).unwrap_err().to_string(),
        "positions: 10001 stage positions: at most 10000 are supported; keep a subset spread \
         over the stage's volume, e.g. one in every 2"
    );
}
