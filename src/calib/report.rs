//! The calibration report: parameters, residuals per view, parameter
//! uncertainty and correlation, a projection-uncertainty grid and warnings.

use super::plausibility::Severity;
use super::refine::{pose_from_block, CalibProblem};
use super::rejected::{rejected_points, RejectedPoints};
use super::residuals::{distortion_field, view_residuals, DistortionField, PixelVector};
use super::starts::StartOutcome;
use super::view_spread::check_view_spread;
use super::CalibrationOptions;
use crate::camera::{Camera, Distortion};
use crate::error::Result;
use crate::geometry::{Pose, PoseJson};
use crate::optim::{BlockProblem, LmResult, Termination};
use crate::report_kind::ReportKind;
use nalgebra::{DMatrix, Point2, Point3, Vector3};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Fewer views than this draw a warning.
const RECOMMENDED_VIEWS: usize = 10;
/// A largest target tilt below this (degrees) draws a warning: the focal
/// length is then poorly separated from the distance.
const MIN_TILT_DEG: f64 = 15.0;
/// Parameter correlations above this draw a warning.
const STRONG_CORRELATION: f64 = 0.95;
/// Grid of the projection-uncertainty map (columns, rows).
const UNCERTAINTY_GRID: (usize, usize) = (9, 7);

/// A point dropped by outlier rejection.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outlier {
    /// Index of the point in its view.
    pub index: usize,
    /// The target's id of the point (the detection's id; the index for
    /// explicit correspondences).
    #[serde(default)]
    pub id: usize,
    /// Its residual norm when it was dropped, px.
    pub residual_px: f64,
    /// Where it was observed, px (0 in reports written before this field).
    #[serde(default)]
    pub x_px: f64,
    /// Where it was observed, px.
    #[serde(default)]
    pub y_px: f64,
    /// Why it was dropped.
    pub reason: String,
}

/// Per-view results.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewReport {
    /// The view's name.
    pub name: String,
    /// RMS of the residual norms of the view's used points, px.
    pub rms_px: f64,
    /// Points used.
    pub n_points: usize,
    /// Pose of the target in the camera frame.
    pub camera_from_target: PoseJson,
    /// Points dropped as outliers.
    pub outliers: Vec<Outlier>,
    /// Observed minus predicted pixel of every point (outliers included),
    /// anchored at the observed pixel, in the view's point order.
    #[serde(default)]
    pub residuals_px: Vec<PixelVector>,
}

/// Correlation matrix of the camera parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Correlation {
    /// Parameter names (rows and columns).
    pub names: Vec<String>,
    /// Correlation coefficients, rows; 0 for held parameters; empty when
    /// the parameters are not all determined.
    pub matrix: Vec<Vec<f64>>,
}

/// How far a projected point may move (1 sigma, worst direction, px) from
/// the uncertainty of the camera parameters, on a grid over the image, for
/// points at the reference depth (mrcal's "projection uncertainty", here
/// from the intrinsics covariance with the point fixed in the camera frame).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProjectionUncertainty {
    /// Distance of the points from the camera, metres (median target distance).
    pub reference_depth_m: f64,
    /// Grid pixel x coordinates.
    pub x_px: Vec<f64>,
    /// Grid pixel y coordinates.
    pub y_px: Vec<f64>,
    /// Per row (y), per column (x): 1-sigma px; `None` where the camera cannot unproject.
    pub std_px: Vec<Vec<Option<f64>>>,
    /// The largest value in the grid, px.
    pub max_std_px: f64,
}

