//! The pose plan's Monte Carlo on rendered images (issue 39, part 3), shared
//! by tests/handeye/handeye_field.rs and examples/plan_monte_carlo.rs (which
//! includes this file by path).
//!
//! The cell: an eye-in-hand camera (640 x 480, f = 560 px, no distortion)
//! 0.1 m in front of the flange, a 9 x 6 chessboard (30 mm squares) on the
//! table, the current view straight down from 0.5 m. The plan starts from
//! that view rendered and detected. Each trial sends the robot to the
//! planned poses with robot noise (the plan's assumed 0.02 deg and 0.1 mm
//! per axis, base frame), renders every view with `robocal::synth::render`
//! (default options: blur 0.7 px, grey-level noise 2, a new noise seed per
//! trial), detects the corners with `robocal::detect::detect`, and solves
//! through `robocal::api::handeye::solve_handeye` (PnP per view, the pose
//! refinement with each view's PnP covariance): the error at the plan's
//! work point is the distance between the point carried by the solved and
//! by the true `gripper_from_camera`.

use nalgebra::{Point3, Translation3, UnitQuaternion, Vector3};
use robocal::api::handeye::{solve_handeye, ImagePoints};
use robocal::calib::View;
use robocal::camera::Camera;
use robocal::detect::{detect, DetectOptions};
use robocal::handeye::plan::{candidate, view_frame, PlanInput, PlanLimits, PlanNoise};
use robocal::handeye::refine::over_pixels::RefineMode;
use robocal::handeye::{HandEyeInput, HandEyeOptions, Pose, Setup};
use robocal::rng::Rng;
use robocal::synth::{render, RenderOptions};
use robocal::target::Target;

/// The rendered cell: the plan's input (its guess is the true
/// `gripper_from_camera`), the printed target and the plan's limits.
pub struct Cell {
    /// What the plan starts from.
    pub input: PlanInput,
    /// The printed board.
    pub target: Target,
    /// The plan's limits (12 poses, the default tilt and roll, a 40 px
    /// image margin so that the chessboard's outer squares stay in view).
    pub limits: PlanLimits,
}

/// The cell of the module docs.
pub fn cell() -> Cell {
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.03,
    };
    let board_m: Vec<Point3<f64>> = target.object_points().into_iter().map(|(_, p)| p).collect();
    let n = board_m.len() as f64;
    let centre = board_m.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n;
    Cell {
        input: PlanInput {
            setup: Setup::EyeInHand,
            base_from_gripper: Pose::from_parts(
                Translation3::new(0.5, 0.1, 0.8),
                UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.2),
            ),
            camera_from_target: Pose::from_parts(
                Translation3::new(-centre.x, -centre.y, 0.5),
                UnitQuaternion::identity(),
            ),
            camera: Camera::pinhole(560.0, 560.0, 319.5, 239.5, 640, 480),
            board_m,
            guess: Pose::from_parts(
                Translation3::new(0.03, -0.02, 0.1),
                UnitQuaternion::from_euler_angles(0.0, 0.0, 0.3),
            ),
        },
        target,
        limits: PlanLimits {
            poses: 12,
            margin_px: 40.0,
            ..PlanLimits::default()
        },
    }
}

/// The render of one view (grey-level noise seeded by `seed`), detected:
/// the board points and their detected pixels, or why not.
pub fn detected_view(cell: &Cell, camera_from_target: &Pose, seed: u64) -> Result<View, String> {
    let options = RenderOptions {
        seed,
        ..RenderOptions::default()
    };
    let rendered = render(
        &cell.input.camera,
        &cell.target,
        camera_from_target,
        &options,
    )
    .map_err(|e| e.to_string())?;
    let detection = detect(&rendered.image, &cell.target, &DetectOptions::default())
        .map_err(|e| e.to_string())?;
    let (object, pixels) = detection.correspondences();
    Ok(View::new("", object, pixels))
}

