//! The small, low-contrast marker scene of issue 36: a 1280x720 webcam
//! (f = 900 px) looking at a marker board from 0.95-1.25 m in six fixed
//! poses, rendered under three print and blur conditions (blur 1.2-1.6
//! px, print 30 / 220 down to 100 / 160, noise sigma 2-3). ChArUco
//! 10x7 DICT_4X4_50 (22 mm markers) shows 16-21 px markers there, AprilGrid
//! 7x5 (25 mm) 18-24 px tags.
//!
//! One definition for the recall test (tests/detect/detect_marker_recall.rs,
//! whose floors were measured on it) and the set written for OpenCV
//! (examples/marker_recall_set.rs, benches/marker_recall_opencv.py): the
//! bench compares OpenCV against the test's floors only while both render
//! the same images.

use super::{board_pose, render, Pinhole, RenderOptions, Rendered};
use crate::error::{Error, Result};
use crate::target::Target;

/// The webcam: 1280x720, f = 900 px, the principal point off the centre.
pub fn webcam() -> Pinhole {
    Pinhole {
        fx: 900.0,
        fy: 900.0,
        cx: 641.2,
        cy: 358.7,
        width: 1280,
        height: 720,
    }
}

/// A board pose: (roll, pitch, yaw) radians, the board's centre (metres,
/// camera frame), as [`board_pose`] takes them.
pub type BoardView = ((f64, f64, f64), (f64, f64, f64));

/// The six poses.
pub const VIEWS: [BoardView; 6] = [
    ((0.1, -0.2, 0.05), (0.0, 0.0, 1.0)),
    ((0.45, 0.3, -0.3), (0.12, -0.05, 1.1)),
    ((-0.35, 0.5, 0.6), (-0.15, 0.08, 1.2)),
    ((0.6, 0.0, 0.2), (0.05, 0.1, 0.95)),
    ((0.0, -0.55, -0.1), (-0.1, -0.1, 1.05)),
    ((0.3, 0.3, 1.2), (0.2, 0.05, 1.25)),
];

/// A print and blur condition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Condition {
    /// Gaussian blur sigma (px).
    pub blur: f64,
    /// The print's black and white grey levels.
    pub black: f64,
    /// See `black`.
    pub white: f64,
    /// Pixel noise sigma (grey levels).
    pub noise: f64,
}

/// The three conditions.
pub const CONDITIONS: [Condition; 3] = [
    Condition {
        blur: 1.2,
        black: 30.0,
        white: 220.0,
        noise: 2.0,
    },
    Condition {
        blur: 1.6,
        black: 80.0,
        white: 170.0,
        noise: 2.0,
    },
    Condition {
        blur: 1.4,
        black: 100.0,
        white: 160.0,
        noise: 3.0,
    },
];

/// Condition `c`'s render of view `v` of `target` (noise seed `10 c + v`).
pub fn render_view(target: &Target, c: usize, v: usize) -> Result<Rendered> {
    let (Some(k), Some(&(rpy, at))) = (CONDITIONS.get(c), VIEWS.get(v)) else {
        return Err(Error::Invalid {
            field: "small-marker view".into(),
            message: format!(
                "the small-marker scene has {} conditions and {} views: no condition {c}, \
                 view {v}",
                CONDITIONS.len(),
                VIEWS.len()
            ),
        });
    };
    let options = RenderOptions {
        blur_sigma_px: k.blur,
        black: k.black,
        white: k.white,
        noise_sigma: k.noise,
        seed: (10 * c + v) as u64,
        ..RenderOptions::default()
    };
    render(&webcam(), target, &board_pose(target, rpy, at), &options)
}
