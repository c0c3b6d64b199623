//! The Scheimpflug (tilted-sensor) model, issue 40: a laser-profiler
//! camera whose sensor is tilted by about 3 and -2 degrees
//! ([`Camera::example_tilted`]) calibrated with the `tilted` model.
//!
//! The tilt is seen only through the lens distortion (without it a tilted
//! sensor is a pinhole with another camera matrix, src/camera/tilt.rs), so
//! the truth has barrel distortion. The coefficients a laser profiler's
//! lens does not need (rational k4 k5 k6, thin prism s1..s4) are held at 0,
//! as OpenCV users pass `CALIB_TILTED_MODEL` with `CALIB_FIX_K4..K6`.

use robocal::calib::{calibrate, CalibrationOptions};
use robocal::detect::{detect, DetectOptions};
use robocal::synth::{board_pose, render, RenderOptions, Scene};
use robocal::target::Target;
use robocal::{Camera, Distortion};

/// The coefficients held at 0 in every fit here.
const HELD: [&str; 7] = ["k4", "k5", "k6", "s1", "s2", "s3", "s4"];

fn options() -> CalibrationOptions {
    CalibrationOptions {
        model: Distortion::named("tilted").expect("the tilted model"),
        fixed_coefficients: HELD.iter().map(|s| s.to_string()).collect(),
        ..CalibrationOptions::default()
    }
}

/// (tau_x, tau_y) of a camera, degrees.
fn tau_deg(c: &Camera) -> (f64, f64) {
    match c.distortion {
        Distortion::Tilted { tau_x, tau_y, .. } => (tau_x.to_degrees(), tau_y.to_degrees()),
        ref other => panic!("not the tilted model: {}", other.model_name()),
    }
}

#[test]
fn noise_free_points_give_back_the_tilt_exactly() {
    let truth = Camera::example_tilted();
    let scene = Scene::calibration(11, &truth, (9, 6), 0.03, 15, 0.0).expect("scene");
    let report = calibrate(&scene.views, (truth.width, truth.height), &options())
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(report.rms_px < 1e-8, "rms {} px", report.rms_px);
    for ((n, got), want) in report
        .camera
        .param_names()
        .iter()
        .zip(report.camera.params())
        .zip(truth.params())
    {
        assert!(
            (got - want).abs() < 1e-7 * want.abs().max(1.0),
            "{n}: {got} vs {want}"
        );
    }
}

/// 0.2 px of noise on every coordinate, five seeded scenes of 15 views:
/// the tilt comes back within 4 of its reported standard deviations (the
/// tilt is seen only through the distortion, so its deviation is large:
/// about 0.4 degree here, see docs/lens-models.md), and the deviation
/// itself is honest (the RMS of the errors over the scenes, in deviations,
/// between 0.3 and 2).
#[test]
fn noisy_points_give_back_the_tilt_within_its_uncertainty() {
    let truth = Camera::example_tilted();
    let (tx, ty) = tau_deg(&truth);
    let (mut worst, mut sum_sq, mut n) = (0.0_f64, 0.0, 0.0);
    for seed in 21..26 {
        let scene = Scene::calibration(seed, &truth, (9, 6), 0.03, 15, 0.2).expect("scene");
        let report = calibrate(&scene.views, (truth.width, truth.height), &options())
            .unwrap_or_else(|e| panic!("{e}"));
        let (gx, gy) = tau_deg(&report.camera);
        let std = |k: &str| report.std.get(k).copied().unwrap_or(f64::NAN).to_degrees();
        let (sx, sy) = (std("tau_x"), std("tau_y"));
        eprintln!(
            "seed {seed}: tau_x {gx:.4} deg (truth {tx:.4}, std {sx:.4}), tau_y {gy:.4} deg (truth {ty:.4}, std {sy:.4}), rms {:.3} px",
            report.rms_px
        );
        for z in [(gx - tx) / sx, (gy - ty) / sy] {
            assert!(z.is_finite(), "seed {seed}: no standard deviation for tau");
            worst = worst.max(z.abs());
            sum_sq += z * z;
            n += 1.0;
        }
    }
    let rms_z = (sum_sq / n).sqrt();
    eprintln!(
        "noise 0.2 px, 5 scenes of 15 views: tau errors {rms_z:.2} std RMS, worst {worst:.2} std"
    );
    assert!(worst < 4.0, "worst tau error {worst} std");
    assert!(rms_z > 0.3 && rms_z < 2.0, "tau errors {rms_z} std RMS");
}

