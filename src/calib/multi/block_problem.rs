//! The one helper the stereo and rig refinements build their block problems
//! with: the residual blocks of a camera's view of a board (pixel residuals,
//! the Jacobian columns of the camera's intrinsics, of where the camera is
//! mounted when that is free, and of the board pose block), the left
//! retraction of a `[rotation vector, translation_m]` 6-vector, and the
//! retraction of a global vector of intrinsics followed by mount poses.
//!
//! The board pose of a block is `frame_from_target` (stereo: the left
//! camera's; rig: the rig's); a camera sees board point X at
//! `camera_from_frame * frame_from_target * X`, with `camera_from_frame`
//! absent for the camera whose frame it is (stereo's left camera).

use crate::calib::refine::CalibProblem;
use crate::camera::Camera;
use crate::error::Result;
use crate::geometry::{rotation_from_rotvec, rotvec_from_rotation, Pose};
use crate::optim::{BlockParams, ResidualBlock};
use nalgebra::{DMatrix, DVector, Matrix2x3, Matrix3, Point3, Vector3};

/// Where a camera is mounted in the frame of the board poses:
/// `camera_from_frame`, its rotation matrix, and the offset of its
/// `[rotation vector, translation_m]` in the global vector (`None`: held,
/// as the rig camera's identity).
pub(crate) struct Mount {
    pub pose: Pose,
    pub rotation: Matrix3<f64>,
    pub offset: Option<usize>,
}

impl Mount {
    /// The mount at `camera_from_frame`, free at `offset` or held.
    pub fn new(camera_from_frame: Pose, offset: Option<usize>) -> Mount {
        Mount {
            rotation: camera_from_frame.rotation.to_rotation_matrix().into_inner(),
            pose: camera_from_frame,
            offset,
        }
    }
}

/// One camera's view of one board pose block.
pub(crate) struct Sight<'a> {
    /// The camera's problem: its views, point masks and aspect.
    pub problem: &'a CalibProblem<'a>,
    /// The camera at the current global vector.
    pub camera: &'a Camera,
    /// Offset of the camera's intrinsics in the global vector.
    pub params_offset: usize,
    /// Where the camera is mounted; `None` for the frame's own camera.
    pub mount: Option<&'a Mount>,
    /// The index of the view in the problem's views.
    pub view: usize,
}

/// Push the residual block of every used point of `sight`, the board at
/// `frame_from_target` (pose block `block`), onto `out`; Jacobians (2 x
/// `n_global` and 2 x 6) only when `jacobians`. Perturbations are on the
/// left: `R <- exp(d) R`, so `d p / d d = -[R p]_x`.
pub(crate) fn push_view_residuals(
    sight: &Sight,
    block: usize,
    frame_from_target: &Pose,
    n_global: usize,
    jacobians: bool,
    out: &mut Vec<ResidualBlock>,
) -> Result<()> {
    let problem = sight.problem;
    let view = &problem.views[sight.view];
    let points = view.object_m.iter().zip(&view.image_px).enumerate();
    for (i, (object, observed)) in points {
        if !problem.used[sight.view][i] {
            continue;
        }
        let rotated = frame_from_target.rotation * object.coords;
        let p_frame = rotated + frame_from_target.translation.vector;
        let p = match sight.mount {
            None => Point3::from(p_frame),
            Some(mount) => mount.pose * Point3::from(p_frame),
        };
        let (pixel, d_point, mut d_params) = if jacobians {
            sight.camera.project_with_jacobians(&p)?
        } else {
            (
                sight.camera.project(&p)?,
                Matrix2x3::zeros(),
                DMatrix::zeros(2, 0),
            )
        };
        let residuals = DVector::from_vec(vec![pixel.x - observed.x, pixel.y - observed.y]);
        let (jac_global, jac_block) = if jacobians {
            fold_aspect(&mut d_params, problem.aspect);
            let mut jg = DMatrix::zeros(2, n_global);
            jg.view_mut((0, sight.params_offset), (2, d_params.ncols()))
                .copy_from(&d_params);
            let d_frame = match sight.mount {
                None => d_point,
                Some(mount) => {
                    if let Some(o) = mount.offset {
                        let turned = mount.rotation * p_frame;
                        jg.view_mut((0, o), (2, 3))
                            .copy_from(&(d_point * (-turned.cross_matrix())));
                        jg.view_mut((0, o + 3), (2, 3)).copy_from(&d_point);
                    }
                    d_point * mount.rotation
                }
            };
            let mut jb = DMatrix::zeros(2, 6);
            jb.view_mut((0, 0), (2, 3))
                .copy_from(&(d_frame * (-rotated.cross_matrix())));
            jb.view_mut((0, 3), (2, 3)).copy_from(&d_frame);
            (jg, jb)
        } else {
            (DMatrix::zeros(2, 0), DMatrix::zeros(2, 0))
        };
        out.push(ResidualBlock {
            block: Some(block),
            residuals,
            jac_global,
            jac_block,
        });
    }
    Ok(())
}

/// Left-perturbation retraction of a `[rotvec, t]` 6-vector.
pub(crate) fn retract_pose(b: &[f64], d: &[f64]) -> Vec<f64> {
    let rotation = rotation_from_rotvec(&Vector3::new(d[0], d[1], d[2]))
        * rotation_from_rotvec(&Vector3::new(b[0], b[1], b[2]));
    let r = rotvec_from_rotation(&rotation);
    vec![r.x, r.y, r.z, b[3] + d[3], b[4] + d[4], b[5] + d[5]]
}

/// The retraction of a global vector whose first `n_params` entries are
/// intrinsics (added) and the rest mount poses (retracted 6 by 6), and of
/// every board pose block.
pub(crate) fn retract(params: &BlockParams, step: &BlockParams, n_params: usize) -> BlockParams {
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

/// Fold the fixed-aspect column (fy = aspect * fx) into fx's.
pub(crate) fn fold_aspect(d_params: &mut DMatrix<f64>, aspect: Option<f64>) {
    if let Some(a) = aspect {
        for r in 0..2 {
            d_params[(r, 0)] += a * d_params[(r, 1)];
            d_params[(r, 1)] = 0.0;
        }
    }
}
