//! Kannala-Brandt equidistant fisheye model (OpenCV's `cv::fisheye`).
//!
//! With theta the angle between the ray and the optical axis,
//! `theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)`
//! and the distorted normalised point is `theta_d * (X, Y) / sqrt(X^2 + Y^2)`.
//! theta comes from `atan2(sqrt(X^2 + Y^2), Z)`, so rays up to (not
//! including) 180 degrees project; OpenCV's `atan(r)` agrees for Z > 0.

use crate::error::{Error, Result};
use nalgebra::{Matrix2x3, Vector2, Vector3};

/// Largest number of Newton steps of the inverse.
const MAX_NEWTON_STEPS: usize = 50;
/// Convergence tolerance on theta_d (radians).
const NEWTON_TOLERANCE: f64 = 1e-14;
/// Below this off-axis distance relative to |p| the ray is on the axis.
const ON_AXIS: f64 = 1e-12;

/// theta_d(theta) and d theta_d / d theta.
fn theta_d(k: &[f64; 4], theta: f64) -> (f64, f64) {
    let t2 = theta * theta;
    let poly = 1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])));
    let deriv = 1.0 + t2 * (3.0 * k[0] + t2 * (5.0 * k[1] + t2 * (7.0 * k[2] + t2 * 9.0 * k[3])));
    (theta * poly, deriv)
}

/// Samples of d theta_d / d theta checked between the axis and a ray.
const DOMAIN_SAMPLES: usize = 8;

/// Whether theta_d increases on [0, theta] (sampled): beyond its first
/// maximum the model maps rays back onto the image.
fn monotonic_up_to(k: &[f64; 4], theta: f64) -> bool {
    (1..=DOMAIN_SAMPLES).all(|i| theta_d(k, theta * i as f64 / DOMAIN_SAMPLES as f64).1 > 0.0)
}

/// Distorted normalised point, Jacobian with respect to the 3-D point and
/// with respect to k1..k4.
pub(crate) fn project(k: &[f64; 4], p: &Vector3<f64>) -> Result<super::ProjectionWithJacobians<4>> {
    let (x, y, z) = (p.x, p.y, p.z);
    let rho = (x * x + y * y).sqrt();
    let norm2 = rho * rho + z * z;
    if !(norm2 > 0.0) || !norm2.is_finite() {
        return Err(Error::invalid(
            "point",
            "a point at the camera centre has no projection",
        ));
    }
    if rho <= ON_AXIS * norm2.sqrt() {
        if z <= 0.0 {
            return Err(Error::invalid(
                "point",
                "a point straight behind the camera has no fisheye projection",
            ));
        }
        // theta ~ rho / z: the first-order model is the pinhole one.
        let d_p = Matrix2x3::new(1.0 / z, 0.0, -x / (z * z), 0.0, 1.0 / z, -y / (z * z));
        return Ok((Vector2::new(x / z, y / z), d_p, [Vector2::zeros(); 4]));
    }
    let theta = rho.atan2(z);
    if !monotonic_up_to(k, theta) {
        return Err(Error::invalid(
            "point",
            format!(
                "ray at {:.2} degrees off axis lies beyond the fold of the fisheye model",
                theta.to_degrees()
            ),
        ));
    }
    let (td, dtd) = theta_d(k, theta);
    let s = td / rho;
    let dtheta = Vector3::new(z * x / (rho * norm2), z * y / (rho * norm2), -rho / norm2);
    let rho3 = rho * rho * rho;
    let ds = Vector3::new(
        dtd * dtheta.x / rho - td * x / rho3,
        dtd * dtheta.y / rho - td * y / rho3,
        dtd * dtheta.z / rho,
    );
    let d_p = Matrix2x3::new(
        s + x * ds.x,
        x * ds.y,
        x * ds.z,
        y * ds.x,
        s + y * ds.y,
        y * ds.z,
    );
    let dir = Vector2::new(x / rho, y / rho);
    let t3 = theta * theta * theta;
    let t2 = theta * theta;
    let d_k = [
        dir * t3,
        dir * (t3 * t2),
        dir * (t3 * t2 * t2),
        dir * (t3 * t2 * t2 * t2),
    ];
    Ok((Vector2::new(s * x, s * y), d_p, d_k))
}

/// The ray (not normalised) whose projection is the distorted normalised `m`.
pub(crate) fn unproject(k: &[f64; 4], m: &Vector2<f64>) -> Result<Vector3<f64>> {
    let target = m.norm();
    if target == 0.0 {
        return Ok(Vector3::z());
    }
    // Newton on theta_d(theta) = target, from theta = target, kept in [0, pi).
    let mut theta = target.min(3.0);
    for _ in 0..MAX_NEWTON_STEPS {
        let (td, dtd) = theta_d(k, theta);
        let residual = td - target;
        if residual.abs() <= NEWTON_TOLERANCE * (1.0 + target) {
            if !monotonic_up_to(k, theta) || theta >= std::f64::consts::PI {
                break;
            }
            let (sin, cos) = theta.sin_cos();
            return Ok(Vector3::new(sin * m.x / target, sin * m.y / target, cos));
        }
        if !(dtd > 0.0) || !residual.is_finite() {
            break;
        }
        theta = (theta - residual / dtd).clamp(0.0, std::f64::consts::PI);
    }
    Err(Error::NoConvergence {
        message: format!(
            "fisheye unprojection of normalised radius {target:.6}: no monotonic solution of theta_d(theta) in [0, pi)"
        ),
    })
}
