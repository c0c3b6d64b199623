//! `camera_from_target` of one view from its target points and pixels with a
//! known camera (perspective-n-point for planar targets): the pixels are
//! undistorted to normalised coordinates, a homography gives the starting
//! pose ([`crate::calib::pose_from_homography`] with K = I), and
//! Levenberg-Marquardt ([`crate::optim`]) minimises the reprojection error
//! over the 6 pose parameters.

use crate::calib::View;
use crate::calib::{homography, homography_problem, pose_from_homography};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{params_from_pose, pose_from_params, rotation_from_rotvec};
use crate::handeye::Pose;
use crate::optim::{self, BlockParams, BlockProblem, LmOptions, ResidualBlock};
use nalgebra::{
    DMatrix, DVector, Matrix2x3, Matrix3, Matrix6, Point2, Point3, SMatrix, Translation3, Vector2,
    Vector3,
};

/// Largest |z| (relative to the target's extent) for the target to count as planar.
const PLANAR_TOLERANCE: f64 = 1e-9;

/// Pose of the target in the camera frame from one view (at least 4 points
/// on the target plane z = 0), with the reprojection RMS (px).
pub fn camera_from_target(camera: &Camera, view: &View) -> Result<(Pose, f64)> {
    let n = view.object_m.len();
    if view.image_px.len() != n {
        return Err(Error::invalid(
            "image_px",
            format!("{} object points but {} pixels", n, view.image_px.len()),
        ));
    }
    if n < 4 {
        return Err(Error::too_few("target points for a pose", 4, n));
    }
    let extent = view
        .object_m
        .iter()
        .map(|p| p.coords.xy().norm())
        .fold(0.0, f64::max);
    if view
        .object_m
        .iter()
        .any(|p| p.z.abs() > PLANAR_TOLERANCE * extent.max(1.0))
    {
        return Err(Error::invalid(
            "object_m",
            "the pose initialisation needs a planar target (every point at z = 0)",
        ));
    }
    let plane: Vec<Point2<f64>> = view.object_m.iter().map(|p| p.xy()).collect();
    if let Some(reason) = homography_problem(&plane) {
        return Err(Error::degenerate(format!(
            "the view's board points cannot fix a pose: {reason}"
        )));
    }
    let normalized = view
        .image_px
        .iter()
        .map(|px| {
            let ray = camera.unproject(px)?;
            if ray.z <= 0.0 {
                return Err(Error::degenerate(format!(
                    "pixel ({:.1}, {:.1}) does not look forward",
                    px.x, px.y
                )));
            }
            Ok(Point2::new(ray.x / ray.z, ray.y / ray.z))
        })
        .collect::<Result<Vec<_>>>()?;
    let h = homography(&plane, &normalized)?;
    let start = pose_from_homography(&Matrix3::identity(), &h)?;
    let problem = PoseProblem { camera, view };
    let lm = optim::solve(
        &problem,
        &BlockParams {
            global: params_from_pose(&start).to_vec(),
            blocks: Vec::new(),
        },
        &LmOptions::default(),
    )?;
    let pose = pose_from_params(&lm.params.global);
    let rms = (2.0 * lm.cost / n as f64).sqrt();
    Ok((pose, rms))
}

/// [`camera_from_target`] plus the pose's `(J^T J)^-1` (per pixel
/// variance) in the convention of [`crate::handeye::refine::pose_residual`]: rotation
/// `exp(w) R` and translation `t + v`, both in the camera frame, order
/// `[w, v]`. Times the pixel variance it is the pose covariance the pose
/// refinement's [`crate::handeye::refine::pose_noise::CameraNoise::PerView`] takes.
pub fn camera_from_target_with_covariance(
    camera: &Camera,
    view: &View,
) -> Result<(Pose, f64, Matrix6<f64>)> {
    let (pose, rms) = camera_from_target(camera, view)?;
    let problem = PoseProblem { camera, view };
    let blocks = problem.residuals_and_jacobian(
        &BlockParams {
            global: params_from_pose(&pose).to_vec(),
            blocks: Vec::new(),
        },
        true,
    )?;
    let covariance = right_step_covariance(&pose, &blocks, "target")?;
    Ok((pose, rms, covariance))
}

/// `(J^T J)^-1` of a pose stepped on the right (`pose * exp(d)`, the
/// problems here) from its residual blocks, in the convention of
/// [`crate::handeye::refine::pose_residual`]: rotation `exp(w) R` and translation `t + v`,
/// order `[w, v]`. `what` names the pose in the error (its points leave it
/// free).
pub(crate) fn right_step_covariance(
    pose: &Pose,
    blocks: &[ResidualBlock],
    what: &str,
) -> Result<Matrix6<f64>> {
    let mut jtj = Matrix6::zeros();
    for b in blocks {
        let j = SMatrix::<f64, 2, 6>::from_column_slice(b.jac_global.as_slice());
        jtj += j.transpose() * j;
    }
    let inverse = jtj.try_inverse().ok_or_else(|| {
        Error::degenerate(format!("the {what} pose is not constrained by its points"))
    })?;
    // Right perturbation pose * exp(d) = (exp(R d_r) R, t + R d_t).
    let r = pose.rotation.to_rotation_matrix().into_inner();
    let mut g = Matrix6::zeros();
    g.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    g.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
    Ok(g * inverse * g.transpose())
}

