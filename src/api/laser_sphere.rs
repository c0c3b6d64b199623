//! The sensor on the robot from scans of a sphere (`robocal laser sphere`,
//! docs/laser.md): per robot pose a laser image of a sphere of known
//! radius (and optionally the same pose with the laser off), the stripe
//! extracted, and [`crate::laser::sphere::calibrate_on_sphere`] refines the
//! laser plane (camera frame), the camera's mounting on the flange and the
//! sphere's centre together. The report (`kind`: `laser_sphere`) holds the
//! plane as a `laser_plane` report does (so `robocal laser points` and
//! `robocal export` read it), the mounting as a hand-eye report does
//! (`gripper_from_camera`), and the plane in the flange frame.

use super::laser::{estimate_json, LaserPlaneJson};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{Plane, PlaneEstimate, Pose, PoseJson};
use crate::image::GrayImage;
use crate::laser::sphere::{calibrate_on_sphere, SphereScan};
use crate::laser::{extract_stripe, StripeOptions};
use nalgebra::Point2;
use serde::Serialize;

/// One scan: the laser image, its laser-off image when taken, the robot's
/// pose.
pub struct SphereScanImage {
    /// The name carried into the report.
    pub name: String,
    /// The laser image.
    pub image: GrayImage,
    /// The same pose with the laser off (subtracted before extraction).
    pub off: Option<GrayImage>,
    /// The flange's pose in the base frame.
    pub base_from_gripper: Pose,
}

/// The laser plane in the flange frame.
#[derive(Debug, Clone, Serialize)]
pub struct FlangePlaneJson {
    /// Unit normal, flange frame.
    pub normal_flange: [f64; 3],
    /// Flange origin to plane, metres.
    pub distance_m: f64,
    /// Covariance of `(nx, ny, nz, distance_m)`, row by row.
    pub covariance: [[f64; 4]; 4],
    /// The normal's angular standard deviation, degrees.
    pub normal_std_deg: f64,
    /// The distance's standard deviation, millimetres.
    pub distance_std_mm: f64,
}

/// The standard deviations of the mounting.
#[derive(Debug, Clone, Serialize)]
pub struct MountStdJson {
    /// Of the right perturbation's rotation vector, degrees.
    pub rotation_deg: [f64; 3],
    /// Of its translation, millimetres.
    pub translation_mm: [f64; 3],
}

/// The sphere.
#[derive(Debug, Clone, Serialize)]
pub struct SphereJson {
    /// Its radius (given), metres.
    pub radius_m: f64,
    /// Its centre in the base frame, metres.
    pub centre_base_m: [f64; 3],
    /// The centre's standard deviations, millimetres.
    pub centre_std_mm: [f64; 3],
}

/// One scan of the report.
#[derive(Debug, Clone, Serialize)]
pub struct SphereScanReport {
    /// The name given.
    pub name: String,
    /// Stripe centres found (all used).
    pub n_points: usize,
    /// The points' RMS distance to the sphere, millimetres.
    pub rms_mm: f64,
}

/// The report (`kind`: `laser_sphere`).
#[derive(Debug, Clone, Serialize)]
pub struct LaserSphereReport {
    /// `laser_sphere`.
    pub kind: &'static str,
    /// The robocal that wrote it.
    pub robocal_version: &'static str,
    /// The laser plane in the camera frame.
    pub laser_plane: LaserPlaneJson,
    /// The camera's mounting on the flange.
    pub gripper_from_camera: PoseJson,
    /// Its standard deviations.
    pub gripper_from_camera_std: MountStdJson,
    /// The laser plane in the flange frame.
    pub laser_plane_flange: FlangePlaneJson,
    /// The sphere.
    pub sphere: SphereJson,
    /// The points' RMS distance to the sphere, millimetres.
    pub rms_mm: f64,
    /// Points used.
    pub n_points: usize,
    /// Levenberg-Marquardt iterations.
    pub iterations: usize,
    /// Per scan.
    pub scans: Vec<SphereScanReport>,
    /// Scans left out or far off the sphere.
    pub warnings: Vec<String>,
}

