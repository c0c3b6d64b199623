//! Small linear-algebra helpers of the hand-eye solvers (on top of
//! [`crate::geometry`]): projection onto SO(3), the mean pose, skew matrices, the smallest
//! eigenvector of a symmetric matrix and a rank-aware least-squares solve.

use crate::error::{Error, Result};
use nalgebra::{
    DMatrix, DVector, Isometry3, Matrix3, Matrix4, Rotation3, Translation3, UnitQuaternion,
    Vector3, Vector4,
};

/// Relative singular-value threshold below which a direction counts as
/// unobservable in [`least_squares`].
pub const RANK_TOLERANCE: f64 = 1e-9;

/// The nearest rotation (Frobenius norm) to `m`, determinant +1 (the
/// shared [`crate::geometry::nearest_rotation`]).
pub fn project_to_so3(m: &Matrix3<f64>) -> Result<Rotation3<f64>> {
    crate::geometry::nearest_rotation(m)
}

/// Skew-symmetric matrix with `skew(a) * b = a x b`.
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Eigenvectors of the symmetric matrix `m` sorted by ascending eigenvalue.
pub fn ascending_eigenvectors(m: &DMatrix<f64>) -> Result<Vec<(f64, DVector<f64>)>> {
    if !m.iter().all(|v| v.is_finite()) {
        return Err(Error::degenerate("normal matrix is not finite"));
    }
    let eig = m.clone().symmetric_eigen();
    let mut pairs: Vec<(f64, DVector<f64>)> = eig
        .eigenvalues
        .iter()
        .enumerate()
        .map(|(i, &l)| (l, eig.eigenvectors.column(i).into_owned()))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(pairs)
}

/// Minimum-norm least-squares solution of the normal equations
/// `normal * x = rhs`: directions whose eigenvalue is below
/// [`RANK_TOLERANCE`] times the largest are left at zero. Returns the
/// solution and the eigenvectors of the dropped (unobservable) directions.
pub fn least_squares(
    normal: &DMatrix<f64>,
    rhs: &DVector<f64>,
) -> Result<(DVector<f64>, Vec<DVector<f64>>)> {
    let pairs = ascending_eigenvectors(normal)?;
    let largest = pairs.last().map(|p| p.0).unwrap_or(0.0);
    if largest <= 0.0 {
        return Err(Error::degenerate(
            "the linear system is empty (no constraint)",
        ));
    }
    let mut x = DVector::zeros(rhs.len());
    let mut dropped = Vec::new();
    for (l, v) in pairs {
        if l <= RANK_TOLERANCE * largest {
            dropped.push(v);
        } else {
            x += &v * (v.dot(rhs) / l);
        }
    }
    Ok((x, dropped))
}

/// Mean pose: chordal mean rotation, arithmetic mean translation.
pub fn mean_pose(poses: &[Isometry3<f64>]) -> Result<Isometry3<f64>> {
    if poses.is_empty() {
        return Err(Error::too_few("poses to average", 1, 0));
    }
    let rotations: Vec<UnitQuaternion<f64>> = poses.iter().map(|p| p.rotation).collect();
    let r = crate::geometry::average_rotations_chordal(&rotations, None)?;
    let t = poses
        .iter()
        .fold(Vector3::zeros(), |acc, p| acc + p.translation.vector)
        / poses.len() as f64;
    Ok(Isometry3::from_parts(Translation3::from(t), r))
}

/// Quaternion as a 4-vector `[w, x, y, z]`.
pub fn quat_wxyz(q: &UnitQuaternion<f64>) -> Vector4<f64> {
    Vector4::new(q.w, q.i, q.j, q.k)
}

/// Matrix of left multiplication: `left(p) * q = p (x) q` in `[w, x, y, z]`.
pub fn quat_left(p: &Vector4<f64>) -> Matrix4<f64> {
    let (w, x, y, z) = (p[0], p[1], p[2], p[3]);
    Matrix4::new(
        w, -x, -y, -z, //
        x, w, -z, y, //
        y, z, w, -x, //
        z, -y, x, w,
    )
}

/// Matrix of right multiplication: `right(p) * q = q (x) p` in `[w, x, y, z]`.
pub fn quat_right(p: &Vector4<f64>) -> Matrix4<f64> {
    let (w, x, y, z) = (p[0], p[1], p[2], p[3]);
    Matrix4::new(
        w, -x, -y, -z, //
        x, w, z, -y, //
        y, -z, w, x, //
        z, y, -x, w,
    )
}

/// Unit quaternion from a `[w, x, y, z]` 4-vector (normalised).
pub fn quat_from_wxyz(v: &Vector4<f64>) -> Result<UnitQuaternion<f64>> {
    let n = v.norm();
    if !n.is_finite() || n < 1e-12 {
        return Err(Error::degenerate("quaternion estimate has zero norm"));
    }
    Ok(UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
        v[0], v[1], v[2], v[3],
    )))
}

/// Rotation angle of a pose in radians, in [0, pi].
pub fn angle(pose: &Isometry3<f64>) -> f64 {
    pose.rotation.angle()
}

/// A pose from a rotation and a translation.
pub fn pose_from(r: &Rotation3<f64>, t: &Vector3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(*t),
        UnitQuaternion::from_rotation_matrix(r),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn quaternion_product_matrices_match_nalgebra() {
        let p = UnitQuaternion::from_scaled_axis(Vector3::new(0.3, -0.2, 0.9));
        let q = UnitQuaternion::from_scaled_axis(Vector3::new(-1.1, 0.4, 0.2));
        let pq = quat_wxyz(&(p * q));
        assert!((quat_left(&quat_wxyz(&p)) * quat_wxyz(&q) - pq).norm() < 1e-14);
        assert!((quat_right(&quat_wxyz(&q)) * quat_wxyz(&p) - pq).norm() < 1e-14);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn projection_recovers_a_scaled_rotation() {
        let r = Rotation3::from_scaled_axis(Vector3::new(0.5, 1.0, -2.0));
        let back = project_to_so3(&(r.matrix() * 3.0)).unwrap();
        assert!((back.matrix() - r.matrix()).norm() < 1e-12);
    }
}
