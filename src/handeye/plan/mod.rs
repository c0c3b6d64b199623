//! A pose plan for hand-eye calibration: from the robot's current pose and
//! one view of the target from it, `N` robot poses that keep the whole
//! target in view and at a working distance, rotate about well-separated
//! axes, are ordered for short moves, and come with the hand-eye error they
//! are predicted to reach at the work point.
//!
//! # How
//!
//! 1. **Where things are.** The current view fixes the target relative to
//!    the robot through a rough hand-eye guess (`guess`: `gripper_from_camera`
//!    eye-in-hand, `gripper_from_target` eye-to-hand, e.g. from CAD;
//!    identity when unknown): eye-in-hand `base_from_target = robot_now *
//!    guess * camera_now`, eye-to-hand `base_from_camera = robot_now *
//!    guess * inverse(camera_now)`. An error in the guess shifts every
//!    planned view by about that error; the image margin absorbs a few
//!    centimetres.
//! 2. **Candidate views.** The camera looks at the board's centre from a
//!    direction tilted by `0..=max_tilt_deg` from the board normal (eight
//!    azimuths), at three distances across the working range, rolled about
//!    its optical axis by up to `max_roll_deg` either way. A candidate is
//!    kept when every board point projects inside the image by
//!    `margin_px`, and the flange stays in the box (when given).
//! 3. **Choice.** Greedy A-optimal design: each step adds the candidate that
//!    most lowers the predicted position variance at the work point (the
//!    board centre, on every candidate's optical axis, at the middle of the
//!    distance range; the plan's `predicted` is then given where the
//!    report's default puts it: the board centre at the planned views' mean
//!    distance, [`crate::handeye::quality::work_point`]), from the
//!    Fisher information of the pose refinement
//!    ([`crate::handeye::refine::pose_problem::fisher_information`]) with
//!    each view's camera pose covariance predicted from the board points
//!    and the pixel noise ([`crate::handeye::refine::pose_shape`]) and
//!    isotropic robot noise. Large rotations about different axes are what
//!    lower it, so the plan has them without a rule for it.
//! 4. **Order.** Nearest neighbour from the current pose, then 2-opt, on a
//!    distance of flange travel plus rotation ([`order`]).
//!
//! Joint limits, reachability and collisions are **not** modelled: the
//! flange box is the only workspace limit; check the poses in the robot's
//! own simulator before running them.

pub mod noise;
pub mod order;

pub use noise::pixel_sigma_from_view;

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::handeye::closed_form::motion::{build_motions, motion_stats, MotionStats};
use crate::handeye::quality::work_point::{
    camera_axis_point, target_centre_camera, work_point_error, Placement, WorkPointError,
};
use crate::handeye::refine::pose_noise::{CameraNoise, NoiseModel};
use crate::handeye::refine::pose_problem::{fisher_information, Covariance12};
use crate::handeye::refine::pose_residual::PoseMeasurement;
use crate::handeye::refine::pose_shape::predicted_covariance;
use crate::handeye::{Chain, MotionPairs, Pose, Setup};
use nalgebra::{Matrix3, Point2, Point3, Rotation3, UnitQuaternion, Vector3};
use serde::Serialize;

/// Most poses a plan holds.
pub const MAX_PLAN_POSES: usize = 200;

/// What the plan may do.
#[derive(Debug, Clone)]
pub struct PlanLimits {
    /// Number of poses (default 15).
    pub poses: usize,
    /// Largest tilt of the board against the camera's view (degrees,
    /// default 40).
    pub max_tilt_deg: f64,
    /// Largest roll about the optical axis from the current view's
    /// (degrees, default 60).
    pub max_roll_deg: f64,
    /// Camera-to-board-centre distance range (m); default the current
    /// distance -20 % .. +20 %.
    pub distance_m: Option<(f64, f64)>,
    /// Box the flange must stay in, base frame (m): `(min, max)`.
    pub flange_box_m: Option<([f64; 3], [f64; 3])>,
    /// Every board point this far inside the image (px, default 20).
    pub margin_px: f64,
}

impl Default for PlanLimits {
    fn default() -> Self {
        PlanLimits {
            poses: 15,
            max_tilt_deg: 40.0,
            max_roll_deg: 60.0,
            distance_m: None,
            flange_box_m: None,
            margin_px: 20.0,
        }
    }
}