/// Result of [`super::calibrate`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraCalibration {
    /// What the report is: `camera` (absent from reports written before
    /// the key existed).
    #[serde(default = "ReportKind::camera")]
    pub kind: ReportKind,
    /// robocal version that produced the report (`crate_version` in reports
    /// written before every report said `robocal_version`).
    #[serde(alias = "crate_version")]
    pub robocal_version: String,
    /// Image width and height, px.
    pub image_size_px: [u32; 2],
    /// Lens model name.
    pub model: String,
    /// The calibrated camera.
    pub camera: Camera,
    /// Camera matrix, rows.
    pub camera_matrix: [[f64; 3]; 3],
    /// Named distortion coefficients.
    pub distortion: BTreeMap<String, f64>,
    /// sqrt(sum of squared residual norms / number of points), px (OpenCV's RMS).
    pub rms_px: f64,
    /// Standard deviation of every camera parameter (0 if held), from the
    /// covariance scaled by the residual variance; empty (with a warning)
    /// when the parameters are not all determined.
    pub std: BTreeMap<String, f64>,
    /// Per-view results.
    pub views: Vec<ViewReport>,
    /// Parameter correlations.
    pub correlation: Correlation,
    /// Projection uncertainty over the image.
    pub projection_uncertainty: ProjectionUncertainty,
    /// With `board_warp`: the board's estimated flex; absent without.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub board_warp: Option<super::BoardWarp>,
    /// With the splined model: where the data constrain the spline;
    /// absent for the other models.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spline_support: Option<super::SplineSupport>,
    /// With the cross-validation option: the projection difference of two
    /// halves of the views for this model and the others, beside its
    /// predicted uncertainty; absent without.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cross_validation: Option<super::cross_validation::CrossValidation>,
    /// Distorted minus undistorted pixel positions on a grid over the image.
    #[serde(default)]
    pub distortion_field: DistortionField,
    /// Things the user should know (coverage, tilt, correlations, ...).
    pub warnings: Vec<String>,
    /// Solver iterations in the last round.
    pub iterations: usize,
    /// Why the solver stopped.
    pub termination: Termination,
    /// Points used in total.
    pub n_points: usize,
    /// The options used.
    pub options: CalibrationOptions,
    /// With the robust option: how many points were rejected, in which
    /// views and where; absent without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rejected: Option<RejectedPoints>,
    /// The worst level of `warnings`: `ok` (none), `warning`, or `error`:
    /// the result is not a calibration (the fit did not converge from any
    /// start) and the first warning, beginning with `error: `, says why.
    #[serde(default)]
    pub severity: Severity,
    /// Zhang's method: the start its result came from (`closed_form`,
    /// `given` with an initial camera, `tsai`, `dlt`, `square_pixels`,
    /// `centred_principal_point`, `square_pixels_centred`,
    /// `distortion_held_then_freed`, `comparison:METHOD`); absent for the
    /// other methods.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<String>,
    /// Every start tried, when the first one did not converge or gave an
    /// implausible camera (the lowest cost wins); absent otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub starts: Vec<StartOutcome>,
}

/// Whether the report checks the views' agreement against the covariance
/// ([`super::view_spread`]): not for a covariance given from elsewhere.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SpreadCheck {
    Check,
    Skip,
}

pub(crate) fn build_report(
    problem: &CalibProblem,
    result: &LmResult,
    outliers: Vec<Vec<Outlier>>,
    size: (u32, u32),
    options: &CalibrationOptions,
    spread: SpreadCheck,
) -> Result<CameraCalibration> {
    let camera = problem.camera(&result.params.global)?;
    let names: Vec<String> = camera.param_names().iter().map(|s| s.to_string()).collect();
    // A singular J^T J at the optimum: some parameter is not determined.
    // The camera is still the least-squares solution; the uncertainty
    // outputs stay empty and a warning says why.
    let covariance = parameter_covariance(result, problem.aspect, names.len());
    // Views that disagree beyond their residuals widen it (not for a
    // splined lens: a view alone determines some of its control points).
    let mut spread_warning = None;
    let covariance = match covariance {
        Some(c)
            if spread == SpreadCheck::Check
                && !matches!(camera.distortion, Distortion::Splined(_)) =>
        {
            let to_camera = |g: &DMatrix<f64>| camera_block(g, problem.aspect, names.len());
            let checked = check_view_spread(
                problem,
                result,
                &options.loss,
                &c,
                &names,
                problem.aspect.is_some(),
                to_camera,
            );
            spread_warning = checked.warning;
            Some(checked.covariance)
        }
        other => other,
    };
    let zero = DMatrix::zeros(0, 0);
    let cov = covariance.as_ref().unwrap_or(&zero);
    // Maps filled by insertion: `collect` into a BTreeMap sorts first and
    // instantiates a stable sort per key type (8 KB of wasm).
    let mut std = BTreeMap::new();
    if let Some(c) = &covariance {
        for (i, n) in names.iter().enumerate() {
            std.insert(n.clone(), c[(i, i)].max(0.0).sqrt());
        }
    }
    let mut distortion = BTreeMap::new();
    for (n, v) in camera
        .distortion
        .coefficient_names()
        .iter()
        .zip(camera.distortion.coefficients())
    {
        distortion.insert(n.to_string(), v);
    }
    let correlation = correlation(&names, cov);
    let blocks = problem.residuals_and_jacobian(&result.params, false)?;
    let mut squared = vec![0.0; problem.views.len()];
    let mut counts = vec![0usize; problem.views.len()];
    for b in &blocks {
        if let Some(v) = b.block {
            squared[v] += b.residuals.norm_squared();
            counts[v] += 1;
        }
    }
    let n_points: usize = counts.iter().sum();
    let poses: Vec<Pose> = result
        .params
        .blocks
        .iter()
        .map(|b| pose_from_block(b))
        .collect();
    let views = problem
        .views
        .iter()
        .enumerate()
        .zip(outliers)
        .map(|((v, view), mut outliers)| {
            for o in &mut outliers {
                if let Some(p) = view.image_px.get(o.index) {
                    (o.x_px, o.y_px) = (p.x, p.y);
                }
            }
            ViewReport {
                name: view.name.clone(),
                rms_px: (squared[v] / counts[v].max(1) as f64).sqrt(),
                n_points: counts[v],
                camera_from_target: PoseJson::from(&poses[v]),
                outliers,
                residuals_px: view_residuals(&camera, &poses[v], view),
            }
        })
        .collect::<Vec<ViewReport>>();
    let rejected = options.outlier_sigma.map(|_| rejected_points(&views, size));
    let mut depths: Vec<f64> = poses.iter().map(|p| p.translation.vector.norm()).collect();
    depths.sort_by(f64::total_cmp);
    let depth = depths.get(depths.len() / 2).copied().unwrap_or(1.0);
    let k = camera.camera_matrix();
    let mut warnings = warnings(problem, &poses, &correlation, covariance.is_none());
    warnings.extend(spread_warning);
    Ok(CameraCalibration {
        kind: ReportKind::Camera,
        robocal_version: crate::VERSION.to_string(),
        image_size_px: [size.0, size.1],
        model: camera.distortion.model_name().to_string(),
        camera_matrix: [0, 1, 2].map(|r| [k[(r, 0)], k[(r, 1)], k[(r, 2)]]),
        distortion,
        rms_px: (squared.iter().sum::<f64>() / n_points.max(1) as f64).sqrt(),
        std,
        projection_uncertainty: projection_uncertainty(&camera, cov, depth),
        distortion_field: distortion_field(&camera),
        severity: Severity::of(&warnings),
        warnings,
        views,
        correlation,
        iterations: result.iterations,
        termination: result.termination,
        n_points,
        options: options.clone(),
        camera,
        board_warp: None,
        spline_support: None,
        cross_validation: None,
        rejected,
        start: None,
        starts: Vec::new(),
    })
}

