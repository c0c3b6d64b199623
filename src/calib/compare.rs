//! The calibration methods side by side (seed 000, Table II): for the same
//! views, every method's intrinsics and the standard deviation of its u and
//! v residuals, with the reason when a method does not apply to the data.

use super::dlt::solve_dlt;
use super::ekf::{calibrate_ekf, EkfOptions};
use super::evaluate::report_at;
use super::{calibrate, calibrate_tsai, CalibrationOptions, CameraCalibration, View};
use crate::camera::{Camera, Distortion};
use crate::error::{Error, Result};
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

/// A calibration method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Zhang's closed form refined by bundle adjustment over all views.
    Zhang,
    /// The linear 12-parameter DLT of each view (non-coplanar points only),
    /// no refinement, no distortion.
    Dlt,
    /// Tsai's two-stage method (coplanar case) and its nonlinear stage.
    Tsai,
    /// The (iterated) extended Kalman filter of seed 000, one point at a time.
    Ekf,
}

impl Method {
    /// Every method, in the order of the comparison table.
    pub const ALL: [Method; 4] = [Method::Zhang, Method::Dlt, Method::Tsai, Method::Ekf];

    /// The method's name in JSON and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Zhang => "zhang",
            Method::Dlt => "dlt",
            Method::Tsai => "tsai",
            Method::Ekf => "ekf",
        }
    }

    /// The method of a name (`zhang`, ...); unknown names are an error that
    /// lists the known ones.
    pub fn from_name(name: &str) -> Result<Method> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| {
                let known: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
                Error::invalid(
                    "method",
                    format!(
                        "unknown method '{name}' (expected one of {}, or all)",
                        known.join(", ")
                    ),
                )
            })
    }
}

/// Calibrate with one method; every method returns the same report type.
pub fn calibrate_with(
    method: Method,
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    match method {
        Method::Zhang => calibrate(views, image_size_px, options),
        Method::Dlt => calibrate_dlt(views, image_size_px, options),
        Method::Tsai => calibrate_tsai(views, image_size_px, options),
        Method::Ekf => calibrate_ekf(views, image_size_px, options, &EkfOptions::default()),
    }
}

/// The 12-parameter DLT of every view (seed 002, via [`super::dlt`]); with
/// several views the camera matrix is the point-weighted mean of the
/// per-view decompositions, reported with each view's own pose. Pinhole
/// only: the DLT has no distortion.
pub fn calibrate_dlt(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
) -> Result<CameraCalibration> {
    let solutions: Vec<_> = views
        .iter()
        .map(|v| {
            solve_dlt(&v.object_m, &v.image_px)
                .map_err(|e| Error::invalid(format!("views[{}]", v.name), format!("DLT: {e}")))
        })
        .collect::<Result<_>>()?;
    let mut k = Matrix3::zeros();
    let mut n = 0.0;
    for (s, v) in solutions.iter().zip(views) {
        k += s.camera_matrix * v.object_m.len() as f64;
        n += v.object_m.len() as f64;
    }
    k /= n.max(1.0);
    let camera = Camera {
        fx: k[(0, 0)],
        fy: k[(1, 1)],
        cx: k[(0, 2)],
        cy: k[(1, 2)],
        skew: k[(0, 1)],
        width: image_size_px.0,
        height: image_size_px.1,
        distortion: Distortion::None,
    };
    let poses: Vec<_> = solutions.iter().map(|s| s.camera_from_world).collect();
    let mut report = report_at(views, &camera, &poses, vec![false; 5], options)?;
    report.options.zero_skew = false;
    report.options.fixed_coefficients = vec![];
    Ok(report)
}

