//! The camera refined jointly with the laser plane, on rendered pairs
//! from a perturbed start camera.

use super::*;
use crate::synth::laser::LaserStripe;
use crate::synth::laser_scene::{example_plane, laser_board_poses};
use crate::synth::{render, RenderOptions};

fn views(camera: &Camera, target: &Target, n: usize) -> Vec<LaserView> {
    laser_board_poses(n)
        .iter()
        .enumerate()
        .map(|(i, pose)| {
            let seed = 40 + 2 * i as u64;
            let mut laser = LaserStripe::new(example_plane());
            laser.seed = seed;
            let off = RenderOptions {
                seed,
                ..RenderOptions::default()
            };
            let on = RenderOptions {
                seed: seed + 1,
                laser: Some(laser),
                ..RenderOptions::default()
            };
            LaserView {
                name: format!("pose {i}"),
                board: render(camera, target, pose, &off)
                    .unwrap_or_else(|e| panic!("{e}"))
                    .image,
                stripe: Some(
                    render(camera, target, pose, &on)
                        .unwrap_or_else(|e| panic!("{e}"))
                        .image,
                ),
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