/// The covariance of the camera parameters, with fy's row and column
/// derived from fx's when the aspect ratio is fixed (fy = a fx).
fn parameter_covariance(
    result: &LmResult,
    aspect: Option<f64>,
    n_camera: usize,
) -> Option<DMatrix<f64>> {
    Some(camera_block(
        result.covariance_global.as_ref()?,
        aspect,
        n_camera,
    ))
}

/// The camera's block of a covariance over the solver's global parameters
/// (a board warp's parameters follow it), fy's row and column from fx's
/// when the aspect ratio is held.
fn camera_block(full: &DMatrix<f64>, aspect: Option<f64>, n_camera: usize) -> DMatrix<f64> {
    let n_camera = n_camera.min(full.nrows());
    let mut c = full.view((0, 0), (n_camera, n_camera)).into_owned();
    if let Some(a) = aspect {
        let n = c.nrows();
        let mut t = DMatrix::<f64>::identity(n, n);
        t[(1, 0)] = a;
        t[(1, 1)] = 0.0;
        c = &t * c * t.transpose();
    }
    c
}

fn correlation(names: &[String], c: &DMatrix<f64>) -> Correlation {
    let n = c.nrows().min(names.len());
    let matrix = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let d = (c[(i, i)] * c[(j, j)]).sqrt();
                    if d > 0.0 {
                        c[(i, j)] / d
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    Correlation {
        names: names.to_vec(),
        matrix,
    }
}

/// The projection uncertainty over the image (the report's grid) of
/// `camera` with parameter covariance `c` (rows and columns in the order
/// of [`Camera::param_names`]; empty: not available) for points at `depth`
/// metres: what live capture predicts for a calibration with a view added.
pub fn projection_uncertainty(
    camera: &Camera,
    c: &DMatrix<f64>,
    depth: f64,
) -> ProjectionUncertainty {
    let (cols, rows) = UNCERTAINTY_GRID;
    let at = |i: usize, n: usize, size: u32| i as f64 * (size as f64 - 1.0) / (n - 1) as f64;
    let x_px: Vec<f64> = (0..cols).map(|i| at(i, cols, camera.width)).collect();
    let y_px: Vec<f64> = (0..rows).map(|i| at(i, rows, camera.height)).collect();
    // d pixel / d params and d pixel / d (camera rotation) at each grid pixel.
    let jacobians_at = |x: f64, y: f64| -> Option<super::splined::PixelJacobians> {
        if c.nrows() == 0 {
            return None;
        }
        let ray = camera.unproject(&Point2::new(x, y)).ok()?;
        let p = ray * depth;
        let (_, d_point, j) = camera.project_with_jacobians(&Point3::from(p)).ok()?;
        // Left perturbation of the point by a small rotation w: dp = -[p]x w.
        let d_rot = d_point * (-p.cross_matrix());
        Some((j, DMatrix::from_column_slice(2, 3, d_rot.as_slice())))
    };
    let jacobians: Vec<Vec<Option<super::splined::PixelJacobians>>> = y_px
        .iter()
        .map(|&y| x_px.iter().map(|&x| jacobians_at(x, y)).collect())
        .collect();
    // A splined lens absorbs a small rotation of the camera frame (every
    // pose turned, the correction shifted): its parameters' covariance
    // holds that nearly free direction, which moves no projection of the
    // scene. As mrcal's uncertainty (and the projection diff) does, the
    // part of a parameter change a rotation explains over the grid is
    // taken out before it counts.
    let implied = match camera.distortion {
        crate::camera::Distortion::Splined(_) => super::splined::implied_rotation(&jacobians),
        _ => None,
    };
    let std_px: Vec<Vec<Option<f64>>> = jacobians
        .iter()
        .map(|row| {
            row.iter()
                .map(|cell| {
                    let (j, r) = cell.as_ref()?;
                    let j = match &implied {
                        Some(m) => j - r * m,
                        None => j.clone(),
                    };
                    let s = &j * c * j.transpose();
                    Some(s.symmetric_eigenvalues().max().max(0.0).sqrt())
                })
                .collect()
        })
        .collect();
    let max_std_px = std_px
        .iter()
        .flatten()
        .flatten()
        .fold(0.0, |a: f64, &b| a.max(b));
    ProjectionUncertainty {
        reference_depth_m: depth,
        x_px,
        y_px,
        std_px,
        max_std_px,
    }
}

fn warnings(
    problem: &CalibProblem,
    poses: &[Pose],
    correlation: &Correlation,
    singular: bool,
) -> Vec<String> {
    let mut out = vec![];
    if singular {
        out.push(
            "the views do not determine every camera parameter (singular normal equations): \
             std, correlation and projection uncertainty are not available; fix parameters or add tilted views"
                .to_string(),
        );
    }
    let n_views = problem.views.len();
    if n_views < RECOMMENDED_VIEWS {
        out.push(format!(
            "only {n_views} views: {RECOMMENDED_VIEWS} or more from varied angles are recommended"
        ));
    }
    // Image corners: the outer thirds of the image in both directions.
    let (w, h) = (
        problem.template.width as f64,
        problem.template.height as f64,
    );
    let mut corner_hits = [false; 4];
    for (view, used) in problem.views.iter().zip(problem.used) {
        for (p, &u) in view.image_px.iter().zip(used) {
            let (left, right) = (p.x < w / 3.0, p.x > 2.0 * w / 3.0);
            let (top, bottom) = (p.y < h / 3.0, p.y > 2.0 * h / 3.0);
            for (i, hit) in [left && top, right && top, left && bottom, right && bottom]
                .iter()
                .enumerate()
            {
                corner_hits[i] |= u && *hit;
            }
        }
    }
    for (name, hit) in ["top-left", "top-right", "bottom-left", "bottom-right"]
        .iter()
        .zip(corner_hits)
    {
        if !hit {
            out.push(format!("no target points in the {name} corner of the image: the distortion there is extrapolated"));
        }
    }
    let max_tilt = poses
        .iter()
        .map(|p| {
            (p.rotation * Vector3::z())
                .z
                .abs()
                .clamp(0.0, 1.0)
                .acos()
                .to_degrees()
        })
        .fold(0.0, f64::max);
    if max_tilt < MIN_TILT_DEG {
        out.push(format!(
            "the target is tilted at most {max_tilt:.1} deg from facing the camera: tilt it 20-45 deg in some views to pin down the focal length"
        ));
    }
    // fx and fy move together by construction (square-ish pixels); their
    // correlation says nothing about a degeneracy, so it is not reported.
    let n = correlation.matrix.len();
    for i in 0..n {
        for j in (i + 1)..n {
            let r = correlation.matrix[i][j];
            let pair = (correlation.names[i].as_str(), correlation.names[j].as_str());
            if r.abs() > STRONG_CORRELATION && pair != ("fx", "fy") {
                out.push(format!(
                    "{} and {} are strongly correlated ({r:.3}): the views do not separate them",
                    pair.0, pair.1
                ));
            }
        }
    }
    out
}
