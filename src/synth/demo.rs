//! The demo session behind the web app's "load demo data" button (and
//! `robocal render --demo`): a seeded eye-in-hand scene with rendered
//! chessboard images, the robot poses that go with them, and the truth.

use super::{render, RenderOptions, Scene};
use crate::camera::{Camera, Distortion};
use crate::error::Result;
use crate::geometry::Pose;
use crate::image::GrayImage;
use crate::io::{format_poses, AngleUnit, LengthUnit, PoseFormat, RobotPose};
use crate::target::Target;
use nalgebra::{Translation3, UnitQuaternion, Vector3};

/// Views in the demo: enough for a well-conditioned calibration.
pub const DEMO_VIEWS: usize = 12;

/// A complete demo session with its ground truth.
#[derive(Debug, Clone)]
pub struct DemoSession {
    /// The printed target (9 x 6 inner corners, 30 mm squares).
    pub target: Target,
    /// Rendered images, named `demo_00.png`, ... in view order.
    pub images: Vec<(String, GrayImage)>,
    /// The robot's `base_from_gripper` poses as a UR-style CSV with an
    /// `image` column (metres, rotation vectors).
    pub poses_csv: String,
    /// The true camera.
    pub camera: Camera,
    /// The true hand-eye transform.
    pub gripper_from_camera: Pose,
    /// The true target pose in the robot base.
    pub base_from_target: Pose,
}

/// The camera of the demo: 1024 x 768, moderate barrel distortion.
pub fn demo_camera() -> Camera {
    Camera {
        fx: 900.0,
        fy: 900.0,
        cx: 511.5,
        cy: 383.5,
        skew: 0.0,
        width: 1024,
        height: 768,
        distortion: Distortion::Brown {
            k1: -0.18,
            k2: 0.05,
            k3: 0.0,
            p1: 0.0005,
            p2: -0.0003,
        },
    }
}

/// Render the demo session for `seed` (deterministic on every platform).
pub fn demo_session(seed: u64) -> Result<DemoSession> {
    let camera = demo_camera();
    let (cols, rows, square_m) = (9, 6, 0.03);
    let target = Target::Chessboard {
        cols,
        rows,
        square_m,
    };
    let scene = Scene::calibration(seed, &camera, (cols, rows), square_m, DEMO_VIEWS, 0.0)?;
    // A camera 10 cm ahead of the flange, looking along the tool axis,
    // rolled 90 degrees; the board lies on the table 0.6 m ahead of the base.
    let gripper_from_camera = Pose::from_parts(
        Translation3::new(0.03, -0.02, 0.10),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2),
    );
    let base_from_target = Pose::from_parts(
        Translation3::new(0.6, -0.1, 0.0),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
    );
    let mut images = Vec::with_capacity(DEMO_VIEWS);
    let mut poses = Vec::with_capacity(DEMO_VIEWS);
    for (i, camera_from_target) in scene.camera_from_target.iter().enumerate() {
        let options = RenderOptions {
            seed: seed.wrapping_add(i as u64),
            vignetting: 0.2,
            ..RenderOptions::default()
        };
        let rendered = render(&camera, &target, camera_from_target, &options)?;
        let name = format!("demo_{i:02}.png");
        // base_from_gripper = base_from_target * target_from_camera * camera_from_gripper
        let base_from_gripper =
            base_from_target * camera_from_target.inverse() * gripper_from_camera.inverse();
        poses.push(RobotPose {
            name: Some(name.clone()),
            line: i + 2,
            base_from_gripper,
        });
        images.push((name, rendered.image));
    }
    let poses_csv = format_poses(&poses, PoseFormat::Ur, LengthUnit::Metre, AngleUnit::Radian);
    Ok(DemoSession {
        target,
        images,
        poses_csv,
        camera,
        gripper_from_camera,
        base_from_target,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{parse_poses, PoseFileOptions};

    // Native only: rendering 12 images takes seconds in a debug wasm build.
    #[test]
    fn the_demo_poses_close_the_hand_eye_loop() {
        let demo = demo_session(7).unwrap();
        assert_eq!(demo.images.len(), DEMO_VIEWS);
        assert_eq!(
            (demo.images[0].1.width, demo.images[0].1.height),
            (1024, 768)
        );
        let parsed = parse_poses(&demo.poses_csv, &PoseFileOptions::default()).unwrap();
        assert_eq!(parsed.format, PoseFormat::Ur);
        assert_eq!(parsed.poses[3].name.as_deref(), Some("demo_03.png"));
        // The CSV round-trips to 1e-12 m / rad (format_poses writes full precision).
        let scene = Scene::calibration(7, &demo.camera, (9, 6), 0.03, DEMO_VIEWS, 0.0).unwrap();
        for (pose, c) in parsed.poses.iter().zip(&scene.camera_from_target) {
            let closed = pose.base_from_gripper * demo.gripper_from_camera * c;
            let err = (closed.inverse() * demo.base_from_target)
                .translation
                .vector
                .norm();
            assert!(err < 1e-9, "loop closure {err} m");
        }
    }
}
