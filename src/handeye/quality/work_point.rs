//! The hand-eye error where it matters: at a work point, in millimetres.
//!
//! **The default work point** is the target's centre where the views see
//! it ([`target_centre_camera`]): each view's `camera_from_target` places
//! the centre `c` (target frame) at `c_i = camera_from_target_i * c` in the
//! camera frame; the point is taken in the mean of their directions
//! `c_i / |c_i|`, at their mean distance `mean |c_i|` (the mean working
//! distance), then carried into `x`'s left frame by the solved `x`.
//! Eye-in-hand the target is one fixed point of the base, and the gripper
//! frame sees it where the camera does from an average pose; eye-to-hand it
//! is fixed in the gripper and rides through the base frame, where the
//! fixed camera sees it on average. With image points `c` is the centre of
//! the board points ([`Placement::BoardCentre`]); with camera poses only
//! the board is unknown and `c` is the target frame's origin
//! ([`Placement::TargetOrigin`]).
//!
//! The pose refinement's covariance of the camera transform `x`
//! (`gripper_from_camera` or `base_from_camera`; rotation errors `w` in
//! `x`'s left frame, translation errors `v`, see
//! [`crate::handeye::refine::pose_residual`]) moves a point `q` held in
//! `x`'s left frame (the gripper frame eye-in-hand, the base frame
//! eye-to-hand) by `dq = v + w x (q - t_x)`: a 3 x 3 position covariance
//! `P = J C J^T` with `J = [-[q - t_x]x, I]`.
//!
//! **The 95 % bound** is the radius of the sphere that holds the 95 %
//! ellipsoid of a 3-D Gaussian with covariance `P`:
//! `sqrt(chi2_3(0.95) * lambda_max(P))` with `chi2_3(0.95) = 7.815`. It is
//! exact for an isotropic error and conservative (covers more than 95 %)
//! for an elongated one; the RMS error `sqrt(tr P)` is reported beside it.
//!
//! **What shrinks it.** The worst direction `u` (the top eigenvector of
//! `P`) is split into its rotation and translation parts. A rotation error
//! of `x` about an axis `a` is seen only by robot motions whose rotation
//! axes are not parallel to `a` (AX = XB: `k_A = R_x k_B`), and a
//! translation error along `u` only by motions rotating about axes across
//! `u` (`(R_A - I) t_x`); the advice names those axes in the camera frame.

use crate::handeye::math::skew;
use crate::handeye::{Pose, Setup};
use nalgebra::{Matrix3, Point3, SMatrix, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

/// The 95 % quantile of chi-squared with 3 degrees of freedom.
pub const CHI2_3_95: f64 = 7.814_727_903_251_178;

/// How a work point was placed (the `placement` key).
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Placement {
    /// The default with image points: the centre of the board points,
    /// where the views see it, at their mean distance (module docs).
    BoardCentre,
    /// The default with camera poses only (the board points unknown): the
    /// target frame's origin, where the views see it, at their mean
    /// distance.
    TargetOrigin,
    /// The tool centre point the user gave.
    ToolCentrePoint,
}

impl Placement {
    /// The point's name in the report (`point`, the verdict).
    pub fn point_name(self) -> &'static str {
        match self {
            Placement::BoardCentre | Placement::TargetOrigin => "target centre",
            Placement::ToolCentrePoint => "tool centre point",
        }
    }
}

/// Where the default work point is (kept with the pose refinement's summary
/// until the report is written: [`crate::handeye::quality::trust::place_work_point`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DefaultWorkPoint {
    /// The point in the camera frame (m).
    pub camera_m: [f64; 3],
    /// How it was placed.
    pub placement: Placement,
}

