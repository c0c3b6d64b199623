//! The bundle-adjustment problem of planar calibration for the shared
//! solver: global parameters = the camera's [`Camera::params`], one block
//! per view = its pose `[rotation vector (3), translation_m (3)]`, one
//! residual block per used point = projected - observed pixel.

use super::View;
use crate::camera::Camera;
use crate::error::Result;
use crate::geometry::{params_from_pose, rotation_from_rotvec, rotvec_from_rotation, Pose};
use crate::optim::{BlockParams, BlockProblem, ResidualBlock};
use nalgebra::{DMatrix, DVector, Matrix2x3, Matrix3, Point3, Vector3};

/// Planar calibration as a block least-squares problem.
pub(crate) struct CalibProblem<'a> {
    /// Model and image size; parameter values come from the solver.
    pub template: &'a Camera,
    pub views: &'a [View],
    /// Per view, per point: used (true) or rejected as an outlier.
    pub used: &'a [Vec<bool>],
    /// With a fixed aspect ratio, `fy = aspect * fx` and fy's column folds into fx's.
    pub aspect: Option<f64>,
}

/// The 6-vector of a pose (rotation vector, translation) as an LM block.
pub(crate) fn block_from_pose(pose: &Pose) -> Vec<f64> {
    params_from_pose(pose).to_vec()
}

pub(crate) use crate::geometry::pose_from_params as pose_from_block;

impl CalibProblem<'_> {
    /// The camera of a global parameter vector.
    pub fn camera(&self, global: &[f64]) -> Result<Camera> {
        let mut g = global.to_vec();
        if let Some(a) = self.aspect {
            g[1] = a * g[0];
        }
        self.template.with_params(&g)
    }
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

impl BlockProblem for CalibProblem<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jacobians: bool,
    ) -> Result<Vec<ResidualBlock>> {
        let camera = self.camera(&params.global)?;
        let n_used = self.used.iter().flatten().filter(|u| **u).count();
        let mut out = Vec::with_capacity(n_used);
        for (b, view) in self.views.iter().enumerate() {
            let pose = pose_from_block(&params.blocks[b]);
            for (i, (object, observed)) in view.object_m.iter().zip(&view.image_px).enumerate() {
                if !self.used[b][i] {
                    continue;
                }
                let rotated = pose.rotation * object.coords;
                let p = Point3::from(rotated + pose.translation.vector);
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
                    DVector::from_column_slice(&[pixel.x - observed.x, pixel.y - observed.y]);
                let jac_block = if jacobians {
                    // Left perturbation R <- exp(d) R: d(R x)/dd = -[R x]_x.
                    let d_rot = d_point * (-skew(&rotated));
                    let mut j = DMatrix::zeros(2, 6);
                    j.view_mut((0, 0), (2, 3)).copy_from(&d_rot);
                    j.view_mut((0, 3), (2, 3)).copy_from(&d_point);
                    if let Some(a) = self.aspect {
                        for r in 0..2 {
                            d_params[(r, 0)] += a * d_params[(r, 1)];
                            d_params[(r, 1)] = 0.0;
                        }
                    }
                    j
                } else {
                    DMatrix::zeros(2, 0)
                };
                out.push(ResidualBlock {
                    block: Some(b),
                    residuals,
                    jac_global: d_params,
                    jac_block,
                });
            }
        }
        Ok(out)
    }

    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        let global = params
            .global
            .iter()
            .zip(&step.global)
            .map(|(x, d)| x + d)
            .collect();
        let blocks = params
            .blocks
            .iter()
            .zip(&step.blocks)
            .map(|(b, d)| {
                let rotation = rotation_from_rotvec(&Vector3::new(d[0], d[1], d[2]))
                    * rotation_from_rotvec(&Vector3::new(b[0], b[1], b[2]));
                let r = rotvec_from_rotation(&rotation);
                vec![r.x, r.y, r.z, b[3] + d[3], b[4] + d[4], b[5] + d[5]]
            })
            .collect();
        BlockParams { global, blocks }
    }
}
