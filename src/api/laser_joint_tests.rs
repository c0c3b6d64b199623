//! The camera refined jointly with the laser plane, on rendered pairs
//! from a perturbed start camera.

use super::*;
use crate::synth::laser::{laser_pair, LaserStripe};
use crate::synth::laser_scene::{example_plane, laser_board_poses};

fn views(camera: &Camera, target: &Target, n: usize) -> Vec<LaserView> {
    laser_board_poses(n)
        .iter()
        .enumerate()
        .map(|(i, pose)| {
            let seed = 40 + 2 * i as u64;
            let mut laser = LaserStripe::new(example_plane());
            laser.seed = seed;
            let (board, stripe) =
                laser_pair(camera, target, pose, &laser, seed).unwrap_or_else(|e| panic!("{e}"));
            LaserView {
                name: format!("pose {i}"),
                board,
                stripe: Some(stripe),
            }
        })
        .collect()
}

/// Normal angle (deg) and distance (mm) of a report's plane from the truth.
fn plane_error(report: &LaserPlaneReport) -> (f64, f64) {
    let truth = example_plane();
    let n = nalgebra::Vector3::from(report.laser_plane.normal_camera);
    let angle = n
        .dot(&truth.normal.into_inner())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees();
    (
        angle,
        (report.laser_plane.distance_m - truth.distance_m).abs() * 1e3,
    )
}

/// The plane's offset (mm) where the stripes are: at the true plane's
/// point 0.5 m down the optical axis (the boards are 0.45-0.55 m away; the
/// distance of [`plane_error`] is taken at the camera centre, 0.1 m from
/// the plane, where a normal error alone moves it: BENCHMARKS.md 18, s26).
fn offset_at_stripes_mm(report: &LaserPlaneReport) -> f64 {
    let n = nalgebra::Vector3::from(report.laser_plane.normal_camera);
    (n.dot(&nalgebra::Vector3::new(0.0, 0.0, 0.5)) - report.laser_plane.distance_m).abs() * 1e3
}

#[test]
fn refining_the_camera_with_the_plane_undoes_a_perturbed_start() {
    let truth = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.025,
    };
    let views = views(&truth, &target, 5);
    // A start 2 % off in focal length and 5 px off in the centre.
    let start = Camera::pinhole(816.0, 816.0, 325.0, 236.0, 640, 480);
    let settings = LaserPlaneSettings::default();
    let plain = laser_plane(&start, &target, &views, &settings).unwrap_or_else(|e| panic!("{e}"));
    let (joint, camera) = laser_plane_refining_camera(&start, &target, &views, &settings)
        .unwrap_or_else(|e| panic!("{e}"));
    let (a0, d0) = plane_error(&plain);
    let (a1, d1) = plane_error(&joint);
    eprintln!(
        "at the stripes: {:.3} mm joint, {:.3} mm start camera",
        offset_at_stripes_mm(&joint),
        offset_at_stripes_mm(&plain)
    );
    eprintln!(
        "joint refinement: camera fx {:.2} fy {:.2} cx {:.2} cy {:.2}; plane off {a1:.4} deg {d1:.3} mm \
         (std {:.4} deg {:.3} mm), with the start camera {a0:.4} deg {d0:.3} mm",
        camera.fx,
        camera.fy,
        camera.cx,
        camera.cy,
        joint.laser_plane.normal_std_deg,
        joint.laser_plane.distance_std_mm
    );
    assert!(
        (camera.fx - 800.0).abs() < 2.0 && (camera.fy - 800.0).abs() < 2.0,
        "{camera:?}"
    );
    assert!(
        (camera.cx - 320.0).abs() < 2.0 && (camera.cy - 240.0).abs() < 2.0,
        "{camera:?}"
    );
    // The start camera biases the plane; the refined one does not.
    assert!(a1 < a0 && d1 < d0, "{a1} {d1} vs {a0} {d0}");
    // Where the stripes are: 0.056 mm against 0.554 (2026-12-07).
    assert!(
        offset_at_stripes_mm(&joint) < 0.2,
        "{}",
        offset_at_stripes_mm(&joint)
    );
    assert!(
        a1 < 3.0 * joint.laser_plane.normal_std_deg.max(0.005)
            && d1 < 3.0 * joint.laser_plane.distance_std_mm.max(0.02),
        "{a1} deg {d1} mm"
    );
    assert!(joint
        .warnings
        .iter()
        .any(|w| w.starts_with("the camera was refined with the plane")));
    // Fewer than 3 poses: an error that says so.
    let err = laser_plane_refining_camera(&start, &target, &views[..2], &settings).unwrap_err();
    assert_eq!(
        err.to_string(),
        "requires at least 3 board poses to refine the camera with the plane, got 2"
    );
}

