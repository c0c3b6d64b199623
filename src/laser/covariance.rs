//! The laser plane's covariance over its `(a, b, d)` (the normal's
//! rotation vector `a e1 + b e2` about [`crate::geometry::tangent_basis`]'s
//! axes and the distance), from two sources:
//!
//! - **the stripe centres' errors**, from the residuals themselves: a
//!   sandwich `A^-1 B A^-1` (`A = J^T J`) whose middle `B` sums the
//!   residual-weighted Jacobians `g_k = J_k r_k` of every centre with those
//!   of its neighbours along the stripe up to [`LAGS`] lines away, with
//!   Bartlett weights `1 - lag / (LAGS + 1)` (Newey-West). A centre's error
//!   is not independent of its neighbours': the speckle, the blur and the
//!   board's squares under the stripe bias runs of neighbouring centres
//!   alike. `s^2 (J^T J)^-1` (the residual variance times the inverse)
//!   assumes independence, and on rendered pairs it was 2.6 times too small
//!   in std; the sandwich also needs no assumption on the centres' stds
//!   being right (their scale cancels). The residuals first lose, image by
//!   image, their fit by the image's own rows of `J` (the stripe line
//!   shifted and turned on that board alone: [`own_line`]) and the variance
//!   is scaled by `m / (m - removed dof)`: a board pose error moves the
//!   line in exactly that way, so without it the board poses' errors were
//!   counted twice, once here through the residuals and once below (the
//!   std 8 % narrower at 4 and 10 poses with it; BENCHMARKS.md section 18,
//!   where the 10-pose std is still 1.5 times the true error).
//! - **the board poses' errors** (when given): a board pose error moves all
//!   of its image's points together; `dX = (X / e) (w . (m x (t - X)) + m .
//!   v)` for the board plane `m . X = e` under the pose perturbation
//!   `exp(w) R, t + v` (camera frame), through the fit's sensitivity
//!   `d theta / d beta = -A^-1 J^T dr/d beta`.

use super::fit::ResidualRow;
use super::plane::StripeObservation;
use crate::error::{Error, Result};
use crate::geometry::Pose;
use nalgebra::{DMatrix, DVector, Matrix3, Matrix3x6, Matrix6, RowVector6, Vector3};

/// Neighbouring centres (scan lines along the stripe) whose errors are
/// taken as correlated.
pub const LAGS: usize = 20;

/// A board pose with its covariance: one image of the fit.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardPose {
    /// The image (the observations' `image`).
    pub image: usize,
    /// The board's pose.
    pub camera_from_target: Pose,
    /// Covariance of the pose perturbation `[w, v]` with `exp(w) R` and `t +
    /// v` in the camera frame (radians, metres), as
    /// [`crate::calib::pnp::camera_from_target_with_covariance`] returns it
    /// times the corners' variance.
    pub covariance: Matrix6<f64>,
}

/// The plane's covariance over `(a, b, d)` from the residual rows at the
/// solution (one per observation, in order) and the boards' poses.
pub(crate) fn plane_covariance(
    obs: &[StripeObservation],
    rows: &[ResidualRow],
    boards: &[BoardPose],
) -> Result<Matrix3<f64>> {
    let mut a = Matrix3::zeros();
    for r in rows {
        a += r.jacobian * r.jacobian.transpose();
    }
    let inv = a.try_inverse().ok_or_else(|| {
        Error::degenerate(
            "the plane's information matrix is singular: the stripes do not constrain it",
        )
    })?;
    let mut images: Vec<usize> = obs.iter().map(|o| o.image).collect();
    images.sort_unstable();
    images.dedup();
    let mut meat = Matrix3::zeros();
    let mut removed = 0usize;
    for &image in &images {
        let (j, r): (Vec<Vector3<f64>>, Vec<f64>) = obs
            .iter()
            .zip(rows)
            .filter(|(o, _)| o.image == image)
            .map(|(_, r)| (r.jacobian, r.residual))
            .unzip();
        let (beta, rank) = own_line(&j, &r);
        removed += rank;
        let g: Vec<DVector<f64>> = j
            .iter()
            .zip(&r)
            .map(|(j, r)| DVector::from_column_slice((j * (r - j.dot(&beta))).as_slice()))
            .collect();
        meat += newey_west(&g, 3).fixed_view::<3, 3>(0, 0);
    }
    let m = rows.len();
    let dof = if m > removed {
        m as f64 / (m - removed) as f64
    } else {
        1.0
    };
    let mut covariance = inv * meat * inv * dof;
    for board in boards {
        let sensitivity = inv * board_jacobian(obs, rows, board);
        covariance += sensitivity * board.covariance * sensitivity.transpose();
    }
    Ok(0.5 * (covariance + covariance.transpose()))
}

