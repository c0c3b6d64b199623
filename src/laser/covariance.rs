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
//!   shifted and turned on that board alone: [`own_line`]): a board pose
//!   error moves the line in exactly that way, so without it the board
//!   poses' errors were counted twice, once here through the residuals and
//!   once below. After the removal an image's `J_k r_k` sum to 0, so the
//!   windowed sum sees less than the errors' variance, the more the longer
//!   the window is against the stripe; the middle is scaled back by the
//!   exact expectation of that shortfall for independent errors
//!   ([`kept_information`], [`unbiased_meat`]; until s28 a scalar `m / (m -
//!   removed dof)`, which left the std 25-40 % narrow: BENCHMARKS.md
//!   section 18).
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
    // What the Newey-West sum of residuals with their own lines removed
    // expects for independent errors of unit variance (see
    // [`kept_information`]).
    let mut kept = Matrix3::zeros();
    for &image in &images {
        let (j, r): (Vec<Vector3<f64>>, Vec<f64>) = obs
            .iter()
            .zip(rows)
            .filter(|(o, _)| o.image == image)
            .map(|(_, r)| (r.jacobian, r.residual))
            .unzip();
        let (beta, pinv) = own_line(&j, &r);
        kept += kept_information(&j, &pinv);
        let g: Vec<DVector<f64>> = j
            .iter()
            .zip(&r)
            .map(|(j, r)| DVector::from_column_slice((j * (r - j.dot(&beta))).as_slice()))
            .collect();
        meat += newey_west(&g, 3).fixed_view::<3, 3>(0, 0);
    }
    let meat = unbiased_meat(&a, &kept, &meat)?;
    let mut covariance = inv * meat * inv;
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

/// Bartlett's weight of a pair of centres `lag` apart along the stripe.
fn bartlett(lag: usize) -> f64 {
    if lag > LAGS {
        0.0
    } else {
        1.0 - lag as f64 / (LAGS + 1) as f64
    }
}

/// The Newey-West middle one image's residuals give, in expectation, for
/// independent errors of unit variance: `sum_kl w_kl J_k J_l^T (I - P)_kl`
/// (`P_kl = J_k^T pinv J_l`, the projection [`own_line`] takes out).
/// Without the removal it would be `sum_k J_k J_k^T`, the image's
/// information; with it, it is less, and much less when the window
/// ([`LAGS`]) is not small against the number of centres: the removed line
/// is exactly what the image's `J_k r_k` sum to (they sum to 0 after it),
/// so a window as long as the stripe would see nothing. For errors that
/// are correlated over fewer lines than the window the shortfall is the
/// same share of their long-run variance, to first order (the removed
/// line varies slowly along the stripe).
fn kept_information(j: &[Vector3<f64>], pinv: &Matrix3<f64>) -> Matrix3<f64> {
    let mut out = Matrix3::zeros();
    for (k, jk) in j.iter().enumerate() {
        out += jk * jk.transpose();
        let q = pinv * jk;
        let lo = k.saturating_sub(LAGS);
        let hi = (k + LAGS).min(j.len() - 1);
        for (l, jl) in j.iter().enumerate().take(hi + 1).skip(lo) {
            out -= jk * jl.transpose() * (bartlett(k.abs_diff(l)) * q.dot(jl));
        }
    }
    out
}

/// The Newey-West middle `meat` made unbiased for independent errors:
/// `T meat T^T` with `T kept T^T = information` (`T = I^1/2 K^-1/2`), so
/// its expectation is the information times the errors' variance, as the
/// sandwich needs (for one image's worth of lags, `m / (m - removed dof)`
/// on average, which this replaces). The window's shortfall is largest
/// along the stripe lines' turn, where the removed line weighs most: with
/// the scalar factor the 2-pose std was 25-35 % narrow (BENCHMARKS.md
/// section 18, s28).
fn unbiased_meat(
    information: &Matrix3<f64>,
    kept: &Matrix3<f64>,
    meat: &Matrix3<f64>,
) -> Result<Matrix3<f64>> {
    let root = |m: &Matrix3<f64>, power: f64| -> Option<Matrix3<f64>> {
        let eig = nalgebra::SymmetricEigen::new(*m);
        let top = eig.eigenvalues.max();
        if !(top > 0.0) {
            return None;
        }
        let d = eig.eigenvalues.map(|v| v.max(MIN_KEPT * top).powf(power));
        Some(eig.eigenvectors * Matrix3::from_diagonal(&d) * eig.eigenvectors.transpose())
    };
    let (Some(half), Some(inverse_half)) = (root(information, 0.5), root(kept, -0.5)) else {
        return Err(Error::degenerate(
            "the plane's information matrix is singular: the stripes do not constrain it",
        ));
    };
    let t = half * inverse_half;
    Ok(t * meat * t.transpose())
}

/// The smallest eigenvalue of the expected middle [`kept_information`]
/// taken, relative to its largest (a stripe of fewer centres than the
/// window leaves almost nothing along its turn).
const MIN_KEPT: f64 = 1e-6;

/// The least-squares fit of one image's residuals `r` by its own rows of
/// the Jacobian `j` (the plane moved for this image alone: its stripe line
/// shifted and turned on the board, two dof) and the pseudo-inverse of
/// `sum J_k J_k^T` it used. What it takes out of the residuals is what a
/// board pose error also does: the line's own offset and slope.
fn own_line(j: &[Vector3<f64>], r: &[f64]) -> (Vector3<f64>, Matrix3<f64>) {
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for (j, r) in j.iter().zip(r) {
        a += j * j.transpose();
        b += j * *r;
    }
    let eig = nalgebra::SymmetricEigen::new(a);
    let top = eig.eigenvalues.iter().fold(0.0f64, |m, v| m.max(*v));
    let mut pinv = Matrix3::zeros();
    for (k, &l) in eig.eigenvalues.iter().enumerate() {
        if top > 0.0 && l > OWN_LINE_TOLERANCE * top {
            let v = eig.eigenvectors.column(k);
            pinv += v * v.transpose() / l;
        }
    }
    (pinv * b, pinv)
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
