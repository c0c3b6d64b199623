//! Refinement that minimises what was measured: the reprojection error of
//! the target points over the hand-eye transform `x` and the target pose `y`
//! (camera poses are not free: view `i` sees the target through
//! `camera_from_target[i] = x^-1 * robot[i]^-1 * y`), with the robot poses
//! trusted, given Gaussian priors, or with their noise estimated (Halcon's
//! "stochastic" idea), and optionally jointly with the camera intrinsics
//! (seed 003: one Levenberg-Marquardt over intrinsics, extrinsics and the
//! hand-eye transform, world = robot base).
//!
//! Non-image control points (seed 003's laser-stripe points with world
//! coordinates read from the robot) are the same problem with the "target"
//! being the world itself: set [`RefineOptions::points_in_world`] and `y` is
//! held at identity.
//!
//! Every pose parameter is 6 numbers `[rotation vector, translation]`; `x`
//! and `y` are updated by right perturbation `P <- P * exp(delta)`. A robot
//! correction is a decoupled left perturbation of `base_from_gripper` in the
//! base frame (`R <- exp(w) R`, `t <- t + v`), the noise model of
//! [`crate::handeye::refine::pose_residual`] and of the pose refinement, in both setups (eye-to-hand,
//! a correction of `gripper_from_base` would tie the translation noise to the
//! rotation noise through the lever arm from the base origin). Jacobians are
//! analytic through the chain `pixel = project(x^-1 robot^-1 y p)`.

use crate::calib::View;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{params_from_pose, pose_from_params};
use crate::handeye::math::skew;
use crate::handeye::refine::pose_residual::{
    difference, left_jacobian_inverse, perturb as perturb_left,
};
use crate::handeye::{Chain, Pose, Setup};
use crate::optim::{self, BlockParams, BlockProblem, LmOptions, ResidualBlock};
use nalgebra::{DMatrix, DVector, Matrix3, SMatrix, Vector3, Vector6};
use serde::{Deserialize, Serialize};

/// How far the robot poses are trusted.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RobotNoise {
    /// Robot poses are exact.
    Trusted,
    /// Each robot pose gets a correction with a Gaussian prior (std per
    /// rotation-vector component in radians, per translation component in
    /// metres; decoupled, in the base frame: `R <- exp(w) R`, `t <- t + v`).
    Prior {
        /// Rotation std (radians).
        rotation_sigma_rad: f64,
        /// Translation std (metres).
        translation_sigma_m: f64,
    },
    /// Start from a prior and re-estimate the std from the corrections
    /// ([`ESTIMATE_ROUNDS`] times).
    Estimate,
}

/// Rounds of noise re-estimation for [`RobotNoise::Estimate`].
pub const ESTIMATE_ROUNDS: usize = 3;
/// Starting prior of [`RobotNoise::Estimate`]: 0.5 mrad and 0.5 mm.
const ESTIMATE_START: (f64, f64) = (5e-4, 5e-4);

/// Refinement settings.
#[derive(Debug, Clone)]
pub struct RefineOptions {
    /// Also refine the camera intrinsics (all of `Camera::params`).
    pub intrinsics: bool,
    /// Robot pose model.
    pub robot_noise: RobotNoise,
    /// Expected pixel noise (px), the weight of the image residuals against
    /// the robot priors (default 0.5).
    pub pixel_sigma_px: f64,
    /// Object points are world coordinates (control points): `y` = identity, held.
    pub points_in_world: bool,
    /// Free one common scale of fx and fy, every other intrinsic held (the
    /// focal check of [`crate::handeye::quality::focal`]); the refined
    /// camera is returned. Ignored when `intrinsics` frees them all.
    pub focal_scale: bool,
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions {
            intrinsics: false,
            robot_noise: RobotNoise::Trusted,
            pixel_sigma_px: 0.5,
            points_in_world: false,
            focal_scale: false,
        }
    }
}

/// Refinement outcome.
#[derive(Debug, Clone)]
pub struct RefineResult {
    /// Refined `gripper_from_camera` / `base_from_camera`.
    pub x: Pose,
    /// Refined target pose.
    pub y: Pose,
    /// The camera (refined, or its focal length scaled, when requested).
    pub camera: Camera,
    /// Reprojection RMS over all points (px).
    pub reprojection_rms_px: f64,
    /// Reprojection RMS per view (px).
    pub per_view_rms_px: Vec<f64>,
    /// Corrected robot poses `base_from_gripper` (equal to the input when trusted).
    pub base_from_gripper: Vec<Pose>,
    /// Estimated robot noise (rotation rad, translation m) with priors.
    pub robot_noise_estimate: Option<(f64, f64)>,
    /// Std of `x` parameters (rotation vector rad x3, translation m x3), when available.
    pub x_std: Option<[f64; 6]>,
}

