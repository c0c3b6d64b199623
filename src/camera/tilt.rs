//! The tilted image sensor of a Scheimpflug camera (OpenCV's
//! `CALIB_TILTED_MODEL`): after the lens distortion, the distorted
//! normalised point `m` (on the plane perpendicular to the optical axis) is
//! carried to the sensor tilted by `tau_x` about the x axis and then by
//! `tau_y` about the y axis, along the ray through the exit pupil:
//!
//! ```text
//! R(tau_x, tau_y) = Ry(tau_y) Rx(tau_x)
//!   Rx = [1 0 0; 0 cos(tau_x) sin(tau_x); 0 -sin(tau_x) cos(tau_x)]
//!   Ry = [cos(tau_y) 0 -sin(tau_y); 0 1 0; sin(tau_y) 0 cos(tau_y)]
//! T = [R33 0 -R13; 0 R33 -R23; 0 0 1] R
//! v = T (m_x, m_y, 1),   m' = (v_x / v_z, v_y / v_z),   pixel = K m'
//! ```
//!
//! (the indices of R are 1-based). The first factor of `T` rescales and
//! recentres so that the optical axis stays at the principal point and the
//! axis's scale is unchanged; to first order in the angles
//! `v_z = 1 + tau_y m_x - tau_x m_y`: a keystone. This is OpenCV's
//! `computeTiltProjectionMatrix` and its use in `projectPoints`, written
//! from the formula of its documentation.
//!
//! Without lens distortion the tilt cannot be told from the pinhole: `K T`
//! factors into an upper-triangular camera matrix times a rotation that the
//! board poses absorb. The tilt is measured through the distortion, whose
//! centre lies on the untilted axis.

use crate::error::{Error, Result};
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

/// A sensor point, its Jacobian with respect to the distorted point and its
/// derivatives with respect to `tau_x` and `tau_y`.
pub(crate) type TiltedPoint = (Vector2<f64>, Matrix2<f64>, [Vector2<f64>; 2]);

/// The tilt homography `T` and its derivatives with respect to `tau_x` and
/// `tau_y`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tilt {
    pub t: Matrix3<f64>,
    pub d_tau_x: Matrix3<f64>,
    pub d_tau_y: Matrix3<f64>,
}

/// The scale-and-shift factor `[R33 0 -R13; 0 R33 -R23; 0 0 1]` of a
/// matrix `r` (also of its derivative: the map is linear but for the 1).
fn projection_z(r: &Matrix3<f64>, one: f64) -> Matrix3<f64> {
    Matrix3::new(
        r[(2, 2)],
        0.0,
        -r[(0, 2)],
        0.0,
        r[(2, 2)],
        -r[(1, 2)],
        0.0,
        0.0,
        one,
    )
}

