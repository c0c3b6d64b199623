//! Hand-eye for robots whose motions all rotate about one axis (4-axis SCARA
//! arms, or a 6-axis arm moved like one).
//!
//! With parallel rotation axes the rotation-only equations fix `R_X` up to a
//! rotation by `phi` about the axis, and `(R_A - I) t = R_X t_B - t_A` never
//! sees the translation along the axis. Writing `R_X = Rot(k, phi) R0`
//! (`R0` maps the camera's axis onto the robot's `k`) makes the translation
//! equation linear in `(t, cos phi, sin phi)`: the observable part is solved
//! in closed form and the component of `t` along `k` is reported as
//! unobservable (set to 0).

use crate::error::{Error, Result};
use crate::handeye::closed_form::motion::axis_spread;
use crate::handeye::math::{least_squares, pose_from};
use crate::handeye::{Motion, Pose};
use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, Unit, UnitQuaternion, Vector3};

/// Rotation axes closer than this (degrees of spread) are treated as parallel.
pub const PARALLEL_AXES_DEG: f64 = 1.0;

/// Solve the observable part; returns the pose and the unit axis (in the
/// frame of `x`'s left side: gripper for eye-in-hand, base for eye-to-hand)
/// along which the translation is unobservable.
pub fn solve(motions: &[Motion]) -> Result<(Pose, Vector3<f64>)> {
    if motions.len() < 2 {
        return Err(Error::too_few(
            "motions with enough rotation",
            2,
            motions.len(),
        ));
    }
    let robot_axes: Vec<Vector3<f64>> = motions
        .iter()
        .map(|m| m.robot.rotation.scaled_axis())
        .collect();
    let (k, _) = axis_spread(&robot_axes.iter().map(|a| a.normalize()).collect::<Vec<_>>());
    // Camera axis: the camera rotation vectors with the signs that make the
    // robot rotation vectors point along +k (alpha = R_X beta keeps signs).
    let kc = motions
        .iter()
        .zip(&robot_axes)
        .fold(Vector3::zeros(), |acc, (m, a)| {
            acc + m.camera.rotation.scaled_axis() * a.dot(&k).signum()
        });
    let kr = robot_axes
        .iter()
        .fold(Vector3::zeros(), |acc, a| acc + a * a.dot(&k).signum());
    let (kc, kr) = (kc.normalize(), kr.normalize());
    if !kc.iter().chain(kr.iter()).all(|v| v.is_finite()) {
        return Err(Error::degenerate("no rotation axis could be estimated"));
    }
    let r0 = UnitQuaternion::rotation_between(&kc, &kr)
        .unwrap_or_else(|| {
            let perp = kc.cross(&Vector3::x());
            let perp = if perp.norm() < 0.1 {
                kc.cross(&Vector3::y())
            } else {
                perp
            };
            UnitQuaternion::from_axis_angle(&Unit::new_normalize(perp), std::f64::consts::PI)
        })
        .to_rotation_matrix();
    // Unknowns [t (3), c, s]: (R_A - I) t - c v_perp - s (k x v) = (k.v) k - t_A.
    let mut normal = DMatrix::zeros(5, 5);
    let mut rhs = DVector::zeros(5);
    for m in motions {
        let v = r0 * m.camera.translation.vector;
        let along = kr * kr.dot(&v);
        let mut a = DMatrix::zeros(3, 5);
        let c = m.robot.rotation.to_rotation_matrix().into_inner() - Matrix3::identity();
        a.view_mut((0, 0), (3, 3)).copy_from(&c);
        a.view_mut((0, 3), (3, 1)).copy_from(&(-(v - along)));
        a.view_mut((0, 4), (3, 1)).copy_from(&(-kr.cross(&v)));
        let b = along - m.robot.translation.vector;
        rhs += a.transpose() * DVector::from_column_slice(b.as_slice());
        normal += a.transpose() * a;
    }
    let (w, _) = least_squares(&normal, &rhs)?;
    let phi = w[4].atan2(w[3]);
    if w[3].hypot(w[4]) < 1e-12 {
        return Err(Error::degenerate(
            "the rotation about the common axis is unobservable: the robot must also translate \
             between poses",
        ));
    }
    let r = Rotation3::from_axis_angle(&Unit::new_normalize(kr), phi) * r0;
    let (t, _) = crate::handeye::closed_form::axxb::translation(motions, &r)?;
    // Make the unobservable component exactly zero (the minimum-norm solve
    // already does up to round-off).
    let t = t - kr * kr.dot(&t);
    Ok((pose_from(&r, &t), kr))
}
