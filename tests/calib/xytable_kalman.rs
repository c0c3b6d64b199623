//! Seed 002's claim, checked on seeded synthetic scenes: when the image noise
//! is known (R estimated from a still target), the Kalman filter weighs the
//! observations by it and beats the unweighted batch least squares.
//!
//! Scene: 18 stage positions (3 x 3 grid at two heights), camera 0.6 m away,
//! anisotropic noise sigma_u = 0.05 px, sigma_v = 0.5 px (e.g. interlaced
//! video, line jitter). Over 40 seeded trials the mean error of the
//! verification point (diagonal intersection of four extra positions,
//! predicted minus its noise-free image) must be smaller for the filter;
//! measured (seed 2024): batch 0.149 px, Kalman 0.107 px.

use nalgebra::{Matrix3, Point3, Translation3, UnitQuaternion};
use robocal::calib::dlt::{normalize_scale, project};
use robocal::synth::Rng;
use robocal::workflows::xytable::{solve_xytable, StageObservation, XyTableRequest};

#[test]
fn noise_aware_kalman_beats_batch_with_anisotropic_noise() {
    let k = Matrix3::new(1200.0, 0.0, 640.0, 0.0, 1200.0, 480.0, 0.0, 0.0, 1.0);
    let pose = robocal::geometry::Pose::from_parts(
        Translation3::new(10.0, -5.0, 600.0),
        UnitQuaternion::from_euler_angles(3.0, 0.1, 0.3),
    );
    let p = normalize_scale(&(k * pose.to_homogeneous().fixed_view::<3, 4>(0, 0)));
    let (su, sv) = (0.05, 0.5);
    let verify_stage = [
        [-60.0, -50.0, 20.0],
        [60.0, -50.0, 20.0],
        [60.0, 50.0, 20.0],
        [-60.0, 50.0, 20.0],
    ];
    let truth_px = project(&p, &Point3::new(0.0, 0.0, 20.0));
    let mut rng = Rng::new(2024);
    let (mut batch_sum, mut kalman_sum) = (0.0, 0.0);
    let trials = 40;
    for _ in 0..trials {
        let obs = |s: [f64; 3], rng: &mut Rng| {
            let q = project(&p, &Point3::new(s[0], s[1], s[2]));
            StageObservation {
                stage_mm: s,
                image_px: [q.x + rng.gaussian(su), q.y + rng.gaussian(sv)],
            }
        };
        let mut observations = Vec::new();
        for z in [0.0, 40.0] {
            for x in [-100.0, 0.0, 100.0] {
                for y in [-80.0, 0.0, 80.0] {
                    observations.push(obs([x, y, z], &mut rng));
                }
            }
        }
        // Verification positions noise-free: the error is then the model's.
        let verification = verify_stage
            .iter()
            .map(|s| {
                let q = project(&p, &Point3::new(s[0], s[1], s[2]));
                StageObservation {
                    stage_mm: *s,
                    image_px: [q.x, q.y],
                }
            })
            .collect();
        let still_target_px = (0..100)
            .map(|_| [640.0 + rng.gaussian(su), 480.0 + rng.gaussian(sv)])
            .collect();
        let r = solve_xytable(&XyTableRequest {
            observations,
            verification,
            still_target_px,
            measurement_noise_px2: None,
            kalman_mode: robocal::calib::dlt_kalman::KalmanMode::Extended,
        })
        .unwrap();
        let v = r.verification.unwrap();
        assert!((v.measured_px[0] - truth_px.x).abs() < 1e-9);
        batch_sum += v.batch_error_px;
        kalman_sum += v.kalman_error_px;
    }
    let (batch, kalman) = (batch_sum / trials as f64, kalman_sum / trials as f64);
    eprintln!(
        "mean verification error over {trials} trials: batch {batch:.4} px, kalman {kalman:.4} px"
    );
    assert!(
        kalman < batch,
        "kalman {kalman} px should beat batch {batch} px"
    );
}