/// Where the plan's pixel noise comes from (the plan JSON's
/// `noise.pixel_sigma_from`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PixelNoiseSource {
    /// The default 0.3 px (nothing measured, nothing given).
    Default,
    /// Given by the user (`--pixel-noise`, `pixel_sigma_px`).
    Given,
    /// Measured on the current view's image points ([`pixel_sigma_from_view`]).
    MeasuredOnView,
}

/// The noise the prediction assumes.
#[derive(Debug, Clone, Copy)]
pub struct PlanNoise {
    /// Corner noise per axis (px, default 0.3; measured on the current
    /// view when its image points are known: [`pixel_sigma_from_view`]).
    pub pixel_sigma_px: f64,
    /// Where `pixel_sigma_px` comes from.
    pub pixel_sigma_from: PixelNoiseSource,
    /// Robot rotation noise per axis (degrees, default 0.02).
    pub robot_rotation_deg: f64,
    /// Robot translation noise per axis (mm, default 0.1).
    pub robot_translation_mm: f64,
}

impl Default for PlanNoise {
    fn default() -> Self {
        PlanNoise {
            pixel_sigma_px: 0.3,
            pixel_sigma_from: PixelNoiseSource::Default,
            robot_rotation_deg: 0.02,
            robot_translation_mm: 0.1,
        }
    }
}

/// What the plan starts from.
#[derive(Debug, Clone)]
pub struct PlanInput {
    /// Camera on the gripper or fixed.
    pub setup: Setup,
    /// The robot's current `base_from_gripper`.
    pub base_from_gripper: Pose,
    /// The camera's view of the target from it.
    pub camera_from_target: Pose,
    /// The camera.
    pub camera: Camera,
    /// The board points (target frame, m).
    pub board_m: Vec<Point3<f64>>,
    /// Rough `gripper_from_camera` (eye-in-hand) or `gripper_from_target`
    /// (eye-to-hand).
    pub guess: Pose,
}

/// One planned pose.
#[derive(Debug, Clone)]
pub struct PlannedPose {
    /// Where to send the flange.
    pub base_from_gripper: Pose,
    /// What the camera should then see.
    pub camera_from_target: Pose,
    /// Tilt of the board against the view (degrees).
    pub tilt_deg: f64,
    /// Camera to board centre (m).
    pub distance_m: f64,
    /// Roll about the optical axis from the current view's (degrees).
    pub roll_deg: f64,
}

/// The plan.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The poses in visiting order (from the current pose).
    pub poses: Vec<PlannedPose>,
    /// Predicted hand-eye error at the work point with these poses.
    pub predicted: WorkPointError,
    /// The predicted 12 x 12 covariance (as the report's).
    pub covariance: Vec<[f64; 12]>,
    /// Motion diversity of the plan (largest rotation, axis spread).
    pub motion: MotionStats,
    /// Flange travel along the tour, from the current pose (m).
    pub travel_m: f64,
    /// Candidates that passed the limits.
    pub candidates: usize,
    /// What the user should know.
    pub notes: Vec<String>,
    /// The noise the prediction assumed.
    pub noise: PlanNoise,
}

/// The transforms the views are mapped through: eye-in-hand
/// `base_from_target`, eye-to-hand `base_from_camera`.
fn anchor(input: &PlanInput) -> Pose {
    match input.setup {
        Setup::EyeInHand => input.base_from_gripper * input.guess * input.camera_from_target,
        Setup::EyeToHand => {
            input.base_from_gripper * input.guess * input.camera_from_target.inverse()
        }
    }
}

/// The flange pose that makes the camera see the target as `camera_from_target`.
pub fn robot_pose_for_view(input: &PlanInput, camera_from_target: &Pose) -> Pose {
    let a = anchor(input);
    match input.setup {
        Setup::EyeInHand => a * camera_from_target.inverse() * input.guess.inverse(),
        Setup::EyeToHand => a * camera_from_target * input.guess.inverse(),
    }
}

/// The hand-eye transforms `(x, y)` the guess implies.
fn implied_transforms(input: &PlanInput) -> (Pose, Pose) {
    match input.setup {
        Setup::EyeInHand => (input.guess, anchor(input)),
        Setup::EyeToHand => (anchor(input), input.guess),
    }
}

