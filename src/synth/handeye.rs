//! Seeded hand-eye scenes generated the way OpenCV's
//! `test_calibration_hand_eye.cpp` does: a random hand-eye transform and
//! target pose, random gripper poses, and optional Gaussian noise added to
//! the rotation vectors and translations of the camera and robot poses.

use super::Rng;
use crate::handeye::{Pose, Setup};
use nalgebra::{Translation3, UnitQuaternion, Vector3};

/// What to generate. Ranges are OpenCV's; noise defaults are OpenCV's noisy
/// test (camera: 0.002 rad, 5 mm; robot: 0.001 rad, 1 mm).
#[derive(Debug, Clone)]
pub struct HandEyeSceneConfig {
    /// Camera on the gripper or fixed.
    pub setup: Setup,
    /// Number of views.
    pub views: usize,
    /// Std of the noise added to each rotation-vector component of the
    /// robot pose (radians).
    pub robot_rotation_sigma_rad: f64,
    /// Std of the noise added to each robot translation component (metres).
    pub robot_translation_sigma_m: f64,
    /// Std of the noise on each rotation-vector component of `camera_from_target` (radians).
    pub camera_rotation_sigma_rad: f64,
    /// Std of the noise on each translation component of `camera_from_target` (metres).
    pub camera_translation_sigma_m: f64,
}

impl HandEyeSceneConfig {
    /// A noise-free scene.
    pub fn noise_free(setup: Setup, views: usize) -> Self {
        HandEyeSceneConfig {
            setup,
            views,
            robot_rotation_sigma_rad: 0.0,
            robot_translation_sigma_m: 0.0,
            camera_rotation_sigma_rad: 0.0,
            camera_translation_sigma_m: 0.0,
        }
    }

    /// OpenCV's noisy test levels.
    pub fn opencv_noise(setup: Setup, views: usize) -> Self {
        HandEyeSceneConfig {
            setup,
            views,
            robot_rotation_sigma_rad: 0.001,
            robot_translation_sigma_m: 0.001,
            camera_rotation_sigma_rad: 0.002,
            camera_translation_sigma_m: 0.005,
        }
    }
}

/// A generated scene: the truth and the (possibly noisy) measurements.
#[derive(Debug, Clone)]
pub struct HandEyeScene {
    /// The setup.
    pub setup: Setup,
    /// True `gripper_from_camera` (eye-in-hand) or `base_from_camera` (eye-to-hand).
    pub x_true: Pose,
    /// True `base_from_target` (eye-in-hand) or `gripper_from_target` (eye-to-hand).
    pub y_true: Pose,
    /// Measured robot poses.
    pub base_from_gripper: Vec<Pose>,
    /// Measured camera poses.
    pub camera_from_target: Vec<Pose>,
    /// Noise-free robot poses.
    pub base_from_gripper_true: Vec<Pose>,
    /// Noise-free camera poses.
    pub camera_from_target_true: Vec<Pose>,
}

fn signed(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    let v = rng.range(lo, hi);
    if rng.uniform() < 0.5 {
        -v
    } else {
        v
    }
}

/// OpenCV's `generatePose`: random axis, angle in `[lo, hi]` with a random
/// sign, translation components in `[t_lo, t_hi]` with random signs.
pub fn random_pose(rng: &mut Rng, angle: (f64, f64), t: (f64, f64)) -> Pose {
    let axis = loop {
        let a = Vector3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        if a.norm() > 1e-3 {
            break a.normalize();
        }
    };
    let theta = signed(rng, angle.0.to_radians(), angle.1.to_radians());
    let tv = Vector3::new(
        signed(rng, t.0, t.1),
        signed(rng, t.0, t.1),
        signed(rng, t.0, t.1),
    );
    Pose::from_parts(
        Translation3::from(tv),
        UnitQuaternion::from_scaled_axis(axis * theta),
    )
}

