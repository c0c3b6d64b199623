//! What the pose refinement reports (the report's `pose_refinement`
//! object, [`PoseRefinementSummary`]) and the per-axis standard deviations
//! of a transform from its covariance.

use crate::handeye::quality::work_point::DefaultWorkPoint;
use crate::handeye::refine::pose_noise::NoiseLevels;
use crate::handeye::refine::pose_problem::Covariance12;
use serde::{Deserialize, Serialize};

/// Per-axis standard deviations of one transform.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, Default)]
pub struct TransformStd {
    /// Rotation std about the x, y, z axes of the transform's left frame (degrees).
    pub rotation_deg: [f64; 3],
    /// Std of `translation_m`'s x, y, z (mm).
    pub translation_mm: [f64; 3],
}

/// What [`crate::handeye::quality::focal::check_focal`] found when the focal length disagrees with the
/// robot: the report's `pose_refinement.focal_check` object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FocalCheck {
    /// The scale of fx and fy that fits the pixels through the robot poses.
    pub scale: f64,
    /// Its jackknife std over the views.
    pub scale_std: f64,
    /// How far the freed solution (camera poses from PnP with the scaled
    /// focal length, pose refinement again) lies from the reported one:
    /// (mm, degrees) of the camera transform; absent when that refit failed.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub freed_moves: Option<[f64; 2]>,
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
    /// `predicted_pnp` model: the nominal planar target whose PnP
    /// covariance shape was predicted at each view's pose.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub camera_noise_nominal_target_m: Option<NominalTargetReport>,
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
    /// With image points: reprojection RMS (px) of the refined transforms
    /// over every point, each view's points projected through
    /// `x^-1 * robot[i]^-1 * y` (also `errors.reprojection_rms_px`).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub reprojection_rms_px: Option<f64>,
    /// With image points: the same per view (px).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub per_view_reprojection_rms_px: Option<Vec<f64>>,
    /// With image points: reprojection RMS (px) of the closed form it
    /// started from.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub closed_form_reprojection_rms_px: Option<f64>,
    /// When the leave-one-out solutions spread wider than the noise model
    /// predicts, or the noise scale rests on few poses (the Student-t
    /// factor of its degrees of freedom): the factor the std (and the
    /// covariance's square root) was widened by, the product of both
    /// ([`crate::handeye::quality::trust`]); absent: not widened.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub std_widened_by: Option<f64>,
    /// The working distance: the mean distance from the camera to the
    /// target's centre over the views (m; the target frame's origin with
    /// camera poses only), the distance of the default work point
    /// ([`crate::handeye::quality::work_point`]).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub work_distance_m: Option<f64>,
    /// The std at the default work point (mm, root-sum-square over the
    /// axes; the report's `work_point_error.rms_mm`): the hand-eye error
    /// where the camera looks at the target
    /// ([`crate::handeye::quality::trust::work_point_std_mm`]).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub work_point_std_mm: Option<f64>,
    /// With image points: present when the camera's focal length disagrees
    /// with the robot's motion beyond its std; the std then include the
    /// shift to the solution with the focal length freed
    /// ([`crate::handeye::quality::focal`]).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub focal_check: Option<FocalCheck>,
    /// The default work point itself, for the report's `work_point_error`
    /// (not written: that object holds it).
    #[serde(skip)]
    pub work_point: Option<DefaultWorkPoint>,
}

#[cfg(test)]
impl PoseRefinementSummary {
    /// A summary holding only `covariance` (tests of what reads it).
    pub(crate) fn for_tests(covariance: Vec<[f64; 12]>) -> Self {
        PoseRefinementSummary {
            started_from: String::new(),
            closed_form_cost: 0.0,
            cost: 0.0,
            camera_noise_model: String::new(),
            noise: NoiseLevels::default(),
            camera_noise_pivot_m: None,
            camera_noise_nominal_target_m: None,
            noise_estimated_per_component: true,
            camera_transform_std: TransformStd::default(),
            target_transform_std: TransformStd::default(),
            covariance,
            whitened_residual_norms: Vec::new(),
            outlier_views: Vec::new(),
            reprojection_rms_px: None,
            per_view_reprojection_rms_px: None,
            closed_form_reprojection_rms_px: None,
            std_widened_by: None,
            work_distance_m: None,
            work_point_std_mm: None,
            focal_check: None,
            work_point: None,
        }
    }
}

/// The nominal target of the `predicted_pnp` camera noise model (metres,
/// target frame, on z = 0).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct NominalTargetReport {
    /// Centre (x, y).
    pub centre: [f64; 2],
    /// Half extents along x and y.
    pub half_extent: [f64; 2],
}

/// The std of the transform whose `[rotation, translation]` block starts
/// at `offset` of a 12 x 12 covariance.
pub(crate) fn transform_std(cov: &Covariance12, offset: usize) -> TransformStd {
    let s = |k: usize| cov[(offset + k, offset + k)].max(0.0).sqrt();
    TransformStd {
        rotation_deg: [s(0), s(1), s(2)].map(f64::to_degrees),
        translation_mm: [s(3), s(4), s(5)].map(|v| v * 1e3),
    }
}
