//! The bundle-adjustment problem of planar calibration for the shared
//! solver: global parameters = the camera's [`Camera::params`], one block
//! per view = its pose `[rotation vector (3), translation_m (3)]`, one
//! residual block per used point = projected - observed pixel. With the
//! board warp estimated ([`BoardExtent`]), two more global parameters
//! follow the camera's; a splined lens adds its smoothness prior as
//! residual blocks of no view.

use super::View;
use crate::camera::{Camera, Distortion, N_PINHOLE_PARAMS};
use crate::error::{Error, Result};
use crate::geometry::{params_from_pose, rotation_from_rotvec, rotvec_from_rotation, Pose};
use crate::optim::{BlockParams, BlockProblem, ResidualBlock, ResidualRun};
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
    /// With the board warp estimated: the board's point extent; the warp's
    /// two parameters (metres) follow the camera's in the global vector.
    pub warp: Option<BoardExtent>,
}

/// The extent of a planar board's points, for mrcal's two-parameter warp:
/// a point at board (x, y) moves along the board's z by
/// `warp_x (1 - xr^2) + warp_y (1 - yr^2)`, with `xr = 2 (x - x0) / width - 1`
/// and `yr` likewise (-1 to 1 over the points): 0 at the edges, the sum at
/// the centre (mrcal's `calobject_warp`, in metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BoardExtent {
    pub x0: f64,
    pub width: f64,
    pub y0: f64,
    pub height: f64,
}

impl BoardExtent {
    /// The extent of every view's points; `None` when they span no area.
    pub fn of(views: &[View]) -> Option<BoardExtent> {
        let pts = views.iter().flat_map(|v| v.object_m.iter());
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in pts {
            lo = [lo[0].min(p.x), lo[1].min(p.y)];
            hi = [hi[0].max(p.x), hi[1].max(p.y)];
        }
        let (width, height) = (hi[0] - lo[0], hi[1] - lo[1]);
        (width > 0.0 && height > 0.0 && width.is_finite() && height.is_finite()).then_some(
            BoardExtent {
                x0: lo[0],
                width,
                y0: lo[1],
                height,
            },
        )
    }

    /// The z offset of board point (x, y) under warp `w` and its
    /// derivatives with respect to `w`.
    pub fn bow(&self, x: f64, y: f64, w: [f64; 2]) -> (f64, [f64; 2]) {
        let xr = 2.0 * (x - self.x0) / self.width - 1.0;
        let yr = 2.0 * (y - self.y0) / self.height - 1.0;
        let d = [1.0 - xr * xr, 1.0 - yr * yr];
        (w[0] * d[0] + w[1] * d[1], d)
    }
}

/// The 6-vector of a pose (rotation vector, translation) as an LM block.
pub(crate) fn block_from_pose(pose: &Pose) -> Vec<f64> {
    params_from_pose(pose).to_vec()
}

pub(crate) use crate::geometry::pose_from_params as pose_from_block;