/// One point's residual block under a pose stepped on the right:
/// `residual` is its pixel minus its observation, `d_pt` the projection's
/// Jacobian with respect to `pose * p` as the camera sees it (a rig
/// camera's rotation already applied), `r` the pose's rotation.
pub(crate) fn right_step_block(
    residual: Vector2<f64>,
    d_pt: &Matrix2x3<f64>,
    r: &Matrix3<f64>,
    p: &Point3<f64>,
    jacobians: bool,
) -> ResidualBlock {
    let mut jac_global = DMatrix::zeros(2, 0);
    if jacobians {
        // Right perturbation pose * exp(d): dw/drot = -R [p]x, dw/dt = R.
        jac_global = DMatrix::zeros(2, 6);
        let d_rot = d_pt * (-r * p.coords.cross_matrix());
        jac_global.view_mut((0, 0), (2, 3)).copy_from(&d_rot);
        jac_global.view_mut((0, 3), (2, 3)).copy_from(&(d_pt * r));
    }
    ResidualBlock {
        block: None,
        residuals: DVector::from_column_slice(residual.as_slice()),
        jac_global,
        jac_block: DMatrix::zeros(2, 0),
    }
}

struct PoseProblem<'a> {
    camera: &'a Camera,
    view: &'a View,
}

impl BlockProblem for PoseProblem<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jacobians: bool,
    ) -> Result<Vec<ResidualBlock>> {
        let pose = pose_from_params(&params.global);
        let r = pose.rotation.to_rotation_matrix().into_inner();
        let mut out = Vec::with_capacity(self.view.object_m.len());
        for (p, obs) in self.view.object_m.iter().zip(&self.view.image_px) {
            let w = pose * p;
            let (pixel, d_pt, _) = self.camera.project_with_jacobians(&w)?;
            out.push(right_step_block(pixel - obs, &d_pt, &r, p, jacobians));
        }
        Ok(out)
    }

    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        retract_pose(params, step)
    }
}

/// One pose as the only global parameters (rotation vector, translation),
/// stepped on the right: `pose * exp(step)`. The PnP problems (one camera,
/// or a held rig) share it.
pub(crate) fn retract_pose(params: &BlockParams, step: &BlockParams) -> BlockParams {
    let d = &step.global;
    let delta = Pose::from_parts(
        Translation3::new(d[3], d[4], d[5]),
        rotation_from_rotvec(&Vector3::new(d[0], d[1], d[2])),
    );
    BlockParams {
        global: params_from_pose(&(pose_from_params(&params.global) * delta)).to_vec(),
        blocks: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Point3, UnitQuaternion};
    use wasm_bindgen_test::wasm_bindgen_test;

    fn grid() -> Vec<Point3<f64>> {
        (0..6)
            .flat_map(|r| (0..9).map(move |c| Point3::new(c as f64 * 0.03, r as f64 * 0.03, 0.0)))
            .collect()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn recovers_the_pose_with_distortion_and_rejects_bad_input() {
        let mut camera = Camera::pinhole(800.0, 810.0, 330.0, 235.0, 640, 480);
        camera.distortion = crate::camera::Distortion::Brown {
            k1: -0.2,
            k2: 0.05,
            k3: 0.0,
            p1: 0.001,
            p2: -0.0005,
        };
        let truth = Pose::from_parts(
            Translation3::new(-0.1, -0.05, 0.6),
            UnitQuaternion::from_scaled_axis(Vector3::new(0.3, -0.2, 0.1)),
        );
        let object = grid();
        let image: Vec<Point2<f64>> = object
            .iter()
            .map(|p| camera.project(&(truth * p)).unwrap())
            .collect();
        let view = View::new("", object.clone(), image);
        let (pose, rms) = camera_from_target(&camera, &view).unwrap();
        assert!(rms < 1e-9, "rms {rms}");
        assert!((pose.translation.vector - truth.translation.vector).norm() < 1e-9);
        assert!(pose.rotation.angle_to(&truth.rotation) < 1e-9);
        let few = View::new("", object[..3].to_vec(), view.image_px[..3].to_vec());
        assert_eq!(
            camera_from_target(&camera, &few).unwrap_err().to_string(),
            "requires at least 4 target points for a pose, got 3"
        );
        let mut bent = view.clone();
        bent.object_m[5].z = 0.01;
        assert_eq!(
            camera_from_target(&camera, &bent).unwrap_err().to_string(),
            "object_m: the pose initialisation needs a planar target (every point at z = 0)"
        );
    }
}
