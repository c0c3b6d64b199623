//! XY-table / camera calibration with one circular target (seed 002): the
//! stage moves the target to N >= 6 known positions (x, y, z in mm); its
//! image centres give the 12-parameter projection matrix, solved by batch
//! least squares (normalized DLT) and by the recursive Kalman filter, whose
//! measurement noise comes from repeated images of the still target. Four
//! extra positions give a verification point: the intersection of the
//! quadrilateral's diagonals, measured in the image and predicted by each
//! projection matrix.
//!
//! Units: stage coordinates in mm at this boundary; `projection_matrix`
//! maps `[x_mm, y_mm, z_mm, 1]` to homogeneous pixels, scaled so that its
//! third row gives the depth in mm; `camera_from_world` is in metres.

use crate::calib::dlt::{
    normalize_scale, project, solution_from_projection, solve_dlt, DltSolution,
};
use crate::calib::dlt_kalman::{
    estimate_measurement_noise, kalman_dlt, KalmanMode, KalmanOptions, KalmanStep,
};
use crate::error::{Error, Result};
use crate::geometry::Pose;
use nalgebra::{Matrix2, Matrix3x4, Matrix4, Point2, Point3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// Most stage positions one XY-table calibration takes. The Kalman history
/// reports the RMS over all positions after every update, which grows with
/// the square of the count: 10,000 positions take 0.3 s, 100,000 took 30 s
/// (docs/bounds.md). Seed 003's tables have tens of positions.
pub const MAX_POSITIONS: usize = 10_000;

/// One stage position and the target's image centre there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StageObservation {
    /// Stage (world) position of the target centre, mm.
    pub stage_mm: [f64; 3],
    /// Image centre of the target, px.
    pub image_px: [f64; 2],
}

/// Where the measurement noise `R` of the Kalman filter came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseSource {
    /// Sample covariance of the repeated images of the still target.
    StillTarget,
    /// Given by the caller.
    Given,
    /// No still-target images and none given: the covariance of the batch
    /// residuals, scaled by 2N / (2N - 11) for the fitted parameters.
    BatchResiduals,
}

/// Input of [`solve_xytable`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct XyTableRequest {
    /// Calibration positions, in the order the filter processes them.
    pub observations: Vec<StageObservation>,
    /// Optional: exactly four extra positions A, B, C, D in order around a
    /// quadrilateral; diagonals AC and BD give the verification point.
    #[serde(default)]
    pub verification: Vec<StageObservation>,
    /// Optional: repeated image centres of the target standing still (px).
    #[serde(default)]
    pub still_target_px: Vec<[f64; 2]>,
    /// Optional: the noise covariance `R` (px^2, row-major 2x2) when no
    /// still-target images are given.
    #[serde(default)]
    pub measurement_noise_px2: Option<[[f64; 2]; 2]>,
    /// Kalman measurement model (default: extended).
    #[serde(default = "default_mode")]
    pub kalman_mode: KalmanMode,
}

fn default_mode() -> KalmanMode {
    KalmanMode::Extended
}

/// One method's projection matrix with its decomposition and residuals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodResult {
    /// 3x4 projection matrix, row-major, for stage coordinates in mm.
    pub projection_matrix: [f64; 12],
    /// Intrinsics K (3x3 row-major, px).
    pub camera_matrix: [f64; 9],
    /// Stage (world) frame in the camera frame, metres.
    #[serde(with = "crate::geometry::pose_serde")]
    pub camera_from_world: Pose,
    /// Per calibration position: projected minus measured, px.
    pub residuals_px: Vec<[f64; 2]>,
    /// RMS of the residual lengths, px.
    pub rms_px: f64,
    /// Kalman only: the estimate after each observation.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub history: Option<Vec<KalmanStep>>,
}

/// The verification point from the four extra positions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Verification {
    /// Intersection of the image diagonals AC and BD, px: the measurement.
    pub measured_px: [f64; 2],
    /// Intersection of the stage diagonals (midpoint of their closest
    /// points), mm.
    pub stage_mm: [f64; 3],
    /// Distance between the two stage diagonals, mm (0 for a planar quadrilateral).
    pub diagonal_gap_mm: f64,
    /// The stage intersection projected by the batch matrix, px.
    pub batch_predicted_px: [f64; 2],
    /// Its distance to the measured point, px.
    pub batch_error_px: f64,
    /// The stage intersection projected by the Kalman matrix, px.
    pub kalman_predicted_px: [f64; 2],
    /// Its distance to the measured point, px.
    pub kalman_error_px: f64,
}