/// A tilted (Scheimpflug) sensor: its tilt trades with the principal point
/// (a near-rotation of the camera the plane's normal follows), which the
/// laser images' boards cannot separate. The joint refinement holds the
/// tilt, the principal point and p1, p2 at the given camera's, says so, and
/// refines the focal lengths and the radial terms: from a start with the
/// board calibration's tilt error (tau 0.11 / 0.31 deg, cx 4.3 px off, as
/// `robocal intrinsics --model tilted` gave in tests/cli/cli_laser.rs) and
/// fx 1 % off, fx comes back to within 6 px (measured 795.6: it takes up
/// part of the held parameters' error, corner RMS 0.14 px from 0.31) and
/// the plane stays within 0.3 deg and 0.8 mm (what the fx bound allows;
/// measured 0.026 deg, 0.59 mm, 2026-12-07 s26).
/// Every parameter free, the CLI workflow's joint refinement drifted 1.40
/// deg (BENCHMARKS.md section 18).
#[test]
fn a_tilted_camera_keeps_its_tilt_when_refined_with_the_plane() {
    let truth = Camera {
        distortion: Camera::example_tilted().distortion,
        ..Camera::pinhole(800.0, 800.0, 319.5, 239.5, 640, 480)
    };
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.025,
    };
    let views = views(&truth, &target, 6);
    let mut p = truth.params();
    let names = truth.param_names();
    let at = |n: &str| names.iter().position(|m| *m == n).unwrap_or(usize::MAX);
    p[at("fx")] = 808.0;
    p[at("cx")] += 4.3;
    p[at("tau_x")] = 0.052 - 0.11f64.to_radians();
    p[at("tau_y")] = -0.035 + 0.31f64.to_radians();
    let start = truth.with_params(&p).unwrap_or_else(|e| panic!("{e}"));
    let settings = LaserPlaneSettings::default();
    let (joint, camera) = laser_plane_refining_camera(&start, &target, &views, &settings)
        .unwrap_or_else(|e| panic!("{e}"));
    let (a1, d1) = plane_error(&joint);
    let c1 = offset_at_stripes_mm(&joint);
    eprintln!(
        "tilted joint: fx {:.2} fy {:.2}; plane off {a1:.4} deg {d1:.3} mm, {c1:.3} mm at the stripes; {:?}",
        camera.fx, camera.fy, joint.warnings
    );
    let q = camera.params();
    for n in ["cx", "cy", "p1", "p2", "tau_x", "tau_y", "skew", "k4", "s1"] {
        assert_eq!(q[at(n)], p[at(n)], "{n} moved");
    }
    assert!((camera.fx - 800.0).abs() < 6.0, "fx {}", camera.fx);
    // fx 6 px (0.75 %) off scales the boards' depths, which moves the
    // plane where the stripes are by 0.5 m * n_z * 0.75 % = 0.74 mm (n_z
    // 0.196): the bound follows the fx bound. Measured 2026-12-07 (s26,
    // centres weighted by std^2 + floor^2): fx 795.6, 0.026 deg, 0.59 mm at
    // the camera centre and 0.64 mm at the stripes (s24's 1 / std^2
    // weights: 0.047 deg, 0.40 mm); 2026-12-08 (s29, variances ranked by
    // the std, the joint's stripe weighted by them too): fx 797.0, 0.023
    // deg, 0.57 mm, 0.48 mm at the stripes.
    assert!(
        a1 < 0.3 && d1 < 0.8 && c1 < 0.8,
        "plane off {a1} deg {d1} mm, {c1} mm at the stripes"
    );
    assert!(
        joint.warnings.iter().any(|w| w
            == "tilted camera: its tilt (tau_x, tau_y), principal point and p1, p2 were held at \
                the given camera's (the boards cannot separate them: they trade with each other \
                as a near-rotation of the camera, which the plane's normal follows); refined: \
                fx, fy, k1, k2, k3"),
        "{:?}",
        joint.warnings
    );
}
