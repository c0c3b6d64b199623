//! The rig calibration's own uncertainty in the rig hand-eye.
//!
//! The rig hand-eye fits each frame's `rig_from_target` with the rig held,
//! so the pose refinement's covariance is conditional on the rig. The rig's
//! intrinsics and `camera_from_rig` come from a bundle adjustment over the
//! same pixels, but the frame poses fitted at the true rig are uncorrelated
//! with that estimate (the Schur complement of the joint problem), so to
//! first order
//!
//! `Cov(x) = Cov(x | rig) + J Cov(rig) J^T`, `J = dx / d rig`.
//!
//! `J Cov(rig) J^T` is evaluated by sigma points: with `Cov(rig) = sum_i
//! l_i v_i v_i^T`, the whole hand-eye (every frame's multi-camera PnP, then
//! the pose refinement from the solution) is re-run at the rig moved by
//! `+-sqrt(l_i) v_i`, and `d_i = (x(+) - x(-)) / 2` gives `sum_i d_i d_i^T`.
//! Exact for a linear map, it needs no derivative of the solvers.

use crate::calib::multi::rig_report::{RigCalibration, RigCovariance, POSE_PARAMETERS};
use crate::error::{Error, Result};
use crate::geometry::rotation_from_rotvec;
use crate::handeye::rig::pnp::HeldRig;
use crate::handeye::Pose;
use nalgebra::{DMatrix, Vector3};

/// Eigenvalues below this fraction of the largest carry no direction.
const NEGLIGIBLE_EIGENVALUE: f64 = 1e-14;

/// The held rig of a rig calibration report, cameras in report order.
pub fn held_rig(report: &RigCalibration) -> Result<HeldRig> {
    Ok(HeldRig {
        cameras: report
            .cameras
            .iter()
            .map(|c| c.calibration.camera.clone())
            .collect(),
        camera_from_rig: report
            .cameras
            .iter()
            .map(|c| c.camera_from_rig.to_pose())
            .collect::<Result<_>>()?,
    })
}

/// The rig moved by `+-` one standard deviation along each principal axis
/// of the report's covariance (see the module docs); `None` when the report
/// carries no covariance (a file of an older version).
pub fn rig_sigma_points(report: &RigCalibration) -> Result<Option<Vec<[HeldRig; 2]>>> {
    let Some(covariance) = &report.covariance else {
        return Ok(None);
    };
    let rig = held_rig(report)?;
    let slots = parameter_slots(report, covariance)?;
    let n = slots.len();
    let matrix = DMatrix::from_fn(n, n, |r, c| covariance.matrix[r][c]);
    if !matrix.iter().all(|v| v.is_finite()) {
        return Err(Error::invalid(
            "covariance.matrix",
            "holds a value that is not finite",
        ));
    }
    let symmetric = (&matrix + matrix.transpose()) * 0.5;
    let eigen = symmetric.symmetric_eigen();
    let largest = eigen.eigenvalues.iter().fold(0.0f64, |a, &b| a.max(b));
    let mut points = Vec::new();
    for (i, &l) in eigen.eigenvalues.iter().enumerate() {
        if l <= NEGLIGIBLE_EIGENVALUE * largest || l <= 0.0 {
            continue;
        }
        let step = eigen.eigenvectors.column(i) * l.sqrt();
        points.push([
            moved(&rig, &slots, step.as_slice(), 1.0)?,
            moved(&rig, &slots, step.as_slice(), -1.0)?,
        ]);
    }
    Ok(Some(points))
}

/// Where a covariance row acts: camera `k`'s intrinsic `i`, or component
/// `i` of its `camera_from_rig`.
#[derive(Clone, Copy)]
enum Slot {
    Intrinsic(usize, usize),
    Pose(usize, usize),
}

fn parameter_slots(report: &RigCalibration, covariance: &RigCovariance) -> Result<Vec<Slot>> {
    let n = covariance.parameters.len();
    if covariance.matrix.len() != n || covariance.matrix.iter().any(|r| r.len() != n) {
        return Err(Error::invalid(
            "covariance.matrix",
            format!(
                "must be {n} x {n} (one row and column per parameter), got {} rows",
                covariance.matrix.len()
            ),
        ));
    }
    covariance
        .parameters
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let field = || format!("covariance.parameters[{i}]");
            let k = report
                .cameras
                .iter()
                .position(|c| c.name == p.camera)
                .ok_or_else(|| {
                    Error::invalid(field(), format!("no camera is named '{}'", p.camera))
                })?;
            let camera = &report.cameras[k].calibration.camera;
            if let Some(j) = camera.param_names().iter().position(|n| *n == p.parameter) {
                return Ok(Slot::Intrinsic(k, j));
            }
            if let Some(j) = POSE_PARAMETERS.iter().position(|n| *n == p.parameter) {
                return Ok(Slot::Pose(k, j));
            }
            Err(Error::invalid(
                field(),
                format!(
                    "camera '{}' has no parameter '{}' (its parameters are {}, {})",
                    p.camera,
                    p.parameter,
                    camera.param_names().join(", "),
                    POSE_PARAMETERS.join(", ")
                ),
            ))
        })
        .collect()
}

/// The rig moved by `sign * step` (intrinsics additively, each
/// `camera_from_rig` by the left perturbation of the rig calibration).
fn moved(rig: &HeldRig, slots: &[Slot], step: &[f64], sign: f64) -> Result<HeldRig> {
    let mut params: Vec<Vec<f64>> = rig.cameras.iter().map(|c| c.params()).collect();
    let mut pose_steps = vec![[0.0; 6]; rig.cameras.len()];
    for (slot, d) in slots.iter().zip(step) {
        match *slot {
            Slot::Intrinsic(k, j) => params[k][j] += sign * d,
            Slot::Pose(k, j) => pose_steps[k][j] += sign * d,
        }
    }
    let cameras = rig
        .cameras
        .iter()
        .zip(&params)
        .map(|(c, p)| c.with_params(p))
        .collect::<Result<_>>()?;
    let camera_from_rig = rig
        .camera_from_rig
        .iter()
        .zip(&pose_steps)
        .map(|(pose, d)| {
            let rotation = rotation_from_rotvec(&Vector3::new(d[0], d[1], d[2])) * pose.rotation;
            let translation = pose.translation.vector + Vector3::new(d[3], d[4], d[5]);
            Pose::from_parts(translation.into(), rotation)
        })
        .collect();
    Ok(HeldRig {
        cameras,
        camera_from_rig,
    })
}
