//! Joint rig refinement as a block problem for the shared solver.
//!
//! Layout: global = `[camera 0 params, camera 1 params, ..., then
//! camera_from_rig (rotation vector 3, translation_m 3) of every camera but
//! the rig camera, in camera order]`; one block per frame some camera used
//! = the frame's `rig_from_target` `[rotation vector, translation_m]`.
//! Camera k sees board point X of frame f at
//! `camera_k_from_rig * rig_from_target_f * X` (the rig camera's
//! camera_from_rig is the identity and not a parameter). Residual blocks
//! come frame by frame (all cameras of one frame together), the order the
//! solver's Schur accumulation likes.

use crate::calib::multi::stereo_problem::{fold_aspect, retract_pose, skew};
use crate::calib::refine::{pose_from_block, CalibProblem};
use crate::camera::Camera;
use crate::error::Result;
use crate::geometry::Pose;
use crate::optim::{BlockParams, BlockProblem, ResidualBlock};
use nalgebra::{DMatrix, DVector, Matrix2x3, Matrix3, Point3};

/// One observation of a frame: camera `camera` used its view `view` (an
/// index into that camera's problem views) of the frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Sighting {
    pub camera: usize,
    pub view: usize,
}

/// Every camera's problem (its views, point masks, aspect) and which
/// views belong to which frame block.
pub(crate) struct RigProblem<'a> {
    /// One per camera; `views[j]` of camera k is the view named by a
    /// [`Sighting`] `{camera: k, view: j}`.
    pub cameras: Vec<CalibProblem<'a>>,
    /// The rig camera (no extrinsic parameters).
    pub rig_camera: usize,
    /// Per frame block, the cameras' views of it.
    pub frames: Vec<Vec<Sighting>>,
}

impl RigProblem<'_> {
    /// Offset of camera k's intrinsics in the global vector.
    pub fn params_offset(&self, camera: usize) -> usize {
        self.cameras[..camera]
            .iter()
            .map(|c| c.template.params().len())
            .sum()
    }

    /// Offset of camera k's camera_from_rig in the global vector (`None`
    /// for the rig camera).
    pub fn pose_offset(&self, camera: usize) -> Option<usize> {
        if camera == self.rig_camera {
            return None;
        }
        let before = if camera > self.rig_camera {
            camera - 1
        } else {
            camera
        };
        Some(self.params_offset(self.cameras.len()) + 6 * before)
    }

    /// Length of the global vector.
    pub fn n_global(&self) -> usize {
        self.params_offset(self.cameras.len()) + 6 * (self.cameras.len() - 1)
    }

    /// Camera k's intrinsics of a global vector.
    pub fn camera(&self, global: &[f64], k: usize) -> Result<Camera> {
        let o = self.params_offset(k);
        let n = self.cameras[k].template.params().len();
        self.cameras[k].camera(&global[o..o + n])
    }

    /// camera_k_from_rig of a global vector.
    pub fn camera_from_rig(&self, global: &[f64], k: usize) -> Pose {
        match self.pose_offset(k) {
            Some(o) => pose_from_block(&global[o..o + 6]),
            None => Pose::identity(),
        }
    }

    /// The camera of every residual block [`BlockProblem::residuals_and_jacobian`]
    /// returns, in its order.
    pub fn residual_cameras(&self) -> Vec<usize> {
        let mut out = Vec::new();
        for sightings in &self.frames {
            for s in sightings {
                let used = &self.cameras[s.camera].used[s.view];
                out.extend(std::iter::repeat(s.camera).take(used.iter().filter(|u| **u).count()));
            }
        }
        out
    }
}

impl BlockProblem for RigProblem<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jacobians: bool,
    ) -> Result<Vec<ResidualBlock>> {
        let g = &params.global;
        let n_global = self.n_global();
        let cameras = (0..self.cameras.len())
            .map(|k| self.camera(g, k))
            .collect::<Result<Vec<_>>>()?;
        let extrinsics: Vec<(Pose, Matrix3<f64>)> = (0..self.cameras.len())
            .map(|k| {
                let pose = self.camera_from_rig(g, k);
                let r = pose.rotation.to_rotation_matrix().into_inner();
                (pose, r)
            })
            .collect();
        let mut out = Vec::new();
        for (b, sightings) in self.frames.iter().enumerate() {
            let rig_from_target = pose_from_block(&params.blocks[b]);
            for s in sightings {
                let problem = &self.cameras[s.camera];
                let camera = &cameras[s.camera];
                let (camera_from_rig, r_c) = &extrinsics[s.camera];
                let view = &problem.views[s.view];
                let points = view.object_m.iter().zip(&view.image_px).enumerate();
                for (i, (object, observed)) in points {
                    if !problem.used[s.view][i] {
                        continue;
                    }
                    let rotated = rig_from_target.rotation * object.coords;
                    let p_rig = rotated + rig_from_target.translation.vector;
                    let p = camera_from_rig * Point3::from(p_rig);
                    let (pixel, d_point, mut d_params) = if jacobians {
                        camera.project_with_jacobians(&p)?
                    } else {
                        (
                            camera.project(&p)?,
                            Matrix2x3::zeros(),
                            DMatrix::zeros(2, 0),
                        )
                    };
                    let residuals =
                        DVector::from_vec(vec![pixel.x - observed.x, pixel.y - observed.y]);
                    let (jac_global, jac_block) = if jacobians {
                        fold_aspect(&mut d_params, problem.aspect);
                        let mut jg = DMatrix::zeros(2, n_global);
                        let o = self.params_offset(s.camera);
                        jg.view_mut((0, o), (2, d_params.ncols()))
                            .copy_from(&d_params);
                        if let Some(o) = self.pose_offset(s.camera) {
                            // camera_from_rig <- exp(d) camera_from_rig: d p / d d = -[R_c p_rig]_x.
                            jg.view_mut((0, o), (2, 3))
                                .copy_from(&(d_point * (-skew(&(r_c * p_rig)))));
                            jg.view_mut((0, o + 3), (2, 3)).copy_from(&d_point);
                        }
                        let d_rig = d_point * r_c;
                        let mut jb = DMatrix::zeros(2, 6);
                        jb.view_mut((0, 0), (2, 3))
                            .copy_from(&(d_rig * (-skew(&rotated))));
                        jb.view_mut((0, 3), (2, 3)).copy_from(&d_rig);
                        (jg, jb)
                    } else {
                        (DMatrix::zeros(2, 0), DMatrix::zeros(2, 0))
                    };
                    out.push(ResidualBlock {
                        block: Some(b),
                        residuals,
                        jac_global,
                        jac_block,
                    });
                }
            }
        }
        Ok(out)
    }

    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        let n_params = self.params_offset(self.cameras.len());
        let mut global: Vec<f64> = params.global[..n_params]
            .iter()
            .zip(&step.global[..n_params])
            .map(|(x, d)| x + d)
            .collect();
        for o in (n_params..params.global.len()).step_by(6) {
            global.extend(retract_pose(
                &params.global[o..o + 6],
                &step.global[o..o + 6],
            ));
        }
        let blocks = params
            .blocks
            .iter()
            .zip(&step.blocks)
            .map(|(b, d)| retract_pose(b, d))
            .collect();
        BlockParams { global, blocks }
    }
}