/// The hand-eye error at one point (the report's `work_point_error` and
/// `tcp_error`).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct WorkPointError {
    /// What the point is: `target centre` or `tool centre point`.
    pub point: String,
    /// How it was placed: `board-centre` or `target-origin` (the default,
    /// with or without image points), `tool-centre-point` (given).
    /// Absent in reports written before it existed.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub placement: Option<Placement>,
    /// The point (metres) in `frame`.
    pub point_m: [f64; 3],
    /// `gripper` (eye-in-hand) or `base` (eye-to-hand): the left frame of
    /// the camera transform, where the error is measured.
    pub frame: String,
    /// The same point in the camera frame (metres).
    pub point_camera_m: [f64; 3],
    /// RMS position error, `sqrt(trace P)` (mm).
    pub rms_mm: f64,
    /// 95 % bound (mm): `sqrt(7.815 * largest eigenvalue of P)`.
    pub bound95_mm: f64,
    /// Unit direction of the largest error, camera frame.
    pub worst_direction_camera: [f64; 3],
    /// Share of the variance along the worst direction that comes from the
    /// camera transform's rotation (0 to 1; the rest: its translation).
    pub rotation_share: f64,
    /// One line: the bound and where it comes from.
    pub verdict: String,
    /// Motions that would shrink it, most useful first.
    pub shrink_by: Vec<String>,
}

/// The 3 x 3 covariance (m^2) of a point `q` (left frame of `x`) from the
/// 6 x 6 covariance of `x` (`[w, v]`, rad and m).
pub fn point_covariance(cov6: &SMatrix<f64, 6, 6>, x: &Pose, q: &Vector3<f64>) -> Matrix3<f64> {
    let j = point_jacobian(x, q);
    let p = j * cov6 * j.transpose();
    (p + p.transpose()) * 0.5
}

fn point_jacobian(x: &Pose, q: &Vector3<f64>) -> SMatrix<f64, 3, 6> {
    let lever = q - x.translation.vector;
    let mut j = SMatrix::<f64, 3, 6>::zeros();
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-skew(&lever)));
    j.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&Matrix3::identity());
    j
}

/// The point `distance_m` in front of the camera on its optical axis, in
/// `x`'s left frame (the plan's views look at the board centre along it).
pub fn camera_axis_point(x: &Pose, distance_m: f64) -> Vector3<f64> {
    (x * Point3::new(0.0, 0.0, distance_m)).coords
}

/// The default work point in the camera frame (module docs): the target
/// point `centre` (target frame) as the views see it, in the mean of its
/// directions at its mean distance. `None` without a view that places it
/// in front of the camera at a finite distance.
pub fn target_centre_camera(
    camera_from_target: &[Pose],
    centre: &Point3<f64>,
) -> Option<Vector3<f64>> {
    let seen: Vec<Vector3<f64>> = camera_from_target
        .iter()
        .map(|c| (c * centre).coords)
        .filter(|p| p.iter().all(|v| v.is_finite()) && p.norm() > 0.0)
        .collect();
    if seen.is_empty() {
        return None;
    }
    let n = seen.len() as f64;
    let distance = seen.iter().map(|p| p.norm()).sum::<f64>() / n;
    let direction = seen
        .iter()
        .map(|p| p.normalize())
        .sum::<Vector3<f64>>()
        .try_normalize(1e-9)?;
    Some(direction * distance)
}

fn camera_axis_name(axis_camera: &Vector3<f64>) -> Option<&'static str> {
    let a = axis_camera.abs();
    let (k, v) = (0..3)
        .map(|k| (k, a[k]))
        .fold((0, 0.0), |b, c| if c.1 > b.1 { c } else { b });
    (v > 0.8).then_some(["x", "y", "optical (z)"][k])
}

/// The axes across `axis` (camera frame), named.
fn across(axis_camera: &Vector3<f64>) -> String {
    match camera_axis_name(axis_camera) {
        Some("x") => "the camera's y and optical axes".to_string(),
        Some("y") => "the camera's x and optical axes".to_string(),
        Some(_) => "the camera's x and y axes (tilt the camera)".to_string(),
        None => format!(
            "axes perpendicular to ({:.2}, {:.2}, {:.2}) in the camera frame",
            axis_camera.x, axis_camera.y, axis_camera.z
        ),
    }
}

