//! Rotation vectors, quaternions in named component orders, 3x3 and 4x4
//! matrices, SVD projection onto SO(3) and the angle between rotations.

use nalgebra::{Matrix3, Matrix4, Quaternion, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::{Pose, Rotation};
use crate::error::{Error, Result};

/// Default tolerance of [`pose_from_matrix4`]: the largest accepted entry of
/// `|RᵀR − I|` and of the bottom-row deviation from `[0 0 0 1]`. Loose enough
/// for matrices printed with 4 decimals, tight enough to reject scaled or
/// sheared matrices.
pub const MATRIX4_TOLERANCE: f64 = 1e-3;

/// Below this angle (radians) the rotation-vector maps use Taylor series
/// instead of `sin(θ)/θ`, which loses precision.
const SMALL_ANGLE: f64 = 1e-6;

/// The rotation `exp([r]×)` of a rotation vector `r` (unit axis times angle in
/// radians). Any length is accepted; angles above pi wrap around.
pub fn rotation_from_rotvec(rotvec: &Vector3<f64>) -> Rotation {
    let theta = rotvec.norm();
    // sin(θ/2)/θ, with its series below SMALL_ANGLE (error < θ⁴/3840).
    let scale = if theta < SMALL_ANGLE {
        0.5 - theta * theta / 48.0
    } else {
        (0.5 * theta).sin() / theta
    };
    let w = (0.5 * theta).cos();
    UnitQuaternion::new_unchecked(Quaternion::new(
        w,
        rotvec.x * scale,
        rotvec.y * scale,
        rotvec.z * scale,
    ))
}

/// The rotation vector (axis times angle, radians) of a rotation, with the
/// angle in `[0, pi]`. At exactly pi both `±axis*pi` are the same rotation;
/// the sign follows the quaternion's vector part.
///
/// Computed from the quaternion with `θ = 2 atan2(|v|, w)`, which stays
/// accurate near 0 and near pi (unlike `acos` of the matrix trace).
pub fn rotvec_from_rotation(rotation: &Rotation) -> Vector3<f64> {
    let q = rotation.quaternion();
    // q and -q are the same rotation; w >= 0 picks the angle in [0, pi].
    let (w, v) = if q.w < 0.0 {
        (-q.w, -q.imag())
    } else {
        (q.w, q.imag())
    };
    let n = v.norm();
    let theta = 2.0 * n.atan2(w);
    // θ / sin(θ/2) with sin(θ/2) = n for a unit quaternion; series near 0.
    let scale = if n < SMALL_ANGLE {
        2.0 / w * (1.0 + n * n / (6.0 * w * w))
    } else {
        theta / n
    };
    v * scale
}

/// A pose as the 6 parameters the solvers optimise: rotation vector
/// (radians) then translation (metres), `[rx, ry, rz, tx, ty, tz]`.
pub fn params_from_pose(pose: &Pose) -> [f64; 6] {
    let r = rotvec_from_rotation(&pose.rotation);
    let t = pose.translation.vector;
    [r.x, r.y, r.z, t.x, t.y, t.z]
}

/// The pose of 6 solver parameters (the inverse of [`params_from_pose`]);
/// only the first 6 values of `p` are read.
///
/// # Panics
/// When `p` has fewer than 6 values (a solver bug, never input data).
pub fn pose_from_params(p: &[f64]) -> Pose {
    let rotation = rotation_from_rotvec(&Vector3::new(p[0], p[1], p[2]));
    Pose::from_parts(Translation3::new(p[3], p[4], p[5]), rotation)
}

fn unit_quaternion(w: f64, x: f64, y: f64, z: f64, field: &str) -> Result<Rotation> {
    let q = Quaternion::new(w, x, y, z);
    let n = q.norm();
    if !n.is_finite() || n < 1e-12 {
        return Err(Error::invalid(
            field,
            format!("quaternion has norm {n}: not a rotation"),
        ));
    }
    Ok(UnitQuaternion::new_unchecked(q / n))
}

/// The rotation of a quaternion given as `[x, y, z, w]` (ROS, Eigen
/// `coeffs()`, scipy). The input is normalised; a zero or non-finite norm is
/// an error.
pub fn rotation_from_quaternion_xyzw(quaternion_xyzw: [f64; 4]) -> Result<Rotation> {
    let [x, y, z, w] = quaternion_xyzw;
    unit_quaternion(w, x, y, z, "quaternion_xyzw")
}

/// The rotation of a quaternion given as `[w, x, y, z]` (ABB, MATLAB,
/// Eigen's constructor). The input is normalised; a zero or non-finite norm
/// is an error.
pub fn rotation_from_quaternion_wxyz(quaternion_wxyz: [f64; 4]) -> Result<Rotation> {
    let [w, x, y, z] = quaternion_wxyz;
    unit_quaternion(w, x, y, z, "quaternion_wxyz")
}

fn canonical(rotation: &Rotation) -> Quaternion<f64> {
    let q = *rotation.quaternion();
    if q.w < 0.0 {
        -q
    } else {
        q
    }
}

/// `[x, y, z, w]` of a rotation, with `w >= 0` (of the two equal quaternions
/// `q` and `-q`).
pub fn quaternion_xyzw_from_rotation(rotation: &Rotation) -> [f64; 4] {
    let q = canonical(rotation);
    [q.i, q.j, q.k, q.w]
}

/// `[w, x, y, z]` of a rotation, with `w >= 0`.
pub fn quaternion_wxyz_from_rotation(rotation: &Rotation) -> [f64; 4] {
    let q = canonical(rotation);
    [q.w, q.i, q.j, q.k]
}

/// The angle in radians, in `[0, pi]`, of the rotation taking `a` to `b`
/// (the geodesic distance on SO(3)); accurate for tiny and near-pi angles.
pub fn rotation_angle_between(a: &Rotation, b: &Rotation) -> f64 {
    let d = a.inverse() * b;
    let q = d.quaternion();
    2.0 * q.imag().norm().atan2(q.w.abs())
}

/// The rotation closest to `m` in the Frobenius norm: `U diag(1, 1, det(U
/// Vᵀ)) Vᵀ` from the SVD `m = U S Vᵀ` (the det fix keeps the result a proper
/// rotation, never a reflection).
///
/// Errors when `m` has non-finite entries or when the answer is not unique
/// (rank below 2, or `σ₂ + sign(det m)·σ₃ = 0`).
pub fn nearest_rotation(m: &Matrix3<f64>) -> Result<Rotation3<f64>> {
    if m.iter().any(|v| !v.is_finite()) {
        return Err(Error::invalid("matrix", "has non-finite entries"));
    }
    let svd = m.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(Error::degenerate("SVD of the 3x3 matrix failed"));
    };
    // nalgebra sorts singular values in decreasing order.
    let s = svd.singular_values;
    let d = (u * v_t).determinant().signum();
    if s[0] <= 0.0 || s[1] + d * s[2] <= 1e-12 * s[0] {
        return Err(Error::degenerate(format!(
            "the nearest rotation is not unique (singular values {:.3e}, {:.3e}, {:.3e})",
            s[0], s[1], s[2]
        )));
    }
    let fix = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d));
    Ok(Rotation3::from_matrix_unchecked(u * fix * v_t))
}

