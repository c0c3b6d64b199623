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
    DMatrix, DVector, Matrix3, Matrix4, Rotation3, SMatrix, SVector, UnitQuaternion, Vector3,
    Vector4,
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
    // Summed in fixed-size matrices (element by element, as the dynamic
    // ones summed them): no allocation per motion.
    let mut normal = Matrix3::zeros();
    let mut rhs = Vector3::zeros();
    for m in motions {
        let c = m.robot.rotation.to_rotation_matrix().into_inner() - Matrix3::identity();
        let d = r * m.camera.translation.vector - m.robot.translation.vector;
        let ct = c.transpose();
        normal += ct * c;
        rhs += ct * d;
    }
    let (normal, rhs) = dynamic3(&normal, &rhs);
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
    // Each side's vectors once for the four turns: the robot's side does
    // not turn, and the camera's turned motion `R0 B R0^T` rotates about
    // `R0` times B's axis by B's angle, so its vector is `R0 p_B` (before:
    // B turned and converted for each turn, equal to rounding).
    let robot_p: Vec<Vector3<f64>> = motions
        .iter()
        .map(|m| rodrigues2(&m.robot.rotation))
        .collect();
    let camera_p: Vec<Vector3<f64>> = motions
        .iter()
        .map(|m| rodrigues2(&m.camera.rotation))
        .collect();
    let mut best: Option<(f64, Rotation3<f64>)> = None;
    for r0 in turns {
        let Ok(p) = tsai_p_prime(&robot_p, &camera_p, &r0) else {
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

fn tsai_p_prime(
    robot_p: &[Vector3<f64>],
    camera_p: &[Vector3<f64>],
    r0: &Rotation3<f64>,
) -> Result<Vector3<f64>> {
    let mut normal = Matrix3::zeros();
    let mut rhs = Vector3::zeros();
    for (pa, pb) in robot_p.iter().zip(camera_p) {
        let pb = r0 * pb;
        let s = skew(&(pa + pb));
        let d = pb - pa;
        normal += s.transpose() * s;
        rhs += s.transpose() * d;
    }
    let (normal, rhs) = dynamic3(&normal, &rhs);
    let (p, dropped) = least_squares(&normal, &rhs)?;
    if !dropped.is_empty() {
        return Err(Error::degenerate("Tsai-Lenz: rotation axes are parallel"));
    }
    Ok(Vector3::new(p[0], p[1], p[2]))
}

/// A 3 x 3 system summed in fixed-size matrices, as the dynamic matrices
/// [`least_squares`] takes.
fn dynamic3(normal: &Matrix3<f64>, rhs: &Vector3<f64>) -> (DMatrix<f64>, DVector<f64>) {
    (
        DMatrix::from_column_slice(3, 3, normal.as_slice()),
        DVector::from_column_slice(rhs.as_slice()),
    )
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
    let mut normal = Matrix4::zeros();
    for m in motions {
        let (qa, qb) = motion_quaternions(m);
        let c = quat_left(&qa) - quat_right(&qb);
        normal += c.transpose() * c;
    }
    smallest_quaternion(&DMatrix::from_column_slice(4, 4, normal.as_slice()))
}

fn smallest_quaternion(normal: &DMatrix<f64>) -> Result<Rotation3<f64>> {
    let pairs = ascending_eigenvectors(normal)?;
    let v = &pairs[0].1;
    Ok(quat_from_wxyz(&Vector4::new(v[0], v[1], v[2], v[3]))?.to_rotation_matrix())
}

/// Chou-Kamel: with equal angles, `q_A q = q q_B` reduces to the rotation
/// axes, `k_A q = q k_B` for pure quaternions; all 4x4 blocks `C` are
/// stacked and `q` is the right singular vector of the smallest singular
/// value, taken as the eigenvector of the smallest eigenvalue of
/// `sum C^T C` (the same vector; the stack itself was 16 bytes x 16 per
/// motion, 130 MB for the half a million motions of 1,000 poses). Unlike
/// Horaud every motion weighs the same whatever its angle.
fn chou_kamel(motions: &[Motion]) -> Result<Rotation3<f64>> {
    let mut normal = Matrix4::zeros();
    for m in motions {
        let (Some(ka), Some(kb)) = (m.robot.rotation.axis(), m.camera.rotation.axis()) else {
            continue;
        };
        let pa = Vector4::new(0.0, ka.x, ka.y, ka.z);
        let pb = Vector4::new(0.0, kb.x, kb.y, kb.z);
        let c = quat_left(&pa) - quat_right(&pb);
        normal += c.transpose() * c;
    }
    smallest_quaternion(&DMatrix::from_column_slice(4, 4, normal.as_slice()))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use nalgebra::{Isometry3, Translation3};
    use wasm_bindgen_test::wasm_bindgen_test;

    /// `n` motions `A_i` about random axes (10 to 120 deg) and
    /// `B_i = X^-1 A_i X` turned by a random 0.05 deg; X near 170 deg, where
    /// Tsai-Lenz needs one of its turns.
    fn noisy_motions(n: usize, seed: u64) -> (Vec<Motion>, Rotation3<f64>) {
        let mut rng = Rng::new(seed);
        let axis =
            |rng: &mut Rng| Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
        let x = UnitQuaternion::from_scaled_axis(axis(&mut rng) * 170f64.to_radians());
        let motions = (0..n)
            .map(|i| {
                let a = UnitQuaternion::from_scaled_axis(
                    axis(&mut rng) * rng.range(10.0, 120.0).to_radians(),
                );
                let noise = UnitQuaternion::from_scaled_axis(axis(&mut rng) * 0.05f64.to_radians());
                let b = noise * x.inverse() * a * x;
                let t = Translation3::new(rng.normal(), rng.normal(), rng.normal());
                Motion {
                    from: i,
                    to: i + 1,
                    robot: Isometry3::from_parts(t, a),
                    camera: Isometry3::from_parts(t, b),
                }
            })
            .collect();
        (motions, x.to_rotation_matrix())
    }

    /// The angle between two rotations (through a quaternion: `acos` of a
    /// rotation matrix's trace gives NaN when they are equal to rounding).
    fn apart(a: &Rotation3<f64>, b: &Rotation3<f64>) -> f64 {
        UnitQuaternion::from_rotation_matrix(&(a.inverse() * b)).angle()
    }

    /// Chou-Kamel as it was: the SVD of every motion's 4 x 4 block stacked.
    fn chou_kamel_stacked(motions: &[Motion]) -> Rotation3<f64> {
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
        let v_t = svd.v_t.unwrap();
        let v = v_t.row(svd.singular_values.imin());
        quat_from_wxyz(&Vector4::new(v[0], v[1], v[2], v[3]))
            .unwrap()
            .to_rotation_matrix()
    }

    /// Tsai-Lenz's `P'` as it was: B turned by each `R0` and converted.
    fn tsai_p_turned(motions: &[Motion], r0: &Rotation3<f64>) -> Vector3<f64> {
        let q0 = UnitQuaternion::from_rotation_matrix(r0);
        let mut normal = Matrix3::zeros();
        let mut rhs = Vector3::zeros();
        for m in motions {
            let pa = rodrigues2(&m.robot.rotation);
            let qb = q0 * m.camera.rotation * r0.inverse();
            let pb = rodrigues2(&UnitQuaternion::from_rotation_matrix(
                &qb.to_rotation_matrix(),
            ));
            let s = skew(&(pa + pb));
            normal += s.transpose() * s;
            rhs += s.transpose() * (pb - pa);
        }
        normal.lu().solve(&rhs).unwrap()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn chou_kamel_from_normal_equations_is_the_stacked_svd_solution() {
        // The smallest eigenvector of sum C^T C is the smallest right
        // singular vector of the stacked C: the same rotation to rounding
        // (measured: 3e-16 to 1.2e-15 rad), for 3 to 500 noisy motions.
        for (n, seed) in [(3, 1), (20, 2), (190, 3), (500, 4)] {
            let (motions, x) = noisy_motions(n, seed);
            let new = chou_kamel(&motions).unwrap();
            let old = chou_kamel_stacked(&motions);
            let angle = apart(&new, &old);
            assert!(angle < 1e-12, "{n} motions: {angle:e} rad apart");
            // And both are a solution: within the 0.05 deg noise of X.
            assert!(apart(&new, &x).to_degrees() < 0.1, "{n} motions");
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn tsai_lenz_turned_vectors_equal_the_turned_motions() {
        // R0 p_B (the vector once, turned) against p of R0 B R0^T (B turned
        // and converted), for each turn: equal to 1e-12 relative.
        let (motions, x) = noisy_motions(200, 7);
        let robot_p: Vec<_> = motions
            .iter()
            .map(|m| rodrigues2(&m.robot.rotation))
            .collect();
        let camera_p: Vec<_> = motions
            .iter()
            .map(|m| rodrigues2(&m.camera.rotation))
            .collect();
        for axis in [Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()] {
            let r0 = Rotation3::from_scaled_axis(axis * std::f64::consts::FRAC_PI_2);
            let new = tsai_p_prime(&robot_p, &camera_p, &r0).unwrap();
            let old = tsai_p_turned(&motions, &r0);
            let relative = (new - old).norm() / old.norm();
            assert!(relative < 1e-12, "turn {axis:?}: {relative:e}");
        }
        assert!(apart(&tsai_lenz(&motions).unwrap(), &x).to_degrees() < 0.1);
    }
}