/// One row of the comparison.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ComparisonRow {
    /// The method's name.
    pub method: String,
    /// Focal length x, px (`None` when the method failed).
    pub fx: Option<f64>,
    /// Focal length y, px.
    pub fy: Option<f64>,
    /// Principal point x, px.
    pub cx: Option<f64>,
    /// Principal point y, px.
    pub cy: Option<f64>,
    /// First radial coefficient, when the model has one.
    pub k1: Option<f64>,
    /// RMS residual norm, px.
    pub rms_px: Option<f64>,
    /// Standard deviation of the u (x) residuals of the used points, px.
    pub std_u_px: Option<f64>,
    /// Standard deviation of the v (y) residuals of the used points, px.
    pub std_v_px: Option<f64>,
    /// Why the method failed or does not apply; `None` on success.
    pub error: Option<String>,
}

impl ComparisonRow {
    /// The row of a method's outcome.
    pub fn new(method: Method, outcome: &Result<CameraCalibration>) -> ComparisonRow {
        let empty = ComparisonRow {
            method: method.name().to_string(),
            fx: None,
            fy: None,
            cx: None,
            cy: None,
            k1: None,
            rms_px: None,
            std_u_px: None,
            std_v_px: None,
            error: None,
        };
        match outcome {
            Err(e) => ComparisonRow {
                error: Some(e.to_string()),
                ..empty
            },
            Ok(report) => {
                let (std_u_px, std_v_px) = residual_std(report);
                ComparisonRow {
                    fx: Some(report.camera.fx),
                    fy: Some(report.camera.fy),
                    cx: Some(report.camera.cx),
                    cy: Some(report.camera.cy),
                    k1: report.distortion.get("k1").copied(),
                    rms_px: Some(report.rms_px),
                    std_u_px,
                    std_v_px,
                    ..empty
                }
            }
        }
    }
}

/// Run every method that applies to the views: each one's outcome, in the
/// order of [`Method::ALL`]. The DLT is left out when every view is a flat
/// board (see [`left_out`]).
pub fn compare_methods(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
) -> Vec<(Method, Result<CameraCalibration>)> {
    let flat = all_views_planar(views);
    Method::ALL
        .into_iter()
        .filter(|m| !(flat && *m == Method::Dlt))
        .map(|m| (m, calibrate_with(m, views, image_size_px, options)))
        .collect()
}

/// Why [`compare_methods`] leaves methods out, said once for the whole
/// table: `None` when every method ran.
pub fn left_out(views: &[View]) -> Option<String> {
    all_views_planar(views).then(|| {
        "dlt left out: the 12-parameter DLT needs target points off one plane (a 3-D target \
         or XY-table positions), and every view here is a flat board"
            .to_string()
    })
}

/// Whether the target points of every view lie in one plane: the smallest
/// eigenvalue of their scatter is at most 1e-12 of the largest.
pub fn all_views_planar(views: &[View]) -> bool {
    views.iter().all(|v| {
        let n = v.object_m.len().max(1) as f64;
        let mean = v
            .object_m
            .iter()
            .fold(nalgebra::Vector3::zeros(), |a, p| a + p.coords)
            / n;
        let scatter = v.object_m.iter().fold(Matrix3::zeros(), |a, p| {
            a + (p.coords - mean) * (p.coords - mean).transpose()
        });
        let eig = scatter.symmetric_eigenvalues();
        eig.min() <= 1e-12 * eig.max().max(f64::MIN_POSITIVE)
    })
}

/// Sample standard deviations of the u and v residuals of the points used
/// (outliers left out); `None` with fewer than 2 points.
pub fn residual_std(report: &CameraCalibration) -> (Option<f64>, Option<f64>) {
    let mut du = vec![];
    let mut dv = vec![];
    for view in &report.views {
        for (i, r) in view.residuals_px.iter().enumerate() {
            if view.outliers.iter().all(|o| o.index != i) {
                du.push(r.dx);
                dv.push(r.dy);
            }
        }
    }
    (sample_std(&du), sample_std(&dv))
}

fn sample_std(values: &[f64]) -> Option<f64> {
    if values.len() < 2 {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    Some((values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt())
}
