//! The recursive Kalman-filter estimate of the 12 DLT parameters (seed 002,
//! Section III): the stage positions are processed one at a time, each
//! updating the estimate and its covariance, with the measurement noise `R`
//! estimated beforehand from repeated images of a still target.
//!
//! State: the 11 free entries of `P` in Hartley-normalized coordinates with
//! the normalization constraint `P34 = 1` (safe there: the normalized world
//! origin is the centroid of the points, in front of the camera). The
//! normalizing transforms are taken from the extent of all observations, a
//! change of units only; a streaming caller would fix them from the stage
//! travel and the image size instead.
//!
//! Measurement model, per observed point X with pixel z = (u, v):
//! - `Linearized`: the DLT constraint `u = p1.X - u (p3.X)` (linear in the
//!   state given the measured u), with noise variance `R d^2`, `d = p3.X` at
//!   the current estimate once it is determined, else 1 (the constraint
//!   multiplies the pixel noise by d, which is near 1 in normalized units).
//!   Works from a diffuse prior.
//! - `Extended` (default): the linearized update until every parameter is
//!   determined (state standard deviations below [`OBSERVABLE_STD`]; an EKF
//!   needs a nominal value to linearize about, the seed's "*" values), then
//!   the EKF update with `h(p) = (p1.X / p3.X, p2.X / p3.X)`
//!   linearized at the current estimate, innovation `z - h(p)`, noise `R`.
//!
//! The update is written in information form (`P^-1 += H^T R^-1 H`,
//! `x += P H^T R^-1 innovation`), the same Kalman update for a static state
//! but numerically safe from a diffuse prior to a tight posterior.

use super::dlt::{self, normalize_scale, project};
use crate::error::{Error, Result};
use nalgebra::{Matrix2, Matrix3, Matrix3x4, Matrix4, Point2, Point3, SMatrix, SVector, Vector2};
use serde::{Deserialize, Serialize};

type State = SVector<f64, 11>;
type Cov = SMatrix<f64, 11, 11>;
type Jac = SMatrix<f64, 2, 11>;

/// Standard deviation (px) added to the measurement noise so that a
/// perfectly still target (zero sample covariance) keeps the information
/// matrix well conditioned; negligible against real image noise (> 0.01 px).
pub const MIN_NOISE_PX: f64 = 1e-3;

/// Standard deviation (normalized units, parameters are of order 1) below
/// which every state entry counts as determined and the `Extended` mode
/// switches to the EKF update.
pub const OBSERVABLE_STD: f64 = 0.1;

/// Which measurement model the filter uses (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum KalmanMode {
    /// The DLT constraint, linear in the state.
    #[serde(rename = "linearized")]
    Linearized,
    /// The EKF on the perspective division, after a linearized start.
    #[serde(rename = "extended")]
    Extended,
}

/// Options of [`kalman_dlt`].
#[derive(Debug, Clone, PartialEq)]
pub struct KalmanOptions {
    /// Pixel noise covariance `R` (px^2), e.g. from [`estimate_measurement_noise`].
    pub measurement_noise_px2: Matrix2<f64>,
    /// Prior standard deviation of every normalized parameter around 0
    /// (default 10: diffuse, the normalized parameters are of order 1).
    pub prior_std: f64,
    /// Measurement model (default `Extended`).
    pub mode: KalmanMode,
}

impl KalmanOptions {
    /// Options with noise `R` and the defaults.
    pub fn new(measurement_noise_px2: Matrix2<f64>) -> Self {
        KalmanOptions {
            measurement_noise_px2,
            prior_std: 10.0,
            mode: KalmanMode::Extended,
        }
    }
}

/// The estimate after one observation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KalmanStep {
    /// 0-based index of the observation just processed.
    pub observation: usize,
    /// `P` (row-major, module scale convention of [`dlt`]) after it.
    pub projection_row_major: [f64; 12],
    /// Reprojection RMS (px) of *all* observations with this estimate.
    pub rms_px: f64,
    /// Trace of the state covariance (normalized units): how much is left
    /// to learn.
    pub covariance_trace: f64,
}

