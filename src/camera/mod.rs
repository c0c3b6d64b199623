//! The camera: pinhole intrinsics plus one lens model ([`Distortion`]).
//!
//! A camera-frame point `p` (x right, y down, z forward) maps to a distorted
//! normalised point `m` by the lens model, then to pixels by
//!
//! ```text
//! u = fx m_x + skew m_y + cx
//! v =          fy m_y + cy
//! ```
//!
//! with pixel (0, 0) the centre of the top-left pixel (as OpenCV). The
//! parameter vector of [`Camera::params`] is `[fx, fy, cx, cy, skew,
//! distortion coefficients...]` in the order of [`Camera::param_names`]; the
//! calibration solvers optimise exactly this vector.

mod distortion;
mod division;
mod eucm;
mod examples;
mod kannala_brandt;
mod models;
mod polynomial;
mod spline_fit;
pub mod splined;
mod tilt;
mod undistort;

#[cfg(test)]
mod tests;

pub use distortion::Distortion;
pub use models::{model_help, model_list, LensModel, LENS_MODELS, MODEL_NAMES};
pub use splined::Spline;
pub use undistort::UndistortMap;

use crate::error::{Error, Result};
use nalgebra::{DMatrix, Matrix2, Matrix2x3, Matrix3, Point2, Point3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// A projection with its Jacobians: the normalised point, its Jacobian with
/// respect to the 3-D point, and its derivative along each of the model's
/// `N` coefficients.
pub(crate) type ProjectionWithJacobians<const N: usize> = (
    nalgebra::Vector2<f64>,
    nalgebra::Matrix2x3<f64>,
    [nalgebra::Vector2<f64>; N],
);

/// Number of pinhole parameters before the distortion coefficients in
/// [`Camera::params`]: fx, fy, cx, cy, skew.
pub const N_PINHOLE_PARAMS: usize = 5;

/// A calibrated (or to-be-calibrated) camera: intrinsics, image size and
/// lens model. Serialises to JSON as these fields, the lens model as an
/// object tagged by `model`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    /// Focal length along x, in pixels.
    pub fx: f64,
    /// Focal length along y, in pixels.
    pub fy: f64,
    /// Principal point x, in pixels (pixel-centre convention).
    pub cx: f64,
    /// Principal point y, in pixels.
    pub cy: f64,
    /// Skew, in pixels (the (0, 1) entry of the camera matrix; Zhang's
    /// gamma). Usually 0.
    pub skew: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The lens model.
    pub distortion: Distortion,
}

impl Camera {
    /// A distortion-free camera.
    pub fn pinhole(fx: f64, fy: f64, cx: f64, cy: f64, width: u32, height: u32) -> Camera {
        Camera {
            fx,
            fy,
            cx,
            cy,
            skew: 0.0,
            width,
            height,
            distortion: Distortion::None,
        }
    }

    /// The same intrinsics without lens distortion (the usual target of an
    /// undistortion map).
    pub fn without_distortion(&self) -> Camera {
        Camera {
            distortion: Distortion::None,
            ..self.clone()
        }
    }

    /// The 3x3 camera matrix `[[fx, skew, cx], [0, fy, cy], [0, 0, 1]]`.
    pub fn camera_matrix(&self) -> Matrix3<f64> {
        Matrix3::new(
            self.fx, self.skew, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0,
        )
    }

    /// All parameters: `[fx, fy, cx, cy, skew, distortion coefficients...]`.
    pub fn params(&self) -> Vec<f64> {
        let mut p = vec![self.fx, self.fy, self.cx, self.cy, self.skew];
        p.extend(self.distortion.coefficients());
        p
    }

