//! Zhang's planar calibration, end to end: validate, homographies,
//! closed-form intrinsics, poses, bundle adjustment with optional iterative
//! outlier rejection, report.

use super::closed_form::{intrinsics_from_homographies, pose_from_homography};
use super::homography::homography;
use super::plausibility::{self, aspect_off, not_converged};
use super::refine::{block_from_pose, BoardExtent, CalibProblem};
use super::report::{build_report, Outlier, SpreadCheck};
use super::starts::{best_start, converged, StartOutcome};
use super::usable::{left_out_clause, usable_views, LeftOut};
use super::{CameraCalibration, View};
use crate::camera::{Camera, Distortion, N_PINHOLE_PARAMS};
use crate::error::{Error, Result};
use crate::optim::{solve, BlockParams, LmOptions, LmResult, Loss};
use nalgebra::{Matrix3, Point2};
use serde::{Deserialize, Serialize};

/// |z| above which a target point is not on the z = 0 plane, metres.
const PLANE_TOLERANCE_M: f64 = 1e-9;
/// Ratio of the median residual norm to sigma for 2-D Gaussian residuals
/// (median of a Rayleigh distribution: sqrt(2 ln 2)).
const RAYLEIGH_MEDIAN: f64 = 1.177_410_022_515_474_6;
/// Residuals below this (px) are never rejected as outliers.
const MIN_OUTLIER_PX: f64 = 0.01;

/// What to estimate and how. Defaults: Brown model (k1 k2 p1 p2 k3 from 0),
/// zero skew, nothing else fixed, squared loss, no outlier rejection.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CalibrationOptions {
    /// The lens model; its coefficients are the initial values (and the
    /// values of fixed coefficients).
    pub model: Distortion,
    /// Start from this camera instead of the closed-form solution (its
    /// lens model is replaced by `model` if they differ).
    pub initial_camera: Option<Camera>,
    /// Hold cx, cy at the initial value (the image centre without an initial camera).
    pub fix_principal_point: bool,
    /// Hold the aspect ratio: fy / fx stays at the ratio of the start
    /// (the closed-form solution or `initial_camera`), or at `aspect_ratio`
    /// when that is given.
    pub fix_aspect_ratio: bool,
    /// With `fix_aspect_ratio`: the held fx / fy (OpenCV's `aspectRatio`
    /// with `CALIB_FIX_ASPECT_RATIO`; 1 = square pixels, fx = fy exactly).
    /// `None` holds the start's ratio instead. Must be finite and > 0.
    pub aspect_ratio: Option<f64>,
    /// Hold the skew at 0 (default true; OpenCV has no skew).
    pub zero_skew: bool,
    /// Coefficient names (of `model`) held at their value in `model`.
    pub fixed_coefficients: Vec<String>,
    /// Robust loss on each point's residual norm, px.
    pub loss: Loss,
    /// With `Some(k)`, points whose residual exceeds k robust sigmas are
    /// dropped and the problem re-solved, until none is dropped.
    pub outlier_sigma: Option<f64>,
    /// Most rejection rounds (default 5).
    pub max_outlier_rounds: usize,
    /// Most solver iterations per round (default 200).
    pub max_iterations: usize,
    /// Estimate the board's flex with the calibration (mrcal's two-parameter
    /// paraboloid, [`super::BoardWarp`]); default false.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub board_warp: bool,
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        CalibrationOptions {
            model: Distortion::Brown {
                k1: 0.0,
                k2: 0.0,
                k3: 0.0,
                p1: 0.0,
                p2: 0.0,
            },
            initial_camera: None,
            fix_principal_point: false,
            fix_aspect_ratio: false,
            aspect_ratio: None,
            zero_skew: true,
            fixed_coefficients: vec![],
            loss: Loss::Squared,
            outlier_sigma: None,
            max_outlier_rounds: 5,
            max_iterations: 200,
            board_warp: false,
        }
    }
}

/// Calibrate a camera from planar-target views of one image size. A view
/// may hold any subset of the target's points; views whose points cannot
/// fix a homography ([`super::usable`]) are left out, each with a warning
/// in the report; too few remaining views is an error that lists them.
pub fn calibrate(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    // 1. Validate the input and leave out the views without a homography.
    validate(views, image_size_px, options)?;
    let (usable, left_out) = usable_views(views);
    let required = required_views(options);
    if usable.len() < required {
        return Err(Error::invalid(
            "views",
            format!(
                "requires at least {required} views whose points fix a homography, got {}{}",
                usable.len(),
                left_out_clause(&left_out)
            ),
        ));
    }
    let mut report = calibrate_usable(&usable, image_size_px, options)?;
    report
        .warnings
        .extend(left_out.iter().map(LeftOut::warning));
    Ok(report)
}

