//! What a hand-eye calibration produces ([`HandEyeResult`], one
//! [`MethodResult`] per closed form). Only the orchestrator
//! ([`crate::handeye::solve`]) writes it; the refiners read it and return
//! their findings.

use crate::error::Error;
use crate::handeye::closed_form::motion::MotionStats;
use crate::handeye::quality::repeat::Repeatability;
use crate::handeye::quality::residuals::{Errors, MotionResidual, ViewResidual};
use crate::handeye::refine::pixel_summary::RefinementSummary;
use crate::handeye::refine::pose_summary::PoseRefinementSummary;
use crate::handeye::{HandEyeMethod, Pose, Setup};
use nalgebra::Vector3;

/// One solver's outcome.
#[derive(Debug, Clone)]
pub struct MethodResult {
    /// The solver.
    pub method: HandEyeMethod,
    /// `(x, y, errors)` or why the solver failed.
    pub outcome: std::result::Result<(Pose, Pose, Errors), Error>,
    /// Distance of `x` from the primary solution: (mm, degrees).
    pub disagreement: Option<(f64, f64)>,
    /// Robust cost of this solution under the pose refinement's noise
    /// model, when the pose refinement ran.
    pub pose_cost: Option<f64>,
}

/// Everything a calibration produces (serialise with
/// [`crate::handeye::report::HandEyeReport::new`]).
#[derive(Debug, Clone)]
pub struct HandEyeResult {
    /// The setup solved.
    pub setup: Setup,
    /// Name of the solution reported as primary (a method name, or `scara`).
    pub method: String,
    /// `gripper_from_camera` (eye-in-hand) or `base_from_camera` (eye-to-hand).
    pub x: Pose,
    /// `base_from_target` (eye-in-hand) or `gripper_from_target` (eye-to-hand).
    pub y: Pose,
    /// Summary errors of the primary solution.
    pub errors: Errors,
    /// Per-view residuals of the primary solution.
    pub per_view: Vec<ViewResidual>,
    /// Per-motion residuals of the primary solution.
    pub per_motion: Vec<MotionResidual>,
    /// Motion diversity.
    pub motion: MotionStats,
    /// Every requested solver.
    pub methods: Vec<MethodResult>,
    /// Unit directions (frame of `x`'s left side) along which the translation
    /// of `x` is unobservable.
    pub unobservable_translation: Vec<Vector3<f64>>,
    /// Leave-one-out and bootstrap, when requested.
    pub repeatability: Option<Repeatability>,
    /// Everything the user should know.
    pub warnings: Vec<String>,
    /// The image-based refinement, when run
    /// ([`crate::handeye::solve::apply_refinement`]).
    pub refinement: Option<RefinementSummary>,
    /// The pose refinement, when run ([`crate::handeye::refine::over_poses`]).
    pub pose_refinement: Option<PoseRefinementSummary>,
}
