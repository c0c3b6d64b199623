//! The laser plane and the observations it is fitted to.
//!
//! A plane is `normal_camera . X = distance_m` for camera-frame points `X`
//! (metres), the normal a unit vector, the distance the camera centre's
//! distance to the plane (>= 0: the normal points away from the camera).

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::Pose;
use nalgebra::{Point2, Point3, Vector3};
use serde::{Deserialize, Serialize};

/// The laser's plane of light in the camera frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LaserPlane {
    /// Unit normal, camera frame (pointing away from the camera centre).
    pub normal_camera: [f64; 3],
    /// Distance of the camera centre to the plane, metres (>= 0).
    pub distance_m: f64,
}

impl LaserPlane {
    /// The plane `n . X = d` with `n` normalised and the sign chosen so the
    /// distance is >= 0; fails for a zero or non-finite normal.
    pub fn new(normal: Vector3<f64>, distance_m: f64) -> Result<LaserPlane> {
        let norm = normal.norm();
        if !(norm.is_finite() && norm > 1e-12 && distance_m.is_finite()) {
            return Err(Error::invalid(
                "laser_plane",
                format!(
                    "needs a non-zero finite normal and a finite distance, got ({}, {}, {}) and {}",
                    normal.x, normal.y, normal.z, distance_m
                ),
            ));
        }
        let (n, d) = (normal / norm, distance_m / norm);
        let (n, d) = if d < 0.0 { (-n, -d) } else { (n, d) };
        Ok(LaserPlane {
            normal_camera: [n.x, n.y, n.z],
            distance_m: d,
        })
    }

    /// The unit normal as a vector.
    pub fn normal(&self) -> Vector3<f64> {
        Vector3::from(self.normal_camera)
    }

    /// Signed distance of a camera-frame point to the plane, metres.
    pub fn signed_distance(&self, p: &Point3<f64>) -> f64 {
        self.normal().dot(&p.coords) - self.distance_m
    }

    /// Where the ray along `ray` (camera frame, through the centre) meets
    /// the plane; `None` when it runs parallel or meets it behind.
    pub fn intersect_ray(&self, ray: &Vector3<f64>) -> Option<Point3<f64>> {
        ray_plane(ray, &self.normal(), self.distance_m)
    }
}

/// `lambda * ray` on the plane `n . X = d`, for lambda > 0.
pub(crate) fn ray_plane(ray: &Vector3<f64>, n: &Vector3<f64>, d: f64) -> Option<Point3<f64>> {
    let den = n.dot(ray);
    if den.abs() < 1e-12 {
        return None;
    }
    let lambda = d / den;
    (lambda > 0.0 && lambda.is_finite()).then(|| Point3::from(ray * lambda))
}

/// The board plane `m . X = e` of a pose `camera_from_target` (target z = 0).
pub(crate) fn board_plane(camera_from_target: &Pose) -> (Vector3<f64>, f64) {
    let m = camera_from_target.rotation * Vector3::z();
    (m, m.dot(&camera_from_target.translation.vector))
}

/// One stripe centre on a board of known pose: the point where its pixel's
/// ray meets the board, and how that point moves when the centre moves one
/// pixel along the scan direction (the image-space residual's scale).
#[derive(Debug, Clone, PartialEq)]
pub struct StripeObservation {
    /// The ray of the stripe centre met with the board plane, camera frame, m.
    pub point_camera: Point3<f64>,
    /// d point / d (centre coordinate along the scan), metres per pixel.
    pub along_scan_m_per_px: Vector3<f64>,
    /// The stripe centre's standard deviation along the scan, pixels.
    pub std_px: f64,
    /// Which image (board pose) the centre comes from.
    pub image: usize,
}

impl StripeObservation {
    /// The observation of the stripe centre `pixel` on the board at
    /// `camera_from_target`; `scan_along_y` when the centre was measured
    /// along a column (a horizontal stripe), else along a row.
    pub fn new(
        camera: &Camera,
        camera_from_target: &Pose,
        pixel: &Point2<f64>,
        scan_along_y: bool,
        std_px: f64,
        image: usize,
    ) -> Result<StripeObservation> {
        let (m, e) = board_plane(camera_from_target);
        let on_board = |px: &Point2<f64>| -> Result<Point3<f64>> {
            let ray = camera.unproject(px)?;
            ray_plane(&ray, &m, e).ok_or_else(|| {
                Error::degenerate(format!(
                    "the ray of pixel ({:.2}, {:.2}) does not meet the board of image {}",
                    px.x,
                    px.y,
                    image + 1
                ))
            })
        };
        let h = 0.5;
        let step = if scan_along_y {
            nalgebra::Vector2::new(0.0, h)
        } else {
            nalgebra::Vector2::new(h, 0.0)
        };
        let p = on_board(pixel)?;
        let plus = on_board(&(pixel + step))?;
        let minus = on_board(&(pixel - step))?;
        if !(std_px.is_finite() && std_px > 0.0) {
            return Err(Error::invalid(
                "std_px",
                format!("a stripe centre's std must be > 0 px, got {std_px}"),
            ));
        }
        Ok(StripeObservation {
            point_camera: p,
            along_scan_m_per_px: (plus - minus) / (2.0 * h),
            std_px,
            image,
        })
    }
}

impl LaserPlane {
    /// `camera_from_plane`: the plane as a frame, z along the normal, the
    /// origin the plane's point closest to the camera centre, x the camera's
    /// x axis projected into the plane (its y axis when x is nearly normal).
    pub fn camera_from_plane(&self) -> Pose {
        let z = self.normal();
        let seed = if z.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let x = (seed - z * z.dot(&seed)).normalize();
        let y = z.cross(&x);
        let r =
            nalgebra::Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[x, y, z]));
        Pose::from_parts(
            nalgebra::Translation3::from(z * self.distance_m),
            nalgebra::UnitQuaternion::from_rotation_matrix(&r),
        )
    }
}
