//! A "true" lens no parametric model fits: a camera's own projection
//! reproduced by a splined stereographic lens, plus a smooth bump field of
//! a few pixels (what a real lens's manufacturing leaves and a polynomial
//! cannot follow). Rendered through it, a calibration can compare every
//! model's projection with the truth.

use crate::camera::{Camera, Distortion, Spline};
use crate::error::{Error, Result};

/// The bump field's control points: 12 x 8 cubic (the splined model's
/// default, so that a default splined fit can reproduce it).
const BUMP_KNOTS: (usize, usize) = (12, 8);

/// `camera`'s projection plus bumps of about `amplitude_px` pixels (a
/// product of sines across the knot grid, x and y different), as a splined
/// camera with `camera`'s fx fy cx cy.
pub fn bumpy_lens(camera: &Camera, amplitude_px: f64) -> Result<Camera> {
    if !(amplitude_px.is_finite() && amplitude_px >= 0.0) {
        return Err(Error::invalid(
            "amplitude_px",
            format!("the bumps' amplitude must be >= 0 px, got {amplitude_px}"),
        ));
    }
    let mut lens = camera.splined_like(&Spline::new(3, BUMP_KNOTS.0, BUMP_KNOTS.1))?;
    let scale = amplitude_px / (0.5 * (camera.fx + camera.fy));
    if let Distortion::Splined(s) = &mut lens.distortion {
        for row in 0..s.ny {
            for col in 0..s.nx {
                let k = 2 * (row * s.nx + col);
                let (c, r) = (col as f64, row as f64);
                s.control[k] += scale * (0.9 * c).sin() * (0.7 * r).cos();
                s.control[k + 1] += scale * (0.5 * c + 0.3).cos() * (0.8 * r).sin();
            }
        }
    }
    Ok(lens)
}
