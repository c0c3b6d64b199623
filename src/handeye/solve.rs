//! The orchestrator: checks, every requested solver, a primary result,
//! residual reports and repeatability.

use crate::error::{Error, Result};
use crate::handeye::closed_form::motion::{build_motions, motion_stats, MotionStats};
use crate::handeye::closed_form::{axxb, axzb, scara};
use crate::handeye::quality::checks;
use crate::handeye::quality::repeat::{repeatability, Repeatability};
use crate::handeye::quality::residuals::{
    combined_score_mm, errors, estimate_target, lever_arm_m, motion_residuals, pose_difference,
    view_residuals, Errors, MotionResidual, ViewResidual,
};
use crate::handeye::refine::over_poses::apply_pose_refinement_resampled;
use crate::handeye::refine::pose_noise::CameraNoise;
use crate::handeye::{Chain, HandEyeMethod, Motion, MotionPairs, Pose, Setup};
use nalgebra::Vector3;

/// Default number of bootstrap resamples.
pub const DEFAULT_BOOTSTRAP_SAMPLES: usize = 100;

/// What to solve: the setup and the paired poses (metres).
#[derive(Debug, Clone)]
pub struct HandEyeInput {
    /// Camera on the gripper or fixed in the world.
    pub setup: Setup,
    /// Robot poses, one per view.
    pub base_from_gripper: Vec<Pose>,
    /// Target poses seen by the camera, one per view, paired with the robot poses.
    pub camera_from_target: Vec<Pose>,
}

/// Tunables, with defaults from [`HandEyeOptions::default`].
#[derive(Debug, Clone)]
pub struct HandEyeOptions {
    /// Methods to run (default: all eight).
    pub methods: Vec<HandEyeMethod>,
    /// Which view pairs become AX = XB motions (default: all pairs).
    pub motion_pairs: MotionPairs,
    /// Input mistakes (units, inverted poses, shifted pairing) are errors
    /// when true (default), warnings when false.
    pub strict_checks: bool,
    /// Bootstrap resamples for repeatability (default
    /// [`DEFAULT_BOOTSTRAP_SAMPLES`]; 0 disables leave-one-out and bootstrap).
    pub bootstrap_samples: usize,
    /// Seed of the bootstrap resampling.
    pub seed: u64,
    /// Refine the closed forms by the maximum-likelihood pose refinement
    /// ([`crate::handeye::refine::over_poses`]; default true). The image path turns it off
    /// and refines over image points instead.
    pub refine_poses: bool,
}

impl Default for HandEyeOptions {
    fn default() -> Self {
        HandEyeOptions {
            methods: HandEyeMethod::ALL.to_vec(),
            motion_pairs: MotionPairs::All,
            strict_checks: true,
            bootstrap_samples: DEFAULT_BOOTSTRAP_SAMPLES,
            seed: 1,
            refine_poses: true,
        }
    }
}

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
    /// ([`crate::handeye::refine::over_pixels::apply_refinement`]).
    pub refinement: Option<crate::handeye::refine::over_pixels::RefinementSummary>,
    /// The pose refinement, when run ([`crate::handeye::refine::over_poses`]).
    pub pose_refinement: Option<crate::handeye::refine::over_poses::PoseRefinementSummary>,
}

/// Solve one method on a chain; returns `(x, y, unobservable directions)`.
pub fn solve_method(
    method: HandEyeMethod,
    chain: &Chain,
    pairs: MotionPairs,
) -> Result<(Pose, Pose, Vec<Vector3<f64>>)> {
    if method.is_axzb() {
        return solve_with_motions(method, chain, &[]);
    }
    solve_with_motions(method, chain, &build_motions(chain, pairs).kept)
}

/// [`solve_method`] with the chain's motions built once by the caller
/// (unused by the AX = ZB methods): at 1,000 poses each build is half a
/// million motions.
fn solve_with_motions(
    method: HandEyeMethod,
    chain: &Chain,
    motions: &[Motion],
) -> Result<(Pose, Pose, Vec<Vector3<f64>>)> {
    if method.is_axzb() {
        let (x, y) = axzb::solve(method, chain)?;
        return Ok((x, y, Vec::new()));
    }
    let (x, unobservable) = axxb::solve(method, motions)?;
    let y = estimate_target(chain, &x)?;
    Ok((x, y, unobservable))
}