fn perturb(p: &[f64], d: &[f64]) -> Vec<f64> {
    params_from_pose(&(pose_from_params(p) * pose_from_params(d))).to_vec()
}

struct Problem<'a> {
    setup: Setup,
    /// The robot's `base_from_gripper` as given (the prior's centre).
    measured: &'a [Pose],
    views: &'a [View],
    camera: &'a Camera,
    intrinsics: bool,
    /// One common scale of fx and fy is `global[12]` (when not `intrinsics`).
    focal_scale: bool,
    pixel_weight: f64,
    prior: Option<(f64, f64)>,
}

impl Problem<'_> {
    fn camera_at(&self, g: &[f64]) -> Result<Camera> {
        if self.intrinsics {
            self.camera.with_params(&g[12..])
        } else if self.focal_scale {
            let s = g[12];
            if !(s.is_finite() && s > 0.0) {
                return Err(Error::invalid(
                    "focal_scale",
                    format!("must be positive and finite, got {s}"),
                ));
            }
            let mut camera = self.camera.clone();
            (camera.fx, camera.fy) = (s * self.camera.fx, s * self.camera.fy);
            Ok(camera)
        } else {
            Ok(self.camera.clone())
        }
    }

    /// `base_from_gripper` of view `i`: the corrected one (its block) with
    /// a prior, else as measured.
    fn robot_at(&self, params: &BlockParams, i: usize) -> Pose {
        match self.prior {
            Some(_) => pose_from_params(&params.blocks[i]),
            None => self.measured[i],
        }
    }
}

/// `robot[i]^-1` of the chain (the map from the target's side of the chain
/// to `x`'s): `gripper_from_base` eye-in-hand, `base_from_gripper` eye-to-hand.
pub(super) fn chain_robot_inverse(setup: Setup, base_from_gripper: &Pose) -> Pose {
    match setup {
        Setup::EyeInHand => base_from_gripper.inverse(),
        Setup::EyeToHand => *base_from_gripper,
    }
}

/// d u / d (decoupled left correction `[w, v]` of `base_from_gripper` =
/// `(R, t)`, base frame), for `u = chain_robot_inverse(robot) * q1`.
pub(super) fn robot_correction_jacobian(
    setup: Setup,
    robot: &Pose,
    q1: &Vector3<f64>,
) -> SMatrix<f64, 3, 6> {
    let r = robot.rotation.to_rotation_matrix().into_inner();
    let t = robot.translation.vector;
    let mut j = SMatrix::<f64, 3, 6>::zeros();
    match setup {
        // u = R^T (q1 - t) <- R^T exp(-w) (q1 - t - v).
        Setup::EyeInHand => {
            j.fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&(r.transpose() * skew(&(q1 - t))));
            j.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-r.transpose()));
        }
        // u = R q1 + t <- exp(w) R q1 + t + v.
        Setup::EyeToHand => {
            j.fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&(-skew(&(r * q1))));
            j.fixed_view_mut::<3, 3>(0, 3)
                .copy_from(&Matrix3::identity());
        }
    }
    j
}