fn board_centre(board: &[Point3<f64>]) -> Point3<f64> {
    let sum = board.iter().fold(Vector3::zeros(), |a, p| a + p.coords);
    Point3::from(sum / board.len().max(1) as f64)
}

/// The view from direction `(tilt, azimuth)` about the board normal at
/// `distance`, rolled by `roll` from the reference x axis `x_ref` (target
/// frame): `camera_from_target`.
fn look_at(
    centre: &Point3<f64>,
    normal: &Vector3<f64>,
    x_ref: &Vector3<f64>,
    (tilt, azimuth, roll, distance): (f64, f64, f64, f64),
) -> Option<Pose> {
    // A direction tilted from the normal, turned about it by the azimuth.
    let u = x_ref - normal * x_ref.dot(normal);
    let u = u.try_normalize(1e-9)?;
    let v = normal.cross(&u);
    let dir = normal * tilt.cos() + (u * azimuth.cos() + v * azimuth.sin()) * tilt.sin();
    let position = centre + dir * distance;
    let z = -dir;
    let x0 = (x_ref - z * x_ref.dot(&z)).try_normalize(1e-9)?;
    let x = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(z), roll) * x0;
    let y = z.cross(&x);
    let target_from_camera_r = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, z]));
    let target_from_camera = Pose::from_parts(
        position.coords.into(),
        UnitQuaternion::from_rotation_matrix(&target_from_camera_r),
    );
    Some(target_from_camera.inverse())
}

pub(crate) fn in_image(input: &PlanInput, camera_from_target: &Pose, margin: f64) -> bool {
    let (w, h) = (input.camera.width as f64, input.camera.height as f64);
    input.board_m.iter().all(|p| {
        let q = camera_from_target * p;
        q.z > 0.0
            && input.camera.project(&q).is_ok_and(|px: Point2<f64>| {
                px.x >= margin && px.y >= margin && px.x <= w - margin && px.y <= h - margin
            })
    })
}

fn in_box(pose: &Pose, bounds: &Option<([f64; 3], [f64; 3])>) -> bool {
    let Some((lo, hi)) = bounds else {
        return true;
    };
    let t = pose.translation.vector;
    (0..3).all(|k| t[k] >= lo[k] && t[k] <= hi[k])
}

/// The noise model of the prediction for `views` (per-view camera pose
/// covariance predicted from the board, scaled by the pixel noise over the
/// focal length).
pub fn plan_noise_model(
    input: &PlanInput,
    views: &[PoseMeasurement],
    noise: &PlanNoise,
) -> Result<NoiseModel> {
    let points: Vec<Vector3<f64>> = input.board_m.iter().map(|p| p.coords).collect();
    let covariances = views
        .iter()
        .map(|m| predicted_covariance(m, &points))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| Error::degenerate("a planned view does not constrain the target pose"))?;
    let f = 0.5 * (input.camera.fx + input.camera.fy);
    let mut model = NoiseModel::new(CameraNoise::PerView(covariances));
    model.variances = vec![
        noise.robot_rotation_deg.to_radians().powi(2),
        (noise.robot_translation_mm * 1e-3).powi(2),
        (noise.pixel_sigma_px / f).powi(2),
    ];
    Ok(model)
}

/// The predicted covariance of `(x, y)` from `views` (`None`: singular).
pub fn predicted_covariance_of(
    input: &PlanInput,
    views: &[PoseMeasurement],
    noise: &PlanNoise,
) -> Result<Option<Covariance12>> {
    let (x, y) = implied_transforms(input);
    let model = plan_noise_model(input, views, noise)?;
    Ok(fisher_information(input.setup, views, &model, &x, &y).try_inverse())
}

fn rows(c: &Covariance12) -> Vec<[f64; 12]> {
    (0..12)
        .map(|r| std::array::from_fn(|k| c[(r, k)]))
        .collect()
}

/// Work-point variance (m^2) of an information matrix, with a small ridge
/// while it is still singular.
fn point_variance(info: &Covariance12, j: &nalgebra::SMatrix<f64, 3, 6>) -> f64 {
    let ridge = 1e-9 * (info.trace() / 12.0).max(1e-12);
    let reg = info + Covariance12::identity() * ridge;
    let Some(cov) = reg.cholesky().map(|c| c.inverse()) else {
        return f64::INFINITY;
    };
    let c6 = cov.fixed_view::<6, 6>(0, 0).into_owned();
    (j * c6 * j.transpose()).trace()
}

