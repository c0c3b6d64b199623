//! Seeded hand-eye scenes where the camera actually looks at a planar grid
//! target (unlike [`super::handeye`]'s OpenCV-style random poses): every
//! camera pose sits at a given distance from the board centre, tilted up to
//! a given angle and rolled about its optical axis, and the robot poses
//! follow from the chain `robot[i] * x * camera[i] = y`. Used by the pose
//! refinement's tests and the Cramér-Rao benchmark (`examples/handeye_crb.rs`).
//! [`observe_looking`] adds what a camera and a robot measure of such a
//! scene (noisy grid pixels, noisy robot poses) and, through PnP with a
//! given camera, the hand-eye input of the image path.
//!
//! Noise is applied the way [`crate::handeye::refine::pose_residual`] models it:
//! decoupled left perturbations, `R <- exp(w) R`, `t <- t + v`.

use super::Rng;
use crate::calib::pnp::camera_from_target_with_covariance;
use crate::calib::View;
use crate::camera::Camera;
use crate::error::Result;
use crate::handeye::refine::pose_residual::perturb;
use crate::handeye::{HandEyeInput, Pose, Setup};
use nalgebra::{Point2, Point3, Rotation3, Translation3, UnitQuaternion, Vector3, Vector6};

/// What to generate.
#[derive(Debug, Clone)]
pub struct LookingConfig {
    /// Camera on the gripper or fixed.
    pub setup: Setup,
    /// Number of views.
    pub views: usize,
    /// Camera-to-board-centre distance (metres), varied by +-10 %.
    pub distance_m: f64,
    /// Grid: columns, rows, spacing (metres), points at z = 0.
    pub grid: (usize, usize, f64),
    /// Largest angle between the optical axis and the board normal (degrees).
    pub max_tilt_deg: f64,
    /// Largest roll about the optical axis (degrees, either sign).
    pub max_roll_deg: f64,
}

impl LookingConfig {
    /// The tests' usual scene: `views` views of a 9x6 grid of 30 mm at
    /// 0.5 m, tilted up to 30 deg and rolled up to 60 deg.
    pub fn half_metre(setup: Setup, views: usize) -> Self {
        LookingConfig {
            setup,
            views,
            distance_m: 0.5,
            grid: (9, 6, 0.03),
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
        }
    }
}

/// The truth of a scene.
#[derive(Debug, Clone)]
pub struct LookingScene {
    /// The setup.
    pub setup: Setup,
    /// True `gripper_from_camera` / `base_from_camera`.
    pub x_true: Pose,
    /// True `base_from_target` / `gripper_from_target`.
    pub y_true: Pose,
    /// True robot poses.
    pub base_from_gripper: Vec<Pose>,
    /// True camera poses.
    pub camera_from_target: Vec<Pose>,
    /// The grid points (target frame).
    pub object_points: Vec<Point3<f64>>,
}

fn random_rotation(rng: &mut Rng, max_angle: f64) -> UnitQuaternion<f64> {
    let axis = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
    UnitQuaternion::from_scaled_axis(axis * rng.range(0.0, max_angle))
}

/// Generate a scene from a seed.
pub fn looking_scene(config: &LookingConfig, seed: u64) -> LookingScene {
    scene(config, seed, false)
}

/// The same scene, but every camera at one height above the board (its
/// distance along the board normal is `distance_m` for every view, so the
/// robot's flange stays on one horizontal plane): the weak geometry of a
/// user who only tilts and turns the gripper at one height. The random
/// draws are those of [`looking_scene`] with the same seed.
pub fn looking_scene_one_height(config: &LookingConfig, seed: u64) -> LookingScene {
    scene(config, seed, true)
}