impl BlockProblem for Problem<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jac: bool,
    ) -> Result<Vec<ResidualBlock>> {
        let g = &params.global;
        let (x, y) = (pose_from_params(&g[0..6]), pose_from_params(&g[6..12]));
        let camera = self.camera_at(g)?;
        let n_global = g.len();
        let mut out = Vec::new();
        for (i, view) in self.views.iter().enumerate() {
            let robot = self.robot_at(params, i);
            let robot_inv = chain_robot_inverse(self.setup, &robot);
            let (rx, ry) = (
                x.rotation.to_rotation_matrix().into_inner(),
                y.rotation.to_rotation_matrix().into_inner(),
            );
            let rr_inv = robot_inv.rotation.to_rotation_matrix().into_inner();
            for (p, obs) in view.object_m.iter().zip(&view.image_px) {
                let q1 = y * p;
                let u = robot_inv * q1;
                let w = x.inverse() * u;
                let (pixel, d_pt, d_cam) = camera.project_with_jacobians(&w)?;
                let r = (pixel - obs) * self.pixel_weight;
                let mut block = ResidualBlock {
                    block: self.prior.map(|_| i),
                    residuals: DVector::from_column_slice(r.as_slice()),
                    jac_global: DMatrix::zeros(2, 0),
                    jac_block: DMatrix::zeros(2, 0),
                };
                if jac {
                    let d_w = d_pt * self.pixel_weight;
                    let mut jg = DMatrix::zeros(2, n_global);
                    // d w / d x-perturbation: [w]x for rotation, -I for translation.
                    let d_u = d_w * rx.transpose();
                    let d_q1 = d_u * rr_inv;
                    let dx_rot = d_w * skew(&w.coords);
                    let dy_rot = d_q1 * (-ry * skew(&p.coords));
                    let dy_t = d_q1 * ry;
                    jg.view_mut((0, 0), (2, 3)).copy_from(&dx_rot);
                    jg.view_mut((0, 3), (2, 3)).copy_from(&(-d_w));
                    jg.view_mut((0, 6), (2, 3)).copy_from(&dy_rot);
                    jg.view_mut((0, 9), (2, 3)).copy_from(&dy_t);
                    if self.intrinsics {
                        jg.view_mut((0, 12), (2, d_cam.ncols()))
                            .copy_from(&(d_cam * self.pixel_weight));
                    } else if self.focal_scale {
                        // fx = s fx0, fy = s fy0: d pixel / d s.
                        let (fx0, fy0) = (self.camera.fx, self.camera.fy);
                        for row in 0..2 {
                            jg[(row, 12)] =
                                (d_cam[(row, 0)] * fx0 + d_cam[(row, 1)] * fy0) * self.pixel_weight;
                        }
                    }
                    block.jac_global = jg;
                    if self.prior.is_some() {
                        let jr = robot_correction_jacobian(self.setup, &robot, &q1.coords);
                        let jb = d_u * jr;
                        block.jac_block = DMatrix::from_column_slice(2, 6, jb.as_slice());
                    }
                }
                out.push(block);
            }
            if let Some((sr, st)) = self.prior {
                // Prior: the decoupled base-frame correction of
                // base_from_gripper (the noise model of pose_residual),
                // weighted by 1/sigma.
                let d = difference(&self.measured[i], &robot);
                let mut rv = d;
                rv.fixed_rows_mut::<3>(0).scale_mut(1.0 / sr);
                rv.fixed_rows_mut::<3>(3).scale_mut(1.0 / st);
                let mut jb = DMatrix::zeros(6, 6);
                if jac {
                    let phi = Vector3::new(d[0], d[1], d[2]);
                    jb.view_mut((0, 0), (3, 3))
                        .copy_from(&(left_jacobian_inverse(&phi) / sr));
                    jb.view_mut((3, 3), (3, 3))
                        .copy_from(&(Matrix3::identity() / st));
                }
                out.push(ResidualBlock {
                    block: Some(i),
                    residuals: DVector::from_column_slice(rv.as_slice()),
                    jac_global: DMatrix::zeros(6, if jac { n_global } else { 0 }),
                    jac_block: if jac { jb } else { DMatrix::zeros(6, 0) },
                });
            }
        }
        Ok(out)
    }

    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        let g = &params.global;
        let s = &step.global;
        let mut global = perturb(&g[0..6], &s[0..6]);
        global.extend(perturb(&g[6..12], &s[6..12]));
        global.extend(g[12..].iter().zip(&s[12..]).map(|(a, b)| a + b));
        BlockParams {
            global,
            blocks: params
                .blocks
                .iter()
                .zip(&step.blocks)
                .map(|(p, d)| {
                    let step = Vector6::from_iterator(d.iter().copied());
                    params_from_pose(&perturb_left(&pose_from_params(p), &step)).to_vec()
                })
                .collect(),
        }
    }
}