/// A [`Pose`] from a 4x4 homogeneous matrix (row `r`, column `c` is `m[(r,
/// c)]`), validated with [`MATRIX4_TOLERANCE`]. See
/// [`pose_from_matrix4_with_tolerance`].
pub fn pose_from_matrix4(m: &Matrix4<f64>) -> Result<Pose> {
    pose_from_matrix4_with_tolerance(m, MATRIX4_TOLERANCE)
}

/// A [`Pose`] from a 4x4 homogeneous matrix. Errors (naming what was found)
/// when an entry is not finite, the bottom row is not `[0 0 0 1]` within
/// `tolerance`, the rotation block is not orthonormal within `tolerance`
/// (largest entry of `|RᵀR − I|`), or it is a reflection (det < 0). An
/// accepted rotation block is projected with [`nearest_rotation`], which
/// removes the rounding of printed matrices.
pub fn pose_from_matrix4_with_tolerance(m: &Matrix4<f64>, tolerance: f64) -> Result<Pose> {
    if m.iter().any(|v| !v.is_finite()) {
        return Err(Error::invalid("matrix4", "has non-finite entries"));
    }
    let bottom = [m[(3, 0)], m[(3, 1)], m[(3, 2)], m[(3, 3)]];
    let expected = [0.0, 0.0, 0.0, 1.0];
    if bottom
        .iter()
        .zip(expected)
        .any(|(b, e)| (b - e).abs() > tolerance)
    {
        return Err(Error::invalid(
            "matrix4",
            format!(
                "bottom row is [{} {} {} {}], expected [0 0 0 1]",
                bottom[0], bottom[1], bottom[2], bottom[3]
            ),
        ));
    }
    let r: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
    let deviation = (r.transpose() * r - Matrix3::identity()).amax();
    if deviation > tolerance {
        return Err(Error::invalid(
            "matrix4",
            format!(
                "rotation block is not orthonormal: largest |RᵀR - I| entry is {deviation:.3e}, tolerance {tolerance:.0e}"
            ),
        ));
    }
    if r.determinant() < 0.0 {
        return Err(Error::invalid(
            "matrix4",
            "rotation block has determinant -1: a reflection, not a rotation",
        ));
    }
    let rotation = UnitQuaternion::from_rotation_matrix(&nearest_rotation(&r)?);
    let t = Translation3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
    Ok(Pose::from_parts(t, rotation))
}

