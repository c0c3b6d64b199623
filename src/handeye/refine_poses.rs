//! The pose refinement ([`super::pose_refine`]) applied to a closed-form
//! [`HandEyeResult`], mirroring [`super::refine_closed_form`] for the image
//! path: the noise levels are first estimated at the fixed-rule closed form,
//! every closed form is scored by the refinement's own robust cost (its
//! `pose_cost`), the lowest one seeds the refinement, and the refined
//! transforms become the primary result (`method` = `refined from <closed
//! form>`) with their covariance and the estimated noise levels
//! ([`PoseRefinementSummary`]). Every closed form stays in `methods`.
//!
//! With parallel rotation axes (SCARA) the translation of `x` along the axis
//! is unobservable: it is held at the closed form's value (0) and reported,
//! and only the observable part is refined.

use super::motion::build_motions;
use super::pose_noise::{CameraNoise, NoiseLevels, NoiseModel};
use super::pose_refine::{
    estimate_noise, evaluate, negative_log_likelihood, refine, Covariance12, PoseRefineOptions,
    HUBER_SCALE,
};
use super::pose_residual::PoseMeasurement;
use super::report::{errors, motion_residuals, pose_difference, view_residuals};
use super::solve::{HandEyeInput, HandEyeResult};
use super::{Chain, MotionPairs, Pose};
use crate::error::Result;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Per-axis standard deviations of one transform.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct TransformStd {
    /// Rotation std about the x, y, z axes of the transform's left frame (degrees).
    pub rotation_deg: [f64; 3],
    /// Std of `translation_m`'s x, y, z (mm).
    pub translation_mm: [f64; 3],
}

/// What the pose refinement did (the report's `pose_refinement` object).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PoseRefinementSummary {
    /// The closed form it started from (the lowest `pose_cost`).
    pub started_from: String,
    /// Robust cost of the starting closed form.
    pub closed_form_cost: f64,
    /// Robust cost after refinement, `0.5 sum rho(|z_i|^2)` over the
    /// whitened residuals (about 3 per good view).
    pub cost: f64,
    /// `diagonal` (camera noise per camera axis, estimated) or `per_view`
    /// (each view's PnP covariance, its scale estimated).
    pub camera_noise_model: String,
    /// The estimated noise levels.
    pub noise: NoiseLevels,
    /// Diagonal model: the target point (metres, target frame) the camera
    /// rotation noise pivots about, when that fits the data better than the
    /// target origin (where the optical axes meet the target plane, on
    /// average); absent: the origin.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub camera_noise_pivot_m: Option<[f64; 3]>,
    /// False when there were too few poses (fewer than 8 inliers): the
    /// documented default levels were then scaled by one common factor.
    pub noise_estimated_per_component: bool,
    /// Std of the camera transform (`gripper_from_camera` or `base_from_camera`).
    pub camera_transform_std: TransformStd,
    /// Std of the target transform (`base_from_target` or `gripper_from_target`).
    pub target_transform_std: TransformStd,
    /// 12 x 12 covariance, rows of `[camera transform rx, ry, rz (rad), tx,
    /// ty, tz (m), target transform rx, ry, rz, tx, ty, tz]`, rotation errors
    /// in each transform's left frame.
    pub covariance: Vec<[f64; 12]>,
    /// Whitened residual norm per view (about 2.4 for a good view).
    pub whitened_residual_norms: Vec<f64>,
    /// Views down-weighted as outliers (whitened norm above 4.1).
    pub outlier_views: Vec<usize>,
}

fn transform_std(cov: &Covariance12, offset: usize) -> TransformStd {
    let s = |k: usize| cov[(offset + k, offset + k)].max(0.0).sqrt();
    TransformStd {
        rotation_deg: [s(0), s(1), s(2)].map(f64::to_degrees),
        translation_mm: [s(3), s(4), s(5)].map(|v| v * 1e3),
    }
}

/// The measurements of an input, in order.
pub fn measurements(input: &HandEyeInput) -> Vec<PoseMeasurement> {
    input
        .base_from_gripper
        .iter()
        .zip(&input.camera_from_target)
        .map(|(b, c)| PoseMeasurement {
            base_from_gripper: *b,
            camera_from_target: *c,
        })
        .collect()
}

/// Where the camera looks on the target: the mean intersection of the
/// optical axes with the target plane z = 0 (target frame), the pivot of
/// the diagonal camera noise model ([`NoiseModel::pivot_levers`]). `None`
/// when an axis is nearly parallel to the plane or the mean is not finite
/// (then the target origin is the pivot).
pub fn board_pivot(views: &[PoseMeasurement]) -> Option<Vector3<f64>> {
    let mut sum = Vector3::zeros();
    for m in views {
        let target_from_camera = m.camera_from_target.inverse();
        let origin = target_from_camera.translation.vector;
        let axis = target_from_camera.rotation * Vector3::z();
        if axis.z.abs() < 0.1 {
            return None;
        }
        sum += origin - axis * (origin.z / axis.z);
    }
    let p = sum / views.len().max(1) as f64;
    p.iter().all(|v| v.is_finite()).then_some(p)
}

