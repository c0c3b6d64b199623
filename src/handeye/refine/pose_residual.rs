//! The per-pose residual of `A_i X = Z B_i` used by the pose refinement
//! ([`crate::handeye::refine::pose_problem`]), with its Jacobians with respect to the unknowns
//! and to the measurement noise.
//!
//! # Parametrisation
//!
//! With the chain `robot[i] * x * camera[i] = y` of [`crate::handeye::Chain`], view
//! `i` implies the target pose `P_i = robot[i] * x * camera[i]`; its residual
//! is the 6-vector `[log(R_P R_y^T), t_P - t_y]` (rotation vector in the
//! frame of `y`'s left side, radians, then translation, metres).
//!
//! Every pose `T = (R, t)` (unknown or measured) is perturbed the same way,
//! decoupled and on the left: `R <- exp(w) R`, `t <- t + v`, so a
//! perturbation `[w, v]` of `x` is its rotation error in the gripper frame
//! (eye-in-hand; base frame eye-to-hand) and the error of its
//! `translation_m` as printed. Noise follows the same convention:
//! the robot's `base_from_gripper` in the base frame, the camera's
//! `camera_from_target` in the camera frame (PnP noise is anisotropic there:
//! depth and the tilts are much noisier than x/y and roll).

use crate::geometry::rotvec_from_rotation;
use crate::handeye::math::skew;
use crate::handeye::{Pose, Setup};
use nalgebra::{Matrix3, Matrix6, SMatrix, Vector3, Vector6};

/// 6 x 12 Jacobian of one residual with respect to `[x, y]` perturbations.
pub type ParamJacobian = SMatrix<f64, 6, 12>;

/// `J_l^-1(phi)`: maps a small left rotation `exp(d) R` to the change of
/// `log(R)`, `log(exp(d) exp(phi)) = phi + J_l^-1(phi) d + O(d^2)`.
pub fn left_jacobian_inverse(phi: &Vector3<f64>) -> Matrix3<f64> {
    let theta = phi.norm();
    let k = skew(phi);
    // Coefficient of [phi]x^2: 1/theta^2 - (1 + cos)/(2 theta sin), series near 0.
    let c = if theta < 1e-4 {
        1.0 / 12.0 + theta * theta / 720.0
    } else {
        1.0 / (theta * theta) - (1.0 + theta.cos()) / (2.0 * theta * theta.sin())
    };
    Matrix3::identity() - 0.5 * k + c * k * k
}

/// Apply a decoupled left perturbation `[w, v]` to a pose.
pub fn perturb(pose: &Pose, d: &Vector6<f64>) -> Pose {
    let w = Vector3::new(d[0], d[1], d[2]);
    let v = Vector3::new(d[3], d[4], d[5]);
    Pose::from_parts(
        (pose.translation.vector + v).into(),
        crate::geometry::rotation_from_rotvec(&w) * pose.rotation,
    )
}

/// The decoupled difference `d` with `perturb(from, d) = to`.
pub fn difference(from: &Pose, to: &Pose) -> Vector6<f64> {
    let w = rotvec_from_rotation(&(to.rotation * from.rotation.inverse()));
    let v = to.translation.vector - from.translation.vector;
    Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z)
}

/// One view's measurements as given: the robot's `base_from_gripper` and the
/// camera's `camera_from_target`.
#[derive(Debug, Clone, Copy)]
pub struct PoseMeasurement {
    /// The robot pose as reported.
    pub base_from_gripper: Pose,
    /// The camera pose as measured.
    pub camera_from_target: Pose,
}

/// The residual of one view and its Jacobians at `(x, y)`.
#[derive(Debug, Clone)]
pub struct ViewLinearisation {
    /// `[log(R_P R_y^T), t_P - t_y]`.
    pub residual: Vector6<f64>,
    /// d residual / d [x, y] perturbations.
    pub jac_params: ParamJacobian,
    /// d residual / d robot noise (`base_from_gripper`, base frame).
    pub jac_robot: Matrix6<f64>,
    /// d residual / d camera noise (`camera_from_target`, camera frame).
    pub jac_camera: Matrix6<f64>,
}

/// `robot[i]` of the chain for a measurement.
fn chain_robot(setup: Setup, m: &PoseMeasurement) -> Pose {
    match setup {
        Setup::EyeInHand => m.base_from_gripper,
        Setup::EyeToHand => m.base_from_gripper.inverse(),
    }
}

/// The residual alone.
pub fn residual(setup: Setup, m: &PoseMeasurement, x: &Pose, y: &Pose) -> Vector6<f64> {
    let implied = chain_robot(setup, m) * x * m.camera_from_target;
    difference(y, &implied)
}