/// The detector's corner error on `view` against the exact projection
/// (sum of squared errors per axis, count of coordinates).
pub fn corner_error(cell: &Cell, camera_from_target: &Pose, view: &View) -> (f64, usize) {
    let mut sum = 0.0;
    for (p, px) in view.object_m.iter().zip(&view.image_px) {
        if let Ok(truth) = cell.input.camera.project(&(camera_from_target * p)) {
            sum += (px - truth).norm_squared();
        }
    }
    (sum, 2 * view.object_m.len())
}

fn left_noise(rng: &mut Rng, p: &Pose, sr: f64, st: f64) -> Pose {
    let w = Vector3::new(rng.gaussian(sr), rng.gaussian(sr), rng.gaussian(sr));
    let v = Vector3::new(rng.gaussian(st), rng.gaussian(st), rng.gaussian(st));
    Pose::from_parts(
        (p.translation.vector + v).into(),
        UnitQuaternion::from_scaled_axis(w) * p.rotation,
    )
}

/// One trial's outcome.
pub struct Trial {
    /// The error at the work point (mm).
    pub error_mm: f64,
    /// The detector's corner error: sum of squares (px^2) and coordinates.
    pub corners: (f64, usize),
}

/// One calibration from `views` (`(base_from_gripper, camera_from_target)`
/// as planned, the truth): robot noise `noise`, rendered and detected
/// images, the hand-eye through `solve_handeye`; the error at `q_camera`
/// (the work point, camera frame).
pub fn trial(
    cell: &Cell,
    views: &[(Pose, Pose)],
    noise: &PlanNoise,
    q_camera: &[f64; 3],
    seed: u64,
) -> Result<Trial, String> {
    let mut rng = Rng::new(seed);
    let (sr, st) = (
        noise.robot_rotation_deg.to_radians(),
        noise.robot_translation_mm * 1e-3,
    );
    let mut robots = Vec::new();
    let mut image_views = Vec::new();
    let mut corners = (0.0, 0);
    for (k, (robot, view)) in views.iter().enumerate() {
        robots.push(left_noise(&mut rng, robot, sr, st));
        let detected = detected_view(cell, view, seed.wrapping_mul(1000).wrapping_add(k as u64))
            .map_err(|e| format!("view {k}: {e}"))?;
        let (s, n) = corner_error(cell, view, &detected);
        corners = (corners.0 + s, corners.1 + n);
        image_views.push(detected);
    }
    let camera = &cell.input.camera;
    let camera_from_target = image_views
        .iter()
        .map(|v| robocal::calib::pnp::camera_from_target(camera, v).map(|p| p.0))
        .collect::<Result<Vec<Pose>, _>>()
        .map_err(|e| e.to_string())?;
    let input = HandEyeInput {
        setup: cell.input.setup,
        base_from_gripper: robots,
        camera_from_target,
    };
    let points = ImagePoints {
        views: &image_views,
        camera,
        camera_std: None,
        refine: RefineMode::None,
        pixel_sigma_px: noise.pixel_sigma_px,
        refine_poses: true,
    };
    let options = HandEyeOptions {
        bootstrap_samples: 0,
        refine_poses: false,
        ..HandEyeOptions::default()
    };
    let report =
        solve_handeye(&input, &options, Some(&points), Vec::new()).map_err(|e| e.to_string())?;
    let x = report
        .gripper_from_camera
        .as_ref()
        .ok_or("no gripper_from_camera in the report")?
        .to_pose()
        .map_err(|e| e.to_string())?;
    let q = Point3::from(*q_camera);
    Ok(Trial {
        error_mm: (x * q - cell.input.guess * q).norm() * 1e3,
        corners,
    })
}

