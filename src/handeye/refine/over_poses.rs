//! The pose refinement ([`crate::handeye::refine::pose_problem`]) applied to a closed-form
//! [`HandEyeResult`], mirroring [`crate::handeye::refine::over_pixels`] for the image
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

use crate::calib::pnp::camera_from_target_with_covariance;
use crate::calib::View;
use crate::camera::Camera;
use crate::error::Result;
use crate::handeye::closed_form::motion::build_motions;
use crate::handeye::quality::repeat::{repeatability, Repeatability};
use crate::handeye::quality::residuals::{
    errors, motion_residuals, pose_difference, view_residuals,
};
use crate::handeye::refine::noise_choice::choose_noise_model;
use crate::handeye::refine::over_pixels::reprojection_rms_per_view_px;
use crate::handeye::refine::pose_noise::{CameraNoise, NoiseLevels};
use crate::handeye::refine::pose_problem::{
    evaluate, refine, Covariance12, PoseRefineOptions, HUBER_SCALE,
};
use crate::handeye::refine::pose_resample::refined_repeatability;
use crate::handeye::refine::pose_residual::PoseMeasurement;
use crate::handeye::refine::pose_shape::NominalTarget;
use crate::handeye::solve::{solve_method, HandEyeInput, HandEyeOptions, HandEyeResult};
use crate::handeye::HandEyeMethod;
use crate::handeye::{Chain, Motion, MotionPairs, Pose};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Per-axis standard deviations of one transform.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, Default)]
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
    /// predicts: the factor the std (and the covariance's square root) was
    /// widened by ([`crate::handeye::quality::trust`]); absent: not widened.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub std_widened_by: Option<f64>,
    /// The working distance: the median camera-target distance (m).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub work_distance_m: Option<f64>,
    /// The std of a point at the working distance on the camera's optical
    /// axis (mm, root-sum-square over the axes): the hand-eye error where
    /// the camera looks ([`crate::handeye::quality::trust::work_point_std_mm`]).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub work_point_std_mm: Option<f64>,
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

pub(crate) fn transform_std(cov: &Covariance12, offset: usize) -> TransformStd {
    let s = |k: usize| cov[(offset + k, offset + k)].max(0.0).sqrt();
    TransformStd {
        rotation_deg: [s(0), s(1), s(2)].map(f64::to_degrees),
        translation_mm: [s(3), s(4), s(5)].map(|v| v * 1e3),
    }
}

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
    apply_pose_refinement_with(result, input, camera_noise, motion_pairs, true)
}

/// The pose refinement with each view's PnP covariance from its image
/// points (`CameraNoise::PerView`, the pixel variance estimated): for image
/// input whose refinement over pixels is off (`refine` none). A view whose
/// covariance cannot be computed leaves the predicted/diagonal models of
/// [`apply_pose_refinement`] in charge, with a warning.
pub fn apply_pose_refinement_from_views(
    result: &mut HandEyeResult,
    input: &HandEyeInput,
    views: &[View],
    camera: &Camera,
    motion_pairs: MotionPairs,
) -> Result<()> {
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
        Ok(c) if c.len() == input.camera_from_target.len() => {
            apply_pose_refinement(result, input, CameraNoise::PerView(c), motion_pairs)?
        }
        other => {
            let why = other
                .err()
                .unwrap_or_else(|| "views and poses differ in number".into());
            result.warnings.push(format!(
                "pose refinement: no PnP covariance ({why}); camera noise modelled from the poses"
            ));
            apply_pose_refinement(result, input, CameraNoise::Diagonal, motion_pairs)?
        }
    }
    add_reprojection_rms(result, input, views, camera)
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
    let chain = Chain::new(
        input.setup,
        &input.base_from_gripper,
        &input.camera_from_target,
    )?;
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
    apply_pose_refinement_resampled(
        result,
        input,
        camera_noise,
        (motion_pairs, None),
        predict_shape,
        resampling,
    )
}

/// [`apply_pose_refinement_with`] whose repeatability, with `resampling`
/// `(bootstrap samples, seed)`, is that of the refined estimate
/// ([`crate::handeye::refine::pose_resample`]), whether or not `result` holds the closed
/// form's; the motions of `motion_pairs` when the caller has them built.
pub(crate) fn apply_pose_refinement_resampled(
    result: &mut HandEyeResult,
    input: &HandEyeInput,
    camera_noise: CameraNoise,
    (motion_pairs, motions): (MotionPairs, Option<&[Motion]>),
    predict_shape: bool,
    resampling: Option<(usize, u64)>,
) -> Result<()> {
    let views = measurements(input);
    let setup = input.setup;
    let axis = result.unobservable_translation.first().copied();
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
            result
                .warnings
                .push(format!("pose refinement skipped: {e}"));
            return Ok(());
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
    result.x = refined.x;
    result.y = refined.y;
    result.method = format!("refined from {started_from}");
    result.per_view = view_residuals(&chain, &result.x, &result.y);
    result.errors = errors(&result.per_view);
    result.per_motion = match motions {
        Some(kept) => motion_residuals(kept, &result.x),
        None => motion_residuals(&build_motions(&chain, motion_pairs).kept, &result.x),
    };
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
    });
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
            &result.x,
            &result.y,
        );
        match resampled {
            Ok(r) => result.repeatability = Some(r),
            Err(e) => {
                result.warnings.push(format!(
                    "repeatability: the resamples of the refined estimate could not be solved \
                     ({e}); the closed form's are reported"
                ));
                result.repeatability = result.repeatability.take().or_else(|| {
                    closed_form_repeatability(&chain, &started_from, samples, seed, motion_pairs)
                });
            }
        }
    }
    crate::handeye::quality::trust::check_translation_scale(
        result,
        input,
        &views,
        &model_for_resamples,
        &options,
    );
    crate::handeye::quality::trust::check_uncertainty(result, input);
    Ok(())
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
