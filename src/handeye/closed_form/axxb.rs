//! AX = XB closed forms that solve the rotation first, then the translation
//! by least squares: Tsai-Lenz, Park-Martin, Horaud, Chou-Kamel, Andreff.
//! Daniilidis (rotation and translation together) is in [`crate::handeye::closed_form::daniilidis`].

use crate::error::{Error, Result};
use crate::handeye::math::{
    ascending_eigenvectors, least_squares, pose_from, project_to_so3, quat_from_wxyz, quat_left,
    quat_right, quat_wxyz, skew,
};
use crate::handeye::{HandEyeMethod, Motion, Pose};
use nalgebra::{
    DMatrix, DVector, Matrix3, Rotation3, SMatrix, SVector, UnitQuaternion, Vector3, Vector4,
};

/// Solve AX = XB with a rotation-then-translation method (every method of
/// this module; Daniilidis is dispatched to its own module).
pub fn solve(method: HandEyeMethod, motions: &[Motion]) -> Result<(Pose, Vec<Vector3<f64>>)> {
    if motions.len() < 2 {
        return Err(Error::too_few(
            "motions with enough rotation",
            2,
            motions.len(),
        ));
    }
    let r = match method {
        HandEyeMethod::TsaiLenz => tsai_lenz(motions)?,
        HandEyeMethod::ParkMartin => park_martin(motions)?,
        HandEyeMethod::Horaud => horaud(motions)?,
        HandEyeMethod::ChouKamel => chou_kamel(motions)?,
        HandEyeMethod::Andreff => andreff(motions)?,
        HandEyeMethod::Daniilidis => {
            return crate::handeye::closed_form::daniilidis::solve(motions)
        }
        HandEyeMethod::Shah | HandEyeMethod::Li => {
            return Err(Error::invalid(
                "method",
                format!("{} solves AX = ZB, not AX = XB", method.name()),
            ))
        }
    };
    let (t, unobservable) = translation(motions, &r)?;
    Ok((pose_from(&r, &t), unobservable))
}

/// Least-squares translation from `(R_A - I) t = R_X t_B - t_A`. Returns the
/// minimum-norm solution and the unobservable directions (the common rotation
/// axis when every motion rotates about parallel axes).
pub fn translation(
    motions: &[Motion],
    r: &Rotation3<f64>,
) -> Result<(Vector3<f64>, Vec<Vector3<f64>>)> {
    let mut normal = DMatrix::zeros(3, 3);
    let mut rhs = DVector::zeros(3);
    for m in motions {
        let c = m.robot.rotation.to_rotation_matrix().into_inner() - Matrix3::identity();
        let d = r * m.camera.translation.vector - m.robot.translation.vector;
        let ct = c.transpose();
        normal += DMatrix::from_column_slice(3, 3, (ct * c).as_slice());
        rhs += DVector::from_column_slice((ct * d).as_slice());
    }
    let (t, dropped) = least_squares(&normal, &rhs)?;
    let dirs = dropped
        .iter()
        .map(|v| Vector3::new(v[0], v[1], v[2]))
        .collect();
    Ok((Vector3::new(t[0], t[1], t[2]), dirs))
}

/// Tsai-Lenz with modified Rodrigues vectors `P = 2 sin(theta/2) k`:
/// `skew(P_A + P_B) P' = P_B - P_A`, `P_X = 2 P' / sqrt(1 + |P'|^2)`.
///
/// `P'` is `tan(theta_X/2) k` and blows up for X near 180 degrees (OpenCV's
/// NaN failure mode). The equation is frame-invariant, so we also solve it for
/// `X' = X R0^T` with `B' = R0 B R0^T` for fixed 90-degree `R0` about x, y, z
/// and keep the best-conditioned (smallest `|P'|`); one of the four always has
/// `theta_X' <= 132` degrees.
fn tsai_lenz(motions: &[Motion]) -> Result<Rotation3<f64>> {
    let turns = [
        Rotation3::identity(),
        Rotation3::from_scaled_axis(Vector3::x() * std::f64::consts::FRAC_PI_2),
        Rotation3::from_scaled_axis(Vector3::y() * std::f64::consts::FRAC_PI_2),
        Rotation3::from_scaled_axis(Vector3::z() * std::f64::consts::FRAC_PI_2),
    ];
    let mut best: Option<(f64, Rotation3<f64>)> = None;
    for r0 in turns {
        let Ok(p) = tsai_p_prime(motions, &r0) else {
            continue;
        };
        let size = p.norm();
        if best.as_ref().map_or(true, |b| size < b.0) {
            let px = p * (2.0 / (1.0 + p.norm_squared()).sqrt());
            let n2 = px.norm_squared();
            let m = Matrix3::identity() * (1.0 - n2 / 2.0)
                + (px * px.transpose() + skew(&px) * (4.0 - n2).max(0.0).sqrt()) * 0.5;
            best = Some((size, project_to_so3(&m)? * r0));
        }
    }
    best.map(|b| b.1)
        .ok_or_else(|| Error::degenerate("Tsai-Lenz: the rotation system is singular"))
}

