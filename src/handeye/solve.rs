//! The orchestrator: checks, every requested solver, a primary result,
//! residual reports and repeatability, then the refinements. It alone
//! writes the [`HandEyeResult`]: the refiners ([`crate::handeye::refine`])
//! return their findings and the `apply_*` functions here write them.

use crate::calib::View;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::handeye::closed_form::motion::{build_motions, motion_stats};
use crate::handeye::closed_form::{estimate_target, scara, solve_with_motions};
use crate::handeye::quality::checks;
use crate::handeye::quality::focal::check_focal;
use crate::handeye::quality::repeat::repeatability;
use crate::handeye::quality::residuals::{
    combined_score_mm, errors, lever_arm_m, motion_residuals, pose_difference, view_residuals,
    Errors,
};
use crate::handeye::refine::over_pixels::{
    refine_over_pixels, reprojection_rms_per_view_px, RefineMode,
};
use crate::handeye::refine::over_poses::{
    camera_noise_from_views, refine_over_poses, PoseFindings,
};
use crate::handeye::refine::pose_noise::CameraNoise;
use crate::handeye::{Chain, HandEyeMethod, Motion, MotionPairs, Pose};
use nalgebra::Vector3;

// The paths `handeye::solve::{HandEyeInput, ...}` of before the split stay.
pub use crate::handeye::input::{HandEyeInput, HandEyeOptions, DEFAULT_BOOTSTRAP_SAMPLES};
pub use crate::handeye::result::{HandEyeResult, MethodResult};

/// Calibrate: check the input, run every requested method, pick the one
/// with the smallest combined closure residual as primary, report.
pub fn calibrate(input: &HandEyeInput, options: &HandEyeOptions) -> Result<HandEyeResult> {
    // 1. Input checks and mistakes, before any solving.
    let chain = input.chain()?;
    // The checks' motions are the chain's for the requested pairs: the
    // solve takes them rather than building them again.
    let (mut warnings, set) = checks::check_input_keeping_motions(input, options)?;
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
    // (score, index, x, y, unobservable directions) of the best so far.
    type Best = (f64, usize, Pose, Pose, Vec<Vector3<f64>>);
    let mut best: Option<Best> = None;
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
        let found = refine_over_poses(
            &result,
            input,
            CameraNoise::Diagonal,
            options.motion_pairs,
            true,
            resampling,
        )?;
        write_pose_findings(
            &mut result,
            found,
            input,
            (options.motion_pairs, Some(motions)),
        )?;
        // The refinement did not run: the closed form's repeatability.
        if result.pose_refinement.is_none() && resampling.is_some() {
            if let Ok(method) = result.method.parse::<HandEyeMethod>() {
                let chain = input.chain()?;
                result.repeatability =
                    Some(repeatability(&chain, method, options, &result.x, &result.y));
            }
        }
    }
    refuse_metres(&result.errors)?;
    Ok(result)
}

/// Make `(x, y)` the primary solution under the name `method`: its
/// residuals per view and per motion, its summary errors, and every
/// method's distance from it.
fn make_primary(
    result: &mut HandEyeResult,
    chain: &Chain,
    motions: &[Motion],
    (x, y): (Pose, Pose),
    method: String,
) {
    result.x = x;
    result.y = y;
    result.method = method;
    result.per_view = view_residuals(chain, &result.x, &result.y);
    result.errors = errors(&result.per_view);
    result.per_motion = motion_residuals(motions, &result.x);
    for m in &mut result.methods {
        if let Ok((mx, _, _)) = &m.outcome {
            m.disagreement = Some(pose_difference(&result.x, mx));
        }
    }
}

/// Fill the reprojection RMS of every closed form and, unless `mode` is
/// [`RefineMode::None`], replace the primary solution by the one refined
/// over the pixels ([`refine_over_pixels`]) and set `result.refinement`.
/// `views` pair one to one with the input poses.
pub fn apply_refinement(
    result: &mut HandEyeResult,
    input: &HandEyeInput,
    views: &[View],
    camera: &Camera,
    mode: RefineMode,
    motion_pairs: MotionPairs,
    pixel_sigma_px: f64,
) -> Result<()> {
    let found = refine_over_pixels(result, input, views, camera, mode, pixel_sigma_px)?;
    for (m, rms) in result.methods.iter_mut().zip(found.method_rms_px) {
        if let (Ok((_, _, e)), Some(rms)) = (&mut m.outcome, rms) {
            e.reprojection_rms_px = Some(rms);
        }
    }
    result.errors.reprojection_rms_px = Some(found.closed_form_rms_px);
    result.warnings.extend(found.warnings);
    let Some(refined) = found.refined else {
        return Ok(());
    };
    let chain = input.chain()?;
    let method = format!("refined from {}", refined.summary.started_from);
    make_primary(
        result,
        &chain,
        &build_motions(&chain, motion_pairs).kept,
        (refined.x, refined.y),
        method,
    );
    result.errors.reprojection_rms_px = Some(refined.summary.reprojection_rms_px);
    result.refinement = Some(refined.summary);
    Ok(())
}

/// Score every closed form, refine from the best over the poses
/// ([`refine_over_poses`]), make the refined transforms primary. A
/// refinement that fails leaves the closed form primary with a warning
/// (never an error: the closed forms stand).
pub fn apply_pose_refinement(
    result: &mut HandEyeResult,
    input: &HandEyeInput,
    camera_noise: CameraNoise,
    motion_pairs: MotionPairs,
) -> Result<()> {
    apply_pose_refinement_with(result, input, camera_noise, motion_pairs, true)
}

