//! The EKF's measurement model and small matrix helpers: the predicted
//! pixel of a target point with its Jacobian over the intrinsics and the
//! view's pose, and the camera of a state vector.

use super::{N_INTRINSICS, N_POSE};
use crate::camera::{Camera, Distortion};
use crate::error::Result;
use nalgebra::{DMatrix, DVector, Matrix2, Matrix3, Matrix3x4, Vector2, Vector3};

/// H P H^T from P H^T (n x 2) restricted to the rows `cols`.
pub(super) fn select(h: &DMatrix<f64>, pht: &DMatrix<f64>, cols: &[usize]) -> Matrix2<f64> {
    let rows = pht.select_rows(cols);
    let s = h * rows;
    Matrix2::new(s[(0, 0)], s[(0, 1)], s[(1, 0)], s[(1, 1)])
}

pub(super) fn symmetrize(p: &mut DMatrix<f64>) {
    crate::optim::dense::symmetrize(p);
}

pub(super) fn camera_of(state: &DVector<f64>, size: (u32, u32)) -> Result<Camera> {
    Camera {
        fx: 1.0,
        fy: 1.0,
        cx: 0.0,
        cy: 0.0,
        skew: 0.0,
        width: size.0,
        height: size.1,
        distortion: Distortion::RadialK1K2K5 {
            k1: 0.0,
            k2: 0.0,
            k5: 0.0,
        },
    }
    .with_params(&[
        state[0], state[1], state[2], state[3], 0.0, state[4], state[5], state[6],
    ])
}

/// The predicted pixel of a target point in view `v` and its 2 x 14
/// Jacobian (intrinsics, then the view's pose).
pub(super) fn measure(
    x: &DVector<f64>,
    v: usize,
    object: &Vector3<f64>,
    size: (u32, u32),
) -> Result<(Vector2<f64>, DMatrix<f64>)> {
    let camera = camera_of(x, size)?;
    let o = N_INTRINSICS + N_POSE * v;
    let (w, q) = (x[o], Vector3::new(x[o + 1], x[o + 2], x[o + 3]));
    let t = Vector3::new(x[o + 4], x[o + 5], x[o + 6]);
    // R(q) X = (w^2 - q.q) X + 2 (q.X) q + 2 w q x X.
    let p = (w * w - q.dot(&q)) * object + 2.0 * q.dot(object) * q + 2.0 * w * q.cross(object);
    let (pixel, d_point, d_params) = camera.project_with_jacobians(&(p + t).into())?;
    let d_w = 2.0 * (w * object + q.cross(object));
    let d_q = -2.0 * object * q.transpose()
        + 2.0 * q * object.transpose()
        + 2.0 * q.dot(object) * Matrix3::identity()
        - 2.0 * w * object.cross_matrix();
    let mut d_pose = Matrix3x4::zeros();
    d_pose.set_column(0, &d_w);
    d_pose.fixed_view_mut::<3, 3>(0, 1).copy_from(&d_q);
    let d_rot = d_point * d_pose;
    let mut h = DMatrix::zeros(2, N_INTRINSICS + N_POSE);
    for r in 0..2 {
        for c in 0..4 {
            h[(r, c)] = d_params[(r, c)];
        }
        // Skip the skew column (index 4) of the camera's parameters.
        for c in 0..3 {
            h[(r, 4 + c)] = d_params[(r, 5 + c)];
        }
        for c in 0..4 {
            h[(r, N_INTRINSICS + c)] = d_rot[(r, c)];
        }
        for c in 0..3 {
            h[(r, N_INTRINSICS + 4 + c)] = d_point[(r, c)];
        }
    }
    Ok((pixel.coords, h))
}
