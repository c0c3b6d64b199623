//! The pose refinement ([`crate::handeye::refine::pose_problem`]) run from
//! a closed-form [`HandEyeResult`], mirroring
//! [`crate::handeye::refine::over_pixels`] for the image path: the noise
//! levels are first estimated at the fixed-rule closed form, every closed
//! form is scored by the refinement's own robust cost (its `pose_cost`),
//! the lowest one seeds the refinement, and the findings
//! ([`PoseFindings`]) go back to the orchestrator, which makes the refined
//! transforms the primary result (`method` = `refined from <closed form>`)
//! with their covariance and the estimated noise levels
//! ([`PoseRefinementSummary`]). Every closed form stays in `methods`.
//!
//! With parallel rotation axes (SCARA) the translation of `x` along the axis
//! is unobservable: it is held at the closed form's value (0) and reported,
//! and only the observable part is refined.

use crate::calib::pnp::camera_from_target_with_covariance;
use crate::calib::View;
use crate::camera::Camera;
use crate::error::Result;
use crate::handeye::closed_form::solve_method;
use crate::handeye::quality::repeat::{repeatability, Repeatability};
use crate::handeye::quality::trust::{check_translation_scale, check_uncertainty};
use crate::handeye::refine::noise_choice::choose_noise_model;
use crate::handeye::refine::pose_noise::CameraNoise;
use crate::handeye::refine::pose_problem::{evaluate, refine, PoseRefineOptions, HUBER_SCALE};
use crate::handeye::refine::pose_resample::refined_repeatability;
use crate::handeye::refine::pose_residual::PoseMeasurement;
use crate::handeye::refine::pose_shape::NominalTarget;
use crate::handeye::refine::pose_summary::{
    transform_std, NominalTargetReport, PoseRefinementSummary,
};
use crate::handeye::{
    Chain, HandEyeInput, HandEyeMethod, HandEyeOptions, HandEyeResult, MotionPairs, Pose,
};

/// The measurements of an input, in order.
pub fn measurements(input: &HandEyeInput) -> Vec<PoseMeasurement> {
    paired(&input.base_from_gripper, &input.camera_from_target)
}

/// Robot and camera poses paired one to one (e.g. a scene's truth).
pub fn paired(base_from_gripper: &[Pose], camera_from_target: &[Pose]) -> Vec<PoseMeasurement> {
    base_from_gripper
        .iter()
        .zip(camera_from_target)
        .map(|(b, c)| PoseMeasurement {
            base_from_gripper: *b,
            camera_from_target: *c,
        })
        .collect()
}

/// What the pose refinement found, for the orchestrator
/// ([`crate::handeye::solve::apply_pose_refinement`]) to write into the
/// result.
#[derive(Debug, Clone)]
pub struct PoseFindings {
    /// The robust cost of each closed form under the estimated noise, in
    /// the order of the result's `methods` (`None`: not evaluated).
    pub pose_costs: Vec<Option<f64>>,
    /// The refined solution, when the refinement ran.
    pub refined: Option<PoseRefined>,
    /// What the user should know, in the order found.
    pub warnings: Vec<String>,
}

/// The refined solution of [`PoseFindings`].
#[derive(Debug, Clone)]
pub struct PoseRefined {
    /// The refined `gripper_from_camera` or `base_from_camera`.
    pub x: Pose,
    /// The refined `base_from_target` or `gripper_from_target`.
    pub y: Pose,
    /// The report's `pose_refinement` object, its uncertainty checked
    /// against the data ([`crate::handeye::quality::trust`]).
    pub summary: PoseRefinementSummary,
    /// The repeatability to report: the refined estimate's, or the closed
    /// form's when those resamples could not be solved; `None`: the
    /// result's stays.
    pub repeatability: Option<Repeatability>,
}

