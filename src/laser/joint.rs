//! Joint refinement of the camera with the laser plane: one
//! Levenberg-Marquardt ([`crate::optim`]) over the camera's parameters
//! (all of [`Camera::params`]), every board pose and the plane, minimising
//! the boards' corner reprojection errors (pixels over the corners' std)
//! and the stripe centres' image residuals (pixels along the scan over
//! their std, as in [`super::fit`]) together. For a camera whose
//! calibration is a little off (another focus, a knock): the boards in the
//! laser images recalibrate it while the plane is fitted.
//!
//! Parameters: the camera's free ones in the global vector (all, or all
//! but those [`refine_holding`] holds), then the plane's `(a,
//! b, d)` about the starting plane (the normal `exp(a e1 + b e2) n0`); one
//! block of 6 numbers (rotation vector, translation) per board pose.
//! Jacobians by central differences (a few dozen parameters; each image's
//! residuals depend on its own pose only).

use super::plane::{board_plane, LaserPlane, StripeObservation};
use crate::camera::{Camera, Distortion};
use crate::error::{Error, Result};
use crate::geometry::{params_from_pose, pose_from_params, tangent_basis, Plane, Pose};
use crate::optim::{self, BlockParams, BlockProblem, LmOptions, ResidualBlock};
use nalgebra::{DMatrix, DVector, Point2, Point3, UnitQuaternion, Vector2};

/// One board pose's data for the joint refinement.
#[derive(Debug, Clone, PartialEq)]
pub struct JointImage {
    /// The board's points (target frame, metres) ...
    pub object_m: Vec<Point3<f64>>,
    /// ... and where they were detected, pixels.
    pub image_px: Vec<Point2<f64>>,
    /// The corners' standard deviation per coordinate, pixels.
    pub corner_std_px: f64,
    /// The board's pose to start from.
    pub camera_from_target: Pose,
    /// Stripe centres on the board: pixel and std along the scan (pixels).
    pub stripe: Vec<(Point2<f64>, f64)>,
    /// The centres were measured along columns (a horizontal stripe).
    pub scan_along_y: bool,
}

/// The joint solution.
#[derive(Debug, Clone)]
pub struct JointSolution {
    /// The refined camera.
    pub camera: Camera,
    /// The refined board poses, in the order of the images.
    pub camera_from_target: Vec<Pose>,
    /// The refined plane.
    pub plane: LaserPlane,
    /// Corner reprojection RMS after / before, pixels.
    pub corner_rms_px: (f64, f64),
}

struct Problem<'a> {
    camera: &'a Camera,
    images: &'a [JointImage],
    plane0: Plane,
    /// Indices into [`Camera::params`] of the refined parameters (the
    /// first `n_camera` entries of the global vector).
    free: Vec<usize>,
    n_camera: usize,
}

impl Problem<'_> {
    /// The camera with the free parameters from `global`, the held ones
    /// at the start camera's.
    fn camera_at(&self, global: &[f64]) -> Result<Camera> {
        let mut p = self.camera.params();
        for (k, &i) in self.free.iter().enumerate() {
            p[i] = global[k];
        }
        self.camera.with_params(&p)
    }

    fn plane(&self, global: &[f64]) -> Plane {
        let (e1, e2) = tangent_basis(&self.plane0.normal);
        let p = &global[self.n_camera..];
        Plane {
            normal: UnitQuaternion::from_scaled_axis(e1 * p[0] + e2 * p[1]) * self.plane0.normal,
            distance_m: self.plane0.distance_m + p[2],
        }
    }

    /// The residuals of image `i`: its corners (2 each) then its centres.
    fn image_residuals(&self, i: usize, global: &[f64], pose: &[f64]) -> Result<DVector<f64>> {
        let camera = self.camera_at(global)?;
        let plane = self.plane(global);
        let pose = pose_from_params(pose);
        let img = &self.images[i];
        let mut r = Vec::with_capacity(2 * img.object_m.len() + img.stripe.len());
        for (p, q) in img.object_m.iter().zip(&img.image_px) {
            let u = camera.project(&(pose * p))?;
            let d: Vector2<f64> = (u - q) / img.corner_std_px;
            r.extend([d.x, d.y]);
        }
        for (px, std) in &img.stripe {
            let o = StripeObservation::new(&camera, &pose, px, img.scan_along_y, *std, i)?;
            let nt = plane.normal.dot(&o.along_scan_m_per_px);
            let e = plane.signed_distance_m(&o.point_camera.coords);
            r.push(if nt.abs() < 1e-15 { 0.0 } else { e / nt / std });
        }
        Ok(DVector::from_vec(r))
    }
}