/// A random plan of `poses` views within the same limits (uniform tilt,
/// azimuth, roll and distance; candidates that leave them are redrawn).
pub fn random_views(cell: &Cell, distance_m: (f64, f64), rng: &mut Rng) -> Vec<(Pose, Pose)> {
    let frame = view_frame(&cell.input);
    let limits = &cell.limits;
    let mut views = Vec::new();
    while views.len() < limits.poses {
        let angles = (
            rng.range(0.0, limits.max_tilt_deg),
            rng.range(0.0, 360.0),
            rng.range(-limits.max_roll_deg, limits.max_roll_deg),
        );
        let d = rng.range(distance_m.0, distance_m.1);
        if let Some(c) = candidate(&cell.input, &frame, angles, d, limits) {
            views.push((c.base_from_gripper, c.camera_from_target));
        }
    }
    views
}

/// RMS of a list.
pub fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|a| a * a).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// What a Monte Carlo run found.
pub struct Run {
    /// The plan's predicted RMS error at its work point (mm).
    pub predicted_mm: f64,
    /// The pixel noise the plan assumed (px).
    pub assumed_sigma_px: f64,
    /// The planned poses' RMS error over the trials (mm).
    pub planned_mm: f64,
    /// Random plans' RMS error, one plan per random trial (mm).
    pub random_mm: f64,
    /// The detector's per-axis corner RMS over every planned image (px).
    pub corner_rms_px: f64,
    /// Trials of the planned poses.
    pub trials: usize,
    /// Trials of random plans.
    pub random_trials: usize,
}

/// Plan from the rendered current view with `noise` (its pixel sigma
/// replaced by the view's measured one when `measured` is set), then
/// `trials` trials of the planned poses and `random_trials` of random
/// plans, seeds from `seed`.
pub fn run(
    (trials, random_trials): (usize, usize),
    seed: u64,
    noise: PlanNoise,
    measured: bool,
) -> Result<Run, String> {
    let cell = cell();
    let now = detected_view(&cell, &cell.input.camera_from_target, seed ^ 0xC0FFEE)?;
    let noise = if measured {
        let (_, sigma) = robocal::handeye::plan::pixel_sigma_from_view(&cell.input.camera, &now)
            .map_err(|e| e.to_string())?;
        PlanNoise {
            pixel_sigma_px: sigma,
            ..noise
        }
    } else {
        noise
    };
    let planned = robocal::handeye::plan::plan(&cell.input, &cell.limits, &noise)
        .map_err(|e| e.to_string())?;
    let q = planned.predicted.point_camera_m;
    let views: Vec<(Pose, Pose)> = planned
        .poses
        .iter()
        .map(|p| (p.base_from_gripper, p.camera_from_target))
        .collect();
    let (mut planned_errors, mut random_errors, mut corners) = (Vec::new(), Vec::new(), (0.0, 0));
    let d = planned.poses.iter().map(|p| p.distance_m);
    let range = (
        d.clone().fold(f64::INFINITY, f64::min),
        d.fold(0.0, f64::max),
    );
    let mut rng = Rng::new(seed ^ 0x5EED);
    for t in 0..trials as u64 {
        let s = seed.wrapping_mul(7919).wrapping_add(t);
        let done = trial(&cell, &views, &noise, &q, s)?;
        planned_errors.push(done.error_mm);
        corners = (corners.0 + done.corners.0, corners.1 + done.corners.1);
    }
    for t in 0..random_trials as u64 {
        let s = seed.wrapping_mul(7919).wrapping_add(t) ^ 0xABCD;
        let random = random_views(&cell, range, &mut rng);
        random_errors.push(trial(&cell, &random, &noise, &q, s)?.error_mm);
    }
    Ok(Run {
        predicted_mm: planned.predicted.rms_mm,
        assumed_sigma_px: noise.pixel_sigma_px,
        planned_mm: rms(&planned_errors),
        random_mm: rms(&random_errors),
        corner_rms_px: (corners.0 / corners.1.max(1) as f64).sqrt(),
        trials,
        random_trials,
    })
}