/// The renderer draws through the tilted camera (its truth points are the
/// model's projections) and the detected corners calibrate the tilt back.
#[test]
fn rendered_boards_through_a_tilted_sensor_calibrate_back() {
    let truth = Camera::example_tilted();
    let target = Target::parse_spec("chessboard:9x6:30mm").expect("spec");
    let poses = [
        ((0.5, -0.5, 0.2), (0.0, 0.0, 0.55)),
        ((-0.35, 0.5, -0.4), (0.06, -0.04, 0.5)),
        ((0.45, 0.25, 0.9), (-0.07, 0.05, 0.55)),
        ((-0.5, -0.3, 0.1), (0.05, 0.05, 0.6)),
        ((0.2, 0.55, -0.2), (-0.05, -0.03, 0.5)),
        ((-0.3, -0.45, 1.4), (0.0, 0.06, 0.6)),
        ((0.4, 0.4, -0.6), (0.08, 0.05, 0.6)),
        ((-0.45, 0.2, 0.5), (-0.08, -0.05, 0.55)),
        ((0.1, -0.45, -1.0), (0.07, -0.06, 0.6)),
        ((0.0, 0.0, 0.3), (-0.04, 0.03, 0.42)),
    ];
    let mut views = Vec::new();
    for (k, (rpy, at)) in poses.iter().enumerate() {
        let pose = board_pose(&target, *rpy, *at);
        let o = RenderOptions {
            seed: 40 + k as u64,
            ..RenderOptions::default()
        };
        let r = render(&truth, &target, &pose, &o).expect("render");
        assert_eq!(r.points.len(), target.point_count(), "view {k}");
        // The renderer's truth is the model's own projection.
        let object = target.object_points();
        for p in &r.points {
            let (_, o) = object.iter().find(|(id, _)| *id == p.id).expect("id");
            let q = truth.project(&(pose * o)).expect("projects");
            assert!(
                (q.x - p.x_px).abs() + (q.y - p.y_px).abs() < 1e-9,
                "view {k}"
            );
        }
        let det = detect(&r.image, &target, &DetectOptions::default())
            .unwrap_or_else(|e| panic!("view {k}: {e}"));
        views.push(robocal::calib::View::from_detection(
            format!("view{k}"),
            &det,
        ));
    }
    let report = calibrate(&views, (truth.width, truth.height), &options())
        .unwrap_or_else(|e| panic!("{e}"));
    let (tx, ty) = tau_deg(&truth);
    let (gx, gy) = tau_deg(&report.camera);
    let std = |k: &str| report.std.get(k).copied().unwrap_or(f64::NAN).to_degrees();
    let (sx, sy) = (std("tau_x"), std("tau_y"));
    eprintln!(
        "rendered: tau_x {gx:.4} deg (truth {tx:.4}, std {sx:.4}), tau_y {gy:.4} deg (truth {ty:.4}, std {sy:.4}), rms {:.4} px",
        report.rms_px
    );
    // Measured: 0.08 degree off each at 0.012 px RMS (the renderer's noise).
    assert!((gx - tx).abs() < 0.2 && (gy - ty).abs() < 0.2);
    assert!((gx - tx).abs() < 4.0 * sx && (gy - ty).abs() < 4.0 * sy);
    assert!((report.camera.fx - truth.fx).abs() < 2.0);
}
