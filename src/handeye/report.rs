//! The JSON report (the output contract of `robocal handeye` and of the
//! wasm `solve_handeye`): `gripper_from_camera` or `base_from_camera`, the
//! target pose, `methods`, `errors`, `warnings`, plus per-view residuals,
//! motion statistics and repeatability.

use crate::geometry::PoseJson;
use crate::handeye::closed_form::motion::MotionStats;
use crate::handeye::quality::repeat::Repeatability;
use crate::handeye::quality::residuals::{Errors, MotionResidual, ViewResidual};
use crate::handeye::quality::verify::{HoldoutReport, TouchReport};
use crate::handeye::quality::work_point::{work_point_error, WorkPointError};
use crate::handeye::refine::pixel_summary::RefinementSummary;
use crate::handeye::refine::pose_summary::PoseRefinementSummary;
use crate::handeye::{HandEyeResult, Pose, Setup};
use nalgebra::Point3;
use serde::{Deserialize, Serialize};

/// One robot pose and the image paired with it.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PairAudit {
    /// Index of the pose in the pose file (0-based, data rows).
    pub pose_index: usize,
    /// The image paired with it (`None` when no image was found for it).
    pub image: Option<String>,
    /// Whether the pair entered the calibration.
    pub used: bool,
    /// Its index among the used views (the `view` of `per_view`), when used.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub view: Option<usize>,
    /// Why it was dropped (detection or pose failure, no image).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub reason: Option<String>,
    /// Reprojection RMS of the target pose fitted to this image alone (px).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub pose_fit_rms_px: Option<f64>,
}

/// One solver in the side-by-side comparison.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct MethodJson {
    /// Method name.
    pub method: String,
    /// The camera transform (key named by the setup), absent when the method failed.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub gripper_from_camera: Option<PoseJson>,
    /// Eye-to-hand camera transform.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub base_from_camera: Option<PoseJson>,
    /// Eye-in-hand target transform.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub base_from_target: Option<PoseJson>,
    /// Eye-to-hand target transform.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub gripper_from_target: Option<PoseJson>,
    /// Closure errors of this method's solution.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub errors: Option<Errors>,
    /// Translation distance of its camera transform from the primary one (mm).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub disagreement_translation_mm: Option<f64>,
    /// Rotation distance of its camera transform from the primary one (degrees).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub disagreement_rotation_deg: Option<f64>,
    /// Why the method failed.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub error: Option<String>,
    /// Robust cost of this solution under the pose refinement's estimated
    /// noise model (the lowest one seeds the refinement), when it ran.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub pose_cost: Option<f64>,
}

/// The full report.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct HandEyeReport {
    /// What the report is: `handeye` (absent from reports written before
    /// the key existed).
    #[serde(default = "crate::report_kind::ReportKind::handeye")]
    pub kind: crate::report_kind::ReportKind,
    /// `eye-in-hand` or `eye-to-hand`.
    pub setup: Setup,
    /// The primary solution's method.
    pub method: String,
    /// Eye-in-hand result.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub gripper_from_camera: Option<PoseJson>,
    /// Eye-to-hand result.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub base_from_camera: Option<PoseJson>,
    /// Eye-in-hand target pose.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub base_from_target: Option<PoseJson>,
    /// Eye-to-hand target pose.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub gripper_from_target: Option<PoseJson>,
    /// Summary errors of the primary solution.
    pub errors: Errors,
    /// Every solver side by side.
    pub methods: Vec<MethodJson>,
    /// Largest disagreement between any solver and the primary: (mm).
    pub methods_max_disagreement_translation_mm: f64,
    /// ... and (degrees).
    pub methods_max_disagreement_rotation_deg: f64,
    /// Per-view residuals.
    pub per_view: Vec<ViewResidual>,
    /// Per-motion residuals.
    pub per_motion: Vec<MotionResidual>,
    /// Motion diversity.
    pub motion: MotionStats,
    /// Unit directions along which the camera transform's translation is unobservable.
    pub unobservable_translation_axes: Vec<[f64; 3]>,
    /// Leave-one-out and bootstrap.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub repeatability: Option<Repeatability>,
    /// Everything the user should know.
    pub warnings: Vec<String>,
    /// Pairing audit of robot poses and images (image input only): every
    /// pose with its image, whether it was used and why not.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub pairs: Vec<PairAudit>,
    /// The image-based refinement, when run (the primary transforms are then
    /// the refined ones).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub refinement: Option<RefinementSummary>,
    /// The maximum-likelihood pose refinement, when run (the primary
    /// transforms are then the refined ones): covariance, per-axis std,
    /// estimated noise levels, outlier views.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub pose_refinement: Option<PoseRefinementSummary>,
    /// The hand-eye error at the work point (by default the target's centre
    /// where the views see it, at their mean distance,
    /// [`crate::handeye::quality::work_point`]), when the pose refinement
    /// gave a covariance.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub work_point_error: Option<WorkPointError>,
    /// The same at the tool centre point, when one was given.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub tcp_error: Option<WorkPointError>,
    /// Held-out poses: predicted against observed target pose
    /// ([`crate::handeye::quality::verify`]), when some were held out.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub holdout: Option<HoldoutReport>,
    /// Touch test: points touched with the tool centre point against the
    /// camera's rays to them, when given.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub touch_test: Option<TouchReport>,
    /// robocal version that produced the report.
    pub robocal_version: String,
}