/// The board centre, the normal on the camera's side and the current
/// view's x axis (target frame): what candidate views are built from.
pub struct ViewFrame {
    centre: Point3<f64>,
    normal: Vector3<f64>,
    x_ref: Vector3<f64>,
}

/// The [`ViewFrame`] of the current view.
pub fn view_frame(input: &PlanInput) -> ViewFrame {
    let centre = board_centre(&input.board_m);
    let target_from_camera = input.camera_from_target.inverse();
    let camera_side = target_from_camera.translation.vector - centre.coords;
    let normal = if camera_side.z >= 0.0 {
        Vector3::z()
    } else {
        -Vector3::z()
    };
    ViewFrame {
        centre,
        normal,
        x_ref: target_from_camera.rotation * Vector3::x(),
    }
}

/// The view at `(tilt, azimuth, roll)` degrees and `distance_m` (module
/// docs, step 2) with its flange pose, when it passes the limits.
pub fn candidate(
    input: &PlanInput,
    frame: &ViewFrame,
    (tilt, azimuth, roll): (f64, f64, f64),
    distance_m: f64,
    limits: &PlanLimits,
) -> Option<PlannedPose> {
    let params = (
        tilt.to_radians(),
        azimuth.to_radians(),
        roll.to_radians(),
        distance_m,
    );
    let view = look_at(&frame.centre, &frame.normal, &frame.x_ref, params)?;
    let robot = robot_pose_for_view(input, &view);
    (in_image(input, &view, limits.margin_px) && in_box(&robot, &limits.flange_box_m)).then_some(
        PlannedPose {
            base_from_gripper: robot,
            camera_from_target: view,
            tilt_deg: tilt,
            distance_m,
            roll_deg: roll,
        },
    )
}