/// Fewest views Zhang's closed form takes: 2 with zero skew or a given
/// start, else 3.
pub(crate) fn required_views(options: &CalibrationOptions) -> usize {
    if options.zero_skew || options.initial_camera.is_some() {
        2
    } else {
        3
    }
}

/// [`calibrate`] on views that each fix a homography.
pub(crate) fn calibrate_usable(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    if let (Distortion::Splined(spline), None) = (&options.model, &options.initial_camera) {
        return super::splined::calibrate_splined(views, image_size_px, options, spline);
    }
    calibrate_from(views, image_size_px, options, None)
}

/// [`calibrate_usable`] with the poses (one `[rotation vector,
/// translation]` block per view) to start from; `None` (or a count that
/// does not match the views): the poses of the homographies.
pub(crate) fn calibrate_from(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
    start_poses: Option<Vec<Vec<f64>>>,
) -> Result<CameraCalibration> {
    let warp = match options.board_warp {
        false => None,
        true => Some(BoardExtent::of(views).ok_or_else(|| {
            Error::invalid(
                "board_warp",
                "the board's points span no area: no warp to estimate",
            )
        })?),
    };
    // 2. Homographies and the closed-form start (or the given guess).
    let homographies: Vec<Matrix3<f64>> = views
        .iter()
        .map(|v| {
            let plane: Vec<Point2<f64>> = v.object_m.iter().map(|p| p.xy()).collect();
            homography(&plane, &v.image_px)
        })
        .collect::<Result<_>>()?;
    let initial = initial_camera(&homographies, image_size_px, options)?;
    // 3. Poses from the homographies.
    let k = initial.camera_matrix();
    let poses = match start_poses {
        Some(p) if p.len() == views.len() => p,
        _ => homographies
            .iter()
            .map(|h| pose_from_homography(&k, h).map(|p| block_from_pose(&p)))
            .collect::<Result<Vec<_>>>()?,
    };
    // 4. Bundle adjustment from the best start, with outlier rounds.
    let all_used: Vec<Vec<bool>> = views.iter().map(|v| vec![true; v.object_m.len()]).collect();
    let mut used = all_used.clone();
    let mut global = initial.params();
    let mut lm_options = lm_options(&initial, options)?;
    if warp.is_some() {
        global.extend([0.0, 0.0]);
        lm_options.fixed_global.extend([false, false]);
    }
    let params = BlockParams {
        global,
        blocks: poses,
    };
    let aspect = held_aspect(&initial, options);
    let first_name = match (&options.initial_camera, &options.model) {
        (Some(_), Distortion::Splined(_)) => super::starts::PARAMETRIC_FIT,
        (Some(_), _) => "given",
        (None, _) => "closed_form",
    };
    let best = best_start(
        &CalibProblem {
            template: &initial,
            views,
            used: &used,
            aspect,
            warp,
        },
        &params,
        first_name,
        &lm_options,
        &homographies,
        options,
    )?;
    let mut result = best.result;
    let mut rounds = 0;
    loop {
        let problem = CalibProblem {
            template: &initial,
            views,
            used: &used,
            aspect,
            warp,
        };
        let Some(k) = options.outlier_sigma else {
            let report = build_report(
                &problem,
                &result,
                vec![vec![]; views.len()],
                image_size_px,
                options,
                SpreadCheck::Check,
            )?;
            return finish(
                report,
                &problem,
                &result,
                &lm_options,
                best.start,
                best.outcomes,
            );
        };
        // Classify every point, dropped ones included, so that inliers
        // pulled off by an outlier in an early round come back.
        let every = CalibProblem {
            used: &all_used,
            ..problem
        };
        let (next_used, outliers) = classify(&every, &result.params, &used, k)?;
        if next_used == used || rounds >= options.max_outlier_rounds {
            // 5. The report.
            let report = build_report(
                &problem,
                &result,
                outliers,
                image_size_px,
                options,
                SpreadCheck::Check,
            )?;
            return finish(
                report,
                &problem,
                &result,
                &lm_options,
                best.start,
                best.outcomes,
            );
        }
        used = next_used;
        rounds += 1;
        let next = CalibProblem {
            template: &initial,
            views,
            used: &used,
            aspect,
            warp,
        };
        result = solve(&next, &result.params, &lm_options)?;
    }
}

