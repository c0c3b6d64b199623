//! The laser plane and the observations it is fitted to.
//!
//! A plane is `normal_camera . X = distance_m` for camera-frame points `X`
//! (metres), the normal a unit vector, the distance the camera centre's
//! distance to the plane (>= 0: the normal points away from the camera).

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{Plane, Pose};
use nalgebra::{Point2, Point3, Vector3};
use serde::{Serialize, Serializer};

/// The laser's plane of light: a [`Plane`] in the camera frame, its normal
/// pointing away from the camera centre (`distance_m >= 0`). Its estimate
/// with covariance is a [`crate::geometry::PlaneEstimate`].
pub type LaserPlane = Plane;

/// The laser plane `normal . X = distance_m` (camera frame) with `normal`
/// normalised (the distance scaled with it) and the sign chosen so the
/// distance is >= 0; fails for a zero or non-finite normal.
pub fn plane_in_camera(normal: Vector3<f64>, distance_m: f64) -> Result<LaserPlane> {
    let norm = normal.norm();
    let scale = if norm > 1e-12 && norm.is_finite() {
        norm
    } else {
        1.0
    };
    Plane::checked("laser_plane", normal, distance_m / scale).map(Plane::facing_away)
}

/// The JSON of a laser plane: `{"normal_camera": [nx, ny, nz],
/// "distance_m": d}` (for `#[serde(serialize_with)]`).
pub fn serialize_camera_plane<S: Serializer>(
    plane: &LaserPlane,
    serializer: S,
) -> std::result::Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    struct Json {
        normal_camera: [f64; 3],
        distance_m: f64,
    }
    let n = plane.normal;
    Json {
        normal_camera: [n.x, n.y, n.z],
        distance_m: plane.distance_m,
    }
    .serialize(serializer)
}

/// The board plane `m . X = e` of a pose `camera_from_target` (target z = 0).
pub(crate) fn board_plane(camera_from_target: &Pose) -> Plane {
    let m = camera_from_target.rotation * Vector3::z_axis();
    Plane {
        normal: m,
        distance_m: m.dot(&camera_from_target.translation.vector),
    }
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
        let board = board_plane(camera_from_target);
        let on_board = |px: &Point2<f64>| -> Result<Point3<f64>> {
            let ray = camera.unproject(px)?;
            board.intersect_ray(&ray).ok_or_else(|| {
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