fn direction_name(v: &Vector3<f64>) -> String {
    match camera_axis_name(v) {
        Some(name) => format!("the camera's {name} axis"),
        None => format!("({:.2}, {:.2}, {:.2}) in the camera frame", v.x, v.y, v.z),
    }
}

/// The error at `q` (metres, `x`'s left frame) from the first 6 x 6 block
/// of a 12 x 12 covariance (the report's `pose_refinement.covariance`,
/// camera transform first). `None` when the block is not finite.
pub fn work_point_error(
    covariance: &[[f64; 12]],
    setup: Setup,
    x: &Pose,
    q: &Vector3<f64>,
    placement: Placement,
) -> Option<WorkPointError> {
    let point = placement.point_name();
    if covariance.len() < 6 {
        return None;
    }
    let cov6 = SMatrix::<f64, 6, 6>::from_fn(|r, c| covariance[r][c]);
    if cov6.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let p = point_covariance(&cov6, x, q);
    let eig = SymmetricEigen::new(p);
    let (k, lambda) = eig
        .eigenvalues
        .iter()
        .copied()
        .enumerate()
        .fold((0, f64::MIN), |b, c| if c.1 > b.1 { c } else { b });
    let lambda = lambda.max(0.0);
    let u = eig.eigenvectors.column(k).into_owned();
    let r_x = x.rotation.to_rotation_matrix().into_inner();
    // Camera-frame directions; the eigenvector's sign is arbitrary, fix it.
    let mut u_cam = r_x.transpose() * u;
    if u_cam[u_cam.iamax()] < 0.0 {
        u_cam = -u_cam;
    }
    let j = point_jacobian(x, q);
    let j_r = j.fixed_view::<3, 3>(0, 0).into_owned();
    let c_rr = cov6.fixed_view::<3, 3>(0, 0).into_owned();
    let c_tt = cov6.fixed_view::<3, 3>(3, 3).into_owned();
    let var_rot = (u.transpose() * j_r * c_rr * j_r.transpose() * u)[0].max(0.0);
    let var_trans = (u.transpose() * c_tt * u)[0].max(0.0);
    let rotation_share = if var_rot + var_trans > 0.0 {
        var_rot / (var_rot + var_trans)
    } else {
        0.0
    };
    let bound95_mm = (CHI2_3_95 * lambda).sqrt() * 1e3;
    let rms_mm = p.trace().max(0.0).sqrt() * 1e3;
    let q_cam = x.inverse() * nalgebra::Point3::from(*q);
    let mut shrink_by = Vec::new();
    let source = if rotation_share >= 0.5 {
        // The rotation axis whose error moves the point along u most.
        let a = c_rr * j_r.transpose() * u;
        let a_cam = if a.norm() > 0.0 {
            r_x.transpose() * a.normalize()
        } else {
            Vector3::z()
        };
        shrink_by.push(format!(
            "rotate the gripper more about {} (the rotation about {} is poorly excited)",
            across(&a_cam),
            direction_name(&a_cam)
        ));
        format!(
            "mostly the hand-eye rotation about {} (lever {:.0} mm)",
            direction_name(&a_cam),
            (q - x.translation.vector).norm() * 1e3
        )
    } else {
        shrink_by.push(format!(
            "rotate the gripper by larger angles about {} (they fix the translation along {})",
            across(&u_cam),
            direction_name(&u_cam)
        ));
        format!(
            "mostly the hand-eye translation along {}",
            direction_name(&u_cam)
        )
    };
    shrink_by.push(
        "add poses spread over the workspace (the error shrinks about as 1 / sqrt(poses))"
            .to_string(),
    );
    let verdict = format!(
        "hand-eye error at the {point}: within {bound95_mm:.2} mm (95 %), RMS {rms_mm:.2} mm, \
         largest along {}; {source}",
        direction_name(&u_cam)
    );
    Some(WorkPointError {
        point: point.to_string(),
        placement: Some(placement),
        point_m: [q.x, q.y, q.z],
        frame: match setup {
            Setup::EyeInHand => "gripper",
            Setup::EyeToHand => "base",
        }
        .to_string(),
        point_camera_m: [q_cam.x, q_cam.y, q_cam.z],
        rms_mm,
        bound95_mm,
        worst_direction_camera: [u_cam.x, u_cam.y, u_cam.z],
        rotation_share,
        verdict,
        shrink_by,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn diag(rot: f64, trans: f64) -> Vec<[f64; 12]> {
        let mut cov = vec![[0.0; 12]; 12];
        for (k, row) in cov.iter_mut().enumerate().take(6) {
            row[k] = if k < 3 { rot * rot } else { trans * trans };
        }
        cov
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn an_isotropic_translation_error_gives_the_chi_square_radius() {
        let x = Pose::identity();
        let e = work_point_error(
            &diag(0.0, 1e-3),
            Setup::EyeInHand,
            &x,
            &Vector3::zeros(),
            Placement::ToolCentrePoint,
        )
        .unwrap();
        assert!((e.bound95_mm - CHI2_3_95.sqrt()).abs() < 1e-9, "{e:?}");
        assert!((e.rms_mm - 3f64.sqrt()).abs() < 1e-9);
        assert!(e.rotation_share < 1e-12);
        assert_eq!(e.frame, "gripper");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn a_rotation_about_x_names_the_other_axes() {
        // Only the rotation about the camera's x axis is uncertain: at 0.5 m
        // on the optical axis the point moves along y by 0.5 * sigma.
        let mut cov = vec![[0.0; 12]; 12];
        cov[0][0] = 1e-6;
        let x = Pose::identity();
        let q = camera_axis_point(&x, 0.5);
        let e = work_point_error(&cov, Setup::EyeToHand, &x, &q, Placement::TargetOrigin).unwrap();
        assert!(
            (e.bound95_mm - 0.5 * CHI2_3_95.sqrt()).abs() < 1e-9,
            "{e:?}"
        );
        assert!((e.worst_direction_camera[1].abs() - 1.0).abs() < 1e-9);
        assert!(e.rotation_share > 0.99);
        assert!(
            e.shrink_by[0].contains("the camera's y and optical axes"),
            "{:?}",
            e.shrink_by
        );
        assert!(e
            .verdict
            .contains("rotation about the camera's x axis (lever 500 mm)"));
        assert_eq!(e.point_camera_m, [0.0, 0.0, 0.5]);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn the_default_point_is_the_target_centre_at_the_mean_distance() {
        // Two views see the centre 0.4 m and 0.6 m away, 20 degrees to
        // either side of the optical axis: the mean direction is the axis,
        // the mean distance 0.5 m (the mean point would be 0.47 m away and
        // off the axis).
        let at = |x: f64, z: f64| {
            Pose::from_parts(
                nalgebra::Translation3::new(x, 0.0, z),
                nalgebra::UnitQuaternion::identity(),
            )
        };
        let (s, c) = 20f64.to_radians().sin_cos();
        let views = [at(-0.4 * s, 0.4 * c), at(0.6 * s, 0.6 * c)];
        let q = target_centre_camera(&views, &Point3::origin()).unwrap();
        assert!((q - Vector3::new(0.0, 0.0, 0.5)).norm() < 1e-12, "{q:?}");
        assert!(target_centre_camera(&[], &Point3::origin()).is_none());
        // The centre is a target point: a board centre 0.1 m along x of
        // the origin, seen straight ahead at 0.5 m.
        let one = [at(-0.1, 0.5)];
        let q = target_centre_camera(&one, &Point3::new(0.1, 0.0, 0.0)).unwrap();
        assert!((q - Vector3::new(0.0, 0.0, 0.5)).norm() < 1e-12, "{q:?}");
    }
}
