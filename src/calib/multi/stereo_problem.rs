//! Joint stereo refinement as a block problem for the shared solver:
//! global = `[left camera params, right camera params, right_from_left
//! (rotation vector 3, translation_m 3)]`, one block per shared view = the
//! left camera's board pose `[rotation vector, translation_m]`; the right
//! camera sees the board at `right_from_left * left_from_target`. The
//! residual blocks and the retraction are those of
//! [`crate::calib::multi::block_problem`].

use crate::calib::multi::block_problem::{push_view_residuals, retract, Mount, Sight};
use crate::calib::refine::{pose_from_block, CalibProblem};
use crate::error::Result;
use crate::geometry::Pose;
use crate::optim::{BlockParams, BlockProblem, ResidualBlock};

/// Both cameras' problems (each holds its views, point masks and aspect
/// ratio); the right problem's views are paired by index with the left's.
pub(crate) struct StereoProblem<'a> {
    pub left: CalibProblem<'a>,
    pub right: CalibProblem<'a>,
    /// Number of left camera parameters (offset of the right ones).
    pub n_left: usize,
    /// Number of right camera parameters.
    pub n_right: usize,
}

impl StereoProblem<'_> {
    /// Offset of right_from_left in the global vector.
    pub fn rfl_offset(&self) -> usize {
        self.n_left + self.n_right
    }

    /// right_from_left of a global vector.
    pub fn right_from_left(&self, global: &[f64]) -> Pose {
        pose_from_block(&global[self.rfl_offset()..self.rfl_offset() + 6])
    }
}

impl BlockProblem for StereoProblem<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jacobians: bool,
    ) -> Result<Vec<ResidualBlock>> {
        let g = &params.global;
        let (nl, nr) = (self.n_left, self.n_right);
        let n_global = nl + nr + 6;
        let left_camera = self.left.camera(&g[..nl])?;
        let right_camera = self.right.camera(&g[nl..nl + nr])?;
        let right_mount = Mount::new(self.right_from_left(g), Some(self.rfl_offset()));
        let sides = [
            (&self.left, &left_camera, 0, None),
            (&self.right, &right_camera, nl, Some(&right_mount)),
        ];
        let mut out = Vec::new();
        for (problem, camera, params_offset, mount) in sides {
            for b in 0..problem.views.len() {
                let sight = Sight {
                    problem,
                    camera,
                    params_offset,
                    mount,
                    view: b,
                };
                let left_from_target = pose_from_block(&params.blocks[b]);
                push_view_residuals(&sight, b, &left_from_target, n_global, jacobians, &mut out)?;
            }
        }
        Ok(out)
    }

    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        retract(params, step, self.rfl_offset())
    }
}
