//! The epipolar geometry and the rectification of a calibrated stereo pair,
//! as OpenCV computes them, for the stereo exports.
//!
//! # Conventions
//!
//! `right_from_left` maps left-camera coordinates into the right camera:
//! `x_right = R x_left + T`, OpenCV's `R`, `T` of `stereoCalibrate`.
//!
//! - The essential matrix is `E = [T]x R` and the fundamental matrix
//!   `F = K2^-T E K1^-1`, so `x_right^T E x_left = 0` for normalised
//!   (undistorted) points and `p_right^T F p_left = 0` for undistorted pixels.
//! - [`rectify`] follows `cv::stereoRectify` with `CALIB_ZERO_DISPARITY` and
//!   `alpha = -1` (OpenCV's "default scaling"; no cropping or zooming to the
//!   valid region, which is what `alpha` in 0..1 adds): each camera turns by
//!   half the relative rotation, then both by the rotation that makes the
//!   baseline the new x axis (y for a vertical pair, when `|T_y| > |T_x|`
//!   after the half turns). The new focal length is the mean of the two
//!   cameras' focal lengths across the baseline (`fy` for a horizontal
//!   pair, as OpenCV 3 and later); the new principal points centre the
//!   undistorted image corners and are made equal (zero disparity at
//!   infinity). A fisheye pair (Kannala-Brandt) gets the same construction
//!   with its exact unprojection (OpenCV's `fisheye::stereoRectify` turns
//!   the cameras the same way but picks its focal length by `balance`).
//!   `R1`, `R2` rotate camera coordinates into the rectified cameras
//!   (`x_rect = R1 x_left`); `P1 = [Kn | 0]`, `P2 = [Kn | Kn (Tx, 0, 0)]`
//!   with `Tx` the baseline along the new axis; `Q` maps
//!   `(u, v, disparity, 1)` to homogeneous 3-D points of the rectified left
//!   camera.
//!
//! Nothing here reads files: the cameras come as [`Camera`] values.

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::Pose;
use nalgebra::{Matrix3, Matrix3x4, Matrix4, Point2, Rotation3, Vector3};

/// `[v]x`, the cross-product matrix: `[v]x w = v x w`.
pub fn cross_matrix(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The essential matrix `E = [T]x R` of `right_from_left`.
pub fn essential_matrix(right_from_left: &Pose) -> Matrix3<f64> {
    cross_matrix(&right_from_left.translation.vector)
        * right_from_left.rotation.to_rotation_matrix().into_inner()
}

/// The fundamental matrix `F = K2^-T E K1^-1` (undistorted pixels).
pub fn fundamental_matrix(
    left: &Camera,
    right: &Camera,
    right_from_left: &Pose,
) -> Result<Matrix3<f64>> {
    let k1_inv = inverse_k(left)?;
    let k2_inv = inverse_k(right)?;
    Ok(k2_inv.transpose() * essential_matrix(right_from_left) * k1_inv)
}

fn inverse_k(c: &Camera) -> Result<Matrix3<f64>> {
    c.camera_matrix().try_inverse().ok_or_else(|| {
        Error::invalid(
            "camera_matrix",
            format!("is singular (fx {}, fy {})", c.fx, c.fy),
        )
    })
}

/// The rectification of a stereo pair (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Rectification {
    /// Left camera into the rectified left camera.
    pub r1: Matrix3<f64>,
    /// Right camera into the rectified right camera.
    pub r2: Matrix3<f64>,
    /// Projection of the rectified left camera, `[Kn | 0]`.
    pub p1: Matrix3x4<f64>,
    /// Projection of the rectified right camera, `[Kn | Kn (Tx, 0, 0)]`
    /// (or `(0, Ty, 0)` for a vertical pair).
    pub p2: Matrix3x4<f64>,
    /// Disparity-to-depth matrix.
    pub q: Matrix4<f64>,
    /// Whether the cameras are one above the other (rows of the rectified
    /// images are then columns: disparities are vertical).
    pub vertical: bool,
}

