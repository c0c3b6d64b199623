//! Seeded synthetic camera rigs (issue 22): four cameras on a circle of
//! radius [`RIG_RADIUS_M`] around the working volume, looking at its
//! centre, in two pairs facing each other (cam0 and cam1 at -35 and +35
//! degrees, cam2 and cam3 at 145 and 215). A board facing one pair is seen
//! by that pair only (the other pair sees its back); "side" frames face 90
//! degrees, half-way between cam1 and cam2, and are the only frames that
//! link the two pairs. Views may be partial (a random part of the board
//! cut off), as marker boards give.
//!
//! The rig frame is cam0's. World frame: origin at the centre, y down.
//! [`robot_poses`] puts the rig (or the board) on a robot for the rig hand-eye.

use super::Rng;
use crate::calib::multi::rig::{RigCameraViews, RigOptions};
use crate::calib::{CalibrationOptions, View};
use crate::camera::Camera;
use crate::geometry::{rotation_from_rotvec, Pose};
use crate::handeye::Setup;
use nalgebra::{Point2, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// Distance of every camera from the centre of the working volume, metres.
pub const RIG_RADIUS_M: f64 = 1.2;
/// Angles of the four cameras around the circle, degrees.
pub const RIG_CAMERA_DEG: [f64; 4] = [-35.0, 35.0, 145.0, 215.0];
/// Board points (columns, rows) and pitch, metres.
pub const RIG_BOARD: (usize, usize, f64) = (10, 7, 0.06);
/// A camera sees the board when its front faces the camera within this
/// angle, degrees.
const MAX_VIEW_ANGLE_DEG: f64 = 65.0;
/// Fewest points a view keeps.
const MIN_VIEW_POINTS: usize = 12;

/// What to generate.
#[derive(Clone, Debug, PartialEq)]
pub struct RigSceneConfig {
    /// Frames facing each pair (so `2 * pair_frames` of them).
    pub pair_frames: usize,
    /// Frames facing 90 degrees, seen by cam1 and cam2 (0: two groups of
    /// cameras that no frame connects).
    pub side_frames: usize,
    /// Standard deviation of the Gaussian noise on each pixel coordinate.
    pub noise_px: f64,
    /// Fraction of views cut to a part of the board.
    pub partial_fraction: f64,
    /// Timing error of free-running cameras: each view is taken this many
    /// milliseconds (standard deviation, drawn per view) off its frame's
    /// moment while the board moves by hand ([`BOARD_DEG_PER_S`],
    /// [`BOARD_M_PER_S`]); 0: every frame's images at one moment. The truth
    /// (`rig_from_target`) is the board at the frame's moment.
    pub timing_ms: f64,
}

/// Speed of the hand-held board while the cameras are off their frame's
/// moment ([`RigSceneConfig::timing_ms`]): rotation, degrees per second ...
pub const BOARD_DEG_PER_S: f64 = 30.0;
/// ... and translation, metres per second, each in a random direction per
/// frame.
pub const BOARD_M_PER_S: f64 = 0.15;

impl Default for RigSceneConfig {
    fn default() -> Self {
        RigSceneConfig {
            pair_frames: 8,
            side_frames: 4,
            noise_px: 0.0,
            partial_fraction: 0.25,
            timing_ms: 0.0,
        }
    }
}

/// A rig, its frames and every camera's views of them.
#[derive(Clone, Debug)]
pub struct RigScene {
    /// Camera names, `cam0` ... `cam3`.
    pub names: Vec<String>,
    /// The true intrinsics of each camera.
    pub cameras: Vec<Camera>,
    /// The true camera_from_rig of each camera (cam0's is the identity).
    pub camera_from_rig: Vec<Pose>,
    /// The true board pose of each frame.
    pub rig_from_target: Vec<Pose>,
    /// The frame keys (`"0"`, `"1"`, ...).
    pub frame_keys: Vec<String>,
    /// Per camera: its views, each with its frame index.
    pub views: Vec<Vec<(usize, View)>>,
}

/// The board of every rig scene as [`RigOptions::target`] names it: 11 x 8
/// squares of 60 mm ([`RIG_BOARD`]'s 10 x 7 inner corners).
pub const RIG_TARGET: &str = "chessboard:11x8:60mm";

impl RigScene {
    /// The cameras' inputs to `calibrate_rig`: every camera's views, the
    /// cameras in `held` with their true intrinsics (held), the others
    /// calibrated from their views.
    pub fn camera_views(&self, held: &[usize]) -> Vec<RigCameraViews> {
        (0..self.names.len())
            .map(|k| RigCameraViews {
                name: self.names[k].clone(),
                image_size_px: (self.cameras[k].width, self.cameras[k].height),
                views: self.views[k].clone(),
                camera: held.contains(&k).then(|| self.cameras[k].clone()),
            })
            .collect()
    }

    /// The rig options for these scenes: the default calibration, frames
    /// grouped by their number (the scene's `frame_keys`), [`RIG_TARGET`],
    /// the rig frame `rig_frame` (none: cam0's).
    pub fn rig_options(rig_frame: Option<&str>) -> RigOptions {
        RigOptions {
            calibration: CalibrationOptions::default(),
            rig_frame: rig_frame.map(str::to_string),
            target: RIG_TARGET.into(),
            grouping: "number".into(),
        }
    }
}

/// world_from_camera of a camera on the circle at `deg`, looking at the centre.
fn world_from_camera(deg: f64, height_m: f64) -> Pose {
    let a = deg.to_radians();
    let z = Vector3::new(-a.sin(), 0.0, a.cos());
    let y = Vector3::new(0.0, 1.0, 0.0);
    let x = y.cross(&z);
    let r = Rotation3::from_basis_unchecked(&[x, y, z]);
    let centre = Vector3::new(RIG_RADIUS_M * a.sin(), height_m, -RIG_RADIUS_M * a.cos());
    Pose::from_parts(
        Translation3::from(centre),
        UnitQuaternion::from_rotation_matrix(&r),
    )
}

/// The scene of `config` for `seed`.
pub fn rig_scene(config: &RigSceneConfig, seed: u64) -> RigScene {
    let mut rng = Rng::new(seed);
    let heights = [0.0, 0.04, -0.03, 0.02];
    let world_from_cameras: Vec<Pose> = RIG_CAMERA_DEG
        .iter()
        .zip(heights)
        .map(|(&deg, h)| world_from_camera(deg, h))
        .collect();
    let world_from_rig = world_from_cameras[0];
    let camera_from_rig: Vec<Pose> = world_from_cameras
        .iter()
        .map(|w| w.inverse() * world_from_rig)
        .collect();
    let cameras: Vec<Camera> = (0..4)
        .map(|k| {
            let base = Camera::example_brown();
            Camera {
                fx: base.fx * (1.0 + 0.02 * k as f64),
                fy: base.fy * (1.0 + 0.02 * k as f64),
                cx: base.cx + 6.0 * k as f64 - 9.0,
                cy: base.cy - 4.0 * k as f64 + 5.0,
                ..base
            }
        })
        .collect();
    let (cols, rows, pitch) = RIG_BOARD;
    let board: Vec<Point3<f64>> = (0..rows)
        .flat_map(|r| (0..cols).map(move |c| Point3::new(c as f64 * pitch, r as f64 * pitch, 0.0)))
        .collect();
    let half = Vector3::new(
        (cols - 1) as f64 * pitch / 2.0,
        (rows - 1) as f64 * pitch / 2.0,
        0.0,
    );
    // Facing angles: the pairs' frames alternate, then the side frames.
    let mut facing = Vec::new();
    for _ in 0..config.pair_frames {
        facing.extend([(0.0, 0.45), (180.0, 0.45)]);
    }
    facing.extend(std::iter::repeat((90.0, 0.08)).take(config.side_frames));
    let mut rig_from_target = Vec::new();
    let mut views = vec![Vec::new(); 4];
    // The timing draws have a generator of their own, so that a scene
    // without timing error is the same as before the option existed.
    let mut timing_rng = Rng::new(seed ^ 0x7131_6d73_0000_0001);
    for (f, &(deg, tilt)) in facing.iter().enumerate() {
        let tilt_rv = Vector3::new(
            rng.range(-tilt, tilt),
            rng.range(-tilt, tilt),
            rng.range(-0.3, 0.3),
        );
        let rotation = world_from_camera(deg, 0.0).rotation * rotation_from_rotvec(&tilt_rv);
        let centre = Vector3::new(
            rng.range(-0.1, 0.1),
            rng.range(-0.1, 0.1),
            rng.range(-0.1, 0.1),
        );
        let world_from_target =
            Pose::from_parts(Translation3::from(centre - rotation * half), rotation);
        rig_from_target.push(world_from_rig.inverse() * world_from_target);
        let front = -(rotation * Vector3::z());
        // The board's motion during this frame (hand-held), when the
        // cameras are off its moment.
        let (spin, drift) = if config.timing_ms > 0.0 {
            (
                random_direction(&mut timing_rng) * BOARD_DEG_PER_S.to_radians(),
                random_direction(&mut timing_rng) * BOARD_M_PER_S,
            )
        } else {
            (Vector3::zeros(), Vector3::zeros())
        };
        for k in 0..4 {
            let world_from_target = if config.timing_ms > 0.0 {
                let dt = timing_rng.gaussian(config.timing_ms) / 1000.0;
                let turned = rotation_from_rotvec(&(spin * dt)) * rotation;
                let moved = centre + drift * dt;
                Pose::from_parts(Translation3::from(moved - turned * half), turned)
            } else {
                world_from_target
            };
            let to_camera = world_from_cameras[k].translation.vector - centre;
            let cos = front.dot(&to_camera) / to_camera.norm();
            if cos < MAX_VIEW_ANGLE_DEG.to_radians().cos() {
                continue;
            }
            let camera_from_target = world_from_cameras[k].inverse() * world_from_target;
            let cut = (rng.uniform() < config.partial_fraction).then(|| 4 + rng.below(cols - 4));
            let mut view = View::new(format!("cam{k}_{f:03}"), Vec::new(), Vec::new());
            for (id, p) in board.iter().enumerate() {
                if cut.is_some_and(|c| id % cols >= c) {
                    continue;
                }
                let Ok(px) = cameras[k].project(&(camera_from_target * p)) else {
                    continue;
                };
                let inside = px.x >= 0.0
                    && px.y >= 0.0
                    && px.x <= (cameras[k].width - 1) as f64
                    && px.y <= (cameras[k].height - 1) as f64;
                if inside {
                    let noisy = Point2::new(
                        px.x + rng.gaussian(config.noise_px),
                        px.y + rng.gaussian(config.noise_px),
                    );
                    view.object_m.push(*p);
                    view.image_px.push(noisy);
                    view.point_ids.push(id);
                }
            }
            if view.object_m.len() >= MIN_VIEW_POINTS {
                views[k].push((f, view));
            }
        }
    }
    RigScene {
        names: (0..4).map(|k| format!("cam{k}")).collect(),
        cameras,
        camera_from_rig,
        frame_keys: (0..facing.len()).map(|f| f.to_string()).collect(),
        rig_from_target,
        views,
    }
}

/// A unit vector in a uniformly random direction.
fn random_direction(rng: &mut Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(rng.normal(), rng.normal(), rng.normal());
        let n = v.norm();
        if n > 1e-9 {
            return v / n;
        }
    }
}

/// Robot poses `base_from_gripper`, one per frame, that carry the scene on
/// a robot. Eye-in-hand: the rig on the gripper at `x` = `gripper_from_rig`,
/// the board fixed at `y` = `base_from_target`, so `base_from_gripper[f] =
/// y * rig_from_target[f]^-1 * x^-1`. Eye-to-hand: the rig fixed at `x` =
/// `base_from_rig`, the board on the gripper at `y` = `gripper_from_target`,
/// so `base_from_gripper[f] = x * rig_from_target[f] * y^-1`.
pub fn robot_poses(scene: &RigScene, setup: Setup, x: &Pose, y: &Pose) -> Vec<Pose> {
    scene
        .rig_from_target
        .iter()
        .map(|t| match setup {
            Setup::EyeInHand => y * t.inverse() * x.inverse(),
            Setup::EyeToHand => x * t * y.inverse(),
        })
        .collect()
}
