//! A seeded video of a board moving through a sequence of poses with holds:
//! the script behind `robocal render --video board.y4m` (issue 21's fake
//! camera for the live-capture tests) with the exact truth of every frame.
//!
//! The script: a lead-in where the board slides into view from the left
//! (frames with the board not found, then partly found), then for each of
//! [`KEYFRAMES`] a hold (the board perfectly still, where auto-capture
//! should fire) followed by a smooth move to the next keyframe (smoothstep
//! in time: translation interpolated linearly, rotation by slerp). The
//! keyframes cover the nine cells of a 3x3 grid over the image, tilts of up
//! to about 40 degrees about both image axes in both directions, and board
//! widths from 30 % to 70 % of the image width (far, middle and near). The seed
//! jitters every keyframe a little (aim, tilt, size, spin) and seeds the
//! pixel noise of each frame.

use super::{render, RenderOptions, Rendered};
use crate::camera::{Camera, Distortion};
use crate::error::{Error, Result};
use crate::geometry::{Pose, PoseJson};
use crate::rng::Rng;
use crate::target::placement::fitted_pose;
use crate::target::Target;
use nalgebra::{Point2, Translation3, UnitQuaternion, Vector3};
use serde::Serialize;

/// The keyframes: where the board's centre is aimed (fraction of the image
/// width and height), its tilt about the image x and y axes (degrees), and
/// the fraction of the image width its points span.
pub const KEYFRAMES: [(f64, f64, f64, f64, f64); 12] = [
    (0.50, 0.50, 0.0, 0.0, 0.45),
    (0.30, 0.30, 25.0, 0.0, 0.42),
    (0.70, 0.30, 0.0, -25.0, 0.42),
    (0.70, 0.70, -25.0, 0.0, 0.42),
    (0.30, 0.70, 0.0, 25.0, 0.42),
    (0.50, 0.50, 30.0, 30.0, 0.70),
    (0.50, 0.22, 0.0, 35.0, 0.30),
    (0.78, 0.50, -35.0, 0.0, 0.30),
    (0.50, 0.78, 0.0, -35.0, 0.30),
    (0.22, 0.50, 35.0, -20.0, 0.30),
    (0.50, 0.50, -30.0, -30.0, 0.30),
    (0.50, 0.50, 0.0, 40.0, 0.65),
];

/// How the video is timed. Defaults: 15 fps, 1 s holds, 1.2 s moves, a
/// 1 s lead-in (about 28 s in all).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VideoOptions {
    /// Frames per second (1..=120).
    pub fps: f64,
    /// Length of each hold, seconds.
    pub hold_s: f64,
    /// Length of each move between holds, seconds.
    pub move_s: f64,
    /// Length of the lead-in (board sliding into view), seconds.
    pub lead_s: f64,
    /// Seed of the keyframe jitter and of the pixel noise.
    pub seed: u64,
}

impl Default for VideoOptions {
    fn default() -> Self {
        VideoOptions {
            fps: 15.0,
            hold_s: 1.0,
            move_s: 1.2,
            lead_s: 1.0,
            seed: 1,
        }
    }
}

/// One frame's truth.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VideoFrame {
    /// Frame index from 0.
    pub index: usize,
    /// Presentation time, milliseconds from the first frame.
    pub time_ms: f64,
    /// The board's pose.
    #[serde(serialize_with = "pose_json")]
    pub camera_from_target: Pose,
    /// The hold this frame belongs to (index into `holds`), `None` while
    /// the board moves.
    pub hold: Option<usize>,
}

/// One still segment of the video.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Hold {
    /// First frame of the hold.
    pub first_frame: usize,
    /// Last frame of the hold (inclusive).
    pub last_frame: usize,
    /// The board's pose during the hold.
    #[serde(serialize_with = "pose_json")]
    pub camera_from_target: Pose,
}

/// The whole script with its truth.
#[derive(Debug, Clone, Serialize)]
pub struct BoardVideo {
    /// The true camera.
    pub camera: Camera,
    /// The board.
    pub target: Target,
    /// Timing and seed.
    pub options: VideoOptions,
    /// Every frame, in order.
    pub frames: Vec<VideoFrame>,
    /// The holds, in order.
    pub holds: Vec<Hold>,
}

fn pose_json<S: serde::Serializer>(pose: &Pose, s: S) -> std::result::Result<S::Ok, S::Error> {
    PoseJson::from(pose).serialize(s)
}

/// The camera of the videos: square pixels, focal length 0.85 times the
/// width, principal point at the centre, mild barrel distortion (k1 = -0.1,
/// k2 = 0.02: within the default Brown model, so a calibration can recover
/// it exactly).
pub fn video_camera(width: u32, height: u32) -> Camera {
    let f = 0.85 * width as f64;
    Camera {
        fx: f,
        fy: f,
        cx: 0.5 * (width as f64 - 1.0),
        cy: 0.5 * (height as f64 - 1.0),
        skew: 0.0,
        width,
        height,
        distortion: Distortion::Brown {
            k1: -0.1,
            k2: 0.02,
            k3: 0.0,
            p1: 0.0,
            p2: 0.0,
        },
    }
}