/// The Newey-West sum over one stripe's per-centre score vectors `g_k =
/// J_k^T r_k` (in order along the stripe, `p` numbers each): `sum_k g_k
/// g_k^T` plus every pair up to [`LAGS`] apart, both ways, with Bartlett
/// weights `1 - lag / (LAGS + 1)`.
pub(crate) fn newey_west(g: &[DVector<f64>], p: usize) -> DMatrix<f64> {
    let mut meat = DMatrix::zeros(p, p);
    for lag in 0..=LAGS.min(g.len().saturating_sub(1)) {
        let weight = 1.0 - lag as f64 / (LAGS + 1) as f64;
        let mut s = DMatrix::zeros(p, p);
        for k in lag..g.len() {
            s += &g[k] * g[k - lag].transpose();
        }
        meat += if lag == 0 {
            s
        } else {
            (&s + s.transpose()) * weight
        };
    }
    meat
}

/// The least-squares fit of one image's residuals `r` by its own rows of
/// the Jacobian `j` (the plane moved for this image alone: its stripe line
/// shifted and turned on the board, two dof) and the rank of that fit.
/// What it takes out of the residuals is what a board pose error also
/// does: the line's own offset and slope.
fn own_line(j: &[Vector3<f64>], r: &[f64]) -> (Vector3<f64>, usize) {
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for (j, r) in j.iter().zip(r) {
        a += j * j.transpose();
        b += j * *r;
    }
    let eig = nalgebra::SymmetricEigen::new(a);
    let top = eig.eigenvalues.iter().fold(0.0f64, |m, v| m.max(*v));
    let mut beta = Vector3::zeros();
    let mut rank = 0;
    for (k, &l) in eig.eigenvalues.iter().enumerate() {
        if top > 0.0 && l > OWN_LINE_TOLERANCE * top {
            let v = eig.eigenvectors.column(k);
            beta += v * (v.dot(&b) / l);
            rank += 1;
        }
    }
    (beta, rank)
}

/// Directions of an image's own Jacobian weaker than this (relative to its
/// strongest) are not fitted by [`own_line`].
const OWN_LINE_TOLERANCE: f64 = 1e-9;

/// `J^T dr / d beta` of one board's pose perturbation `beta = [w, v]`.
fn board_jacobian(
    obs: &[StripeObservation],
    rows: &[ResidualRow],
    board: &BoardPose,
) -> Matrix3x6<f64> {
    let pose = &board.camera_from_target;
    let m = pose.rotation * Vector3::z();
    let t = pose.translation.vector;
    let e = m.dot(&t);
    let mut out = Matrix3x6::zeros();
    if e.abs() < 1e-12 {
        return out;
    }
    for (o, r) in obs.iter().zip(rows).filter(|(o, _)| o.image == board.image) {
        let x = o.point_camera.coords;
        let s = r.d_point.dot(&x) / e;
        let dw = m.cross(&(t - x)) * s;
        let dv = m * s;
        let dr = RowVector6::new(dw.x, dw.y, dw.z, dv.x, dv.y, dv.z);
        out += r.jacobian * dr;
    }
    out
}