/// Calibrate: check the input, run every requested method, pick the one
/// with the smallest combined closure residual as primary, report.
pub fn calibrate(input: &HandEyeInput, options: &HandEyeOptions) -> Result<HandEyeResult> {
    // 1. Input checks and mistakes, before any solving.
    let chain = Chain::new(
        input.setup,
        &input.base_from_gripper,
        &input.camera_from_target,
    )?;
    let mut warnings = checks::check_input(input, options)?;
    let set = build_motions(&chain, options.motion_pairs);
    let motion = motion_stats(&set);
    if set.discarded > 0 {
        warnings.push(format!(
            "{} of {} motion pairs were discarded because they rotate less than {} deg",
            set.discarded,
            set.discarded + set.kept.len(),
            crate::handeye::MIN_MOTION_ROTATION_DEG
        ));
    }
    let distances: Vec<f64> = input
        .camera_from_target
        .iter()
        .map(|p| p.translation.vector.norm())
        .collect();
    warnings.extend(crate::handeye::quality::trust::geometry_warnings(
        chain.len(),
        &motion,
        &distances,
    ));
    let lever = lever_arm_m(&chain);
    // 2. Parallel rotation axes (SCARA): only the observable part.
    if motion.axis_spread_deg < scara::PARALLEL_AXES_DEG {
        let (x, axis) = scara::solve(&set.kept)?;
        let y = estimate_target(&chain, &x)?;
        warnings.push(checks::scara_message(
            input.setup,
            &axis,
            motion.axis_spread_deg,
        ));
        let per_view = view_residuals(&chain, &x, &y);
        let result = HandEyeResult {
            setup: input.setup,
            method: "scara".to_string(),
            x,
            y,
            errors: errors(&per_view),
            per_view,
            per_motion: motion_residuals(&set.kept, &x),
            motion,
            methods: Vec::new(),
            unobservable_translation: vec![axis],
            repeatability: None,
            warnings,
            refinement: None,
            pose_refinement: None,
        };
        return with_pose_refinement(result, input, options, &set.kept);
    }
    // 3. Every requested method; a failing one is reported, not fatal.
    let mut methods = Vec::new();
    let mut best: Option<(f64, usize, Pose, Pose, Vec<Vector3<f64>>)> = None;
    for (i, &method) in options.methods.iter().enumerate() {
        let outcome = solve_with_motions(method, &chain, &set.kept).map(|(x, y, u)| {
            let e = errors(&view_residuals(&chain, &x, &y));
            let score = combined_score_mm(&e, lever);
            if best.as_ref().map_or(true, |b| score < b.0) {
                best = Some((score, i, x, y, u));
            }
            (x, y, e)
        });
        methods.push(MethodResult {
            method,
            outcome,
            disagreement: None,
            pose_cost: None,
        });
    }
    let Some((_, best_index, x, y, unobservable)) = best else {
        let reasons: Vec<String> = methods
            .iter()
            .filter_map(|m| {
                m.outcome
                    .as_ref()
                    .err()
                    .map(|e| format!("{}: {e}", m.method.name()))
            })
            .collect();
        return Err(Error::degenerate(format!(
            "every hand-eye method failed ({})",
            reasons.join("; ")
        )));
    };
    for m in &mut methods {
        if let Ok((mx, _, _)) = &m.outcome {
            m.disagreement = Some(pose_difference(&x, mx));
        }
    }
    let primary = methods[best_index].method;
    // 4. Residuals and repeatability of the primary solution; with the
    // pose refinement on, that of the refined estimate instead (below), and
    // the closed form's only when the refinement does not run.
    let per_view = view_residuals(&chain, &x, &y);
    let repeat = if options.bootstrap_samples > 0 && !options.refine_poses {
        Some(repeatability(&chain, primary, options, &x, &y))
    } else {
        None
    };
    let result = HandEyeResult {
        setup: input.setup,
        method: primary.name().to_string(),
        x,
        y,
        errors: errors(&per_view),
        per_view,
        per_motion: motion_residuals(&set.kept, &x),
        motion,
        methods,
        unobservable_translation: unobservable,
        repeatability: repeat,
        warnings,
        refinement: None,
        pose_refinement: None,
    };
    with_pose_refinement(result, input, options, &set.kept)
}

/// `result` with the pose refinement applied when `options.refine_poses`;
/// a translation RMS of metres is refused.
fn with_pose_refinement(
    mut result: HandEyeResult,
    input: &HandEyeInput,
    options: &HandEyeOptions,
    motions: &[Motion],
) -> Result<HandEyeResult> {
    if options.refine_poses {
        let resampling = (options.bootstrap_samples > 0 && result.method != "scara")
            .then_some((options.bootstrap_samples, options.seed));
        apply_pose_refinement_resampled(
            &mut result,
            input,
            CameraNoise::Diagonal,
            (options.motion_pairs, Some(motions)),
            true,
            resampling,
        )?;
        // The refinement did not run: the closed form's repeatability.
        if result.pose_refinement.is_none() && resampling.is_some() {
            if let Ok(method) = result.method.parse::<HandEyeMethod>() {
                let chain = Chain::new(
                    input.setup,
                    &input.base_from_gripper,
                    &input.camera_from_target,
                )?;
                result.repeatability =
                    Some(repeatability(&chain, method, options, &result.x, &result.y));
            }
        }
    }
    refuse_metres(&result.errors)?;
    Ok(result)
}

/// A translation RMS (mm) from which a solution is no calibration: the
/// poses do not fit one hand-eye transform.
pub const MAX_TRANSLATION_RMS_MM: f64 = 1000.0;

/// Refuse a solution whose per-view translation RMS is a metre or more.
pub(crate) fn refuse_metres(errors: &Errors) -> Result<()> {
    let rms = errors.translation_rms_mm;
    if rms < MAX_TRANSLATION_RMS_MM {
        return Ok(());
    }
    Err(Error::degenerate(format!(
        "the hand-eye solution's translation RMS is {rms:.1} mm ({:.2} m): the poses do not \
         fit one hand-eye transform, so no transform is written: check the units of both pose \
         files, the setup (eye-in-hand or eye-to-hand) and that pose i belongs with image i",
        rms / 1e3
    )))
}
