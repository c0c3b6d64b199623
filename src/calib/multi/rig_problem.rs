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
//! solver's Schur accumulation likes. The residual blocks and the
//! retraction are those of [`crate::calib::multi::block_problem`].

use crate::calib::multi::block_problem::{push_view_residuals, retract, Mount, Sight};
use crate::calib::refine::{pose_from_block, CalibProblem};
use crate::camera::Camera;
use crate::error::Result;
use crate::geometry::Pose;
use crate::optim::{BlockParams, BlockProblem, ResidualBlock};

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
        // The rig camera's mount is the identity, held.
        let mounts: Vec<Mount> = (0..self.cameras.len())
            .map(|k| Mount::new(self.camera_from_rig(g, k), self.pose_offset(k)))
            .collect();
        let mut out = Vec::new();
        for (b, sightings) in self.frames.iter().enumerate() {
            let rig_from_target = pose_from_block(&params.blocks[b]);
            for s in sightings {
                let sight = Sight {
                    problem: &self.cameras[s.camera],
                    camera: &cameras[s.camera],
                    params_offset: self.params_offset(s.camera),
                    mount: Some(&mounts[s.camera]),
                    view: s.view,
                };
                push_view_residuals(&sight, b, &rig_from_target, n_global, jacobians, &mut out)?;
            }
        }
        Ok(out)
    }

    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        retract(params, step, self.params_offset(self.cameras.len()))
    }
}