impl CalibProblem<'_> {
    /// The camera of a global parameter vector.
    pub fn camera(&self, global: &[f64]) -> Result<Camera> {
        let n = self.n_camera();
        let expected = n + if self.warp.is_some() { 2 } else { 0 };
        if global.len() != expected || n < 2 {
            return Err(Error::invalid(
                "params",
                format!(
                    "the calibration has {expected} global parameters, got {}",
                    global.len()
                ),
            ));
        }
        let mut g = global[..n].to_vec();
        if let Some(a) = self.aspect {
            g[1] = a * g[0];
        }
        self.template.with_params(&g)
    }

    /// The camera's parameter count (the global vector's first entries).
    pub fn n_camera(&self) -> usize {
        N_PINHOLE_PARAMS + self.template.distortion.coefficient_names().len()
    }

    /// The global vector of `camera` (and a flat board when warped).
    pub fn global_of(&self, camera: &Camera) -> Vec<f64> {
        let mut g = camera.params();
        if self.warp.is_some() {
            g.extend([0.0, 0.0]);
        }
        g
    }

    /// The warp `[warp_x, warp_y]` (metres) of a global vector; zero
    /// without the warp.
    pub fn warp_of(&self, global: &[f64]) -> [f64; 2] {
        let n = self.n_camera();
        match (self.warp, global.get(n), global.get(n + 1)) {
            (Some(_), Some(&x), Some(&y)) => [x, y],
            _ => [0.0, 0.0],
        }
    }

    /// Whether a pose step turns the whole pose (`[R | t] <- exp(d) [R | t]`,
    /// then `t += dt`) rather than its rotation alone: for a splined lens.
    fn whole_pose_steps(&self) -> bool {
        matches!(self.template.distortion, Distortion::Splined(_))
    }

    /// The smoothness prior of a splined lens: per second difference of
    /// neighbouring control values' change from the template's (the
    /// start's), `weight * f * (d0 - 2 d1 + d2)` with `d = c - c_start`,
    /// for the x and the y correction (pixels; f the mean focal length of
    /// the template, a constant). Measured from the start (the parametric
    /// fit's lens) because a fisheye's own correction from the
    /// stereographic base curves strongly towards the border: a prior on
    /// the correction itself pulled the border cells, where a few points
    /// hold it, towards a straight extrapolation (5.4 px off the truth
    /// where the uncertainty map said 0.86 px, BENCHMARKS 17 L3).
    fn smoothness_blocks(
        &self,
        camera: &Camera,
        n_global: usize,
        jacobians: bool,
    ) -> Vec<ResidualBlock> {
        let (Distortion::Splined(start), Distortion::Splined(s)) =
            (&self.template.distortion, &camera.distortion)
        else {
            return Vec::new();
        };
        let scale = start.smoothness * 0.5 * (self.template.fx + self.template.fy);
        if !(scale > 0.0) {
            return Vec::new();
        }
        // The prior smooths what the data add to the start's lens, not the
        // lens itself; a start without control values is the zero lens.
        let reference = |k: usize| start.control.get(k).copied().unwrap_or(0.0);
        s.smoothness_stencils()
            .into_iter()
            .map(|idx| {
                let coef = [1.0, -2.0, 1.0];
                let mut r = DVector::zeros(2);
                let mut j = DMatrix::zeros(2, if jacobians { n_global } else { 0 });
                for (k, c) in idx.iter().zip(coef) {
                    for comp in 0..2 {
                        r[comp] += scale * c * (s.control[k + comp] - reference(k + comp));
                        if jacobians {
                            j[(comp, N_PINHOLE_PARAMS + k + comp)] = scale * c;
                        }
                    }
                }
                ResidualBlock {
                    block: None,
                    residuals: r,
                    jac_global: j,
                    jac_block: DMatrix::zeros(2, 0),
                }
            })
            .collect()
    }
}