/// The report with its start, the plausibility warnings and, for a fit
/// that did not converge, the error-level warning first.
fn finish(
    mut report: CameraCalibration,
    problem: &CalibProblem,
    result: &LmResult,
    lm: &LmOptions,
    start: String,
    outcomes: Vec<StartOutcome>,
) -> Result<CameraCalibration> {
    let mut checks = Vec::new();
    if !converged(result) {
        let names: Vec<String> = if outcomes.is_empty() {
            vec![start.clone()]
        } else {
            outcomes.iter().map(|o| o.start.clone()).collect()
        };
        checks.push(not_converged(result.iterations, report.rms_px, &names));
    }
    let square = if aspect_off(&report.camera) && problem.aspect.is_none() {
        square_pixel_rms(problem, result, lm)
    } else {
        None
    };
    report.spline_support = super::splined::spline_support(problem, &report.camera);
    checks.extend(plausibility::warnings(
        &report.camera,
        report.rms_px,
        square,
        report.spline_support.as_ref(),
    ));
    report.board_warp = super::board_warp::board_warp(problem, result);
    checks.extend(
        report
            .board_warp
            .as_ref()
            .and_then(super::board_warp::warp_warning),
    );
    if let Some(support) = &report.spline_support {
        checks.extend(super::splined::spline_warnings(support, report.rms_px));
    }
    checks.append(&mut report.warnings);
    report.warnings = checks;
    report.start = Some(start);
    report.starts = outcomes;
    report.refresh_severity();
    Ok(report)
}

/// The RMS (px) of the fit from `result` with fy held at fx (square
/// pixels); `None` when it fails.
fn square_pixel_rms(problem: &CalibProblem, result: &LmResult, lm: &LmOptions) -> Option<f64> {
    let square = CalibProblem {
        aspect: Some(1.0),
        ..*problem
    };
    let mut fixed = lm.fixed_global.clone();
    if let Some(f) = fixed.get_mut(1) {
        *f = true;
    }
    let r = solve(
        &square,
        &result.params,
        &LmOptions {
            fixed_global: fixed,
            ..lm.clone()
        },
    )
    .ok()?;
    Some((2.0 * r.cost / (r.n_residuals / 2).max(1) as f64).sqrt())
}

fn validate(views: &[View], image_size_px: (u32, u32), options: &CalibrationOptions) -> Result<()> {
    if image_size_px.0 == 0 || image_size_px.1 == 0 {
        return Err(Error::invalid(
            "image_size_px",
            format!(
                "must be positive, got {}x{}",
                image_size_px.0, image_size_px.1
            ),
        ));
    }
    let required = required_views(options);
    if views.len() < required {
        return Err(Error::too_few("views", required, views.len()));
    }
    for v in views {
        if v.object_m.len() != v.image_px.len() {
            return Err(Error::invalid(
                format!("views[{}].image_px", v.name),
                format!(
                    "{} target points but {} image points",
                    v.object_m.len(),
                    v.image_px.len()
                ),
            ));
        }
        if let Some(p) = v
            .object_m
            .iter()
            .find(|p| p.z.abs() > PLANE_TOLERANCE_M || !p.iter().all(|x| x.is_finite()))
        {
            return Err(Error::invalid(
                format!("views[{}].object_m", v.name),
                format!(
                    "planar calibration needs target points on z = 0, got z = {}",
                    p.z
                ),
            ));
        }
    }
    if let Some(r) = options.aspect_ratio {
        if !options.fix_aspect_ratio {
            return Err(Error::invalid(
                "aspect_ratio",
                "is the held fx / fy: set fix_aspect_ratio too",
            ));
        }
        if !(r.is_finite() && r > 0.0) {
            return Err(Error::invalid(
                "aspect_ratio",
                format!(
                    "fx / fy must be finite and > 0, got {}",
                    crate::error::compact(r)
                ),
            ));
        }
    }
    for name in &options.fixed_coefficients {
        if !options.model.coefficient_names().contains(&name.as_str()) {
            return Err(Error::invalid(
                "fixed_coefficients",
                format!(
                    "the {} model has no coefficient '{name}' (it has {})",
                    options.model.model_name(),
                    options.model.coefficient_names().join(", ")
                ),
            ));
        }
    }
    Ok(())
}

fn initial_camera(
    homographies: &[Matrix3<f64>],
    size: (u32, u32),
    options: &CalibrationOptions,
) -> Result<Camera> {
    if let Some(c) = &options.initial_camera {
        return Ok(with_aspect_ratio(
            Camera {
                width: size.0,
                height: size.1,
                distortion: options.model.clone(),
                ..c.clone()
            },
            options,
        ));
    }
    let k = intrinsics_from_homographies(homographies, size, options.zero_skew)?;
    let (mut cx, mut cy) = (k[(0, 2)], k[(1, 2)]);
    if options.fix_principal_point {
        cx = 0.5 * (size.0 as f64 - 1.0);
        cy = 0.5 * (size.1 as f64 - 1.0);
    }
    let skew = if options.zero_skew { 0.0 } else { k[(0, 1)] };
    Ok(with_aspect_ratio(
        Camera {
            fx: k[(0, 0)],
            fy: k[(1, 1)],
            cx,
            cy,
            skew,
            width: size.0,
            height: size.1,
            distortion: options.model.clone(),
        },
        options,
    ))
}