fn perturb(rng: &mut Rng, p: &Pose, sigma_r: f64, sigma_t: f64) -> Pose {
    if sigma_r == 0.0 && sigma_t == 0.0 {
        return *p;
    }
    let rv = p.rotation.scaled_axis()
        + Vector3::new(
            rng.gaussian(sigma_r),
            rng.gaussian(sigma_r),
            rng.gaussian(sigma_r),
        );
    let t = p.translation.vector
        + Vector3::new(
            rng.gaussian(sigma_t),
            rng.gaussian(sigma_t),
            rng.gaussian(sigma_t),
        );
    Pose::from_parts(Translation3::from(t), UnitQuaternion::from_scaled_axis(rv))
}

/// Generate a scene from a seed.
pub fn handeye_scene(config: &HandEyeSceneConfig, seed: u64) -> HandEyeScene {
    let mut rng = Rng::new(seed);
    let near = (0.05, 0.5);
    let far = (0.5, 3.5);
    let (x, y) = match config.setup {
        Setup::EyeInHand => (
            random_pose(&mut rng, (10.0, 50.0), near),
            random_pose(&mut rng, (5.0, 85.0), far),
        ),
        Setup::EyeToHand => (
            random_pose(&mut rng, (10.0, 50.0), far),
            random_pose(&mut rng, (5.0, 85.0), near),
        ),
    };
    let mut scene = HandEyeScene {
        setup: config.setup,
        x_true: x,
        y_true: y,
        base_from_gripper: Vec::new(),
        camera_from_target: Vec::new(),
        base_from_gripper_true: Vec::new(),
        camera_from_target_true: Vec::new(),
    };
    for _ in 0..config.views {
        let base_from_gripper = random_pose(&mut rng, (5.0, 45.0), (0.5, 1.5));
        let camera_from_target = match config.setup {
            Setup::EyeInHand => x.inverse() * base_from_gripper.inverse() * y,
            Setup::EyeToHand => x.inverse() * base_from_gripper * y,
        };
        let noisy_camera = perturb(
            &mut rng,
            &camera_from_target,
            config.camera_rotation_sigma_rad,
            config.camera_translation_sigma_m,
        );
        // OpenCV perturbs the pose it hands to the solver: gripper2base for
        // eye-in-hand, base2gripper for eye-to-hand.
        let (sr, st) = (
            config.robot_rotation_sigma_rad,
            config.robot_translation_sigma_m,
        );
        let noisy_robot = match config.setup {
            Setup::EyeInHand => perturb(&mut rng, &base_from_gripper, sr, st),
            Setup::EyeToHand => perturb(&mut rng, &base_from_gripper.inverse(), sr, st).inverse(),
        };
        scene.base_from_gripper.push(noisy_robot);
        scene.camera_from_target.push(noisy_camera);
        scene.base_from_gripper_true.push(base_from_gripper);
        scene.camera_from_target_true.push(camera_from_target);
    }
    scene
}

/// Image points of a planar grid target (`cols` x `rows` points, `spacing`
/// metres, z = 0 in the target frame) in every view of `scene`, projected
/// with `camera` through the noise-free camera poses, plus Gaussian pixel
/// noise `pixel_sigma` per coordinate. Points that fail to project are left out.
pub fn project_grid(
    scene: &HandEyeScene,
    camera: &crate::camera::Camera,
    grid: (usize, usize, f64),
    pixel_sigma: f64,
    seed: u64,
) -> Vec<crate::calib::View> {
    let mut rng = Rng::new(seed);
    let (cols, rows, spacing) = grid;
    let object: Vec<nalgebra::Point3<f64>> = (0..rows)
        .flat_map(|r| {
            (0..cols)
                .map(move |c| nalgebra::Point3::new(c as f64 * spacing, r as f64 * spacing, 0.0))
        })
        .collect();
    scene
        .camera_from_target_true
        .iter()
        .map(|pose| {
            let mut view = crate::calib::View::new("", Vec::new(), Vec::new());
            for p in &object {
                if let Ok(px) = camera.project(&(pose * p)) {
                    view.object_m.push(*p);
                    view.image_px.push(nalgebra::Point2::new(
                        px.x + rng.gaussian(pixel_sigma),
                        px.y + rng.gaussian(pixel_sigma),
                    ));
                }
            }
            view
        })
        .collect()
}