fn tsai_p_prime(motions: &[Motion], r0: &Rotation3<f64>) -> Result<Vector3<f64>> {
    let mut normal = DMatrix::zeros(3, 3);
    let mut rhs = DVector::zeros(3);
    for m in motions {
        let pa = rodrigues2(&m.robot.rotation);
        let qb = UnitQuaternion::from_rotation_matrix(r0) * m.camera.rotation * r0.inverse();
        let pb = rodrigues2(&UnitQuaternion::from_rotation_matrix(
            &qb.to_rotation_matrix(),
        ));
        let s = skew(&(pa + pb));
        let d = pb - pa;
        normal += DMatrix::from_column_slice(3, 3, (s.transpose() * s).as_slice());
        rhs += DVector::from_column_slice((s.transpose() * d).as_slice());
    }
    let (p, dropped) = least_squares(&normal, &rhs)?;
    if !dropped.is_empty() {
        return Err(Error::degenerate("Tsai-Lenz: rotation axes are parallel"));
    }
    Ok(Vector3::new(p[0], p[1], p[2]))
}

fn rodrigues2(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    let theta = q.angle();
    q.axis()
        .map(|k| k.into_inner() * (2.0 * (theta / 2.0).sin()))
        .unwrap_or_else(Vector3::zeros)
}

/// Park-Martin: with `alpha = log R_A`, `beta = log R_B`, `alpha = R_X beta`;
/// `R_X` maximises `sum alpha^T R beta` (orthogonal Procrustes by SVD, which
/// equals Park-Martin's `(M^T M)^-1/2 M^T` when M has full rank and stays
/// defined with only two motions).
fn park_martin(motions: &[Motion]) -> Result<Rotation3<f64>> {
    let mut m = Matrix3::zeros();
    for mo in motions {
        let alpha = mo.robot.rotation.scaled_axis();
        let beta = mo.camera.rotation.scaled_axis();
        m += alpha * beta.transpose();
    }
    project_to_so3(&m)
}

/// Quaternions of A and B with non-negative scalar parts (equal rotation
/// angles make the two scalar parts equal).
fn motion_quaternions(m: &Motion) -> (Vector4<f64>, Vector4<f64>) {
    let pos = |q: &UnitQuaternion<f64>| {
        let v = quat_wxyz(q);
        if v[0] < 0.0 {
            -v
        } else {
            v
        }
    };
    (pos(&m.robot.rotation), pos(&m.camera.rotation))
}

/// Horaud-Dornaika: `q_A q = q q_B`, i.e. `(L(q_A) - R(q_B)) q = 0`; `q` is
/// the eigenvector of the smallest eigenvalue of `sum (L - R)^T (L - R)`.
fn horaud(motions: &[Motion]) -> Result<Rotation3<f64>> {
    let mut normal = DMatrix::zeros(4, 4);
    for m in motions {
        let (qa, qb) = motion_quaternions(m);
        let c = quat_left(&qa) - quat_right(&qb);
        normal += DMatrix::from_column_slice(4, 4, (c.transpose() * c).as_slice());
    }
    smallest_quaternion(&normal)
}

fn smallest_quaternion(normal: &DMatrix<f64>) -> Result<Rotation3<f64>> {
    let pairs = ascending_eigenvectors(normal)?;
    let v = &pairs[0].1;
    Ok(quat_from_wxyz(&Vector4::new(v[0], v[1], v[2], v[3]))?.to_rotation_matrix())
}