impl CalibProblem<'_> {
    /// One run per view with used points: see [`BlockProblem::residual_runs`].
    fn runs(&self, params: &BlockParams) -> Result<Vec<ResidualRun>> {
        let camera = self.camera(&params.global)?;
        let n_global = params.global.len();
        let n_camera = self.n_camera();
        let warp = self.warp_of(&params.global);
        // The polynomial lens's coefficients taken once, not per point.
        let poly = camera.poly_parts();
        let mut out = Vec::with_capacity(self.views.len());
        for (b, view) in self.views.iter().enumerate() {
            let rows = 2 * self.used[b].iter().filter(|u| **u).count();
            if rows == 0 {
                continue;
            }
            let pose = pose_from_block(&params.blocks[b]);
            // The view's rotation as a matrix once, not the quaternion turn
            // per point (about half the flops).
            let rotation = pose.rotation.to_rotation_matrix();
            let mut residuals = DVector::zeros(rows);
            let mut jg_t = DMatrix::zeros(n_global, rows);
            let mut jb_t = DMatrix::zeros(6, rows);
            let mut k = 0;
            for (i, (object, observed)) in view.object_m.iter().zip(&view.image_px).enumerate() {
                if !self.used[b][i] {
                    continue;
                }
                let mut board = object.coords;
                let mut d_warp = [0.0; 2];
                if let Some(extent) = &self.warp {
                    let (dz, d) = extent.bow(board.x, board.y, warp);
                    board.z += dz;
                    d_warp = d;
                }
                let rotated = rotation * board;
                let p = Point3::from(rotated + pose.translation.vector);
                let column = |c: usize, x: f64, y: f64| {
                    if c < n_camera {
                        jg_t[(c, k)] = x;
                        jg_t[(c, k + 1)] = y;
                    }
                };
                let (pixel, d_point) = match &poly {
                    Some((poly, cols)) => {
                        camera.poly_jacobian_columns(poly, cols, &p.coords, column)
                    }
                    None => camera.project_with_jacobian_columns(&p, column),
                }?;
                residuals[k] = pixel.x - observed.x;
                residuals[k + 1] = pixel.y - observed.y;
                // Left perturbation R <- exp(d) R: d(R x)/dd = -[R x]_x.
                let d_rot = d_point * (-skew(&rotated));
                for r in 0..2 {
                    for c in 0..3 {
                        jb_t[(c, k + r)] = d_rot[(r, c)];
                        jb_t[(c + 3, k + r)] = d_point[(r, c)];
                    }
                }
                if let Some(a) = self.aspect {
                    for r in 0..2 {
                        jg_t[(0, k + r)] += a * jg_t[(1, k + r)];
                        jg_t[(1, k + r)] = 0.0;
                    }
                }
                if self.warp.is_some() {
                    // d p / d warp_i = R e_z d_i.
                    let along = d_point * (rotation * Vector3::z());
                    for (i, d) in d_warp.iter().enumerate() {
                        jg_t[(n_camera + i, k)] = along.x * d;
                        jg_t[(n_camera + i, k + 1)] = along.y * d;
                    }
                }
                k += 2;
            }
            out.push(ResidualRun {
                block: Some(b),
                group: 2,
                residuals,
                jac_global_t: jg_t,
                jac_block_t: jb_t,
            });
        }
        Ok(out)
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
        let n_global = params.global.len();
        let warp = self.warp_of(&params.global);
        let n_used = self.used.iter().flatten().filter(|u| **u).count();
        let mut out = Vec::with_capacity(n_used);
        for (b, view) in self.views.iter().enumerate() {
            let pose = pose_from_block(&params.blocks[b]);
            let rotation = pose.rotation.to_rotation_matrix();
            for (i, (object, observed)) in view.object_m.iter().zip(&view.image_px).enumerate() {
                if !self.used[b][i] {
                    continue;
                }
                let mut board = object.coords;
                let mut d_warp = [0.0; 2];
                if let Some(extent) = &self.warp {
                    let (dz, d) = extent.bow(board.x, board.y, warp);
                    board.z += dz;
                    d_warp = d;
                }
                let rotated = rotation * board;
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
                    // Left perturbation R <- exp(d) R: d(R x)/dd = -[R x]_x;
                    // of the whole pose (splined): d(R x + t)/dd = -[R x + t]_x.
                    let d_rot = if self.whole_pose_steps() {
                        d_point * (-skew(&p.coords))
                    } else {
                        d_point * (-skew(&rotated))
                    };
                    let mut j = DMatrix::zeros(2, 6);
                    j.view_mut((0, 0), (2, 3)).copy_from(&d_rot);
                    j.view_mut((0, 3), (2, 3)).copy_from(&d_point);
                    if let Some(a) = self.aspect {
                        for r in 0..2 {
                            d_params[(r, 0)] += a * d_params[(r, 1)];
                            d_params[(r, 1)] = 0.0;
                        }
                    }
                    if self.warp.is_some() {
                        // d p / d warp_i = R e_z d_i.
                        let n = d_params.ncols();
                        d_params = d_params.resize_horizontally(n_global, 0.0);
                        let along = d_point * (rotation * Vector3::z());
                        for (i, d) in d_warp.iter().enumerate() {
                            d_params[(0, n + i)] = along.x * d;
                            d_params[(1, n + i)] = along.y * d;
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
        out.extend(self.smoothness_blocks(&camera, n_global, jacobians));
        Ok(out)
    }

    /// The residual blocks of every view but a splined lens's (whose prior
    /// adds blocks of no view) stacked per view as they are computed: the
    /// same values as [`Self::residuals_and_jacobian`], without its three
    /// small matrices per point.
    fn residual_runs(&self, params: &BlockParams) -> Option<Result<Vec<ResidualRun>>> {
        if matches!(self.template.distortion, Distortion::Splined(_)) {
            return None;
        }
        Some(self.runs(params))
    }

    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        let global = params
            .global
            .iter()
            .zip(&step.global)
            .map(|(x, d)| x + d)
            .collect();
        let whole = self.whole_pose_steps();
        let blocks = params
            .blocks
            .iter()
            .zip(&step.blocks)
            .map(|(b, d)| {
                let rotation = rotation_from_rotvec(&Vector3::new(d[0], d[1], d[2]))
                    * rotation_from_rotvec(&Vector3::new(b[0], b[1], b[2]));
                let r = rotvec_from_rotation(&rotation);
                let mut t = Vector3::new(b[3], b[4], b[5]);
                if whole {
                    t = rotation_from_rotvec(&Vector3::new(d[0], d[1], d[2])) * t;
                }
                vec![r.x, r.y, r.z, t.x + d[3], t.y + d[4], t.z + d[5]]
            })
            .collect();
        BlockParams { global, blocks }
    }
}

#[cfg(test)]
#[path = "refine_tests.rs"]
mod tests;