impl BlockProblem for Problem<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jacobians: bool,
    ) -> Result<Vec<ResidualBlock>> {
        let mut out = Vec::with_capacity(self.images.len());
        for (i, pose) in params.blocks.iter().enumerate() {
            let residuals = self.image_residuals(i, &params.global, pose)?;
            let (mut jac_global, mut jac_block) = (DMatrix::zeros(0, 0), DMatrix::zeros(0, 0));
            if jacobians {
                let m = residuals.len();
                jac_global = DMatrix::zeros(m, params.global.len());
                for k in 0..params.global.len() {
                    let h = step(params.global[k], k < self.n_camera);
                    let (mut plus, mut minus) = (params.global.clone(), params.global.clone());
                    plus[k] += h;
                    minus[k] -= h;
                    let col = (self.image_residuals(i, &plus, pose)?
                        - self.image_residuals(i, &minus, pose)?)
                        / (2.0 * h);
                    jac_global.set_column(k, &col);
                }
                jac_block = DMatrix::zeros(m, 6);
                for k in 0..6 {
                    let h = 1e-6;
                    let (mut plus, mut minus) = (pose.clone(), pose.clone());
                    plus[k] += h;
                    minus[k] -= h;
                    let col = (self.image_residuals(i, &params.global, &plus)?
                        - self.image_residuals(i, &params.global, &minus)?)
                        / (2.0 * h);
                    jac_block.set_column(k, &col);
                }
            }
            out.push(ResidualBlock {
                block: Some(i),
                residuals,
                jac_global,
                jac_block,
            });
        }
        Ok(out)
    }
}

/// A central-difference step: relative for the camera's parameters (pixels
/// and coefficients), 1e-7 for the plane's.
fn step(value: f64, camera: bool) -> f64 {
    if camera {
        1e-6 * value.abs().max(1e-2)
    } else {
        1e-7
    }
}

fn corner_rms(camera: &Camera, images: &[JointImage], poses: &[Pose]) -> Result<f64> {
    let (mut s, mut n) = (0.0, 0usize);
    for (img, pose) in images.iter().zip(poses) {
        for (p, q) in img.object_m.iter().zip(&img.image_px) {
            s += (camera.project(&(pose * p))? - q).norm_squared();
            n += 1;
        }
    }
    Ok((s / n.max(1) as f64).sqrt())
}

/// Refine `camera`, the board poses and `plane` together (every camera
/// parameter free).
pub fn refine_with_intrinsics(
    camera: &Camera,
    images: &[JointImage],
    plane: &LaserPlane,
) -> Result<JointSolution> {
    refine_holding(camera, images, plane, &[])
}