/// Rectify a pair the way `cv::stereoRectify` does with
/// `CALIB_ZERO_DISPARITY` and `alpha = -1`, for images of `image_size_px`
/// (both cameras must have that size: OpenCV rectifies one size).
pub fn rectify(left: &Camera, right: &Camera, right_from_left: &Pose) -> Result<Rectification> {
    if (left.width, left.height) != (right.width, right.height) {
        return Err(Error::invalid(
            "image_size_px",
            format!(
                "stereo rectification needs one image size, but the left camera is {}x{} and the right {}x{}",
                left.width, left.height, right.width, right.height
            ),
        ));
    }
    let (nx, ny) = (left.width as f64, left.height as f64);
    // 1. Half the relative rotation each, so both look the same way.
    let half = Rotation3::from_scaled_axis(-0.5 * right_from_left.rotation.scaled_axis());
    let t = half * right_from_left.translation.vector;
    let norm_t = t.norm();
    if !(norm_t > 0.0) || !norm_t.is_finite() {
        return Err(Error::invalid(
            "right_from_left",
            "the baseline is zero: the cameras are at one place, so there is nothing to rectify",
        ));
    }
    // 2. Turn the baseline onto the x axis (y for a vertical pair).
    let idx = if t.x.abs() > t.y.abs() { 0 } else { 1 };
    let c = t[idx];
    let mut axis = Vector3::zeros();
    axis[idx] = if c > 0.0 { 1.0 } else { -1.0 };
    let w = t.cross(&axis);
    let nw = w.norm();
    let w = if nw > 0.0 {
        w * ((c.abs() / norm_t).clamp(-1.0, 1.0).acos() / nw)
    } else {
        w
    };
    let onto_axis = Rotation3::from_scaled_axis(w);
    let r1 = (onto_axis * half.inverse()).into_inner();
    let r2 = (onto_axis * half).into_inner();
    let t_new = r2 * right_from_left.translation.vector;
    // 3. One focal length for both: the mean across the baseline.
    let fc = if idx == 0 {
        0.5 * (left.fy + right.fy)
    } else {
        0.5 * (left.fx + right.fx)
    };
    // 4. Principal points that centre the undistorted corners, then shared.
    let mut centres = [[0.0; 2]; 2];
    for (k, (cam, r)) in [(left, r1), (right, r2)].into_iter().enumerate() {
        let mut sum = [0.0, 0.0];
        for (u, v) in [
            (0.0, 0.0),
            (nx - 1.0, 0.0),
            (0.0, ny - 1.0),
            (nx - 1.0, ny - 1.0),
        ] {
            let p = r * cam.unproject(&Point2::new(u, v))?;
            if !(p.z > 0.0) {
                return Err(Error::invalid(
                    "right_from_left",
                    "an image corner turns behind the rectified camera: the cameras look too far apart to rectify",
                ));
            }
            sum[0] += fc * p.x / p.z;
            sum[1] += fc * p.y / p.z;
        }
        centres[k] = [
            (nx - 1.0) / 2.0 - sum[0] / 4.0,
            (ny - 1.0) / 2.0 - sum[1] / 4.0,
        ];
    }
    let cx = 0.5 * (centres[0][0] + centres[1][0]);
    let cy = 0.5 * (centres[0][1] + centres[1][1]);
    let mut p1 = Matrix3x4::zeros();
    p1[(0, 0)] = fc;
    p1[(1, 1)] = fc;
    p1[(0, 2)] = cx;
    p1[(1, 2)] = cy;
    p1[(2, 2)] = 1.0;
    let mut p2 = p1;
    p2[(idx, 3)] = t_new[idx] * fc;
    // Zero disparity: the principal points are equal, so Q's last entry is 0.
    let q = Matrix4::new(
        1.0,
        0.0,
        0.0,
        -cx, //
        0.0,
        1.0,
        0.0,
        -cy, //
        0.0,
        0.0,
        0.0,
        fc, //
        0.0,
        0.0,
        -1.0 / t_new[idx],
        0.0,
    );
    Ok(Rectification {
        r1,
        r2,
        p1,
        p2,
        q,
        vertical: idx == 1,
    })
}

#[cfg(test)]
#[path = "stereo_rectify_tests.rs"]
mod tests;