    /// Names of [`Camera::params`], e.g. `fx fy cx cy skew k1 k2 p1 p2 k3`.
    pub fn param_names(&self) -> Vec<&'static str> {
        let mut names = vec!["fx", "fy", "cx", "cy", "skew"];
        names.extend_from_slice(self.distortion.coefficient_names());
        names
    }

    /// The same camera model and image size with new parameters (layout of
    /// [`Camera::params`]). Focal lengths must be positive and finite.
    pub fn with_params(&self, params: &[f64]) -> Result<Camera> {
        let expected = N_PINHOLE_PARAMS + self.distortion.coefficient_names().len();
        if params.len() != expected {
            return Err(Error::invalid(
                "params",
                format!(
                    "a camera with the {} model has {expected} parameters, got {}",
                    self.distortion.model_name(),
                    params.len()
                ),
            ));
        }
        let (pinhole, coeffs) = params.split_at(N_PINHOLE_PARAMS);
        if let Some(i) = pinhole.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                self.param_names()[i],
                format!("must be finite, got {}", pinhole[i]),
            ));
        }
        for (name, value) in [("fx", pinhole[0]), ("fy", pinhole[1])] {
            if value <= 0.0 {
                return Err(Error::invalid(
                    name,
                    format!("focal length must be > 0 px, got {value}"),
                ));
            }
        }
        Ok(Camera {
            fx: pinhole[0],
            fy: pinhole[1],
            cx: pinhole[2],
            cy: pinhole[3],
            skew: pinhole[4],
            width: self.width,
            height: self.height,
            distortion: self.distortion.with_coefficients(coeffs)?,
        })
    }

    /// Pixel of a camera-frame point. Fails for points the model cannot
    /// project (behind the camera for the perspective models, outside the
    /// field of view of the wide-angle ones, outside the division model's
    /// domain).
    pub fn project(&self, p_camera: &Point3<f64>) -> Result<Point2<f64>> {
        let m = self.distortion.project_point(&p_camera.coords)?;
        Ok(self.pixel_from_normalized(&m))
    }

    /// [`Camera::project`] with the analytic Jacobians: d pixel / d point
    /// (2x3) and d pixel / d params (2 x `params().len()`, columns in the
    /// order of [`Camera::param_names`]).
    pub fn project_with_jacobians(
        &self,
        p_camera: &Point3<f64>,
    ) -> Result<(Point2<f64>, Matrix2x3<f64>, DMatrix<f64>)> {
        let mut columns: Vec<(usize, f64, f64)> = Vec::with_capacity(N_PINHOLE_PARAMS + 14);
        let (pixel, d_point) =
            self.project_with_jacobian_columns(p_camera, |c, x, y| columns.push((c, x, y)))?;
        let mut d_params = DMatrix::zeros(2, columns.len());
        for (c, x, y) in columns {
            d_params[(0, c)] = x;
            d_params[(1, c)] = y;
        }
        Ok((pixel, d_point, d_params))
    }

    /// [`Camera::project_with_jacobians`] handing d pixel / d params to
    /// `column(c, d_u, d_v)` one parameter `c` at a time (every column, in
    /// order) instead of into a new matrix: for a solver that stacks them
    /// itself.
    pub(crate) fn project_with_jacobian_columns(
        &self,
        p_camera: &Point3<f64>,
        mut column: impl FnMut(usize, f64, f64),
    ) -> Result<(Point2<f64>, Matrix2x3<f64>)> {
        if let Some((poly, cols)) = self.poly_parts() {
            return self.poly_jacobian_columns(&poly, cols, &p_camera.coords, column);
        }
        let ray = self.distortion.project_ray(&p_camera.coords)?;
        let k = self.linear_part();
        let (mx, my) = (ray.m.x, ray.m.y);
        column(0, mx, 0.0);
        column(1, 0.0, my);
        column(2, 1.0, 0.0);
        column(3, 0.0, 1.0);
        column(4, my, 0.0);
        for (i, d) in ray.d_coeffs.iter().enumerate() {
            let col = k * d;
            column(N_PINHOLE_PARAMS + i, col.x, col.y);
        }
        Ok((self.pixel_from_normalized(&ray.m), k * ray.d_point))
    }

    /// The polynomial family's coefficients and the model's columns of
    /// them, for [`Camera::poly_jacobian_columns`]; `None` for other models.
    pub(crate) fn poly_parts(&self) -> Option<(polynomial::Poly, &'static [usize])> {
        match self.distortion.family() {
            distortion::Family::Poly(poly, cols) => Some((poly, cols)),
            _ => None,
        }
    }

    /// [`Camera::project_with_jacobian_columns`] of the polynomial family
    /// (`poly` and `cols` from [`Camera::poly_parts`], taken once for many
    /// points): the expressions of [`Distortion::project_ray`] (so the same
    /// bits) without its vector of columns, and only the model's own
    /// coefficient columns computed.
    pub(crate) fn poly_jacobian_columns(
        &self,
        poly: &polynomial::Poly,
        cols: &[usize],
        p: &Vector3<f64>,
        mut column: impl FnMut(usize, f64, f64),
    ) -> Result<(Point2<f64>, Matrix2x3<f64>)> {
        if !(p.z > 0.0) || !p.iter().all(|v| v.is_finite()) {
            return Err(distortion::not_in_front(p));
        }
        let n = Vector2::new(p.x / p.z, p.y / p.z);
        let d_n_d_p = Matrix2x3::new(1.0 / p.z, 0.0, -n.x / p.z, 0.0, 1.0 / p.z, -n.y / p.z);
        if !poly.in_domain(n.norm_squared()) {
            return Err(self.distortion.beyond_fold(&n));
        }
        let (m, d_n, columns) = poly.distort_lazy(&n);
        let d_point = d_n * d_n_d_p;
        let k = self.linear_part();
        column(0, m.x, 0.0);
        column(1, 0.0, m.y);
        column(2, 1.0, 0.0);
        column(3, 0.0, 1.0);
        column(4, m.y, 0.0);
        for (i, &c) in cols.iter().enumerate() {
            let col = k * columns.column(c);
            column(N_PINHOLE_PARAMS + i, col.x, col.y);
        }
        Ok((self.pixel_from_normalized(&m), k * d_point))
    }

    /// The unit-norm bearing (camera frame) of a pixel. Iterative for the
    /// polynomial models; fails with [`Error::NoConvergence`] when the
    /// inverse does not converge or lands beyond a fold of the model.
    pub fn unproject(&self, pixel: &Point2<f64>) -> Result<Vector3<f64>> {
        let m = self.normalized_from_pixel(pixel)?;
        self.distortion.unproject_ray(&m)
    }

    /// Apply the lens model to an ideal normalised point `(X/Z, Y/Z)`.
    pub fn distort_normalized(&self, undistorted: &Point2<f64>) -> Result<Point2<f64>> {
        Ok(Point2::from(
            self.distortion.distort_point(&undistorted.coords)?,
        ))
    }

    /// Remove the lens model from a distorted normalised point: the ideal
    /// `(X/Z, Y/Z)`. Fails for rays at or beyond 90 degrees (no pinhole image).
    pub fn undistort_normalized(&self, distorted: &Point2<f64>) -> Result<Point2<f64>> {
        let ray = self.distortion.unproject_ray(&distorted.coords)?;
        if !(ray.z > 0.0) {
            return Err(Error::invalid(
                "point",
                format!(
                    "({:.6}, {:.6}) is a ray at or beyond 90 degrees: it has no undistorted pinhole position",
                    distorted.x, distorted.y
                ),
            ));
        }
        Ok(Point2::new(ray.x / ray.z, ray.y / ray.z))
    }

    /// The 2x2 linear part of the camera matrix.
    fn linear_part(&self) -> Matrix2<f64> {
        Matrix2::new(self.fx, self.skew, 0.0, self.fy)
    }

    fn pixel_from_normalized(&self, m: &Vector2<f64>) -> Point2<f64> {
        Point2::new(
            self.fx * m.x + self.skew * m.y + self.cx,
            self.fy * m.y + self.cy,
        )
    }

    fn normalized_from_pixel(&self, pixel: &Point2<f64>) -> Result<Vector2<f64>> {
        if !(self.fx > 0.0 && self.fy > 0.0) {
            return Err(Error::invalid(
                "camera",
                format!(
                    "focal lengths must be > 0 px, got fx {} fy {}",
                    self.fx, self.fy
                ),
            ));
        }
        let my = (pixel.y - self.cy) / self.fy;
        let mx = (pixel.x - self.cx - self.skew * my) / self.fx;
        Ok(Vector2::new(mx, my))
    }
}
