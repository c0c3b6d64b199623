//! Enhanced unified camera model (Khomenko et al. 2016), for wide angle
//! and fisheye lenses.
//!
//! `d = sqrt(beta (X^2 + Y^2) + Z^2)`, `m = (X, Y) / (alpha d + (1 - alpha) Z)`
//! with `alpha` in [0, 1] and `beta > 0`. alpha = 0 is the pinhole camera.
//! A point projects when `Z > -w d`, `w = alpha / (1 - alpha)` for alpha <=
//! 0.5, else `(1 - alpha) / alpha`, the limit where the projection stays
//! one-to-one.

use crate::error::{Error, Result};
use nalgebra::{Matrix2x3, Vector2, Vector3};

fn validity_w(alpha: f64) -> f64 {
    if alpha > 0.5 {
        (1.0 - alpha) / alpha
    } else {
        alpha / (1.0 - alpha)
    }
}

fn check_params(alpha: f64, beta: f64) -> Result<()> {
    if !(0.0..1.0).contains(&alpha) || !(beta > 0.0) || !beta.is_finite() {
        return Err(Error::invalid(
            "distortion",
            format!("EUCM needs 0 <= alpha < 1 and beta > 0, got alpha {alpha}, beta {beta}"),
        ));
    }
    Ok(())
}

/// Normalised point, Jacobian with respect to the 3-D point and with
/// respect to (alpha, beta).
pub(crate) fn project(
    alpha: f64,
    beta: f64,
    p: &Vector3<f64>,
) -> Result<super::ProjectionWithJacobians<2>> {
    check_params(alpha, beta)?;
    let (x, y, z) = (p.x, p.y, p.z);
    let r2 = x * x + y * y;
    let d = (beta * r2 + z * z).sqrt();
    let den = alpha * d + (1.0 - alpha) * z;
    if !(z > -validity_w(alpha) * d) || !(den > 0.0) {
        return Err(Error::invalid(
            "point",
            format!("point ({x:.4}, {y:.4}, {z:.4}) is outside the EUCM field of view"),
        ));
    }
    let dd = Vector3::new(
        alpha * beta * x / d,
        alpha * beta * y / d,
        alpha * z / d + 1.0 - alpha,
    );
    let den2 = den * den;
    let d_p = Matrix2x3::new(
        1.0 / den - x * dd.x / den2,
        -x * dd.y / den2,
        -x * dd.z / den2,
        -y * dd.x / den2,
        1.0 / den - y * dd.y / den2,
        -y * dd.z / den2,
    );
    let xy = Vector2::new(x, y);
    let d_alpha = xy * (-(d - z) / den2);
    let d_beta = xy * (-alpha * r2 / (2.0 * d * den2));
    Ok((xy / den, d_p, [d_alpha, d_beta]))
}

/// The ray (not normalised) whose projection is the normalised `m`.
pub(crate) fn unproject(alpha: f64, beta: f64, m: &Vector2<f64>) -> Result<Vector3<f64>> {
    check_params(alpha, beta)?;
    let r2 = m.norm_squared();
    let disc = 1.0 - (2.0 * alpha - 1.0) * beta * r2;
    if disc < 0.0 {
        return Err(Error::invalid(
            "pixel",
            format!(
                "normalised radius {:.6} is outside the EUCM image circle",
                r2.sqrt()
            ),
        ));
    }
    let mz = (1.0 - beta * alpha * alpha * r2) / (alpha * disc.sqrt() + 1.0 - alpha);
    Ok(Vector3::new(m.x, m.y, mz))
}