/// The residual and its analytic Jacobians.
pub fn linearise(setup: Setup, m: &PoseMeasurement, x: &Pose, y: &Pose) -> ViewLinearisation {
    let a = chain_robot(setup, m);
    let c = &m.camera_from_target;
    let residual = residual(setup, m, x, y);
    let phi = Vector3::new(residual[0], residual[1], residual[2]);
    let jl = left_jacobian_inverse(&phi);
    let ra = a.rotation.to_rotation_matrix().into_inner();
    let rx = x.rotation.to_rotation_matrix().into_inner();
    let rpy = (a.rotation * x.rotation * c.rotation * y.rotation.inverse())
        .to_rotation_matrix()
        .into_inner();
    let tc = c.translation.vector;
    // Gripper-to-target vector in the base frame (eye-in-hand names).
    let lever = ra * (x.translation.vector + rx * tc);
    let mut jp = ParamJacobian::zeros();
    // x: R_P <- exp(R_a w) R_P; t_P += -R_a [R_x t_c]x w + R_a v.
    jp.fixed_view_mut::<3, 3>(0, 0).copy_from(&(jl * ra));
    jp.fixed_view_mut::<3, 3>(3, 0)
        .copy_from(&(-ra * skew(&(rx * tc))));
    jp.fixed_view_mut::<3, 3>(3, 3).copy_from(&ra);
    // y: R_P R_y^T <- M exp(-w) = exp(-M w) M; t residual -= v.
    jp.fixed_view_mut::<3, 3>(0, 6).copy_from(&(-jl * rpy));
    jp.fixed_view_mut::<3, 3>(3, 9)
        .copy_from(&(-Matrix3::identity()));
    // Chain robot perturbed on the left by [w_a, v_a].
    let mut g = Matrix6::zeros();
    g.fixed_view_mut::<3, 3>(0, 0).copy_from(&jl);
    g.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-skew(&lever)));
    g.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&Matrix3::identity());
    let jac_robot = match setup {
        Setup::EyeInHand => g,
        Setup::EyeToHand => {
            // robot = bfg^-1: bfg <- (exp(w) R_b, t_b + v) gives
            // w_a = -R_a w, v_a = -R_a [t_b]x w - R_a v.
            let tb = m.base_from_gripper.translation.vector;
            let mut k = Matrix6::zeros();
            k.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-ra));
            k.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-ra * skew(&tb)));
            k.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-ra));
            g * k
        }
    };
    // Camera: R_P <- exp(R_a R_x w) R_P; t_P += R_a R_x v.
    let rax = ra * rx;
    let mut jac_camera = Matrix6::zeros();
    jac_camera
        .fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(jl * rax));
    jac_camera.fixed_view_mut::<3, 3>(3, 3).copy_from(&rax);
    ViewLinearisation {
        residual,
        jac_params: jp,
        jac_robot,
        jac_camera,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};
    use wasm_bindgen_test::wasm_bindgen_test;

    fn pose(r: [f64; 3], t: [f64; 3]) -> Pose {
        Pose::from_parts(
            Translation3::new(t[0], t[1], t[2]),
            UnitQuaternion::from_scaled_axis(Vector3::from(r)),
        )
    }

    fn unit(k: usize) -> Vector6<f64> {
        let mut d = Vector6::zeros();
        d[k] = 1.0;
        d
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn jacobians_match_central_differences_in_both_setups() {
        // A residual far from zero (0.3 rad) exercises J_l^-1; one view with
        // a robot rotation near pi exercises the log near its edge.
        let x = pose([0.2, -0.4, 0.9], [0.03, -0.05, 0.1]);
        let y = pose([2.9, 0.3, -0.2], [0.6, 0.2, -0.1]);
        for setup in [Setup::EyeInHand, Setup::EyeToHand] {
            for robot_rotation in [[0.3, 0.1, -0.5], [0.0, 3.0, 0.1]] {
                let m = PoseMeasurement {
                    base_from_gripper: pose(robot_rotation, [0.5, -0.3, 0.7]),
                    camera_from_target: pose([0.1, -0.2, 0.4], [0.05, 0.02, 0.6]),
                };
                let lin = linearise(setup, &m, &x, &y);
                let h = 1e-6;
                for k in 0..6 {
                    let e = unit(k) * h;
                    let central =
                        |f: &dyn Fn(&Vector6<f64>) -> Vector6<f64>| (f(&e) - f(&-e)) / (2.0 * h);
                    let dx = central(&|d| residual(setup, &m, &perturb(&x, d), &y));
                    let dy = central(&|d| residual(setup, &m, &x, &perturb(&y, d)));
                    let dr = central(&|d| {
                        let mut p = m;
                        p.base_from_gripper = perturb(&m.base_from_gripper, d);
                        residual(setup, &p, &x, &y)
                    });
                    let dc = central(&|d| {
                        let mut p = m;
                        p.camera_from_target = perturb(&m.camera_from_target, d);
                        residual(setup, &p, &x, &y)
                    });
                    let checks = [
                        (dx, lin.jac_params.column(k).into_owned(), "x"),
                        (dy, lin.jac_params.column(6 + k).into_owned(), "y"),
                        (dr, lin.jac_robot.column(k).into_owned(), "robot"),
                        (dc, lin.jac_camera.column(k).into_owned(), "camera"),
                    ];
                    for (numeric, analytic, name) in checks {
                        assert!(
                            (numeric - analytic).amax() < 1e-7,
                            "{setup:?} {name} column {k}: {numeric} vs {analytic}"
                        );
                    }
                }
            }
        }
    }
}