/// `R_c p` per view for a pivot `p` (target frame).
pub fn pivot_levers(views: &[PoseMeasurement], pivot: &Vector3<f64>) -> Vec<Vector3<f64>> {
    views
        .iter()
        .map(|m| m.camera_from_target.rotation * pivot)
        .collect()
}

/// Score every closed form, refine from the best, make the refined
/// transforms primary. A refinement that fails leaves the closed form
/// primary with a warning (never an error: the closed forms stand).
pub fn apply_pose_refinement(
    result: &mut HandEyeResult,
    input: &HandEyeInput,
    camera_noise: CameraNoise,
    motion_pairs: MotionPairs,
) -> Result<()> {
    let views = measurements(input);
    let setup = input.setup;
    let axis = result.unobservable_translation.first().copied();
    let options = PoseRefineOptions {
        camera_noise: camera_noise.clone(),
        unobservable_translation: axis,
    };
    let model_name = match camera_noise {
        CameraNoise::Diagonal => "diagonal",
        CameraNoise::PerView(_) => "per_view",
    };
    let diagonal = matches!(camera_noise, CameraNoise::Diagonal);
    let mut pivot = None;
    let mut noise = NoiseModel::new(camera_noise);
    if let Err(e) = estimate_noise(setup, &views, &mut noise, &result.x, &result.y, axis) {
        result
            .warnings
            .push(format!("pose refinement skipped: {e}"));
        return Ok(());
    }
    // The diagonal camera noise about the target origin or about where the
    // camera looks on the target: the one the data make more likely.
    if let (true, Some(p)) = (diagonal, board_pivot(&views)) {
        let mut pivoted = NoiseModel::new(CameraNoise::Diagonal);
        pivoted.pivot_levers = pivot_levers(&views, &p);
        let better = estimate_noise(setup, &views, &mut pivoted, &result.x, &result.y, axis)
            .and_then(|_| {
                let with = negative_log_likelihood(setup, &views, &pivoted, &result.x, &result.y)?;
                let without = negative_log_likelihood(setup, &views, &noise, &result.x, &result.y)?;
                Ok(with < without)
            });
        if better.unwrap_or(false) {
            noise = pivoted;
            pivot = Some([p.x, p.y, p.z]);
        }
    }
    // Every closed form under the same noise levels; the lowest seeds.
    let mut start: (f64, String, Pose, Pose) =
        match evaluate(setup, &views, &noise, &result.x, &result.y) {
            Ok((_, c)) => (c, result.method.clone(), result.x, result.y),
            Err(e) => {
                result
                    .warnings
                    .push(format!("pose refinement skipped: {e}"));
                return Ok(());
            }
        };
    for m in &mut result.methods {
        if let Ok((x, y, _)) = &m.outcome {
            if let Ok((_, c)) = evaluate(setup, &views, &noise, x, y) {
                m.pose_cost = Some(c);
                if c < start.0 {
                    start = (c, m.method.name().to_string(), *x, *y);
                }
            }
        }
    }
    let (closed_form_cost, started_from, x0, y0) = start;
    let refined = match refine(setup, &views, &x0, &y0, noise, &options) {
        Ok(r) => r,
        Err(e) => {
            result.warnings.push(format!(
                "pose refinement failed, the closed form is kept: {e}"
            ));
            return Ok(());
        }
    };
    let chain = Chain::new(setup, &input.base_from_gripper, &input.camera_from_target)?;
    result.x = refined.x;
    result.y = refined.y;
    result.method = format!("refined from {started_from}");
    result.per_view = view_residuals(&chain, &result.x, &result.y);
    result.errors = errors(&result.per_view);
    result.per_motion = motion_residuals(&build_motions(&chain, motion_pairs).kept, &result.x);
    for m in &mut result.methods {
        if let Ok((mx, _, _)) = &m.outcome {
            m.disagreement = Some(pose_difference(&result.x, mx));
        }
    }
    if !refined.outliers.is_empty() {
        let list: Vec<String> = refined.outliers.iter().map(|v| v.to_string()).collect();
        result.warnings.push(format!(
            "pose refinement: view(s) {} fit the others poorly (whitened residual above {HUBER_SCALE}) \
             and were down-weighted as outliers; check those robot/camera pose pairs",
            list.join(", ")
        ));
    }
    let cov = refined.covariance;
    result.pose_refinement = Some(PoseRefinementSummary {
        started_from,
        closed_form_cost,
        cost: refined.cost,
        camera_noise_model: model_name.to_string(),
        noise: refined.noise.levels(),
        camera_noise_pivot_m: pivot,
        noise_estimated_per_component: refined.noise_per_component,
        camera_transform_std: transform_std(&cov, 0),
        target_transform_std: transform_std(&cov, 6),
        covariance: (0..12)
            .map(|r| std::array::from_fn(|c| cov[(r, c)]))
            .collect(),
        whitened_residual_norms: refined.whitened_norms,
        outlier_views: refined.outliers,
    });
    Ok(())
}