fn flange_json(estimate: &PlaneEstimate) -> FlangePlaneJson {
    let j = estimate_json(estimate);
    FlangePlaneJson {
        normal_flange: j.normal_camera,
        distance_m: j.distance_m,
        covariance: j.covariance,
        normal_std_deg: j.normal_std_deg,
        distance_std_mm: j.distance_std_mm,
    }
}

/// The laser plane and the camera's mounting from scans of a sphere of
/// `radius_m`, starting from `start_plane` (camera frame) and
/// `start_mount` (`gripper_from_camera`).
pub fn laser_sphere(
    camera: &Camera,
    scans: &[SphereScanImage],
    radius_m: f64,
    start_plane: &Plane,
    start_mount: &Pose,
    stripe: &StripeOptions,
) -> Result<LaserSphereReport> {
    let mut warnings = Vec::new();
    let mut used = Vec::new();
    let mut names = Vec::new();
    for s in scans {
        if (s.image.width, s.image.height) != (camera.width, camera.height) {
            return Err(Error::invalid(
                "image",
                format!(
                    "'{}' is {}x{} but the camera is {}x{}",
                    s.name, s.image.width, s.image.height, camera.width, camera.height
                ),
            ));
        }
        let found = extract_stripe(&s.image, s.off.as_ref(), stripe)?;
        if found.points.len() < 3 {
            warnings.push(format!(
                "{}: {} stripe points, left out (the stripe misses the sphere?)",
                s.name,
                found.points.len()
            ));
            continue;
        }
        used.push(SphereScan {
            base_from_gripper: s.base_from_gripper,
            pixels: found
                .points
                .iter()
                .map(|p| Point2::new(p.x_px, p.y_px))
                .collect(),
        });
        names.push(s.name.clone());
    }
    let c = calibrate_on_sphere(camera, &used, radius_m, start_plane, start_mount)?;
    let scans: Vec<SphereScanReport> = names
        .into_iter()
        .zip(used.iter().zip(&c.scan_rms_m))
        .map(|(name, (scan, rms))| SphereScanReport {
            name,
            n_points: scan.pixels.len(),
            rms_mm: rms * 1e3,
        })
        .collect();
    for s in &scans {
        if s.rms_mm > 3.0 * c.rms_m * 1e3 {
            warnings.push(format!(
                "{}: {:.3} mm RMS off the sphere, over 3 times the overall {:.3} mm (a wrong robot pose, or another object under the stripe?)",
                s.name,
                s.rms_mm,
                c.rms_m * 1e3
            ));
        }
    }
    let std = |v: f64| v.max(0.0).sqrt();
    let m = &c.gripper_from_camera_covariance;
    Ok(LaserSphereReport {
        kind: crate::report_kind::ReportKind::LaserSphere.name(),
        robocal_version: crate::VERSION,
        laser_plane: estimate_json(&c.plane_camera),
        gripper_from_camera: PoseJson::from(&c.gripper_from_camera),
        gripper_from_camera_std: MountStdJson {
            rotation_deg: std::array::from_fn(|i| std(m[(i, i)]).to_degrees()),
            translation_mm: std::array::from_fn(|i| std(m[(i + 3, i + 3)]) * 1e3),
        },
        laser_plane_flange: flange_json(&c.plane_flange),
        sphere: SphereJson {
            radius_m,
            centre_base_m: [c.centre_base.x, c.centre_base.y, c.centre_base.z],
            centre_std_mm: std::array::from_fn(|i| std(c.centre_covariance[(i, i)]) * 1e3),
        },
        rms_mm: c.rms_m * 1e3,
        n_points: c.n_points,
        iterations: c.iterations,
        scans,
        warnings,
    })
}