fn scene(config: &LookingConfig, seed: u64, one_height: bool) -> LookingScene {
    let mut rng = Rng::new(seed);
    let (cols, rows, spacing) = config.grid;
    let object_points: Vec<Point3<f64>> = (0..rows)
        .flat_map(|r| {
            (0..cols).map(move |c| Point3::new(c as f64 * spacing, r as f64 * spacing, 0.0))
        })
        .collect();
    let centre = Vector3::new(
        (cols - 1) as f64 * spacing / 2.0,
        (rows - 1) as f64 * spacing / 2.0,
        0.0,
    );
    // A camera 5-15 cm off the flange (eye-in-hand) or 1-2 m from the base.
    let x_t = match config.setup {
        Setup::EyeInHand => Vector3::new(
            rng.range(-0.1, 0.1),
            rng.range(-0.1, 0.1),
            rng.range(0.05, 0.15),
        ),
        Setup::EyeToHand => Vector3::new(
            rng.range(0.8, 1.5),
            rng.range(-0.5, 0.5),
            rng.range(0.5, 1.0),
        ),
    };
    let x_true = Pose::from_parts(Translation3::from(x_t), random_rotation(&mut rng, 3.0));
    let y_t = match config.setup {
        Setup::EyeInHand => Vector3::new(
            rng.range(0.5, 1.0),
            rng.range(-0.3, 0.3),
            rng.range(-0.2, 0.2),
        ),
        Setup::EyeToHand => Vector3::new(
            rng.range(-0.1, 0.1),
            rng.range(-0.1, 0.1),
            rng.range(0.05, 0.2),
        ),
    };
    let y_true = Pose::from_parts(Translation3::from(y_t), random_rotation(&mut rng, 3.0));
    let mut scene = LookingScene {
        setup: config.setup,
        x_true,
        y_true,
        base_from_gripper: Vec::new(),
        camera_from_target: Vec::new(),
        object_points,
    };
    let board = (cols as f64 * spacing).max(rows as f64 * spacing);
    for _ in 0..config.views {
        let tilt_axis_angle = rng.range(0.0, std::f64::consts::TAU);
        let tilt = rng.range(0.0, config.max_tilt_deg.to_radians());
        let roll = rng.range(-1.0, 1.0) * config.max_roll_deg.to_radians();
        let tilt_axis = Vector3::new(tilt_axis_angle.cos(), tilt_axis_angle.sin(), 0.0);
        // Optical axis (target frame): the board normal +z tilted.
        let z_c = Rotation3::from_scaled_axis(tilt_axis * tilt) * Vector3::z();
        let aim =
            centre + Vector3::new(rng.range(-0.05, 0.05), rng.range(-0.05, 0.05), 0.0) * board;
        let spread = rng.range(0.9, 1.1);
        let distance = if one_height {
            config.distance_m / z_c.z
        } else {
            config.distance_m * spread
        };
        let position = aim - z_c * distance;
        let x_c0 = Vector3::y().cross(&z_c).normalize();
        let x_c = Rotation3::from_scaled_axis(z_c * roll) * x_c0;
        let y_c = z_c.cross(&x_c);
        let target_from_camera_r =
            Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[x_c, y_c, z_c]));
        let target_from_camera = Pose::from_parts(
            Translation3::from(position),
            UnitQuaternion::from_rotation_matrix(&target_from_camera_r),
        );
        let camera_from_target = target_from_camera.inverse();
        let robot = y_true * target_from_camera * x_true.inverse();
        let base_from_gripper = match config.setup {
            Setup::EyeInHand => robot,
            Setup::EyeToHand => robot.inverse(),
        };
        scene.base_from_gripper.push(base_from_gripper);
        scene.camera_from_target.push(camera_from_target);
    }
    scene
}

/// A robot pose error that is a smooth function of the pose, like a
/// kinematic model error: the same pose always gets the same error, of
/// amplitude `amp_mm` (translation) and `amp_deg` (rotation) per axis,
/// applied on the left (base frame).
pub fn kinematic_error(pose: &Pose, amp_mm: f64, amp_deg: f64) -> Pose {
    let p = pose.translation.vector;
    let w = pose.rotation.scaled_axis();
    let k = std::f64::consts::TAU / 0.4;
    let dt = Vector3::new(
        (k * p.x).sin(),
        (k * p.y + 1.0).sin(),
        (k * p.z + 2.0).sin(),
    );
    let dr = Vector3::new(
        (3.0 * w.x).sin(),
        (3.0 * w.y + 1.0).sin(),
        (3.0 * w.z + 2.0).sin(),
    );
    Pose::from_parts(
        Translation3::from(dt * amp_mm * 1e-3),
        UnitQuaternion::from_scaled_axis(dr * amp_deg.to_radians()),
    ) * pose
}