/// The final estimate and its convergence history.
#[derive(Debug, Clone, PartialEq)]
pub struct KalmanSolution {
    /// The final `P` (scale convention of [`dlt`]).
    pub projection: Matrix3x4<f64>,
    /// One entry per observation, in processing order.
    pub history: Vec<KalmanStep>,
}

/// Sample covariance (px^2, divisor n - 1) of repeated observations of one
/// still target: the measurement noise `R` of the filter.
pub fn estimate_measurement_noise(centres: &[Point2<f64>]) -> Result<Matrix2<f64>> {
    if centres.len() < 2 {
        return Err(Error::too_few(
            "repeated observations of the still target",
            2,
            centres.len(),
        ));
    }
    let n = centres.len() as f64;
    let m = centres.iter().map(|p| p.coords).sum::<Vector2<f64>>() / n;
    let mut s = Matrix2::zeros();
    for p in centres {
        let d = p.coords - m;
        s += d * d.transpose();
    }
    Ok(s / (n - 1.0))
}

/// Run the filter over the observations in order.
pub fn kalman_dlt(
    points_world: &[Point3<f64>],
    pixels: &[Point2<f64>],
    options: &KalmanOptions,
) -> Result<KalmanSolution> {
    // The batch checks (counts, coplanarity) apply equally to the filter.
    dlt::projection_dlt(points_world, pixels)?;
    let r = options.measurement_noise_px2;
    if !(r[(0, 0)] >= 0.0
        && r[(1, 1)] >= 0.0
        && r.determinant() >= -1e-30
        && r.iter().all(|v| v.is_finite()))
    {
        return Err(Error::invalid(
            "measurement_noise_px2",
            "expected a symmetric positive semi-definite 2x2 matrix",
        ));
    }
    if !(options.prior_std > 0.0) {
        return Err(Error::invalid(
            "prior_std",
            format!("expected a positive number, got {}", options.prior_std),
        ));
    }
    let (t3, t2, s2) = normalizers(points_world, pixels);
    let r_n = (r + Matrix2::identity() * MIN_NOISE_PX.powi(2)) * (s2 * s2);
    let t2_inv = t2
        .try_inverse()
        .ok_or_else(|| Error::degenerate("all pixels coincide"))?;
    let mut x = State::zeros();
    // Information (inverse covariance) of the state: the same Kalman update
    // for a static state, numerically safe from a diffuse prior to a tight
    // posterior (the covariance form loses positivity over that range).
    let mut info = Cov::identity() / options.prior_std.powi(2);
    let mut history = Vec::with_capacity(points_world.len());
    let mut extended = false;
    for (k, (xw, px)) in points_world.iter().zip(pixels).enumerate() {
        let xh = t3 * nalgebra::Vector4::new(xw.x, xw.y, xw.z, 1.0);
        let z = t2 * nalgebra::Vector3::new(px.x, px.y, 1.0);
        let z = Vector2::new(z.x, z.y);
        let singular = || Error::NoConvergence {
            message: format!("Kalman update {k}: the state information became singular"),
        };
        let cov = info.cholesky().ok_or_else(singular)?.inverse();
        let determined = cov.diagonal().max() < OBSERVABLE_STD * OBSERVABLE_STD;
        extended = extended || (options.mode == KalmanMode::Extended && determined);
        let (h, innovation, noise) = if extended {
            extended_model(&x, &xh, &z, &r_n)
        } else {
            linearized_model(&x, &xh, &z, &r_n, determined)
        };
        let noise_inv = noise.try_inverse().ok_or_else(singular)?;
        info += h.transpose() * noise_inv * h;
        info = (info + info.transpose()) * 0.5;
        let chol = info.cholesky().ok_or_else(singular)?;
        // Kalman gain K = P+ H^T R^-1 with P+ = info^-1.
        x += chol.solve(&(h.transpose() * noise_inv * innovation));
        let cov = chol.inverse();
        let p = normalize_scale(&(t2_inv * state_to_matrix(&x) * t3));
        let rms_px = rms(&p, points_world, pixels);
        history.push(KalmanStep {
            observation: k,
            projection_row_major: std::array::from_fn(|i| p[(i / 4, i % 4)]),
            rms_px,
            covariance_trace: cov.trace(),
        });
    }
    let projection = normalize_scale(&(t2_inv * state_to_matrix(&x) * t3));
    Ok(KalmanSolution {
        projection,
        history,
    })
}