/// Output of [`solve_xytable`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct XyTableReport {
    /// Batch least squares (normalized DLT).
    pub batch: MethodResult,
    /// Recursive Kalman filter.
    pub kalman: MethodResult,
    /// The noise covariance `R` used by the filter (px^2, row-major).
    pub measurement_noise_px2: [[f64; 2]; 2],
    /// Where `R` came from.
    pub noise_source: NoiseSource,
    /// The verification point, when four extra positions were given.
    pub verification: Option<Verification>,
    /// The request, for re-solving.
    pub input: XyTableRequest,
}

/// Solve both methods and the verification point.
pub fn solve_xytable(request: &XyTableRequest) -> Result<XyTableReport> {
    let n = request.observations.len();
    if n > MAX_POSITIONS {
        return Err(Error::invalid(
            "positions",
            format!(
                "{n} stage positions: at most {MAX_POSITIONS} are supported; keep a subset spread \
                 over the stage's volume, e.g. one in every {}",
                n.div_ceil(MAX_POSITIONS)
            ),
        ));
    }
    // 1. World points in metres inside, pixels as given.
    let world: Vec<Point3<f64>> = request
        .observations
        .iter()
        .map(|o| metres(o.stage_mm))
        .collect();
    let pixels: Vec<Point2<f64>> = request
        .observations
        .iter()
        .map(|o| Point2::from(o.image_px))
        .collect();
    // 2. Batch least squares.
    let batch = solve_dlt(&world, &pixels)?;
    // 3. Measurement noise.
    let (r, noise_source) = measurement_noise(request, &batch)?;
    // 4. The recursive filter.
    let mut options = KalmanOptions::new(r);
    options.mode = request.kalman_mode;
    let kf = kalman_dlt(&world, &pixels, &options)?;
    let kalman = solution_from_projection(&kf.projection, &world, &pixels)?;
    let history = kf
        .history
        .into_iter()
        .map(|mut s| {
            let p = Matrix3x4::from_row_slice(&s.projection_row_major);
            let q = to_mm(&p);
            s.projection_row_major = row_major(&q);
            s
        })
        .collect();
    // 5. Verification point.
    let verification = match request.verification.len() {
        0 => None,
        4 => Some(verify(
            &request.verification,
            &to_mm(&batch.projection),
            &to_mm(&kalman.projection),
        )?),
        n => {
            return Err(Error::invalid(
                "verification",
                format!(
                    "expected exactly 4 positions (A, B, C, D around a quadrilateral), got {n}"
                ),
            ))
        }
    };
    Ok(XyTableReport {
        batch: method_result(&batch, None),
        kalman: method_result(&kalman, Some(history)),
        measurement_noise_px2: [[r[(0, 0)], r[(0, 1)]], [r[(1, 0)], r[(1, 1)]]],
        noise_source,
        verification,
        input: request.clone(),
    })
}

fn measurement_noise(
    request: &XyTableRequest,
    batch: &DltSolution,
) -> Result<(Matrix2<f64>, NoiseSource)> {
    if !request.still_target_px.is_empty() {
        let c: Vec<Point2<f64>> = request
            .still_target_px
            .iter()
            .map(|p| Point2::from(*p))
            .collect();
        return Ok((estimate_measurement_noise(&c)?, NoiseSource::StillTarget));
    }
    if let Some(m) = request.measurement_noise_px2 {
        return Ok((
            Matrix2::new(m[0][0], m[0][1], m[1][0], m[1][1]),
            NoiseSource::Given,
        ));
    }
    let n = batch.residuals_px.len() as f64;
    let mut s = Matrix2::zeros();
    for r in &batch.residuals_px {
        let v = Vector2::from(*r);
        s += v * v.transpose();
    }
    // 2n scalar residuals, 11 fitted parameters.
    let dof = (2.0 * n - 11.0).max(1.0);
    Ok((s * (2.0 / dof), NoiseSource::BatchResiduals))
}