/// The 4x4 homogeneous matrix of a pose (bottom row `[0 0 0 1]`).
pub fn matrix4_from_pose(pose: &Pose) -> Matrix4<f64> {
    pose.to_homogeneous()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use std::f64::consts::PI;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// A random unit axis.
    pub(crate) fn random_axis(rng: &mut Rng) -> Vector3<f64> {
        loop {
            let v = Vector3::new(rng.normal(), rng.normal(), rng.normal());
            if v.norm() > 1e-3 {
                return v.normalize();
            }
        }
    }

    /// Angles concentrated on the hard cases: exactly 0, tiny, near pi, pi.
    fn hard_angle(rng: &mut Rng, i: usize) -> f64 {
        match i % 6 {
            0 => 0.0,
            1 => 10f64.powf(rng.range(-12.0, -3.0)),
            2 => PI - 10f64.powf(rng.range(-12.0, -3.0)),
            3 => PI,
            _ => rng.range(0.0, PI),
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn rotvec_round_trips_including_zero_and_pi() {
        let mut rng = Rng::new(1);
        for i in 0..5000 {
            let angle = hard_angle(&mut rng, i);
            let rotvec = random_axis(&mut rng) * angle;
            let r = rotation_from_rotvec(&rotvec);
            // Against nalgebra's independent axis-angle constructor.
            let reference = UnitQuaternion::from_scaled_axis(rotvec);
            assert!(rotation_angle_between(&r, &reference) < 1e-12, "case {i}");
            let back = rotvec_from_rotation(&r);
            // Same rotation always; same vector unless at pi (where ±axis agree).
            assert!(rotation_angle_between(&rotation_from_rotvec(&back), &r) < 1e-12);
            if angle < PI - 1e-6 {
                assert!((back - rotvec).norm() < 1e-12 * (1.0 + angle), "case {i}");
            } else {
                assert!((back.norm() - angle).abs() < 1e-9, "case {i} angle");
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn quaternion_orders_round_trip_and_name_components() {
        // 90 deg about z: w = x... = cos45, z = sin45.
        let r = rotation_from_rotvec(&Vector3::new(0.0, 0.0, PI / 2.0));
        let h = 0.5f64.sqrt();
        let xyzw = quaternion_xyzw_from_rotation(&r);
        let wxyz = quaternion_wxyz_from_rotation(&r);
        for (a, b) in xyzw.iter().zip([0.0, 0.0, h, h]) {
            assert!((a - b).abs() < 1e-15);
        }
        assert_eq!(wxyz, [xyzw[3], xyzw[0], xyzw[1], xyzw[2]]);
        let mut rng = Rng::new(2);
        for i in 0..3000 {
            let r = rotation_from_rotvec(&(random_axis(&mut rng) * hard_angle(&mut rng, i)));
            let a = rotation_from_quaternion_xyzw(quaternion_xyzw_from_rotation(&r)).unwrap();
            let b = rotation_from_quaternion_wxyz(quaternion_wxyz_from_rotation(&r)).unwrap();
            assert!(rotation_angle_between(&a, &r) < 1e-12);
            assert!(rotation_angle_between(&b, &r) < 1e-12);
            assert!(quaternion_xyzw_from_rotation(&r)[3] >= 0.0);
        }
        let err = rotation_from_quaternion_wxyz([0.0; 4]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "quaternion_wxyz: quaternion has norm 0: not a rotation"
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn angle_between_is_accurate_near_zero_and_pi() {
        let mut rng = Rng::new(3);
        for i in 0..3000 {
            let a = rotation_from_rotvec(&(random_axis(&mut rng) * rng.range(0.0, 3.0)));
            let angle = hard_angle(&mut rng, i);
            let b = a * rotation_from_rotvec(&(random_axis(&mut rng) * angle));
            let got = rotation_angle_between(&a, &b);
            assert!(
                (got - angle).abs() < 1e-12 + 1e-12 * angle,
                "case {i}: {got} vs {angle}"
            );
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn nearest_rotation_recovers_noisy_and_fixes_reflections() {
        let mut rng = Rng::new(4);
        for _ in 0..2000 {
            let r = rotation_from_rotvec(&(random_axis(&mut rng) * rng.range(0.0, PI)));
            let truth = r.to_rotation_matrix();
            // Noise 1e-4 per entry moves the nearest rotation by O(1e-4) rad.
            let noise = Matrix3::from_fn(|_, _| rng.gaussian(1e-4));
            let got = nearest_rotation(&(truth.matrix() + noise)).unwrap();
            let got_q = UnitQuaternion::from_rotation_matrix(&got);
            assert!(rotation_angle_between(&got_q, &r) < 1e-3);
            assert!((got.matrix().determinant() - 1.0).abs() < 1e-12);
            // Exact input comes back exactly; a scaled one too.
            let same = nearest_rotation(&(truth.matrix() * 3.0)).unwrap();
            assert!((same.matrix() - truth.matrix()).amax() < 1e-12);
        }
        // A reflection projects to the nearest proper rotation, diag(1,1,-1) -> ?
        let reflect = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, -3.0));
        let got = nearest_rotation(&reflect).unwrap();
        assert!((got.matrix().determinant() - 1.0).abs() < 1e-12);
        // Singular values 3, 2, 1 with det < 0: the smallest (x axis) flips.
        let expected = Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, -1.0));
        assert!((got.matrix() - expected).amax() < 1e-12);
        assert!(matches!(
            nearest_rotation(&Matrix3::zeros()),
            Err(Error::Degenerate { .. })
        ));
        let rank1 = Vector3::new(1.0, 2.0, 3.0) * Vector3::new(0.0, 1.0, 1.0).transpose();
        assert!(nearest_rotation(&rank1).is_err());
        assert!(nearest_rotation(&Matrix3::from_element(f64::NAN)).is_err());
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn matrix4_round_trips_and_validates() {
        let mut rng = Rng::new(5);
        for i in 0..2000 {
            let r = rotation_from_rotvec(&(random_axis(&mut rng) * hard_angle(&mut rng, i)));
            let t = Translation3::new(rng.range(-2.0, 2.0), rng.range(-2.0, 2.0), 0.5);
            let pose = Pose::from_parts(t, r);
            let back = pose_from_matrix4(&matrix4_from_pose(&pose)).unwrap();
            assert!((back.to_homogeneous() - pose.to_homogeneous()).amax() < 1e-14);
        }
        let mut m = Matrix4::identity();
        m[(3, 2)] = 1.0;
        assert_eq!(
            pose_from_matrix4(&m).unwrap_err().to_string(),
            "matrix4: bottom row is [0 0 1 1], expected [0 0 0 1]"
        );
        let mut m = Matrix4::identity();
        m[(0, 0)] = 1.2;
        assert_eq!(
            pose_from_matrix4(&m).unwrap_err().to_string(),
            "matrix4: rotation block is not orthonormal: largest |RᵀR - I| entry is 4.400e-1, tolerance 1e-3"
        );
        let mut m = Matrix4::identity();
        m[(2, 2)] = -1.0;
        assert_eq!(
            pose_from_matrix4(&m).unwrap_err().to_string(),
            "matrix4: rotation block has determinant -1: a reflection, not a rotation"
        );
        // 4-decimal printing is accepted and cleaned to an exact rotation.
        let r = rotation_from_rotvec(&Vector3::new(0.3, -1.1, 0.7));
        let mut m = matrix4_from_pose(&Pose::from_parts(Translation3::new(1.0, 2.0, 3.0), r));
        m.iter_mut().for_each(|v| *v = (*v * 1e4).round() / 1e4);
        let p = pose_from_matrix4(&m).unwrap();
        assert!(rotation_angle_between(&p.rotation, &r) < 1e-4);
        let rm = p.rotation.to_rotation_matrix();
        assert!((rm.matrix().transpose() * rm.matrix() - Matrix3::identity()).amax() < 1e-14);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn solver_parameters_round_trip_a_pose() {
        let p = [0.3, -1.2, 2.9, 0.5, -0.25, 1.75];
        let pose = pose_from_params(&p);
        // 0.3, -1.2, 2.9 has angle 3.15 > pi: the canonical vector is the
        // same rotation the other way round, so compare poses, then params
        // of an angle below pi exactly.
        let back = pose_from_params(&params_from_pose(&pose));
        assert!(rotation_angle_between(&back.rotation, &pose.rotation) < 1e-12);
        assert!((back.translation.vector - pose.translation.vector).norm() < 1e-15);
        let q = [0.1, 0.2, -0.3, 1.0, 2.0, 3.0];
        let got = params_from_pose(&pose_from_params(&q));
        for (g, w) in got.iter().zip(q) {
            assert!((g - w).abs() < 1e-14, "{got:?} vs {q:?}");
        }
        // Right-multiplying the identity step changes nothing.
        let step = pose_from_params(&[0.0; 6]);
        assert_eq!(pose * step, pose);
    }
}