impl BoardVideo {
    /// The script for `target` seen by `camera`.
    pub fn new(camera: &Camera, target: &Target, options: &VideoOptions) -> Result<BoardVideo> {
        check_options(options)?;
        let target = target.clone().validated()?;
        let mut rng = Rng::new(options.seed);
        let keys: Vec<Pose> = KEYFRAMES
            .iter()
            .map(|k| keyframe_pose(camera, &target, *k, &mut rng))
            .collect::<Result<_>>()?;
        let frames_of = |s: f64| (s * options.fps).round() as usize;
        let (n_lead, n_hold, n_move) = (
            frames_of(options.lead_s),
            frames_of(options.hold_s).max(1),
            frames_of(options.move_s),
        );
        let mut poses: Vec<(Pose, Option<usize>)> = Vec::new();
        // The lead-in starts with the board one image width (at its depth)
        // to the left of the first keyframe.
        let first = keys[0];
        let depth = first.translation.vector.z;
        let offset = Vector3::new(-1.1 * camera.width as f64 * depth / camera.fx, 0.0, 0.0);
        let start = Pose::from_parts(
            Translation3::from(first.translation.vector + offset),
            first.rotation,
        );
        for i in 0..n_lead {
            poses.push((blend(&start, &first, i as f64 / n_lead as f64), None));
        }
        let mut holds = Vec::with_capacity(keys.len());
        for (k, key) in keys.iter().enumerate() {
            holds.push(Hold {
                first_frame: poses.len(),
                last_frame: poses.len() + n_hold - 1,
                camera_from_target: *key,
            });
            poses.extend(std::iter::repeat((*key, Some(k))).take(n_hold));
            if let Some(next) = keys.get(k + 1) {
                for i in 1..=n_move {
                    poses.push((blend(key, next, i as f64 / (n_move + 1) as f64), None));
                }
            }
        }
        let frames = poses
            .into_iter()
            .enumerate()
            .map(|(index, (camera_from_target, hold))| VideoFrame {
                index,
                time_ms: index as f64 * 1000.0 / options.fps,
                camera_from_target,
                hold,
            })
            .collect();
        Ok(BoardVideo {
            camera: camera.clone(),
            target,
            options: options.clone(),
            frames,
            holds,
        })
    }

    /// Render frame `index` (pixel noise seeded by the video's seed and the
    /// frame index; `base` gives the other photometric settings).
    pub fn render_frame(&self, index: usize, base: &RenderOptions) -> Result<Rendered> {
        let frame = self.frames.get(index).ok_or_else(|| {
            Error::invalid(
                "frame",
                format!(
                    "expected a frame index below {}, got {index}",
                    self.frames.len()
                ),
            )
        })?;
        let options = RenderOptions {
            seed: self
                .options
                .seed
                .wrapping_mul(1_000_003)
                .wrapping_add(index as u64),
            ..base.clone()
        };
        render(
            &self.camera,
            &self.target,
            &frame.camera_from_target,
            &options,
        )
    }
}

fn check_options(o: &VideoOptions) -> Result<()> {
    let ok = o.fps.is_finite() && (1.0..=120.0).contains(&o.fps);
    let times = [("hold", o.hold_s), ("move", o.move_s), ("lead", o.lead_s)];
    if !ok {
        return Err(Error::invalid(
            "video",
            format!(
                "expected a frame rate between 1 and 120 fps, got {}",
                crate::error::compact(o.fps)
            ),
        ));
    }
    for (name, s) in times {
        if !(s.is_finite() && (0.0..=60.0).contains(&s)) {
            return Err(Error::invalid(
                "video",
                format!(
                    "expected a {name} time between 0 and 60 s, got {}",
                    crate::error::compact(s)
                ),
            ));
        }
    }
    Ok(())
}

/// Smoothstep blend from `a` (t = 0) to `b` (t = 1).
fn blend(a: &Pose, b: &Pose, t: f64) -> Pose {
    let s = t * t * (3.0 - 2.0 * t);
    let translation = a.translation.vector.lerp(&b.translation.vector, s);
    let rotation = a.rotation.slerp(&b.rotation, s);
    Pose::from_parts(Translation3::from(translation), rotation)
}

/// The pose of one keyframe, jittered by `rng`.
fn keyframe_pose(
    camera: &Camera,
    target: &Target,
    key: (f64, f64, f64, f64, f64),
    rng: &mut Rng,
) -> Result<Pose> {
    let (u, v, tilt_x, tilt_y, span) = key;
    let (w, h) = (camera.width as f64, camera.height as f64);
    let aim = Point2::new(
        (u + rng.range(-0.03, 0.03)) * w,
        (v + rng.range(-0.03, 0.03)) * h,
    );
    let rotation = UnitQuaternion::from_axis_angle(
        &Vector3::x_axis(),
        (tilt_x + rng.range(-4.0, 4.0)).to_radians(),
    ) * UnitQuaternion::from_axis_angle(
        &Vector3::y_axis(),
        (tilt_y + rng.range(-4.0, 4.0)).to_radians(),
    ) * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), rng.range(-0.15, 0.15));
    fitted_pose(camera, target, &aim, rotation, span * rng.range(0.95, 1.05))
}