/// `H`, innovation and noise of the DLT constraint (linear in the state).
fn linearized_model(
    x: &State,
    xh: &nalgebra::Vector4<f64>,
    z: &Vector2<f64>,
    r_n: &Matrix2<f64>,
    determined: bool,
) -> (Jac, Vector2<f64>, Matrix2<f64>) {
    let mut h = Jac::zeros();
    for j in 0..4 {
        h[(0, j)] = xh[j];
        h[(1, 4 + j)] = xh[j];
    }
    for j in 0..3 {
        h[(0, 8 + j)] = -z.x * xh[j];
        h[(1, 8 + j)] = -z.y * xh[j];
    }
    // Before the state is determined its denominator is meaningless; in
    // normalized coordinates the true one is close to 1.
    let d = if determined { denominator(x, xh) } else { 1.0 };
    (h, z - h * x, r_n * (d * d))
}

/// `H`, innovation and noise of the EKF on `h(p) = (p1.X / p3.X, p2.X / p3.X)`.
fn extended_model(
    x: &State,
    xh: &nalgebra::Vector4<f64>,
    z: &Vector2<f64>,
    r_n: &Matrix2<f64>,
) -> (Jac, Vector2<f64>, Matrix2<f64>) {
    let d = denominator(x, xh);
    let nu: f64 = (0..4).map(|j| x[j] * xh[j]).sum();
    let nv: f64 = (0..4).map(|j| x[4 + j] * xh[j]).sum();
    let mut h = Jac::zeros();
    for j in 0..4 {
        h[(0, j)] = xh[j] / d;
        h[(1, 4 + j)] = xh[j] / d;
    }
    for j in 0..3 {
        h[(0, 8 + j)] = -nu * xh[j] / (d * d);
        h[(1, 8 + j)] = -nv * xh[j] / (d * d);
    }
    (h, z - Vector2::new(nu / d, nv / d), *r_n)
}

fn denominator(x: &State, xh: &nalgebra::Vector4<f64>) -> f64 {
    x[8] * xh[0] + x[9] * xh[1] + x[10] * xh[2] + xh[3]
}

fn state_to_matrix(x: &State) -> Matrix3x4<f64> {
    Matrix3x4::new(
        x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], x[8], x[9], x[10], 1.0,
    )
}

fn rms(p: &Matrix3x4<f64>, points: &[Point3<f64>], pixels: &[Point2<f64>]) -> f64 {
    let sum: f64 = points
        .iter()
        .zip(pixels)
        .map(|(x, u)| (project(p, x) - u).norm_squared())
        .sum();
    (sum / points.len().max(1) as f64).sqrt()
}

