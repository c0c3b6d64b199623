//! Quality measures: closure residuals per view and per motion, summary
//! errors (seed 004's translation/rotation RMS and max), and the distance
//! between two solutions.

use crate::handeye::{Chain, Motion, Pose};
use serde::{Deserialize, Serialize};

/// Residual of one view: how far `robot[i] * x * camera[i]` lands from the
/// solved target pose `y`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ViewResidual {
    /// View index (position in the input lists).
    pub view: usize,
    /// Translation residual (mm).
    pub translation_mm: f64,
    /// Rotation residual (degrees).
    pub rotation_deg: f64,
}

/// Residual of one motion pair: `(A X)^-1 (X B)`, and the difference of the
/// robot and camera rotation angles (which must be equal whatever X is).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct MotionResidual {
    /// First view.
    pub from: usize,
    /// Second view.
    pub to: usize,
    /// Translation residual (mm).
    pub translation_mm: f64,
    /// Rotation residual (degrees).
    pub rotation_deg: f64,
    /// |robot angle - camera angle| (degrees).
    pub angle_mismatch_deg: f64,
}

/// Summary errors (the `errors` object of the JSON contract).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, Default)]
pub struct Errors {
    /// RMS of the per-view translation residuals (mm).
    pub translation_rms_mm: f64,
    /// Largest per-view translation residual (mm).
    pub translation_max_mm: f64,
    /// RMS of the per-view rotation residuals (degrees).
    pub rotation_rms_deg: f64,
    /// Largest per-view rotation residual (degrees).
    pub rotation_max_deg: f64,
    /// Reprojection RMS (pixels) when image points were given, else `None`.
    pub reprojection_rms_px: Option<f64>,
}

/// Translation (mm) and rotation (degrees) between two poses.
pub fn pose_difference(a: &Pose, b: &Pose) -> (f64, f64) {
    let d = a.inverse() * b;
    (
        (a.translation.vector - b.translation.vector).norm() * 1e3,
        d.rotation.angle().to_degrees(),
    )
}

/// Per-view closure residuals of a solution.
pub fn view_residuals(chain: &Chain, x: &Pose, y: &Pose) -> Vec<ViewResidual> {
    (0..chain.len())
        .map(|i| {
            let (t, r) = pose_difference(y, &chain.implied_target(i, x));
            ViewResidual {
                view: i,
                translation_mm: t,
                rotation_deg: r,
            }
        })
        .collect()
}

/// Per-motion residuals of a solution.
pub fn motion_residuals(motions: &[Motion], x: &Pose) -> Vec<MotionResidual> {
    motions
        .iter()
        .map(|m| {
            let (t, r) = pose_difference(&(m.robot * x), &(x * m.camera));
            MotionResidual {
                from: m.from,
                to: m.to,
                translation_mm: t,
                rotation_deg: r,
                angle_mismatch_deg: (m.robot_angle() - m.camera_angle()).abs().to_degrees(),
            }
        })
        .collect()
}

fn rms_max(values: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let n = values.clone().count().max(1) as f64;
    let rms = (values.clone().map(|v| v * v).sum::<f64>() / n).sqrt();
    (rms, values.fold(0.0, f64::max))
}

/// Summary errors of per-view residuals.
pub fn errors(residuals: &[ViewResidual]) -> Errors {
    let (t_rms, t_max) = rms_max(residuals.iter().map(|r| r.translation_mm));
    let (r_rms, r_max) = rms_max(residuals.iter().map(|r| r.rotation_deg));
    Errors {
        translation_rms_mm: t_rms,
        translation_max_mm: t_max,
        rotation_rms_deg: r_rms,
        rotation_max_deg: r_max,
        reprojection_rms_px: None,
    }
}

/// RMS translation (mm) and rotation (degrees) of motion residuals.
pub fn motion_rms(residuals: &[MotionResidual]) -> (f64, f64) {
    let (t, _) = rms_max(residuals.iter().map(|r| r.translation_mm));
    let (r, _) = rms_max(residuals.iter().map(|r| r.rotation_deg));
    (t, r)
}

/// One number to rank solutions: the RMS displacement (mm) at the target,
/// combining the translation residual with the rotation residual times the
/// RMS camera-to-target distance `lever_m`.
pub fn combined_score_mm(errors: &Errors, lever_m: f64) -> f64 {
    let rot_mm = errors.rotation_rms_deg.to_radians() * lever_m * 1e3;
    (errors.translation_rms_mm.powi(2) + rot_mm.powi(2)).sqrt()
}

/// RMS camera-to-target distance (metres), the lever arm of rotation errors.
pub fn lever_arm_m(chain: &Chain) -> f64 {
    let n = chain.len().max(1) as f64;
    (chain
        .camera
        .iter()
        .map(|c| c.translation.vector.norm_squared())
        .sum::<f64>()
        / n)
        .sqrt()
}