/// Plan `limits.poses` poses (module docs).
pub fn plan(input: &PlanInput, limits: &PlanLimits, noise: &PlanNoise) -> Result<Plan> {
    if limits.poses < 3 || limits.poses > MAX_PLAN_POSES {
        return Err(Error::invalid(
            "poses",
            format!("{} poses: a plan holds 3 to {MAX_PLAN_POSES}", limits.poses),
        ));
    }
    if input.board_m.len() < 4 {
        return Err(Error::too_few("board points", 4, input.board_m.len()));
    }
    let centre = board_centre(&input.board_m);
    let now_distance = (input.camera_from_target * centre).coords.norm();
    let (d_lo, d_hi) = limits
        .distance_m
        .unwrap_or((0.8 * now_distance, 1.2 * now_distance));
    if !(d_lo > 0.0 && d_hi >= d_lo) {
        return Err(Error::invalid(
            "distance",
            format!("working distance range {d_lo} .. {d_hi} m is empty"),
        ));
    }
    let frame = view_frame(input);
    let (x, y) = implied_transforms(input);
    let max_tilt = limits.max_tilt_deg.clamp(0.0, 80.0);
    let tilt_steps = (max_tilt / 10.0).ceil().max(1.0) as usize;
    let mut candidates: Vec<PlannedPose> = Vec::new();
    for ti in 0..=tilt_steps {
        let tilt = max_tilt * ti as f64 / tilt_steps as f64;
        let azimuths = if ti == 0 { 1 } else { 8 };
        for ai in 0..azimuths {
            let azimuth = std::f64::consts::TAU * ai as f64 / 8.0;
            for di in 0..3 {
                let distance = d_lo + (d_hi - d_lo) * di as f64 / 2.0;
                for ri in 0..5 {
                    let roll = limits.max_roll_deg * (ri as f64 - 2.0) / 2.0;
                    let degrees = (tilt, azimuth.to_degrees(), roll);
                    if let Some(c) = candidate(input, &frame, degrees, distance, limits) {
                        candidates.push(c);
                    }
                }
            }
        }
    }
    if candidates.len() < limits.poses {
        return Err(Error::degenerate(format!(
            "only {} candidate poses keep the whole target in view within the limits, {} \
             wanted: widen the tilt or distance range, the flange box, or lower the image margin",
            candidates.len(),
            limits.poses
        )));
    }
    let measurements: Vec<PoseMeasurement> = candidates
        .iter()
        .map(|c| PoseMeasurement {
            base_from_gripper: c.base_from_gripper,
            camera_from_target: c.camera_from_target,
        })
        .collect();
    let model = plan_noise_model(input, &measurements, noise)?;
    let infos: Vec<Covariance12> = (0..measurements.len())
        .map(|i| {
            let one = NoiseModel {
                camera: match &model.camera {
                    CameraNoise::PerView(c) => CameraNoise::PerView(vec![c[i]]),
                    CameraNoise::Diagonal => CameraNoise::Diagonal,
                },
                variances: model.variances.clone(),
                pivot_levers: Vec::new(),
            };
            fisher_information(input.setup, &measurements[i..=i], &one, &x, &y)
        })
        .collect();
    let work_distance = 0.5 * (d_lo + d_hi);
    let q = camera_axis_point(&x, work_distance);
    let lever = q - x.translation.vector;
    let mut j = nalgebra::SMatrix::<f64, 3, 6>::zeros();
    j.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(-crate::handeye::math::skew(&lever)));
    j.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&Matrix3::identity());
    let mut chosen: Vec<usize> = Vec::new();
    let mut info = Covariance12::zeros();
    while chosen.len() < limits.poses {
        let best = (0..candidates.len())
            .filter(|i| !chosen.contains(i))
            .map(|i| (i, point_variance(&(info + infos[i]), &j)))
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        let Some((i, _)) = best else { break };
        chosen.push(i);
        info += infos[i];
    }
    let start = input.base_from_gripper;
    let robot: Vec<Pose> = chosen
        .iter()
        .map(|&i| candidates[i].base_from_gripper)
        .collect();
    let tour = order::short_tour(&start, &robot);
    let poses: Vec<PlannedPose> = tour
        .iter()
        .map(|&k| candidates[chosen[k]].clone())
        .collect();
    let travel_m =
        order::tour_travel_m(&start, &tour.iter().map(|&k| robot[k]).collect::<Vec<_>>());
    let covariance = info
        .try_inverse()
        .ok_or_else(|| Error::degenerate("the planned poses leave the hand-eye unobservable"))?;
    let cov_rows = rows(&covariance);
    // The report's default work point for these views: the board centre
    // (on every planned view's optical axis) at their mean distance.
    let planned_views: Vec<Pose> = poses.iter().map(|p| p.camera_from_target).collect();
    let q = target_centre_camera(&planned_views, &centre)
        .map(|q_camera| (x * Point3::from(q_camera)).coords)
        .unwrap_or(q);
    let predicted = work_point_error(&cov_rows, input.setup, &x, &q, Placement::BoardCentre)
        .ok_or_else(|| Error::degenerate("the predicted covariance is not finite"))?;
    let chain = Chain::new(
        input.setup,
        &poses
            .iter()
            .map(|p| p.base_from_gripper)
            .collect::<Vec<_>>(),
        &poses
            .iter()
            .map(|p| p.camera_from_target)
            .collect::<Vec<_>>(),
    )?;
    let motion = motion_stats(&build_motions(&chain, MotionPairs::All));
    let mut notes = vec![
        "joint limits, reachability and collisions are not modelled: check the poses in the \
         robot's simulator before running them"
            .to_string(),
    ];
    match noise.pixel_sigma_from {
        PixelNoiseSource::Default => notes.push(format!(
            "the prediction assumes {:.2} px corner noise, not measured: give the current view's \
             image (its PnP residual gives the detector's noise) or the noise you know",
            noise.pixel_sigma_px
        )),
        PixelNoiseSource::MeasuredOnView => notes.push(format!(
            "corner noise {:.3} px per axis, measured on the current view (its PnP residual)",
            noise.pixel_sigma_px
        )),
        PixelNoiseSource::Given => {}
    }
    if motion.angle_max_deg < 30.0 {
        notes.push(format!(
            "the largest rotation between two planned poses is {:.0} deg (30 or more is \
             advised): the limits (tilt, roll, flange box) keep it small",
            motion.angle_max_deg
        ));
    }
    Ok(Plan {
        poses,
        predicted,
        covariance: cov_rows,
        motion,
        travel_m,
        candidates: candidates.len(),
        notes,
        noise: *noise,
    })
}

#[cfg(test)]
mod tests;
