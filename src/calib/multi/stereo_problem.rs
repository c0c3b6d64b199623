//! Joint stereo refinement as a block problem for the shared solver:
//! global = `[left camera params, right camera params, right_from_left
//! (rotation vector 3, translation_m 3)]`, one block per shared view = the
//! left camera's board pose `[rotation vector, translation_m]`; the right
//! camera sees the board at `right_from_left * left_from_target`.

use crate::calib::refine::{pose_from_block, CalibProblem};
use crate::error::Result;
use crate::geometry::{rotation_from_rotvec, rotvec_from_rotation, Pose};
use crate::optim::{BlockParams, BlockProblem, ResidualBlock};
use nalgebra::{DMatrix, DVector, Matrix2x3, Matrix3, Point3, Vector3};

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

pub(crate) fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Left-perturbation retraction of a `[rotvec, t]` 6-vector.
pub(crate) fn retract_pose(b: &[f64], d: &[f64]) -> Vec<f64> {
    let rotation = rotation_from_rotvec(&Vector3::new(d[0], d[1], d[2]))
        * rotation_from_rotvec(&Vector3::new(b[0], b[1], b[2]));
    let r = rotvec_from_rotation(&rotation);
    vec![r.x, r.y, r.z, b[3] + d[3], b[4] + d[4], b[5] + d[5]]
}

/// Fold the fixed-aspect column (fy = aspect * fx) into fx's.
pub(crate) fn fold_aspect(d_params: &mut DMatrix<f64>, aspect: Option<f64>) {
    if let Some(a) = aspect {
        for r in 0..2 {
            d_params[(r, 0)] += a * d_params[(r, 1)];
            d_params[(r, 1)] = 0.0;
        }
    }
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
        let rfl = self.right_from_left(g);
        let r_f = rfl.rotation.to_rotation_matrix().into_inner();
        let mut out = Vec::new();
        for (side, problem) in [(0, &self.left), (1, &self.right)] {
            let camera = if side == 0 {
                &left_camera
            } else {
                &right_camera
            };
            for (b, view) in problem.views.iter().enumerate() {
                let pose = pose_from_block(&params.blocks[b]);
                let points = view.object_m.iter().zip(&view.image_px).enumerate();
                for (i, (object, observed)) in points {
                    if !problem.used[b][i] {
                        continue;
                    }
                    let rotated = pose.rotation * object.coords;
                    let p_left = rotated + pose.translation.vector;
                    let p = if side == 0 {
                        Point3::from(p_left)
                    } else {
                        rfl * Point3::from(p_left)
                    };
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
                        let mut jb = DMatrix::zeros(2, 6);
                        if side == 0 {
                            jg.view_mut((0, 0), (2, nl)).copy_from(&d_params);
                            jb.view_mut((0, 0), (2, 3))
                                .copy_from(&(d_point * (-skew(&rotated))));
                            jb.view_mut((0, 3), (2, 3)).copy_from(&d_point);
                        } else {
                            jg.view_mut((0, nl), (2, nr)).copy_from(&d_params);
                            let o = nl + nr;
                            // R_f <- exp(d) R_f: d p / d d = -[R_f p_left]_x.
                            jg.view_mut((0, o), (2, 3))
                                .copy_from(&(d_point * (-skew(&(r_f * p_left)))));
                            jg.view_mut((0, o + 3), (2, 3)).copy_from(&d_point);
                            let d_left = d_point * r_f;
                            jb.view_mut((0, 0), (2, 3))
                                .copy_from(&(d_left * (-skew(&rotated))));
                            jb.view_mut((0, 3), (2, 3)).copy_from(&d_left);
                        }
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
        let o = self.rfl_offset();
        let mut global: Vec<f64> = params.global[..o]
            .iter()
            .zip(&step.global[..o])
            .map(|(x, d)| x + d)
            .collect();
        global.extend(retract_pose(
            &params.global[o..o + 6],
            &step.global[o..o + 6],
        ));
        let blocks = params
            .blocks
            .iter()
            .zip(&step.blocks)
            .map(|(b, d)| retract_pose(b, d))
            .collect();
        BlockParams { global, blocks }
    }
}