/// [`refine_with_intrinsics`] with the camera parameters named in `held`
/// ([`Camera::param_names`]) kept at `camera`'s values; an unknown name is
/// an error naming the model's parameters.
pub fn refine_holding(
    camera: &Camera,
    images: &[JointImage],
    plane: &LaserPlane,
    held: &[&str],
) -> Result<JointSolution> {
    let names = camera.param_names();
    if let Some(bad) = held.iter().find(|h| !names.contains(h)) {
        return Err(Error::invalid(
            "held",
            format!(
                "the {} camera has no parameter '{bad}' (it has {})",
                camera.distortion.model_name(),
                names.join(", ")
            ),
        ));
    }
    let free: Vec<usize> = (0..names.len())
        .filter(|&i| !held.contains(&names[i]))
        .collect();
    if images.len() < 3 {
        return Err(Error::too_few(
            "board poses to refine the camera with the plane",
            3,
            images.len(),
        ));
    }
    if let Some(i) = images
        .iter()
        .position(|m| !(m.corner_std_px.is_finite() && m.corner_std_px > 0.0))
    {
        return Err(Error::invalid(
            "corner_std_px",
            format!(
                "image {} needs a corner std > 0 px, got {}",
                i + 1,
                images[i].corner_std_px
            ),
        ));
    }
    let n_camera = free.len();
    let start = camera.params();
    let mut global: Vec<f64> = free.iter().map(|&i| start[i]).collect();
    let problem = Problem {
        camera,
        images,
        plane0: *plane,
        free,
        n_camera,
    };
    global.extend([0.0, 0.0, 0.0]);
    let initial = BlockParams {
        global,
        blocks: images
            .iter()
            .map(|m| params_from_pose(&m.camera_from_target).to_vec())
            .collect(),
    };
    let before: Vec<Pose> = images.iter().map(|m| m.camera_from_target).collect();
    let lm = optim::solve(
        &problem,
        &initial,
        &LmOptions {
            max_iterations: 50,
            cost_tolerance: 1e-10,
            ..LmOptions::default()
        },
    )?;
    let refined = problem.camera_at(&lm.params.global)?;
    let poses: Vec<Pose> = lm
        .params
        .blocks
        .iter()
        .map(|b| pose_from_params(b))
        .collect();
    let plane = problem.plane(&lm.params.global).facing_away();
    // The board planes must stay in front of the camera.
    if poses.iter().any(|p| board_plane(p).distance_m.abs() < 1e-9) {
        return Err(Error::degenerate(
            "the joint refinement put a board through the camera centre",
        ));
    }
    Ok(JointSolution {
        corner_rms_px: (
            corner_rms(&refined, images, &poses)?,
            corner_rms(camera, images, &before)?,
        ),
        camera: refined,
        camera_from_target: poses,
        plane,
    })
}

/// The camera parameters the joint refinement ([`refine_holding`]) holds at
/// the given camera's, and a warning saying why when it is more than the
/// parameters held at 0.
///
/// - A zero skew or distortion coefficient was held at 0 by the board
///   calibration (OpenCV's `CALIB_FIX_*`, robocal's `--fix`): it stays so.
/// - A tilted (Scheimpflug) sensor's tilt trades with the principal point
///   and the decentering terms (correlation 0.999 over board poses: a
///   near-rotation of the camera frame, which the plane's normal follows).
///   The laser images' few boards cannot separate them: refined freely,
///   they drifted 1.40 deg along that direction (BENCHMARKS.md section 18),
///   so tau_x, tau_y, cx, cy, p1 and p2 are held at the board calibration's
///   and the warning says so.
pub fn held_parameters(camera: &Camera) -> (Vec<&'static str>, Option<String>) {
    let names = camera.param_names();
    let params = camera.params();
    let mut held: Vec<&'static str> = names
        .iter()
        .zip(&params)
        .skip(2)
        .filter(|(n, v)| **v == 0.0 && !matches!(**n, "cx" | "cy"))
        .map(|(n, _)| *n)
        .collect();
    let tilted = matches!(camera.distortion, Distortion::Tilted { .. });
    if !tilted {
        return (held, None);
    }
    for name in ["cx", "cy", "p1", "p2", "tau_x", "tau_y"] {
        if !held.contains(&name) {
            held.push(name);
        }
    }
    let free: Vec<&str> = names
        .iter()
        .filter(|n| !held.contains(n))
        .copied()
        .collect();
    (
        held,
        Some(format!(
            "tilted camera: its tilt (tau_x, tau_y), principal point and p1, p2 were held at the \
             given camera's (the boards cannot separate them: they trade with each other as a \
             near-rotation of the camera, which the plane's normal follows); refined: {}",
            free.join(", ")
        )),
    )
}