/// A Gaussian decoupled left perturbation: rotation std `sigma_rot` (rad)
/// and translation std `sigma_t` (m) per axis, each of 3 values.
pub fn perturbed(rng: &mut Rng, pose: &Pose, sigma_rot: [f64; 3], sigma_t: [f64; 3]) -> Pose {
    let d = Vector6::new(
        rng.gaussian(sigma_rot[0]),
        rng.gaussian(sigma_rot[1]),
        rng.gaussian(sigma_rot[2]),
        rng.gaussian(sigma_t[0]),
        rng.gaussian(sigma_t[1]),
        rng.gaussian(sigma_t[2]),
    );
    perturb(pose, &d)
}

/// The benchmarks' poses of a scene as measured: robot 0.02 deg / 0.1 mm
/// per axis, camera 0.05 deg (0.01 deg about the optical axis) and 0.05 /
/// 0.3 mm (x, y / depth), drawn from `Rng::new(seed)`, every robot pose
/// first (so a seed gives the same draws whatever reads them).
pub fn noisy_input(scene: &LookingScene, seed: u64) -> HandEyeInput {
    let mut rng = Rng::new(seed);
    let (r, c) = (0.02f64.to_radians(), 0.05f64.to_radians());
    let base_from_gripper = scene
        .base_from_gripper
        .iter()
        .map(|p| perturbed(&mut rng, p, [r; 3], [1e-4; 3]))
        .collect();
    let camera_from_target = scene
        .camera_from_target
        .iter()
        .map(|p| perturbed(&mut rng, p, [c, c, c / 5.0], [5e-5, 5e-5, 3e-4]))
        .collect();
    HandEyeInput {
        setup: scene.setup,
        base_from_gripper,
        camera_from_target,
    }
}

/// Grid pixels of every view through the true camera poses plus Gaussian
/// noise `pixel_sigma` per coordinate; points outside the image are left out.
pub fn grid_pixels(
    scene: &LookingScene,
    camera: &Camera,
    pixel_sigma: f64,
    rng: &mut Rng,
) -> Vec<View> {
    let (w, h) = (camera.width as f64, camera.height as f64);
    scene
        .camera_from_target
        .iter()
        .map(|pose| {
            let mut view = View::new("", Vec::new(), Vec::new());
            for p in &scene.object_points {
                if let Ok(px) = camera.project(&(pose * p)) {
                    let q = Point2::new(
                        px.x + rng.gaussian(pixel_sigma),
                        px.y + rng.gaussian(pixel_sigma),
                    );
                    if q.x >= -0.5 && q.y >= -0.5 && q.x <= w - 0.5 && q.y <= h - 0.5 {
                        view.object_m.push(*p);
                        view.image_px.push(q);
                    }
                }
            }
            view
        })
        .collect()
}

/// What the camera and the robot of [`observe_looking`] add to the truth.
#[derive(Debug, Clone, Copy)]
pub struct LookingNoise {
    /// Pixel noise per coordinate (px).
    pub pixel_sigma: f64,
    /// Robot pose noise per axis ([`perturbed`]): rotation (rad),
    /// translation (m).
    pub robot_sigma: (f64, f64),
    /// A robot error smooth in the pose ([`kinematic_error`]: translation
    /// mm, rotation deg), put on the true poses before the noise; `None`:
    /// none.
    pub kinematic: Option<(f64, f64)>,
}

/// A looking scene as measured.
#[derive(Debug, Clone)]
pub struct LookingObserved {
    /// The truth.
    pub scene: LookingScene,
    /// Each view's grid pixels through the true camera ([`grid_pixels`]).
    pub views: Vec<View>,
    /// The robot poses as the robot reports them.
    pub base_from_gripper: Vec<Pose>,
}

