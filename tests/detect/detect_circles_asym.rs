//! The asymmetric circle grid on strongly tilted, distorted views (issue
//! 36: "found 77 of 77 circles of the 7x11 asymmetric circle grid" on
//! eye-to-hand images OpenCV reads).
//!
//! Beyond about 55 degrees of tilt a grid's nearest neighbours are no
//! longer its diagonal ones: a row step (two grid units) comes out shorter
//! than a diagonal step (sqrt 2 units) foreshortened the other way, and the
//! lattice grows along a row and a diagonal. It still holds every circle;
//! the lattice-to-board maps must take that basis too
//! (`src/detect/lattice.rs`).

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use robocal::camera::Camera;
use robocal::detect::{detect, DetectOptions};
use robocal::synth::{render, RenderOptions};
use robocal::target::Target;

/// The board's centre at `at` (metres, camera frame), tilted by `tilt`
/// radians about an axis in its plane at `axis` radians from its x axis,
/// turned by `yaw` in its plane.
fn pose(target: &Target, tilt: f64, axis: f64, yaw: f64, at: Vector3<f64>) -> Isometry3<f64> {
    let pts = target.object_points();
    let mx = pts.iter().map(|p| p.1.x).fold(0.0, f64::max) / 2.0;
    let my = pts.iter().map(|p| p.1.y).fold(0.0, f64::max) / 2.0;
    let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
    let in_plane = nalgebra::Unit::new_normalize(Vector3::new(axis.cos(), axis.sin(), 0.0));
    let r = UnitQuaternion::from_axis_angle(&in_plane, tilt) * turn;
    Isometry3::from_parts(Translation3::from(at - r * Vector3::new(mx, my, 0.0)), r)
}

#[test]
fn strongly_tilted_asymmetric_grids_are_assembled() {
    let cams = [
        ("std", Camera::example_pinhole()),
        ("strong distortion", Camera::example_brown()),
    ];
    let mut failures = Vec::new();
    let mut views = 0;
    for spec in [
        "circles:7x11:15mm:asymmetric",
        "circles:11x7:15mm:asymmetric",
        "circles:7x11:15mm:asymmetric:light-on-dark",
    ] {
        let target = Target::parse_spec(spec).unwrap();
        for (name, cam) in &cams {
            for (k, (tilt_deg, axis_deg, yaw_deg)) in [
                (58.0, 0.0, 0.0),
                (62.0, 90.0, 0.0),
                (60.0, 30.0, 15.0),
                (64.0, 0.0, 90.0),
                (56.0, 120.0, -30.0),
                (60.0, 45.0, 45.0),
            ]
            .into_iter()
            .enumerate()
            {
                let p = pose(
                    &target,
                    f64::to_radians(tilt_deg),
                    f64::to_radians(axis_deg),
                    f64::to_radians(yaw_deg),
                    Vector3::new(0.01, -0.01, 0.3),
                );
                let o = RenderOptions {
                    seed: 700 + k as u64,
                    ..RenderOptions::default()
                };
                let Ok(r) = render(cam, &target, &p, &o) else {
                    continue;
                };
                if r.points.len() != target.point_count() {
                    continue;
                }
                views += 1;
                match detect(&r.image, &target, &DetectOptions::default()) {
                    Ok(det) => {
                        let worst = det
                            .points
                            .iter()
                            .zip(&r.points)
                            .map(|(d, t)| {
                                assert_eq!(d.id, t.id, "{spec} {name} view {k}");
                                ((d.x_px - t.x_px).powi(2) + (d.y_px - t.y_px).powi(2)).sqrt()
                            })
                            .fold(0.0, f64::max);
                        eprintln!("{spec} {name} view {k} ({tilt_deg} deg): worst {worst:.3} px");
                        assert!(worst < 0.5, "{spec} {name} view {k}: worst {worst} px");
                    }
                    Err(e) => {
                        eprintln!("{spec} {name} view {k} ({tilt_deg} deg): {e}");
                        failures.push(format!("{spec} {name} view {k}: {e}"));
                    }
                }
            }
        }
    }
    eprintln!("{} of {views} views found", views - failures.len());
    assert!(views >= 30, "{views} views with the whole grid in view");
    // No grid is refused with every circle found ("found 77 of 77").
    assert!(
        failures.iter().all(|f| !f.contains("found 77 of 77")),
        "{failures:#?}"
    );
    // Measured 2026-12-07: 26 of 33; the rest are lattices that stop
    // short of the grid's far rows at 60-64 degrees (62-76 of 77).
    assert!(failures.len() <= 7, "{failures:#?}");
}
