//! Seeded synthetic data: the one generator shared by tests, benchmarks,
//! examples and the web app's demo button. Deterministic for a given seed on
//! every platform (native and wasm).

mod albedo;
mod bow;
pub mod clutter;
pub mod demo;
pub mod effects;
pub mod handeye;
pub mod handeye_looking;
pub mod laser;
pub mod laser_cubes;
pub mod laser_raycast;
pub mod laser_scene;
pub mod laser_sphere;
pub mod lens;
pub mod render;
pub mod rig;
pub mod scene;
pub mod video;

pub use scene::Scene;

/// The seeded generator of every scene (at the crate root: the hand-eye
/// bootstrap draws from it too).
pub use crate::rng::Rng;
pub use clutter::clutter;
pub use effects::Effects;
pub use render::{render, Pinhole, Projection, RenderOptions, Rendered};
pub use video::{video_camera, BoardVideo, VideoOptions};

use crate::target::Target;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// `camera_from_target` with the board's centre (the middle of its point
/// extent) at `at = (x, y, z)` metres in the camera frame and the board
/// rotated by roll, pitch, yaw `rpy` (radians, nalgebra's Euler angles):
/// the pose a test or a scene asks for when it thinks of where the board is.
pub fn board_pose(target: &Target, rpy: (f64, f64, f64), at: (f64, f64, f64)) -> Isometry3<f64> {
    let pts = target.object_points();
    let mx = pts.iter().map(|p| p.1.x).fold(0.0, f64::max) / 2.0;
    let my = pts.iter().map(|p| p.1.y).fold(0.0, f64::max) / 2.0;
    let r = UnitQuaternion::from_euler_angles(rpy.0, rpy.1, rpy.2);
    let t = Vector3::new(at.0, at.1, at.2) - r * Vector3::new(mx, my, 0.0);
    Isometry3::from_parts(Translation3::from(t), r)
}

#[cfg(test)]
mod effects_tests;