/// The start with the requested fx / fy, keeping the geometric mean of the
/// focal lengths.
fn with_aspect_ratio(camera: Camera, options: &CalibrationOptions) -> Camera {
    match (options.fix_aspect_ratio, options.aspect_ratio) {
        (true, Some(r)) => {
            let f = (camera.fx * camera.fy).abs().sqrt();
            Camera {
                fx: f * r.sqrt(),
                fy: f / r.sqrt(),
                ..camera
            }
        }
        _ => camera,
    }
}

/// The held fy / fx of the problem (fy = aspect * fx), if any.
pub(crate) fn held_aspect(start: &Camera, options: &CalibrationOptions) -> Option<f64> {
    match (options.fix_aspect_ratio, options.aspect_ratio) {
        (false, _) => None,
        (true, Some(r)) => Some(1.0 / r),
        (true, None) => Some(start.fy / start.fx),
    }
}

pub(crate) fn lm_options(initial: &Camera, options: &CalibrationOptions) -> Result<LmOptions> {
    let names = initial.param_names();
    let mut fixed = vec![false; names.len()];
    fixed[1] = options.fix_aspect_ratio;
    fixed[2] = options.fix_principal_point;
    fixed[3] = options.fix_principal_point;
    fixed[4] = options.zero_skew;
    if let Distortion::Splined(_) = initial.distortion {
        // The spline's constant and linear terms are the base projection's
        // fx fy cx cy: those stay at the parametric fit's.
        fixed[..4].fill(true);
    }
    for (i, name) in names.iter().enumerate().skip(N_PINHOLE_PARAMS) {
        fixed[i] = options.fixed_coefficients.iter().any(|f| f == name);
    }
    Ok(LmOptions {
        max_iterations: options.max_iterations,
        loss: options.loss,
        fixed_global: fixed,
        ..LmOptions::default()
    })
}

/// The points kept (per view, per point) and the outliers left out.
type Classified = (Vec<Vec<bool>>, Vec<Vec<Outlier>>);

/// The points within k robust sigmas (sigma from the median residual of
/// the currently used points), and an [`Outlier`] record for each point the
/// current mask leaves out.
fn classify(
    every: &CalibProblem,
    params: &BlockParams,
    used: &[Vec<bool>],
    k: f64,
) -> Result<Classified> {
    let blocks = crate::optim::BlockProblem::residuals_and_jacobian(every, params, false)?;
    let norms: Vec<f64> = blocks.iter().map(|b| b.residuals.norm()).collect();
    let mut used_norms: Vec<f64> = norms
        .iter()
        .zip(used.iter().flatten())
        .filter(|(_, &u)| u)
        .map(|(r, _)| *r)
        .collect();
    used_norms.sort_by(f64::total_cmp);
    let sigma = used_norms.get(used_norms.len() / 2).copied().unwrap_or(0.0) / RAYLEIGH_MEDIAN;
    // Residuals of exact data are rounding noise (1e-10 px) whose 3 sigma
    // would still cut a few per cent of perfect points: no residual under
    // MIN_OUTLIER_PX is an outlier (no detector is that accurate).
    let threshold = (k * sigma).max(MIN_OUTLIER_PX);
    let mut next = Vec::with_capacity(used.len());
    let mut outliers = Vec::with_capacity(used.len());
    let mut it = norms.iter().zip(used.iter().flatten());
    for view in used {
        let mut view_next = Vec::with_capacity(view.len());
        let mut view_outliers = vec![];
        for index in 0..view.len() {
            let Some((&r, &was_used)) = it.next() else {
                break;
            };
            // Noise-free data has sigma 0: keep everything then.
            view_next.push(r <= threshold);
            if !was_used {
                let reason = if r > threshold {
                    format!("residual {r:.3} px > {k} x robust sigma {sigma:.3} px")
                } else {
                    format!("dropped in an earlier round; now {r:.3} px (rejection round limit reached)")
                };
                // The position is filled in by the report (it knows the view's pixels).
                view_outliers.push(Outlier {
                    index,
                    id: every
                        .views
                        .get(outliers.len())
                        .map_or(index, |v| v.point_id(index)),
                    residual_px: r,
                    x_px: 0.0,
                    y_px: 0.0,
                    reason,
                });
            }
        }
        next.push(view_next);
        outliers.push(view_outliers);
    }
    Ok((next, outliers))
}