fn metres(mm: [f64; 3]) -> Point3<f64> {
    Point3::new(mm[0] * 1e-3, mm[1] * 1e-3, mm[2] * 1e-3)
}

/// `P` for metres -> `P` for millimetres, depth row in mm.
fn to_mm(p: &Matrix3x4<f64>) -> Matrix3x4<f64> {
    normalize_scale(&(p * Matrix4::from_diagonal(&nalgebra::Vector4::new(1e-3, 1e-3, 1e-3, 1.0))))
}

fn row_major(p: &Matrix3x4<f64>) -> [f64; 12] {
    std::array::from_fn(|i| p[(i / 4, i % 4)])
}

fn method_result(s: &DltSolution, history: Option<Vec<KalmanStep>>) -> MethodResult {
    let k = s.camera_matrix;
    MethodResult {
        projection_matrix: row_major(&to_mm(&s.projection)),
        camera_matrix: std::array::from_fn(|i| k[(i / 3, i % 3)]),
        camera_from_world: s.camera_from_world,
        residuals_px: s.residuals_px.clone(),
        rms_px: s.rms_px,
        history,
    }
}

fn verify(
    v: &[StageObservation],
    batch_mm: &Matrix3x4<f64>,
    kalman_mm: &Matrix3x4<f64>,
) -> Result<Verification> {
    let px: Vec<Vector2<f64>> = v.iter().map(|o| Vector2::from(o.image_px)).collect();
    let measured = intersect_2d(px[0], px[2], px[1], px[3])?;
    let st: Vec<Vector3<f64>> = v.iter().map(|o| Vector3::from(o.stage_mm)).collect();
    let (stage, gap) = intersect_3d(st[0], st[2], st[1], st[3])?;
    let x = Point3::from(stage);
    let pb = project(batch_mm, &x);
    let pk = project(kalman_mm, &x);
    Ok(Verification {
        measured_px: [measured.x, measured.y],
        stage_mm: [stage.x, stage.y, stage.z],
        diagonal_gap_mm: gap,
        batch_predicted_px: [pb.x, pb.y],
        batch_error_px: (pb.coords - measured).norm(),
        kalman_predicted_px: [pk.x, pk.y],
        kalman_error_px: (pk.coords - measured).norm(),
    })
}

/// Intersection of the lines a1-a2 and b1-b2 in the image.
fn intersect_2d(
    a1: Vector2<f64>,
    a2: Vector2<f64>,
    b1: Vector2<f64>,
    b2: Vector2<f64>,
) -> Result<Vector2<f64>> {
    let (da, db) = (a2 - a1, b2 - b1);
    let cross = da.x * db.y - da.y * db.x;
    if cross.abs() <= 1e-12 * da.norm() * db.norm() {
        return Err(Error::degenerate("the image diagonals AC and BD are parallel: give A, B, C, D in order around the quadrilateral"));
    }
    let w = b1 - a1;
    let s = (w.x * db.y - w.y * db.x) / cross;
    Ok(a1 + da * s)
}

/// Closest-point midpoint of the lines a1-a2 and b1-b2 in 3-D, and their distance.
fn intersect_3d(
    a1: Vector3<f64>,
    a2: Vector3<f64>,
    b1: Vector3<f64>,
    b2: Vector3<f64>,
) -> Result<(Vector3<f64>, f64)> {
    let (da, db, w) = (a2 - a1, b2 - b1, a1 - b1);
    let (a, b, c, d, e) = (
        da.dot(&da),
        da.dot(&db),
        db.dot(&db),
        da.dot(&w),
        db.dot(&w),
    );
    let den = a * c - b * b;
    if den <= 1e-12 * a * c {
        return Err(Error::degenerate("the stage diagonals AC and BD are parallel: give A, B, C, D in order around the quadrilateral"));
    }
    let s = (b * e - c * d) / den;
    let t = (a * e - b * d) / den;
    let (pa, pb) = (a1 + da * s, b1 + db * t);
    Ok(((pa + pb) / 2.0, (pa - pb).norm()))
}

#[cfg(test)]
#[path = "xytable_tests.rs"]
mod tests;