/// [`looking_scene`] from `seed`, seen through `camera` and moved by a
/// robot with `noise`: one generator seeded `noise_seed` draws the pixel
/// noise of every view, then each robot pose's noise.
pub fn observe_looking(
    config: &LookingConfig,
    seed: u64,
    camera: &Camera,
    noise: &LookingNoise,
    noise_seed: u64,
) -> LookingObserved {
    observe_scene(looking_scene(config, seed), camera, noise, noise_seed)
}

/// `scene` (e.g. [`looking_scene_one_height`]'s) seen through `camera` and
/// moved by a robot with `noise`, as [`observe_looking`] does.
pub fn observe_scene(
    scene: LookingScene,
    camera: &Camera,
    noise: &LookingNoise,
    noise_seed: u64,
) -> LookingObserved {
    let mut rng = Rng::new(noise_seed);
    let views = grid_pixels(&scene, camera, noise.pixel_sigma, &mut rng);
    let (sr, st) = noise.robot_sigma;
    let base_from_gripper = scene
        .base_from_gripper
        .iter()
        .map(|p| {
            let p = match noise.kinematic {
                Some((mm, deg)) => kinematic_error(p, mm, deg),
                None => *p,
            };
            perturbed(&mut rng, &p, [sr; 3], [st; 3])
        })
        .collect();
    LookingObserved {
        scene,
        views,
        base_from_gripper,
    }
}

impl LookingObserved {
    /// The hand-eye input of the image path: each view's board pose by PnP
    /// through `camera` (the calibration in use, which need not be the
    /// truth) and the reported robot poses.
    pub fn handeye_input(&self, camera: &Camera) -> Result<HandEyeInput> {
        let camera_from_target = self
            .views
            .iter()
            .map(|v| Ok(camera_from_target_with_covariance(camera, v)?.0))
            .collect::<Result<_>>()?;
        Ok(HandEyeInput {
            setup: self.scene.setup,
            base_from_gripper: self.base_from_gripper.clone(),
            camera_from_target,
        })
    }
}

