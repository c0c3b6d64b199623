//! `rig_from_target` of one frame from every rig camera that saw the board
//! in it (multi-camera perspective-n-point with the rig held): camera `k`
//! sees board point `p` at `project_k(camera_from_rig[k] * rig_from_target * p)`.
//! The start is the single-camera pose ([`crate::calib::pnp::camera_from_target`])
//! of the camera with the most points, carried into the rig frame; then
//! Levenberg-Marquardt over the 6 pose parameters and all cameras' pixels.

use crate::calib::pnp::{camera_from_target, right_step_block, right_step_covariance};
use crate::calib::View;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{params_from_pose, pose_from_params};
use crate::handeye::Pose;
use crate::optim::{self, BlockParams, BlockProblem, LmOptions, ResidualBlock};
use nalgebra::Matrix6;

/// The rig held fixed: every camera's intrinsics and `camera_from_rig`.
#[derive(Debug, Clone)]
pub struct HeldRig {
    /// Intrinsics of camera `k`.
    pub cameras: Vec<Camera>,
    /// `camera_from_rig` of camera `k` (identity for the rig camera).
    pub camera_from_rig: Vec<Pose>,
}

/// One frame's board pose in the rig frame.
#[derive(Debug, Clone)]
pub struct RigPose {
    /// The board pose.
    pub rig_from_target: Pose,
    /// Reprojection RMS over every camera's points (px).
    pub rms_px: f64,
    /// `(J^T J)^-1` of the pose (per pixel variance) in the convention of
    /// [`crate::handeye::refine::pose_residual`]: rotation `exp(w) R`, translation `t + v`,
    /// in the rig frame, order `[w, v]`.
    pub covariance: Matrix6<f64>,
    /// Points used, summed over the cameras.
    pub points: usize,
}

/// The board pose of one frame from `views` (camera index, its points).
pub fn rig_from_target(rig: &HeldRig, views: &[(usize, View)]) -> Result<RigPose> {
    if let Some(&(k, _)) = views.iter().find(|(k, _)| *k >= rig.cameras.len()) {
        return Err(Error::invalid(
            "camera",
            format!(
                "view of camera {k}, but the rig has {} cameras",
                rig.cameras.len()
            ),
        ));
    }
    // The start: the camera with the most points whose own pose is fixed.
    let mut order: Vec<&(usize, View)> = views.iter().collect();
    order.sort_by_key(|(_, v)| std::cmp::Reverse(v.object_m.len()));
    let mut start = None;
    let mut why = Vec::new();
    for (k, v) in order {
        match camera_from_target(&rig.cameras[*k], v) {
            Ok((pose, _)) => {
                start = Some(rig.camera_from_rig[*k].inverse() * pose);
                break;
            }
            Err(e) => why.push(format!("camera {k}: {e}")),
        }
    }
    let start = start.ok_or_else(|| {
        Error::degenerate(format!(
            "no camera's points fix the board pose ({})",
            if why.is_empty() {
                "no camera saw the board".to_string()
            } else {
                why.join("; ")
            }
        ))
    })?;
    let problem = RigPoseProblem { rig, views };
    let lm = optim::solve(
        &problem,
        &BlockParams {
            global: params_from_pose(&start).to_vec(),
            blocks: Vec::new(),
        },
        &LmOptions::default(),
    )?;
    let pose = pose_from_params(&lm.params.global);
    let points: usize = views.iter().map(|(_, v)| v.object_m.len()).sum();
    let blocks = problem.residuals_and_jacobian(&lm.params, true)?;
    let covariance = right_step_covariance(&pose, &blocks, "board")?;
    Ok(RigPose {
        rig_from_target: pose,
        rms_px: (2.0 * lm.cost / points as f64).sqrt(),
        covariance,
        points,
    })
}

struct RigPoseProblem<'a> {
    rig: &'a HeldRig,
    views: &'a [(usize, View)],
}

impl BlockProblem for RigPoseProblem<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jacobians: bool,
    ) -> Result<Vec<ResidualBlock>> {
        let pose = pose_from_params(&params.global);
        let r = pose.rotation.to_rotation_matrix().into_inner();
        let mut out = Vec::new();
        for (k, view) in self.views {
            let camera_from_rig = self.rig.camera_from_rig[*k];
            let rc = camera_from_rig.rotation.to_rotation_matrix().into_inner();
            for (p, obs) in view.object_m.iter().zip(&view.image_px) {
                let w = camera_from_rig * (pose * p);
                let (pixel, d_pt, _) = self.rig.cameras[*k].project_with_jacobians(&w)?;
                // The rig camera's rotation carries the board point on.
                let d_pt = d_pt * rc;
                out.push(right_step_block(pixel - obs, &d_pt, &r, p, jacobians));
            }
        }
        Ok(out)
    }

    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        crate::calib::pnp::retract_pose(params, step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::rig::{rig_scene, RigSceneConfig};
    use wasm_bindgen_test::wasm_bindgen_test;

    fn views(scene: &crate::synth::rig::RigScene, frame: usize) -> Vec<(usize, View)> {
        scene
            .views
            .iter()
            .enumerate()
            .filter_map(|(k, list)| {
                list.iter()
                    .find(|(f, _)| *f == frame)
                    .map(|(_, v)| (k, v.clone()))
            })
            .collect()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn every_frame_pose_is_exact_and_bad_views_are_named() {
        let scene = rig_scene(&RigSceneConfig::default(), 3);
        let rig = HeldRig {
            cameras: scene.cameras.clone(),
            camera_from_rig: scene.camera_from_rig.clone(),
        };
        for (f, truth) in scene.rig_from_target.iter().enumerate() {
            let v = views(&scene, f);
            let p = rig_from_target(&rig, &v).unwrap();
            let dt = (p.rig_from_target.translation.vector - truth.translation.vector).norm();
            assert!(dt < 1e-9 && p.rig_from_target.rotation.angle_to(&truth.rotation) < 1e-9);
            assert!(p.rms_px < 1e-9 && p.covariance[(5, 5)] > 0.0);
        }
        // Three points in one camera fix nothing.
        let mut v = views(&scene, 0);
        v.truncate(1);
        v[0].1.object_m.truncate(3);
        v[0].1.image_px.truncate(3);
        let k = v[0].0;
        assert_eq!(
            rig_from_target(&rig, &v).unwrap_err().to_string(),
            format!(
                "no camera's points fix the board pose (camera {k}: requires at least 4 \
                 target points for a pose, got 3)"
            )
        );
        v[0].0 = 9;
        assert_eq!(
            rig_from_target(&rig, &v).unwrap_err().to_string(),
            "camera: view of camera 9, but the rig has 4 cameras"
        );
    }
}