impl Tilt {
    /// The tilt of angles `tau_x`, `tau_y` (radians).
    pub fn new(tau_x: f64, tau_y: f64) -> Tilt {
        let (sx, cx) = tau_x.sin_cos();
        let (sy, cy) = tau_y.sin_cos();
        let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cx, sx, 0.0, -sx, cx);
        let ry = Matrix3::new(cy, 0.0, -sy, 0.0, 1.0, 0.0, sy, 0.0, cy);
        let drx = Matrix3::new(0.0, 0.0, 0.0, 0.0, -sx, cx, 0.0, -cx, -sx);
        let dry = Matrix3::new(-sy, 0.0, -cy, 0.0, 0.0, 0.0, cy, 0.0, -sy);
        let r = ry * rx;
        let dr_x = ry * drx;
        let dr_y = dry * rx;
        let p = projection_z(&r, 1.0);
        Tilt {
            t: p * r,
            d_tau_x: projection_z(&dr_x, 0.0) * r + p * dr_x,
            d_tau_y: projection_z(&dr_y, 0.0) * r + p * dr_y,
        }
    }

    /// The sensor point of the distorted normalised point `m`, its 2x2
    /// Jacobian with respect to `m` and its derivatives with respect to
    /// `tau_x` and `tau_y`.
    pub fn apply(&self, m: &Vector2<f64>) -> Result<TiltedPoint> {
        let v = self.t * Vector3::new(m.x, m.y, 1.0);
        let out = dehomogenise(&v, m)?;
        let w = 1.0 / v.z;
        // d out / d v, a 2x3 matrix written by rows.
        let d_out =
            |dv: &Vector3<f64>| Vector2::new(w * (dv.x - out.x * dv.z), w * (dv.y - out.y * dv.z));
        let d_m = Matrix2::from_columns(&[
            d_out(&self.t.column(0).into_owned()),
            d_out(&self.t.column(1).into_owned()),
        ]);
        let h = Vector3::new(m.x, m.y, 1.0);
        let d_tau = [d_out(&(self.d_tau_x * h)), d_out(&(self.d_tau_y * h))];
        Ok((out, d_m, d_tau))
    }

    /// [`Tilt::apply`]'s point alone.
    pub fn apply_value(&self, m: &Vector2<f64>) -> Result<Vector2<f64>> {
        dehomogenise(&(self.t * Vector3::new(m.x, m.y, 1.0)), m)
    }

    /// The distorted normalised point whose sensor point is `s` (the exact
    /// inverse of the homography).
    pub fn invert(&self, s: &Vector2<f64>) -> Result<Vector2<f64>> {
        let Some(inverse) = self.t.try_inverse() else {
            return Err(Error::invalid(
                "distortion",
                "the sensor tilt is singular (tau_x or tau_y at 90 degrees)",
            ));
        };
        dehomogenise(&(inverse * Vector3::new(s.x, s.y, 1.0)), s)
    }
}

/// `(v_x / v_z, v_y / v_z)`, refused when `v_z` is not positive (the point
/// `m` lies on or beyond the horizon of the tilted sensor).
fn dehomogenise(v: &Vector3<f64>, m: &Vector2<f64>) -> Result<Vector2<f64>> {
    let in_front = v.z > 0.0 && v.iter().all(|c| c.is_finite());
    if !in_front {
        return Err(Error::invalid(
            "point",
            format!(
                "normalised point ({:.4}, {:.4}) lies beyond the horizon of the tilted sensor",
                m.x, m.y
            ),
        ));
    }
    Ok(Vector2::new(v.x / v.z, v.y / v.z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// The closed form of OpenCV's documentation:
    /// `R = [cy, sy sx, -sy cx; 0, cx, sx; sy, -cy sx, cy cx]`, and the
    /// derivatives of `T` by central differences.
    #[wasm_bindgen_test(unsupported = test)]
    fn the_tilt_matrix_and_its_derivatives() {
        let (tx, ty) = (0.05_f64, -0.03_f64);
        let (sx, cx) = tx.sin_cos();
        let (sy, cy) = ty.sin_cos();
        let r = Matrix3::new(cy, sy * sx, -sy * cx, 0.0, cx, sx, sy, -cy * sx, cy * cx);
        let p = Matrix3::new(cy * cx, 0.0, sy * cx, 0.0, cy * cx, -sx, 0.0, 0.0, 1.0);
        let tilt = Tilt::new(tx, ty);
        assert!((tilt.t - p * r).norm() < 1e-15);
        let h = 1e-6;
        let fx = (Tilt::new(tx + h, ty).t - Tilt::new(tx - h, ty).t) / (2.0 * h);
        let fy = (Tilt::new(tx, ty + h).t - Tilt::new(tx, ty - h).t) / (2.0 * h);
        assert!((fx - tilt.d_tau_x).norm() < 1e-9);
        assert!((fy - tilt.d_tau_y).norm() < 1e-9);
        // No tilt is the identity; the axis stays put.
        assert!((Tilt::new(0.0, 0.0).t - Matrix3::identity()).norm() < 1e-15);
        let axis = tilt
            .apply_value(&Vector2::zeros())
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(axis.norm() < 1e-15);
        // The inverse is exact.
        let m = Vector2::new(0.4, -0.3);
        let s = tilt.apply_value(&m).unwrap_or_else(|e| panic!("{e}"));
        let back = tilt.invert(&s).unwrap_or_else(|e| panic!("{e}"));
        assert!((back - m).norm() < 1e-15);
    }
}
