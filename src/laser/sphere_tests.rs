//! The sensor on the robot from scans of a sphere: exact from exact stripe
//! centres, and from rendered laser images (stripes extracted) within
//! bounds and within the reported std.

use super::sphere::{calibrate_on_sphere, SphereCalibration, SphereScan};
use super::LaserPlane;
use crate::geometry::Pose;
use crate::synth::laser_scene::example_plane;
use crate::synth::laser_sphere::{
    example_emitter, example_mounting, example_sensor_camera, example_sphere, example_starts,
    rendered_scans, sphere_scan_poses, SphereScene,
};
use nalgebra::{Point3, Vector3};

/// Errors against the truth: plane normal deg, plane distance mm, mounting
/// rotation deg, mounting translation mm, centre mm.
fn errors(
    c: &SphereCalibration,
    plane: &LaserPlane,
    mount: &Pose,
    scene: &SphereScene,
) -> [f64; 5] {
    let p = &c.plane_camera.plane;
    let diff = mount.inverse() * c.gripper_from_camera;
    [
        p.normal
            .dot(&plane.normal)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees(),
        (p.distance_m - plane.distance_m).abs() * 1e3,
        diff.rotation.angle().to_degrees(),
        diff.translation.vector.norm() * 1e3,
        (c.centre_base - scene.centre_base).norm() * 1e3,
    ]
}

/// Exact stripe centres: the plane/sphere circle, lit and seen, projected.
fn exact_scans(
    poses: &[Pose],
    mount: &Pose,
    plane: &LaserPlane,
    scene: &SphereScene,
) -> Vec<SphereScan> {
    let cam = example_sensor_camera();
    let n = plane.normal.into_inner();
    let e = example_emitter(plane);
    poses
        .iter()
        .map(|b| {
            let c = ((b * mount).inverse() * scene.centre_base).coords;
            let off = n.dot(&c) - plane.distance_m;
            let rho = (scene.radius_m.powi(2) - off * off).sqrt();
            let q = c - n * off;
            let u = n.cross(&Vector3::x()).normalize();
            let v = n.cross(&u);
            let pixels = (0..360)
                .filter_map(|k| {
                    let a = (k as f64).to_radians();
                    let p = q + (u * a.cos() + v * a.sin()) * rho;
                    let seen = (-p).dot(&(p - c)) > 0.0;
                    let lit = (e.coords - p).dot(&(p - c)) > 0.0;
                    (seen && lit)
                        .then(|| cam.project(&Point3::from(p)).ok())
                        .flatten()
                })
                .collect();
            SphereScan {
                base_from_gripper: *b,
                pixels,
            }
        })
        .collect()
}

#[test]
fn exact_profiles_give_the_exact_sensor() {
    let (plane, mount, scene) = (example_plane(), example_mounting(), example_sphere());
    let poses = sphere_scan_poses(6, &scene, &mount, &plane);
    let scans = exact_scans(&poses, &mount, &plane, &scene);
    assert!(
        scans.iter().all(|s| s.pixels.len() > 30),
        "{:?}",
        scans.iter().map(|s| s.pixels.len()).collect::<Vec<_>>()
    );
    let (start_plane, start_mount) = example_starts(&plane, &mount);
    let c = calibrate_on_sphere(
        &example_sensor_camera(),
        &scans,
        scene.radius_m,
        &start_plane,
        &start_mount,
    )
    .unwrap();
    let e = errors(&c, &plane, &mount, &scene);
    assert!(e.iter().all(|v| *v < 1e-4), "{e:?}");
    assert!(c.rms_m < 1e-8, "{}", c.rms_m);
    // The plane in the flange frame is the true one moved by the mounting.
    let truth_flange = plane.in_frame(&mount);
    assert!((c.plane_flange.plane.distance_m - truth_flange.distance_m).abs() < 1e-7);
}

#[test]
fn scans_without_turns_or_too_few_are_refused() {
    let (plane, mount, scene) = (example_plane(), example_mounting(), example_sphere());
    let poses = sphere_scan_poses(6, &scene, &mount, &plane);
    let scans = exact_scans(&poses[..2], &mount, &plane, &scene);
    let err = calibrate_on_sphere(
        &example_sensor_camera(),
        &scans,
        scene.radius_m,
        &plane,
        &mount,
    )
    .unwrap_err();
    assert!(err.to_string().contains("at least 3 are needed"), "{err}");
    let err =
        calibrate_on_sphere(&example_sensor_camera(), &scans, -1.0, &plane, &mount).unwrap_err();
    assert!(err.to_string().contains("radius"), "{err}");
}

#[test]
fn rendered_scans_give_the_sensor_within_bounds() {
    let (plane, mount, scene) = (example_plane(), example_mounting(), example_sphere());
    let cam = example_sensor_camera();
    let poses = sphere_scan_poses(8, &scene, &mount, &plane);
    let scans = rendered_scans(&cam, &poses, &mount, &plane, &scene, 11).unwrap();
    // Each centre against the true stripe: its ray meets the true plane at
    // a point this far from the sphere.
    let mut centre_err = (0.0, 0usize);
    for scan in &scans {
        let c = ((scan.base_from_gripper * mount).inverse() * scene.centre_base).coords;
        for px in &scan.pixels {
            let x = plane.intersect_ray(&cam.unproject(px).unwrap()).unwrap();
            centre_err.0 += ((x.coords - c).norm() - scene.radius_m).abs();
            centre_err.1 += 1;
        }
    }
    assert!(
        scans.iter().all(|s| s.pixels.len() > 30),
        "{:?}",
        scans.iter().map(|s| s.pixels.len()).collect::<Vec<_>>()
    );
    let (start_plane, start_mount) = example_starts(&plane, &mount);
    let c = calibrate_on_sphere(&cam, &scans, scene.radius_m, &start_plane, &start_mount).unwrap();
    let e = errors(&c, &plane, &mount, &scene);
    let std_normal_deg = (0.5
        * (c.plane_camera.covariance[(0, 0)] + c.plane_camera.covariance[(1, 1)]))
        .sqrt()
        .to_degrees();
    let std_d_mm = c.plane_camera.covariance[(2, 2)].sqrt() * 1e3;
    eprintln!(
        "sphere scans: errors {e:?}, std normal {std_normal_deg} deg, distance {std_d_mm} mm, rms {} mm, {} points, mean true-plane miss {} mm",
        c.rms_m * 1e3,
        c.n_points,
        centre_err.0 / centre_err.1 as f64 * 1e3
    );
    assert!(
        e[0] < 0.2 && e[1] < 0.5 && e[2] < 0.3 && e[3] < 1.0 && e[4] < 1.0,
        "{e:?}"
    );
}