type PosePair = (
    Option<PoseJson>,
    Option<PoseJson>,
    Option<PoseJson>,
    Option<PoseJson>,
);

/// The four optional keys for `(x, y)` in `setup`: (gripper_from_camera,
/// base_from_camera, base_from_target, gripper_from_target).
fn keyed(setup: Setup, x: &Pose, y: &Pose) -> PosePair {
    match setup {
        Setup::EyeInHand => (Some(x.into()), None, Some(y.into()), None),
        Setup::EyeToHand => (None, Some(x.into()), None, Some(y.into())),
    }
}

impl HandEyeReport {
    /// [`HandEyeReport::new`], refused when any number in it is NaN or
    /// infinite (the error names the field: `report.per_view[3].translation_mm`).
    pub fn checked(result: &HandEyeResult) -> crate::error::Result<Self> {
        let report = HandEyeReport::new(result);
        crate::finite::check_finite("report", &report)?;
        Ok(report)
    }

    /// Build the serialisable report of a result.
    pub fn new(result: &HandEyeResult) -> Self {
        let methods: Vec<MethodJson> = result
            .methods
            .iter()
            .map(|m| {
                let mut j = MethodJson {
                    method: m.method.name().to_string(),
                    gripper_from_camera: None,
                    base_from_camera: None,
                    base_from_target: None,
                    gripper_from_target: None,
                    errors: None,
                    disagreement_translation_mm: m.disagreement.map(|d| d.0),
                    disagreement_rotation_deg: m.disagreement.map(|d| d.1),
                    error: None,
                    pose_cost: m.pose_cost,
                };
                match &m.outcome {
                    Ok((x, y, e)) => {
                        let k = keyed(result.setup, x, y);
                        (j.gripper_from_camera, j.base_from_camera) = (k.0, k.1);
                        (j.base_from_target, j.gripper_from_target) = (k.2, k.3);
                        j.errors = Some(e.clone());
                    }
                    Err(e) => j.error = Some(e.to_string()),
                }
                j
            })
            .collect();
        let max_t = methods
            .iter()
            .filter_map(|m| m.disagreement_translation_mm)
            .fold(0.0, f64::max);
        let max_r = methods
            .iter()
            .filter_map(|m| m.disagreement_rotation_deg)
            .fold(0.0, f64::max);
        let k = keyed(result.setup, &result.x, &result.y);
        HandEyeReport {
            kind: crate::report_kind::ReportKind::Handeye,
            setup: result.setup,
            method: result.method.clone(),
            gripper_from_camera: k.0,
            base_from_camera: k.1,
            base_from_target: k.2,
            gripper_from_target: k.3,
            errors: result.errors.clone(),
            methods,
            methods_max_disagreement_translation_mm: max_t,
            methods_max_disagreement_rotation_deg: max_r,
            per_view: result.per_view.clone(),
            per_motion: result.per_motion.clone(),
            motion: result.motion.clone(),
            unobservable_translation_axes: result
                .unobservable_translation
                .iter()
                .map(|v| [v.x, v.y, v.z])
                .collect(),
            repeatability: result.repeatability.clone(),
            warnings: result.warnings.clone(),
            pairs: Vec::new(),
            refinement: result.refinement.clone(),
            pose_refinement: result.pose_refinement.clone(),
            work_point_error: default_work_point_error(result),
            tcp_error: None,
            holdout: None,
            touch_test: None,
            robocal_version: crate::VERSION.to_string(),
        }
    }
}

/// The error at the default work point (the target's centre where the
/// views see it, at their mean distance: `pose_refinement.work_distance_m`,
/// [`crate::handeye::quality::work_point`]), from the refinement's
/// covariance.
fn default_work_point_error(result: &HandEyeResult) -> Option<WorkPointError> {
    let summary = result.pose_refinement.as_ref()?;
    let point = summary.work_point?;
    let q = result.x * Point3::from(point.camera_m);
    work_point_error(
        &summary.covariance,
        result.setup,
        &result.x,
        &q.coords,
        point.placement,
    )
}
