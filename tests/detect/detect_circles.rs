//! Circle grids and dot plates rendered by the project's renderer at
//! 1280x960, noise sigma 2 grey levels, tilts up to 49 degrees, through the
//! 'std' camera (`Camera::example_pinhole`, f = 1000 px, no distortion) and
//! the strong-distortion camera (`Camera::example_brown`, k1 = -0.28: about
//! 20 px of barrel distortion at the image corners), compared with the
//! renderer's exact projections of the circle centres.
//!
//! Tolerances (issue 20): mean centre error <= 0.03 px and max <= 0.15 px
//! per image. Their origin: 64 edge points per circle, each from a
//! mid-level crossing of a 190-level step with noise sigma 2 (about 0.03 px
//! per point at the renders' edge slope), give a centre sd of about
//! 0.03 / sqrt(32) ~ 0.006 px per axis, so noise alone stays far below the
//! bounds; the bounds test the remaining *bias*, which without the
//! perspective correction reaches 0.1-0.4 px at these tilts (the ellipse
//! centres are checked to be that far off, so the test can fail).

use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use robocal::camera::Camera;
use robocal::detect::{detect, CentreModel, DetectOptions};
use robocal::synth::{board_pose, render, RenderOptions};
use robocal::target::{DetectedPoint, Detection, Target};

/// Roll, pitch, yaw (radians) and the board centre (m, camera frame).
type ViewPose = ((f64, f64, f64), (f64, f64, f64));

/// Views: roll, pitch, yaw (radians) and the board centre (m, camera frame).
/// The first is tilted by 49 degrees, the others by 30-40 degrees and off
/// the image centre, where distortion bends the board most.
const VIEWS: [ViewPose; 3] = [
    ((0.63, -0.63, 0.2), (0.0, 0.0, 0.5)),
    ((-0.35, 0.5, -0.4), (0.08, -0.05, 0.45)),
    ((0.55, 0.25, 0.9), (-0.09, 0.06, 0.5)),
];

const SPECS: [&str; 5] = [
    "circles:4x11:20mm:asymmetric",
    "circles:4x11:20mm:asymmetric:light-on-dark",
    "circles:7x5:20mm",
    "circles:7x5:20mm:light-on-dark",
    "dots:7x7:25mm",
];

/// Mean and max distance between detection and truth, by id.
fn errors(det: &Detection, truth: &[DetectedPoint]) -> (f64, f64) {
    assert_eq!(det.points.len(), truth.len(), "point count");
    let d: Vec<f64> = det
        .points
        .iter()
        .zip(truth)
        .map(|(d, t)| {
            assert_eq!(d.id, t.id);
            ((d.x_px - t.x_px).powi(2) + (d.y_px - t.y_px).powi(2)).sqrt()
        })
        .collect();
    (
        d.iter().sum::<f64>() / d.len() as f64,
        d.iter().cloned().fold(0.0, f64::max),
    )
}

/// Detections of every centre model on each view of `spec` through `cam`:
/// `(view, model, mean px, max px)`.
fn measure(cam: &Camera, name: &str, spec: &str, seed: u64) -> Vec<(usize, CentreModel, f64, f64)> {
    let target = Target::parse_spec(spec).expect("spec");
    let mut out = Vec::new();
    for (k, (rpy, at)) in VIEWS.into_iter().enumerate() {
        let o = RenderOptions {
            seed: seed + k as u64,
            ..RenderOptions::default()
        };
        let r = render(cam, &target, &board_pose(&target, rpy, at), &o).expect("render");
        assert_eq!(
            r.points.len(),
            target.point_count(),
            "{spec} view {k}: whole board in view"
        );
        for model in CentreModel::ALL {
            let options = DetectOptions {
                circle_centres: model,
                ..DetectOptions::default()
            };
            let det = detect(&r.image, &target, &options)
                .unwrap_or_else(|e| panic!("{spec} view {k}: {e}"));
            assert_eq!(det.centre_model, Some(model));
            let (mean, max) = errors(&det, &r.points);
            eprintln!(
                "{name} {spec} view {k} {:16}: mean {mean:.4} px, max {max:.4} px",
                model.name()
            );
            out.push((k, model, mean, max));
        }
    }
    out
}

fn check(cam: &Camera, name: &str, seed: u64) {
    for spec in SPECS {
        let rows = measure(cam, name, spec, seed);
        for &(k, model, mean, max) in &rows {
            match model {
                CentreModel::PerspectivePole => assert!(
                    mean <= 0.03 && max <= 0.15,
                    "{name} {spec} view {k}: mean {mean} px, max {max} px"
                ),
                // The uncorrected centres must miss the mean bound on the
                // 49-degree view, or this test could not fail.
                CentreModel::EllipseCentre if k == 0 => assert!(
                    mean > 0.03,
                    "{name} {spec} view {k}: ellipse centres mean {mean} px"
                ),
                CentreModel::EllipseCentre | CentreModel::LocalQuadratic => {}
            }
        }
    }
}

