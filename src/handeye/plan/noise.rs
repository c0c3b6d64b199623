//! The pixel noise the plan's prediction assumes, measured on the current
//! view: the corner detector's real noise, not a guess.
//!
//! PnP fits the view's 6 pose parameters to its `n` detected points; the
//! `2n` residual coordinates then scatter with the per-axis corner noise
//! `sigma` less the 6 degrees of freedom the pose absorbed, so
//! `sigma = sqrt(sum r^2 / (2n - 6))` (`rms * sqrt(n / (2n - 6))` with the
//! reprojection RMS per point). The residual holds whatever the camera
//! model leaves out too (a lens poorly calibrated, a board not flat): then
//! the measured noise is larger than the detector's and the prediction
//! cautious.

use crate::calib::pnp::camera_from_target;
use crate::calib::View;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::handeye::Pose;

/// The view's `camera_from_target` and the per-axis pixel noise measured
/// on it (module docs). Needs 4 or more points.
pub fn pixel_sigma_from_view(camera: &Camera, view: &View) -> Result<(Pose, f64)> {
    let (pose, rms) = camera_from_target(camera, view)?;
    let n = view.object_m.len() as f64;
    let sigma = rms * (n / (2.0 * n - 6.0)).sqrt();
    if !sigma.is_finite() {
        return Err(Error::degenerate(
            "the current view's reprojection residual is not finite",
        ));
    }
    Ok((pose, sigma))
}
