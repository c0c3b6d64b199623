//! Seeded laser-plane scenes at the level of stripe centres (no images):
//! the true centre of the plane/board line in every column (row) where it
//! falls on the board, with Gaussian noise along the scan, as observations
//! for [`crate::laser::fit_plane`]. Used by tests and the Monte Carlo.

use super::laser::stripe_truth;
use crate::camera::Camera;
use crate::error::Result;
use crate::geometry::Pose;
use crate::laser::{LaserPlane, StripeObservation};
use crate::rng::Rng;
use nalgebra::{Point2, Vector3};

/// A plane like a triangulation sensor's: the laser 0.1 m above the
/// camera (-y), fanned along x, aimed at the optical axis 0.5 m away.
pub fn example_plane() -> LaserPlane {
    LaserPlane {
        normal: nalgebra::Unit::new_normalize(Vector3::new(0.0, -0.5, 0.1)),
        distance_m: 0.1 * 0.5 / 0.26f64.sqrt(),
    }
}

/// Board poses for a laser scene: `n` poses 0.45-0.55 m away, each tilted
/// by up to 25 deg about a direction that turns from pose to pose, so the
/// stripe lines differ in direction and depth.
pub fn laser_board_poses(n: usize) -> Vec<Pose> {
    (0..n)
        .map(|k| {
            let a = k as f64 * 2.4;
            let tilt = 0.25 + 0.2 * ((k as f64) * 0.7).sin();
            let rpy = (tilt * a.cos(), tilt * a.sin(), 0.3 * (k as f64 * 1.3).sin());
            let depth = 0.5 + 0.05 * ((k as f64) * 1.9).sin();
            let r = nalgebra::UnitQuaternion::from_euler_angles(rpy.0, rpy.1, rpy.2);
            // Board frame origin 0.1 m left and up of the optical axis.
            let t = Vector3::new(0.0, 0.0, depth) - r * Vector3::new(0.1, 0.075, 0.0);
            Pose::from_parts(nalgebra::Translation3::from(t), r)
        })
        .collect()
}

/// The stripe centres on a `extent_m = (x, y)` board (target frame from
/// the origin) in each pose, every `step`-th column (or row), with noise
/// N(0, noise_px^2) along the scan; `std_px` is given to the fit.
pub fn stripe_observations(
    camera: &Camera,
    poses: &[Pose],
    plane: &LaserPlane,
    extent_m: (f64, f64),
    step: usize,
    noise_px: f64,
    rng: &mut Rng,
) -> Result<Vec<StripeObservation>> {
    let mut out = Vec::new();
    for (i, pose) in poses.iter().enumerate() {
        let along_columns = columns_for(camera, pose, plane);
        for (k, (idx, v)) in stripe_truth(camera, pose, plane, along_columns)
            .into_iter()
            .enumerate()
        {
            if k % step.max(1) != 0 {
                continue;
            }
            let px = if along_columns {
                Point2::new(idx as f64, v)
            } else {
                Point2::new(v, idx as f64)
            };
            let Ok(ray) = camera.unproject(&px) else {
                continue;
            };
            let m = pose.rotation * Vector3::z();
            let e = m.dot(&pose.translation.vector);
            let b = pose.inverse() * nalgebra::Point3::from(ray * (e / m.dot(&ray)));
            if b.x < 0.0 || b.y < 0.0 || b.x > extent_m.0 || b.y > extent_m.1 {
                continue;
            }
            let noisy = if along_columns {
                Point2::new(px.x, px.y + rng.gaussian(noise_px))
            } else {
                Point2::new(px.x + rng.gaussian(noise_px), px.y)
            };
            out.push(StripeObservation::new(
                camera,
                pose,
                &noisy,
                along_columns,
                noise_px.max(1e-3),
                i,
            )?);
        }
    }
    Ok(out)
}

/// Whether the stripe of `plane` on the board at `pose` runs closer to the
/// image's x axis (scan columns) than to its y axis.
pub fn columns_for(camera: &Camera, pose: &Pose, plane: &LaserPlane) -> bool {
    let cols = stripe_truth(camera, pose, plane, true).len();
    let rows = stripe_truth(camera, pose, plane, false).len();
    cols >= rows
}
