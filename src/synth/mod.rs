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
pub mod small_markers;
pub mod video;

pub use scene::Scene;

/// The seeded generator of every scene (at the crate root: the hand-eye
/// bootstrap draws from it too).
pub use crate::rng::Rng;
pub use clutter::clutter;
pub use effects::Effects;
pub use render::{render, Pinhole, Projection, RenderOptions, Rendered};
pub use video::{video_camera, BoardVideo, VideoOptions};

use crate::target::{DetectedPoint, Target};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// `camera_from_target` with the board's centre (the middle of its point
/// extent) at `at = (x, y, z)` metres in the camera frame and the board
/// rotated by roll, pitch, yaw `rpy` (radians, nalgebra's Euler angles):
/// the pose a test or a scene asks for when it thinks of where the board is.
pub fn board_pose(target: &Target, rpy: (f64, f64, f64), at: (f64, f64, f64)) -> Isometry3<f64> {
    let r = UnitQuaternion::from_euler_angles(rpy.0, rpy.1, rpy.2);
    let t = Vector3::new(at.0, at.1, at.2) - r * board_centre(target);
    Isometry3::from_parts(Translation3::from(t), r)
}

/// `camera_from_target` with the board's centre at `at` (metres, camera
/// frame), the board tilted by `tilt` radians about an axis in its plane at
/// `axis` radians from its x axis, after a turn by `yaw` radians in its
/// plane: the steep views of the circle-grid tests ([`STEEP_VIEWS_DEG`]).
pub fn tilted_board_pose(
    target: &Target,
    tilt: f64,
    axis: f64,
    yaw: f64,
    at: Vector3<f64>,
) -> Isometry3<f64> {
    let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
    let in_plane = nalgebra::Unit::new_normalize(Vector3::new(axis.cos(), axis.sin(), 0.0));
    let r = UnitQuaternion::from_axis_angle(&in_plane, tilt) * turn;
    Isometry3::from_parts(Translation3::from(at - r * board_centre(target)), r)
}

/// The steep views of the asymmetric circle-grid test
/// (tests/detect/detect_circles_asym.rs) and `examples/steep_asym_set.rs`
/// ([`steep_view`]): (tilt, axis, yaw) of [`tilted_board_pose`], degrees.
pub const STEEP_VIEWS_DEG: [(f64, f64, f64); 6] = [
    (58.0, 0.0, 0.0),
    (62.0, 90.0, 0.0),
    (60.0, 30.0, 15.0),
    (64.0, 0.0, 90.0),
    (56.0, 120.0, -30.0),
    (60.0, 45.0, 45.0),
];

/// The middle of the board's point extent, target frame.
fn board_centre(target: &Target) -> Vector3<f64> {
    let pts = target.object_points();
    let mx = pts.iter().map(|p| p.1.x).fold(0.0, f64::max) / 2.0;
    let my = pts.iter().map(|p| p.1.y).fold(0.0, f64::max) / 2.0;
    Vector3::new(mx, my, 0.0)
}

/// The `k`-th steep view ([`STEEP_VIEWS_DEG`]) of `target` through
/// `camera`: the board's centre at (10, -10, 300) mm, rendered with seed
/// `700 + k`; `None` when it does not render, or when a point falls outside
/// the image or a circle is cut by its border (each centre must lie at least
/// a quarter of its distance to the nearest other centre from the border).
pub fn steep_view(target: &Target, camera: &dyn Projection, k: usize) -> Option<Rendered> {
    let (tilt, axis, yaw) = *STEEP_VIEWS_DEG.get(k)?;
    let pose = tilted_board_pose(
        target,
        tilt.to_radians(),
        axis.to_radians(),
        yaw.to_radians(),
        Vector3::new(0.01, -0.01, 0.3),
    );
    let options = RenderOptions {
        seed: 700 + k as u64,
        ..RenderOptions::default()
    };
    let r = render(camera, target, &pose, &options).ok()?;
    let whole = r.points.len() == target.point_count()
        && circles_whole_in_image(&r.points, r.image.width, r.image.height);
    whole.then_some(r)
}

/// Whether every circle of `points` (a rendering's true centres) lies
/// whole in a `width` x `height` image: each centre at least a quarter of
/// its distance to the nearest other centre from the border. A circle's
/// radius is a quarter of the grid unit and its nearest neighbour about
/// 1.4 units away, so the circles of the views kept are whole; the views
/// left out have a circle cut by the border, which no detector can centre.
fn circles_whole_in_image(points: &[DetectedPoint], width: u32, height: u32) -> bool {
    points.iter().all(|p| {
        let nearest = points
            .iter()
            .filter(|q| q.id != p.id)
            .map(|q| (q.x_px - p.x_px).hypot(q.y_px - p.y_px))
            .fold(f64::INFINITY, f64::min);
        let border = (p.x_px + 0.5)
            .min(width as f64 - 0.5 - p.x_px)
            .min(p.y_px + 0.5)
            .min(height as f64 - 0.5 - p.y_px);
        border >= 0.25 * nearest
    })
}

#[cfg(test)]
mod effects_tests;