/// The camera noise of each view from its image points: each view's PnP
/// covariance (`CameraNoise::PerView`, the pixel variance estimated), for
/// image input whose refinement over pixels is off (`refine` none). A view
/// whose covariance cannot be computed leaves the predicted/diagonal models
/// in charge, with the warning returned.
pub fn camera_noise_from_views(
    input: &HandEyeInput,
    views: &[View],
    camera: &Camera,
) -> (CameraNoise, Option<String>) {
    let covariances: std::result::Result<Vec<_>, String> = views
        .iter()
        .enumerate()
        .map(|(i, v)| {
            camera_from_target_with_covariance(camera, v)
                .map(|(_, _, c)| c)
                .map_err(|e| format!("view {i}: {e}"))
        })
        .collect();
    match covariances {
        Ok(c) if c.len() == input.camera_from_target.len() => (CameraNoise::PerView(c), None),
        other => {
            let why = other
                .err()
                .unwrap_or_else(|| "views and poses differ in number".into());
            (
                CameraNoise::Diagonal,
                Some(format!(
                    "pose refinement: no PnP covariance ({why}); camera noise modelled from the \
                     poses"
                )),
            )
        }
    }
}

/// Score every closed form of `result`, refine from the best, and check
/// the refined estimate's uncertainty against the data. A refinement that
/// cannot run is no error (the closed forms stand): the findings then hold
/// the warning and no refined solution. With `resampling` `(bootstrap
/// samples, seed)` the repeatability is that of the refined estimate
/// ([`crate::handeye::refine::pose_resample`]); with `predict_shape` false,
/// a [`CameraNoise::Diagonal`] request never switches to the predicted
/// per-view shape (the diagonal model alone, for comparisons).
pub fn refine_over_poses(
    result: &HandEyeResult,
    input: &HandEyeInput,
    camera_noise: CameraNoise,
    motion_pairs: MotionPairs,
    predict_shape: bool,
    resampling: Option<(usize, u64)>,
) -> Result<PoseFindings> {
    let views = measurements(input);
    let setup = input.setup;
    let axis = result.unobservable_translation.first().copied();
    let mut found = PoseFindings {
        pose_costs: vec![None; result.methods.len()],
        refined: None,
        warnings: Vec::new(),
    };
    let chosen = match choose_noise_model(
        setup,
        &views,
        camera_noise.clone(),
        &result.x,
        &result.y,
        axis,
        predict_shape,
    ) {
        Ok(c) => c,
        Err(e) => {
            found.warnings.push(format!("pose refinement skipped: {e}"));
            return Ok(found);
        }
    };
    let noise = chosen.noise.clone();
    let options = PoseRefineOptions {
        camera_noise: noise.camera.clone(),
        unobservable_translation: axis,
    };
    // Every closed form under the same noise levels; the lowest seeds.
    let mut start: (f64, String, Pose, Pose) =
        match evaluate(setup, &views, &noise, &result.x, &result.y) {
            Ok((_, c)) => (c, result.method.clone(), result.x, result.y),
            Err(e) => {
                found.warnings.push(format!("pose refinement skipped: {e}"));
                return Ok(found);
            }
        };
    for (m, cost) in result.methods.iter().zip(&mut found.pose_costs) {
        if let Ok((x, y, _)) = &m.outcome {
            if let Ok((_, c)) = evaluate(setup, &views, &noise, x, y) {
                *cost = Some(c);
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
            found.warnings.push(format!(
                "pose refinement failed, the closed form is kept: {e}"
            ));
            return Ok(found);
        }
    };
    // The model choice again at the refined solution: at a closed form its
    // error inflates the levels and favours the wrong nominal target (at
    // 2.3 m the fixed-rule closed form is ~1 mm off, three times the bound).
    let (mut chosen, mut options, mut refined) = (chosen, options, refined);
    if matches!(camera_noise, CameraNoise::Diagonal) && predict_shape {
        let again = choose_noise_model(
            setup,
            &views,
            camera_noise,
            &refined.x,
            &refined.y,
            axis,
            predict_shape,
        );
        if let Some(again) = again.ok().filter(|a| !a.same_model(&chosen)) {
            let again_options = PoseRefineOptions {
                camera_noise: again.noise.camera.clone(),
                unobservable_translation: axis,
            };
            let (x1, y1) = (refined.x, refined.y);
            if let Ok(r) = refine(setup, &views, &x1, &y1, again.noise.clone(), &again_options) {
                (chosen, options, refined) = (again, again_options, r);
            }
        }
    }
    let model_for_resamples = chosen.noise.clone();
    let final_noise = refined.noise.clone();
    let chain = Chain::new(setup, &input.base_from_gripper, &input.camera_from_target)?;
    let (x, y) = (refined.x, refined.y);
    if !refined.outliers.is_empty() {
        let list: Vec<String> = refined.outliers.iter().map(|v| v.to_string()).collect();
        found.warnings.push(format!(
            "pose refinement: view(s) {} fit the others poorly (whitened residual above {HUBER_SCALE}) \
             and were down-weighted as outliers; check those robot/camera pose pairs",
            list.join(", ")
        ));
    }
    let cov = refined.covariance;
    let mut summary = PoseRefinementSummary {
        started_from: started_from.clone(),
        closed_form_cost,
        cost: refined.cost,
        camera_noise_model: chosen.name,
        noise: refined.noise.levels(),
        camera_noise_pivot_m: chosen.pivot,
        camera_noise_nominal_target_m: chosen.nominal.map(|t: NominalTarget| NominalTargetReport {
            centre: [t.centre.x, t.centre.y],
            half_extent: t.half,
        }),
        noise_estimated_per_component: refined.noise_per_component,
        camera_transform_std: transform_std(&cov, 0),
        target_transform_std: transform_std(&cov, 6),
        covariance: (0..12)
            .map(|r| std::array::from_fn(|c| cov[(r, c)]))
            .collect(),
        whitened_residual_norms: refined.whitened_norms,
        outlier_views: refined.outliers,
        reprojection_rms_px: None,
        per_view_reprojection_rms_px: None,
        closed_form_reprojection_rms_px: None,
        std_widened_by: None,
        work_distance_m: None,
        work_point_std_mm: None,
        focal_check: None,
        work_point: None,
    };
    let mut repeatability = None;
    if let Some((samples, seed)) = resampling {
        let name = format!("refined from {started_from}");
        let resampled = refined_repeatability(
            setup,
            &views,
            &chain,
            &final_noise,
            &options,
            &name,
            (samples, seed, motion_pairs),
            &x,
            &y,
        );
        match resampled {
            Ok(r) => repeatability = Some(r),
            Err(e) => {
                found.warnings.push(format!(
                    "repeatability: the resamples of the refined estimate could not be solved \
                     ({e}); the closed form's are reported"
                ));
                if result.repeatability.is_none() {
                    repeatability = closed_form_repeatability(
                        &chain,
                        &started_from,
                        samples,
                        seed,
                        motion_pairs,
                    );
                }
            }
        }
    }
    let reported = repeatability.as_ref().or(result.repeatability.as_ref());
    let scale = check_translation_scale(
        &mut summary,
        (&x, &y),
        input,
        &views,
        (&model_for_resamples, &options),
    );
    found.warnings.extend(scale);
    found
        .warnings
        .extend(check_uncertainty(&mut summary, &x, reported, input));
    found.refined = Some(PoseRefined {
        x,
        y,
        summary,
        repeatability,
    });
    Ok(found)
}

/// The repeatability of the closed form `name` (when it is a method name)
/// over the same resamples: what the report holds when the refined
/// estimate's resamples cannot be solved.
fn closed_form_repeatability(
    chain: &Chain,
    name: &str,
    bootstrap_samples: usize,
    seed: u64,
    motion_pairs: MotionPairs,
) -> Option<Repeatability> {
    let method: HandEyeMethod = name.parse().ok()?;
    let (x, y, _) = solve_method(method, chain, motion_pairs).ok()?;
    let options = HandEyeOptions {
        bootstrap_samples,
        seed,
        motion_pairs,
        ..HandEyeOptions::default()
    };
    Some(repeatability(chain, method, &options, &x, &y))
}
