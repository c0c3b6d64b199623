//! The division model (Fitzgibbon 2001; Halcon's "division" model) in
//! normalised coordinates.
//!
//! The model is defined in the undistorting direction, which is closed-form:
//! `n = m / (1 + kappa |m|^2)` (m distorted, n undistorted). Distorting is
//! the root of `kappa r_u r_d^2 - r_d + r_u = 0` on the branch through the
//! origin: `m = n * 2 / (1 + sqrt(1 - 4 kappa |n|^2))`, defined while
//! `4 kappa |n|^2 < 1` (always for barrel distortion, kappa < 0).
//!
//! Halcon's kappa is in 1/m^2 on the metric image plane; ours is in
//! normalised units: `kappa_normalised = kappa_halcon * focal_m^2`.

use crate::error::{Error, Result};
use nalgebra::{Matrix2, Vector2};

/// Distorted point, Jacobian with respect to the undistorted point, and
/// derivative with respect to kappa.
pub(crate) fn distort(
    kappa: f64,
    n: &Vector2<f64>,
) -> Result<(Vector2<f64>, Matrix2<f64>, Vector2<f64>)> {
    let r2 = n.norm_squared();
    let disc = 1.0 - 4.0 * kappa * r2;
    if disc.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::invalid(
            "point",
            format!(
                "normalised radius {:.6} is outside the division model's domain (kappa {kappa}: needs 4 kappa r^2 < 1)",
                r2.sqrt()
            ),
        ));
    }
    let q = disc.sqrt();
    let g = 2.0 / (1.0 + q);
    let common = 4.0 / (q * (1.0 + q) * (1.0 + q));
    let dg_dr2 = kappa * common;
    let dg_dkappa = r2 * common;
    let d_n = Matrix2::identity() * g + (n * n.transpose()) * (2.0 * dg_dr2);
    Ok((n * g, d_n, n * dg_dkappa))
}

/// The undistorted normalised point of a distorted one (closed form).
pub(crate) fn undistort(kappa: f64, m: &Vector2<f64>) -> Result<Vector2<f64>> {
    let denominator = 1.0 + kappa * m.norm_squared();
    if denominator.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::invalid(
            "pixel",
            format!(
                "normalised radius {:.6} is outside the division model's domain (kappa {kappa}: needs 1 + kappa r^2 > 0)",
                m.norm()
            ),
        ));
    }
    let n = m / denominator;
    // Points beyond the fold map back to a different distorted radius.
    let (back, _, _) = distort(kappa, &n)?;
    if (back - m).norm() > 1e-9 * (1.0 + m.norm()) {
        return Err(Error::NoConvergence {
            message: format!(
                "undistorting ({:.6}, {:.6}): the point lies beyond the fold of the division model",
                m.x, m.y
            ),
        });
    }
    Ok(n)
}
