//! Profiles to points: each stripe centre's ray met with the laser plane,
//! in the camera frame, and in the flange and base frames when the camera's
//! mounting (`gripper_from_camera`) and the robot's pose (`base_from_gripper`)
//! are given.

use super::plane::LaserPlane;
use super::stripe::Stripe;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::Pose;
use nalgebra::{Point2, Point3};
use serde::Serialize;

/// One profile point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProfilePoint {
    /// The stripe centre, pixels.
    pub pixel: [f64; 2],
    /// The point in the camera frame, metres.
    pub camera_m: [f64; 3],
    /// The point in the flange (gripper) frame, when the mounting is given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flange_m: Option<[f64; 3]>,
    /// The point in the robot base frame, when the robot pose is given too.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base_m: Option<[f64; 3]>,
}

/// The 3-D point of a stripe centre: its ray met with the plane.
pub fn point_on_plane(
    camera: &Camera,
    plane: &LaserPlane,
    pixel: &Point2<f64>,
) -> Result<Point3<f64>> {
    let ray = camera.unproject(pixel)?;
    plane.intersect_ray(&ray).ok_or_else(|| {
        Error::degenerate(format!(
            "the ray of pixel ({:.2}, {:.2}) does not meet the laser plane in front of the camera",
            pixel.x, pixel.y
        ))
    })
}

/// Every centre of `stripe` as a 3-D point (centres whose ray misses the
/// plane are left out and counted in the second value).
pub fn profile_points(
    camera: &Camera,
    plane: &LaserPlane,
    stripe: &Stripe,
    gripper_from_camera: Option<&Pose>,
    base_from_gripper: Option<&Pose>,
) -> Result<(Vec<ProfilePoint>, usize)> {
    if base_from_gripper.is_some() && gripper_from_camera.is_none() {
        return Err(Error::invalid(
            "base_from_gripper",
            "a robot pose needs the camera's mounting (gripper_from_camera) too",
        ));
    }
    let mut out = Vec::with_capacity(stripe.points.len());
    let mut missed = 0;
    for s in &stripe.points {
        let px = Point2::new(s.x_px, s.y_px);
        let Ok(p) = point_on_plane(camera, plane, &px) else {
            missed += 1;
            continue;
        };
        let flange = gripper_from_camera.map(|g| g * p);
        let base = match (base_from_gripper, flange) {
            (Some(b), Some(f)) => Some(b * f),
            _ => None,
        };
        out.push(ProfilePoint {
            pixel: [s.x_px, s.y_px],
            camera_m: [p.x, p.y, p.z],
            flange_m: flange.map(|f| [f.x, f.y, f.z]),
            base_m: base.map(|b| [b.x, b.y, b.z]),
        });
    }
    Ok((out, missed))
}