/// Move view `view`'s camera by `offset_m` along its own axes (orientation
/// kept) and the robot pose with it, so that the chain still closes: a
/// lateral offset pushes the board towards an image edge, the way a
/// partial view of a marker board is taken. Out-of-range views are ignored.
pub fn shift_view(scene: &mut LookingScene, view: usize, offset_m: Vector3<f64>) {
    let Some(camera_from_target) = scene.camera_from_target.get(view).copied() else {
        return;
    };
    // The camera moves by +offset in its frame: points move by -offset.
    let shifted = Translation3::from(-offset_m) * camera_from_target;
    let robot = scene.y_true * shifted.inverse() * scene.x_true.inverse();
    scene.camera_from_target[view] = shifted;
    scene.base_from_gripper[view] = match scene.setup {
        Setup::EyeInHand => robot,
        Setup::EyeToHand => robot.inverse(),
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// A shifted view keeps the chain exact (to rounding) and moves the
    /// camera by the offset along its own axes, orientation unchanged.
    #[wasm_bindgen_test(unsupported = test)]
    fn a_shifted_view_moves_the_camera_and_keeps_the_chain_closed() {
        for setup in [Setup::EyeInHand, Setup::EyeToHand] {
            let config = LookingConfig {
                setup,
                views: 4,
                distance_m: 0.5,
                grid: (9, 6, 0.03),
                max_tilt_deg: 30.0,
                max_roll_deg: 60.0,
            };
            let mut scene = looking_scene(&config, 7);
            let before = scene.camera_from_target[1];
            let offset = Vector3::new(0.05, -0.02, 0.01);
            shift_view(&mut scene, 1, offset);
            shift_view(&mut scene, 99, offset); // out of range: ignored
            let after = scene.camera_from_target[1];
            // The camera centre in the target frame moved by R * offset.
            let moved = after.inverse().translation.vector - before.inverse().translation.vector;
            let expected = before.inverse().rotation * offset;
            assert!((moved - expected).norm() < 1e-12, "moved {moved:?} m");
            assert!(after.rotation.angle_to(&before.rotation) < 1e-12);
            for k in 0..4 {
                let robot = match setup {
                    Setup::EyeInHand => scene.base_from_gripper[k],
                    Setup::EyeToHand => scene.base_from_gripper[k].inverse(),
                };
                let y = robot * scene.x_true * scene.camera_from_target[k];
                let d = (y.to_homogeneous() - scene.y_true.to_homogeneous()).amax();
                assert!(
                    d < 1e-12,
                    "{setup:?} view {k}: chain off by {d} (m, unitless)"
                );
            }
        }
    }

    /// Without noise the observation is the truth: the robot poses to
    /// rounding (1e-12 m and rad) and the board poses by PnP from exact
    /// pixels to 1e-9 (m and rad).
    #[wasm_bindgen_test(unsupported = test)]
    fn a_noise_free_observation_gives_the_true_poses() {
        let camera = Camera::pinhole(1100.0, 1100.0, 639.5, 479.5, 1280, 960);
        let config = LookingConfig::half_metre(Setup::EyeToHand, 5);
        let clean = LookingNoise {
            pixel_sigma: 0.0,
            robot_sigma: (0.0, 0.0),
            kinematic: None,
        };
        let seen = observe_looking(&config, 3, &camera, &clean, 4);
        let input = seen.handeye_input(&camera).unwrap();
        assert_eq!(input.setup, Setup::EyeToHand);
        let off = |a: &Pose, b: &Pose| {
            let d = a.inverse() * b;
            (d.rotation.angle(), d.translation.vector.norm())
        };
        for k in 0..5 {
            let (r, t) = off(
                &input.base_from_gripper[k],
                &seen.scene.base_from_gripper[k],
            );
            assert!(r < 1e-12 && t < 1e-12, "robot {k}: {r} rad, {t} m");
            let (r, t) = off(
                &input.camera_from_target[k],
                &seen.scene.camera_from_target[k],
            );
            assert!(r < 1e-9 && t < 1e-9, "board {k}: {r} rad, {t} m");
            assert_eq!(
                seen.views[k].image_px.len(),
                54,
                "view {k}: points in the image"
            );
        }
    }

    /// One height: every camera centre lies `distance_m` above the board
    /// (target z = -distance), the views keep their tilts and the chain
    /// closes; the plain scene of the same seed varies its heights.
    #[wasm_bindgen_test(unsupported = test)]
    fn a_one_height_scene_keeps_every_camera_at_the_distance() {
        let config = LookingConfig {
            setup: Setup::EyeInHand,
            views: 12,
            distance_m: 0.5,
            grid: (9, 6, 0.03),
            max_tilt_deg: 10.0,
            max_roll_deg: 60.0,
        };
        let flat = looking_scene_one_height(&config, 3);
        let plain = looking_scene(&config, 3);
        let heights = |s: &LookingScene| -> Vec<f64> {
            s.camera_from_target
                .iter()
                .map(|p| p.inverse().translation.vector.z)
                .collect()
        };
        for (k, z) in heights(&flat).iter().enumerate() {
            assert!((z + 0.5).abs() < 1e-12, "view {k}: camera at z = {z} m");
        }
        let spread = heights(&plain)
            .iter()
            .fold(0.0f64, |m, z| m.max((z + 0.5).abs()));
        assert!(spread > 0.01, "plain scene heights within {spread} m");
        // The same draws: the same orientations.
        for (a, b) in flat
            .camera_from_target
            .iter()
            .zip(&plain.camera_from_target)
        {
            assert!(a.rotation.angle_to(&b.rotation) < 1e-12);
        }
        for (k, (robot, camera)) in flat
            .base_from_gripper
            .iter()
            .zip(&flat.camera_from_target)
            .enumerate()
        {
            let y = robot * flat.x_true * camera;
            let d = (y.to_homogeneous() - flat.y_true.to_homogeneous()).amax();
            assert!(d < 1e-12, "view {k}: chain off by {d}");
        }
    }
}