/// Refine `(x0, y0)` (e.g. the closed-form result) against the image points.
pub fn refine(
    setup: Setup,
    base_from_gripper: &[Pose],
    views: &[View],
    camera: &Camera,
    x0: &Pose,
    y0: &Pose,
    options: &RefineOptions,
) -> Result<RefineResult> {
    if views.len() != base_from_gripper.len() {
        return Err(Error::invalid(
            "views",
            format!(
                "{} views of image points but {} robot poses",
                views.len(),
                base_from_gripper.len()
            ),
        ));
    }
    // Validates the pose count; the corrections live on base_from_gripper.
    Chain::new(setup, base_from_gripper, base_from_gripper)?;
    let y_start = if options.points_in_world {
        Pose::identity()
    } else {
        *y0
    };
    let mut global = params_from_pose(x0).to_vec();
    global.extend(params_from_pose(&y_start).to_vec());
    let focal_scale = options.focal_scale && !options.intrinsics;
    if options.intrinsics {
        global.extend(camera.params());
    } else if focal_scale {
        global.push(1.0);
    }
    let mut fixed_global = vec![false; global.len()];
    if options.points_in_world {
        fixed_global[6..12].iter_mut().for_each(|f| *f = true);
    }
    let mut prior = match options.robot_noise {
        RobotNoise::Trusted => None,
        RobotNoise::Prior {
            rotation_sigma_rad,
            translation_sigma_m,
        } => Some((rotation_sigma_rad, translation_sigma_m)),
        RobotNoise::Estimate => Some(ESTIMATE_START),
    };
    let rounds = match options.robot_noise {
        RobotNoise::Estimate => ESTIMATE_ROUNDS,
        RobotNoise::Trusted | RobotNoise::Prior { .. } => 1,
    };
    if options.pixel_sigma_px <= 0.0 {
        return Err(Error::invalid("pixel_sigma_px", "must be positive"));
    }
    let mut params = BlockParams {
        global,
        blocks: match prior {
            Some(_) => base_from_gripper
                .iter()
                .map(|p| params_from_pose(p).to_vec())
                .collect(),
            None => Vec::new(),
        },
    };
    let mut result = None;
    for _ in 0..rounds {
        let problem = Problem {
            setup,
            measured: base_from_gripper,
            views,
            camera,
            intrinsics: options.intrinsics,
            focal_scale,
            pixel_weight: 1.0 / options.pixel_sigma_px,
            prior,
        };
        let lm = optim::solve(
            &problem,
            &params,
            &LmOptions {
                fixed_global: fixed_global.clone(),
                ..Default::default()
            },
        )?;
        params = lm.params.clone();
        if let (RobotNoise::Estimate, Some(_)) = (options.robot_noise, prior) {
            prior = Some(estimate_noise(base_from_gripper, &params.blocks));
        }
        result = Some((lm, problem.camera_at(&params.global)?));
    }
    let (lm, camera_out) = result.ok_or_else(|| Error::invalid("refine", "no round ran"))?;
    let x = pose_from_params(&params.global[0..6]);
    let y = pose_from_params(&params.global[6..12]);
    let robots: Vec<Pose> = match prior {
        Some(_) => params.blocks.iter().map(|b| pose_from_params(b)).collect(),
        None => base_from_gripper.to_vec(),
    };
    let mut per_view = Vec::new();
    let (mut sum, mut count) = (0.0, 0usize);
    for (view, robot) in views.iter().zip(&robots) {
        let camera_from_target = x.inverse() * chain_robot_inverse(setup, robot) * y;
        let (mut s, mut n) = (0.0, 0usize);
        for (p, obs) in view.object_m.iter().zip(&view.image_px) {
            let px = camera_out.project(&(camera_from_target * p))?;
            s += (px - obs).norm_squared();
            n += 1;
        }
        per_view.push(if n > 0 { (s / n as f64).sqrt() } else { 0.0 });
        sum += s;
        count += n;
    }
    let x_std = lm.std_global().map(|s| {
        // Residuals were divided by pixel_sigma: scale back is already in the
        // residual variance; report as is.
        [s[0], s[1], s[2], s[3], s[4], s[5]]
    });
    Ok(RefineResult {
        x,
        y,
        camera: camera_out,
        reprojection_rms_px: (sum / count.max(1) as f64).sqrt(),
        per_view_rms_px: per_view,
        base_from_gripper: robots,
        robot_noise_estimate: prior.filter(|_| options.robot_noise != RobotNoise::Trusted),
        x_std,
    })
}

/// Robot noise from the corrections (decoupled, base frame): RMS per
/// component of the rotation vectors (rad) and translations (m), floored to
/// keep the prior finite.
fn estimate_noise(robot0: &[Pose], blocks: &[Vec<f64>]) -> (f64, f64) {
    let (mut sr, mut st) = (0.0, 0.0);
    for (r0, b) in robot0.iter().zip(blocks) {
        let d = difference(r0, &pose_from_params(b));
        sr += d.fixed_rows::<3>(0).norm_squared();
        st += d.fixed_rows::<3>(3).norm_squared();
    }
    let n = (3 * robot0.len().max(1)) as f64;
    ((sr / n).sqrt().max(1e-7), (st / n).sqrt().max(1e-7))
}