/// Hartley normalizers (3-D 4x4, 2-D 3x3) and the 2-D scale factor.
fn normalizers(
    points: &[Point3<f64>],
    pixels: &[Point2<f64>],
) -> (Matrix4<f64>, Matrix3<f64>, f64) {
    let n = points.len() as f64;
    let c3 = points
        .iter()
        .map(|p| p.coords)
        .sum::<nalgebra::Vector3<f64>>()
        / n;
    let m3 = points.iter().map(|p| (p.coords - c3).norm()).sum::<f64>() / n;
    let s3 = if m3 > 0.0 { 3f64.sqrt() / m3 } else { 1.0 };
    let mut t3 = Matrix4::identity() * s3;
    t3[(3, 3)] = 1.0;
    t3.fixed_view_mut::<3, 1>(0, 3).copy_from(&(-s3 * c3));
    let c2 = pixels.iter().map(|p| p.coords).sum::<Vector2<f64>>() / n;
    let m2 = pixels.iter().map(|p| (p.coords - c2).norm()).sum::<f64>() / n;
    let s2 = if m2 > 0.0 { 2f64.sqrt() / m2 } else { 1.0 };
    let t2 = Matrix3::new(s2, 0.0, -s2 * c2.x, 0.0, s2, -s2 * c2.y, 0.0, 0.0, 1.0);
    (t3, t2, s2)
}

#[cfg(test)]
mod tests {
    use super::super::dlt::scene;
    use super::*;
    use crate::rng::Rng;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn relative_error(a: &Matrix3x4<f64>, b: &Matrix3x4<f64>) -> f64 {
        (a - b).norm() / b.norm()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn noise_free_filter_reaches_the_exact_projection() {
        let truth = normalize_scale(&scene::projection());
        let pts = scene::stage_points();
        let px: Vec<Point2<f64>> = pts.iter().map(|x| project(&truth, x)).collect();
        for mode in [KalmanMode::Linearized, KalmanMode::Extended] {
            let mut o = KalmanOptions::new(Matrix2::zeros());
            o.mode = mode;
            let s = kalman_dlt(&pts, &px, &o).unwrap();
            let e = relative_error(&s.projection, &truth);
            assert!(e < 1e-9, "{mode:?}: relative error {e:e}");
            assert_eq!(s.history.len(), pts.len());
            assert!(s.history.last().unwrap().rms_px < 1e-6, "{mode:?}");
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn noise_estimate_is_the_sample_covariance() {
        let c = [
            Point2::new(1.0, 2.0),
            Point2::new(3.0, 2.0),
            Point2::new(2.0, 5.0),
        ];
        let r = estimate_measurement_noise(&c).unwrap();
        // mean (2, 3): du = -1, 1, 0; dv = -1, -1, 2 -> var u 1, var v 3, cov 0.
        assert!((r - Matrix2::new(1.0, 0.0, 0.0, 3.0)).norm() < 1e-12, "{r}");
        assert_eq!(
            estimate_measurement_noise(&c[..1]).unwrap_err().to_string(),
            "requires at least 2 repeated observations of the still target, got 1"
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn noisy_filter_matches_batch_accuracy() {
        // sigma = 0.2 px on 18 points: the reprojection RMS of a good fit is
        // about sigma * sqrt((2n - 11) / (2n)) = 0.13 px; both estimates must
        // stay below 2 sigma and within 20 % of each other.
        let truth = normalize_scale(&scene::projection());
        let pts = scene::stage_points();
        let mut rng = Rng::new(7);
        let sigma = 0.2;
        let px: Vec<Point2<f64>> = pts
            .iter()
            .map(|x| project(&truth, x) + Vector2::new(rng.gaussian(sigma), rng.gaussian(sigma)))
            .collect();
        let batch = dlt::solve_dlt(&pts, &px).unwrap();
        let kf = kalman_dlt(
            &pts,
            &px,
            &KalmanOptions::new(Matrix2::identity() * sigma * sigma),
        )
        .unwrap();
        let kf_rms = kf.history.last().unwrap().rms_px;
        assert!(
            batch.rms_px < 2.0 * sigma && kf_rms < 2.0 * sigma,
            "{} {kf_rms}",
            batch.rms_px
        );
        assert!(
            (kf_rms - batch.rms_px).abs() < 0.2 * batch.rms_px,
            "{} {kf_rms}",
            batch.rms_px
        );
    }
}