#[test]
fn centres_on_the_std_camera_within_003_px_mean() {
    check(&Camera::example_pinhole(), "std", 300);
}

#[test]
fn centres_through_strong_distortion_within_003_px_mean() {
    check(&Camera::example_brown(), "brown", 400);
}

#[test]
fn large_circles_through_strong_distortion_within_003_px_mean() {
    // The 7x5 grid at 0.25 m: circles ~44 px across, 46 degrees tilt,
    // through the strong-distortion lens, where the lens's variation across
    // one circle is largest. Measured with the 3x3 window (noise sigma 2):
    // mean ~0.020 px, max ~0.05 px; a 5x5 window gave 0.035 / 0.077 px and
    // the ellipse centres 0.20 / 0.29 px.
    let cam = Camera::example_brown();
    for (k, spec) in ["circles:7x5:20mm", "circles:7x5:20mm:light-on-dark"]
        .into_iter()
        .enumerate()
    {
        let target = Target::parse_spec(spec).expect("spec");
        let o = RenderOptions {
            seed: 500 + k as u64,
            ..RenderOptions::default()
        };
        let pose = board_pose(&target, (0.6, -0.6, 0.2), (0.0, 0.0, 0.25));
        let r = render(&cam, &target, &pose, &o).expect("render");
        assert_eq!(r.points.len(), 35, "{spec}: whole board in view");
        for model in [CentreModel::PerspectivePole, CentreModel::EllipseCentre] {
            let options = DetectOptions {
                circle_centres: model,
                ..DetectOptions::default()
            };
            let det = detect(&r.image, &target, &options).unwrap_or_else(|e| panic!("{spec}: {e}"));
            let (mean, max) = errors(&det, &r.points);
            eprintln!(
                "{spec} large {}: mean {mean:.4} px, max {max:.4} px",
                model.name()
            );
            match model {
                CentreModel::PerspectivePole => assert!(
                    mean <= 0.03 && max <= 0.15,
                    "{spec}: mean {mean} px, max {max} px"
                ),
                CentreModel::EllipseCentre | CentreModel::LocalQuadratic => {
                    assert!(mean > 0.1, "{spec}: ellipse centres mean {mean} px")
                }
            }
        }
    }
}

#[test]
fn large_steep_circles_with_vignetting_through_strong_distortion() {
    // benches/compare_opencv.py's set circles_symmetric_steep_distorted
    // (examples/render_set.rs): the 7x5 grid filling half the image width
    // (circles ~40 px across) through the strong-distortion lens, tilted
    // 45-50 degrees, off the image centre, with vignetting and an
    // illumination gradient, noise sigma 2, blur 0.7 px. View 0 is that
    // set's image 000 (the pose, seed and lighting render_set drew): with
    // local homographies alone it gave mean 0.0332 px, max 0.111 px, the
    // error on the board's edge circles, whose windows lie on one side of
    // them; with the grid's radial distortion taken out first (src/detect/
    // centres.rs) 0.0077 / 0.021 px. Views 1-2 are two more such poses of
    // both polarities (measured 0.006-0.010 px mean, max <= 0.025 px).
    let cam = Camera::example_brown();
    let set_image_000 = Isometry3::from_parts(
        Translation3::new(
            -0.028439263132906206,
            -0.037052783402780044,
            0.2631502368388675,
        ),
        UnitQuaternion::from_euler_angles(0.1125, 0.7540, 0.0745),
    );
    let views = [
        (set_image_000, 10484784671355085727u64, 0.330, 0.210),
        (
            board_pose(
                &Target::parse_spec("circles:7x5:20mm").expect("spec"),
                (-0.75, 0.35, -0.2),
                (-0.05, 0.02, 0.25),
            ),
            601,
            0.4,
            -0.3,
        ),
        (
            board_pose(
                &Target::parse_spec("circles:7x5:20mm").expect("spec"),
                (0.3, 0.8, 1.2),
                (0.03, -0.04, 0.27),
            ),
            602,
            0.35,
            0.25,
        ),
    ];
    for spec in ["circles:7x5:20mm", "circles:7x5:20mm:light-on-dark"] {
        let target = Target::parse_spec(spec).expect("spec");
        for (k, (pose, seed, vignetting, gradient)) in views.iter().enumerate() {
            let o = RenderOptions {
                seed: *seed,
                vignetting: *vignetting,
                gradient: *gradient,
                blur_sigma_px: 0.7,
                noise_sigma: 2.0,
                ..RenderOptions::default()
            };
            let r = render(&cam, &target, pose, &o).expect("render");
            assert_eq!(r.points.len(), 35, "{spec} view {k}: whole board in view");
            let det = detect(&r.image, &target, &DetectOptions::default())
                .unwrap_or_else(|e| panic!("{spec} view {k}: {e}"));
            let (mean, max) = errors(&det, &r.points);
            eprintln!("{spec} steep vignetted view {k}: mean {mean:.4} px, max {max:.4} px");
            assert!(
                mean <= 0.03 && max <= 0.15,
                "{spec} view {k}: mean {mean} px, max {max} px"
            );
        }
    }
}