/// Chou-Kamel: with equal angles, `q_A q = q q_B` reduces to the rotation
/// axes, `k_A q = q k_B` for pure quaternions; all 4x4 blocks are stacked and
/// `q` is the right singular vector of the smallest singular value. Unlike
/// Horaud every motion weighs the same whatever its angle.
fn chou_kamel(motions: &[Motion]) -> Result<Rotation3<f64>> {
    let mut stacked = DMatrix::zeros(4 * motions.len(), 4);
    for (i, m) in motions.iter().enumerate() {
        let (Some(ka), Some(kb)) = (m.robot.rotation.axis(), m.camera.rotation.axis()) else {
            continue;
        };
        let pa = Vector4::new(0.0, ka.x, ka.y, ka.z);
        let pb = Vector4::new(0.0, kb.x, kb.y, kb.z);
        let c = quat_left(&pa) - quat_right(&pb);
        stacked
            .view_mut((4 * i, 0), (4, 4))
            .copy_from_slice(c.as_slice());
    }
    let svd = stacked.svd(false, true);
    let v_t = svd
        .v_t
        .ok_or_else(|| Error::degenerate("Chou-Kamel: SVD failed"))?;
    let imin = svd.singular_values.imin();
    let v = v_t.row(imin);
    Ok(quat_from_wxyz(&Vector4::new(v[0], v[1], v[2], v[3]))?.to_rotation_matrix())
}

/// Andreff, Horaud and Espiau 2001: one linear least squares over the 12
/// unknowns `[vec(R_X), t_X]` (row-major vec), stacking per motion the
/// rotation rows `(I9 - R_A (x) R_B) vec(R_X) = 0` and the translation rows
/// `(I3 (x) t_B^T) vec(R_X) + (I3 - R_A) t_X = t_A` (from `R_A t_X + t_A =
/// R_X t_B + t_X`). The translation rows fix the scale of `vec(R_X)` and add
/// their information to the rotation, which is what makes the method more
/// than a null-space solve. The estimate is rescaled to unit determinant,
/// projected onto SO(3), and `t_X` is re-solved with the projected rotation
/// (see [`translation`]).
fn andreff(motions: &[Motion]) -> Result<Rotation3<f64>> {
    // Fixed-size per motion (half a million motions at 1,000 poses): no
    // allocation, and the products unrolled by the compiler.
    let mut normal = SMatrix::<f64, 12, 12>::zeros();
    let mut rhs = SVector::<f64, 12>::zeros();
    for m in motions {
        let ra = m.robot.rotation.to_rotation_matrix().into_inner();
        let rb = m.camera.rotation.to_rotation_matrix().into_inner();
        let tb = m.camera.translation.vector;
        let ta = m.robot.translation.vector;
        let mut k = SMatrix::<f64, 12, 12>::zeros();
        for r in 0..9 {
            for c in 0..9 {
                let g = ra[(r / 3, c / 3)] * rb[(r % 3, c % 3)];
                k[(r, c)] = if r == c { 1.0 } else { 0.0 } - g;
            }
        }
        for r in 0..3 {
            for c in 0..3 {
                k[(9 + r, 3 * r + c)] = tb[c];
                k[(9 + r, 9 + c)] = if r == c { 1.0 } else { 0.0 } - ra[(r, c)];
            }
        }
        // K^T b with b = [0 (9), t_A]: only the translation rows count.
        for c in 0..12 {
            rhs[c] += k[(9, c)] * ta[0] + k[(10, c)] * ta[1] + k[(11, c)] * ta[2];
        }
        normal += k.tr_mul(&k);
    }
    let normal = DMatrix::from_column_slice(12, 12, normal.as_slice());
    let rhs = DVector::from_column_slice(rhs.as_slice());
    let (w, dropped) = least_squares(&normal, &rhs)?;
    if !dropped.is_empty() {
        return Err(Error::degenerate(
            "Andreff: the linear system is rank deficient (too little motion diversity)",
        ));
    }
    let m = Matrix3::from_row_slice(&w.as_slice()[0..9]);
    let det = m.determinant();
    if !det.is_finite() || det.abs() < 1e-12 {
        return Err(Error::degenerate(
            "Andreff: the rotation estimate is singular",
        ));
    }
    project_to_so3(&(m * (det.signum() / det.abs().cbrt())))
}

/// Kronecker product of two 3x3 matrices (9x9).
pub fn kron(a: &Matrix3<f64>, b: &Matrix3<f64>) -> DMatrix<f64> {
    DMatrix::from_fn(9, 9, |r, c| a[(r / 3, c / 3)] * b[(r % 3, c % 3)])
}