/// The pose refinement with each view's PnP covariance from its image
/// points ([`camera_noise_from_views`]): for image input whose refinement
/// over pixels is off (`refine` none); then the reprojection RMS of the
/// refined transforms.
///
/// `camera_fx_std`: the std (px) of the camera's calibrated fx, when known;
/// the focal check writes no warning for a disagreement within it.
pub fn apply_pose_refinement_from_views(
    result: &mut HandEyeResult,
    input: &HandEyeInput,
    views: &[View],
    (camera, camera_fx_std): (&Camera, Option<f64>),
    motion_pairs: MotionPairs,
) -> Result<()> {
    let (camera_noise, warning) = camera_noise_from_views(input, views, camera);
    result.warnings.extend(warning);
    apply_pose_refinement(result, input, camera_noise, motion_pairs)?;
    add_reprojection_rms(result, input, views, camera)?;
    apply_focal_check(result, input, views, (camera, camera_fx_std), motion_pairs);
    Ok(())
}

/// The focal length checked against the robot's motion
/// ([`crate::handeye::quality::focal::check_focal`]): when it disagrees,
/// the shift to the freed solution joins the covariance (the std and the
/// error at the working distance follow), the finding goes into
/// `pose_refinement.focal_check` and its warning into the result.
fn apply_focal_check(
    result: &mut HandEyeResult,
    input: &HandEyeInput,
    views: &[View],
    camera: (&Camera, Option<f64>),
    motion_pairs: MotionPairs,
) {
    use crate::handeye::quality::trust::{add_shift_to_covariance, work_point_std_mm};
    let Some(found) = check_focal(result, input, views, camera, motion_pairs) else {
        return;
    };
    let rotation = result.x.rotation.to_rotation_matrix().into_inner();
    if let Some(summary) = result.pose_refinement.as_mut() {
        if let Some((dx, dy)) = &found.shift {
            add_shift_to_covariance(summary, dx, dy);
            if let Some(point) = summary.work_point.as_ref().map(|w| w.camera_m) {
                let q = nalgebra::Vector3::from(point);
                summary.work_point_std_mm = Some(work_point_std_mm(summary, &rotation, &q));
            }
        }
        if found.check.is_some() {
            summary.focal_check = found.check;
        }
    }
    result.warnings.extend(found.warning);
}

/// With image points and the pose refinement run: the reprojection RMS of
/// the refined transforms (`errors.reprojection_rms_px` and the summary's
/// keys, as the refinement over pixels reports them), every view's target
/// points projected through the chain's implied `camera_from_target`
/// ([`reprojection_rms_per_view_px`]). Not computable (a point behind the
/// camera): a warning, the key left out.
fn add_reprojection_rms(
    result: &mut HandEyeResult,
    input: &HandEyeInput,
    views: &[View],
    camera: &Camera,
) -> Result<()> {
    let Some(summary) = result.pose_refinement.as_mut() else {
        return Ok(());
    };
    let chain = input.chain()?;
    let closed_form = result
        .methods
        .iter()
        .find(|m| m.method.name() == summary.started_from)
        .and_then(|m| m.outcome.as_ref().ok())
        .and_then(|(_, _, e)| e.reprojection_rms_px);
    match reprojection_rms_per_view_px(&chain, views, camera, &result.x, &result.y) {
        Ok((rms, per_view)) => {
            result.errors.reprojection_rms_px = Some(rms);
            summary.reprojection_rms_px = Some(rms);
            summary.per_view_reprojection_rms_px = Some(per_view);
            summary.closed_form_reprojection_rms_px = closed_form;
        }
        Err(e) => {
            result.errors.reprojection_rms_px = None;
            result.warnings.push(format!(
                "pose refinement: no reprojection RMS of the refined transforms: {e}; check the \
                 robot poses' units and convention"
            ));
        }
    }
    Ok(())
}

/// [`apply_pose_refinement`]; with `predict_shape` false, a
/// [`CameraNoise::Diagonal`] request never switches to the predicted
/// per-view shape (the diagonal model alone, for comparisons).
pub fn apply_pose_refinement_with(
    result: &mut HandEyeResult,
    input: &HandEyeInput,
    camera_noise: CameraNoise,
    motion_pairs: MotionPairs,
    predict_shape: bool,
) -> Result<()> {
    let resampling = result
        .repeatability
        .as_ref()
        .map(|r| (r.bootstrap_samples, r.seed));
    let found = refine_over_poses(
        result,
        input,
        camera_noise,
        motion_pairs,
        predict_shape,
        resampling,
    )?;
    write_pose_findings(result, found, input, (motion_pairs, None))
}

/// Write what the pose refinement found: every closed form's `pose_cost`,
/// its warnings, and, when it ran, the refined transforms as the primary
/// solution with their summary and repeatability; the motions of
/// `motion_pairs` when the caller has them built.
fn write_pose_findings(
    result: &mut HandEyeResult,
    found: PoseFindings,
    input: &HandEyeInput,
    (motion_pairs, motions): (MotionPairs, Option<&[Motion]>),
) -> Result<()> {
    for (m, cost) in result.methods.iter_mut().zip(found.pose_costs) {
        if cost.is_some() {
            m.pose_cost = cost;
        }
    }
    result.warnings.extend(found.warnings);
    let Some(refined) = found.refined else {
        return Ok(());
    };
    let chain = input.chain()?;
    let built;
    let motions = match motions {
        Some(kept) => kept,
        None => {
            built = build_motions(&chain, motion_pairs).kept;
            &built
        }
    };
    let method = format!("refined from {}", refined.summary.started_from);
    make_primary(result, &chain, motions, (refined.x, refined.y), method);
    result.pose_refinement = Some(refined.summary);
    if let Some(r) = refined.repeatability {
        result.repeatability = Some(r);
    }
    Ok(())
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
