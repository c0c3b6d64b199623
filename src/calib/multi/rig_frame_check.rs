//! Are a rig's frames grouped right? Proven from the board poses each
//! camera found alone, before the joint fit (issue 35: "same for the rig's
//! frame grouping").
//!
//! # The test
//!
//! Two cameras `a` and `b` fixed to each other (`b_from_a = X`) see the
//! board of frame `f` at `B_f = X * A_f`. The board's motion between frames
//! `f` and `g` as `b` sees it, `B_g * B_f^-1 = X * (A_g * A_f^-1) * X^-1`,
//! is conjugate to the motion `a` sees: **their rotation angles are equal
//! whatever `X` is**, so the grouping can be judged before `X` is known. A
//! grouping's mismatch is the median over motion pairs of the absolute
//! difference of the two angles (degrees): noise-level (hundredths of a
//! degree) when both images of each frame were taken at one moment,
//! degrees when one camera's images sit in the wrong frames. Motions that
//! rotate less than [`MIN_ANGLE_DEG`] on both sides say nothing and are
//! left out.
//!
//! Along each edge of the co-observation spanning tree the child camera's
//! frames are also tried shifted by 1 to [`MAX_SHIFT`] frames either way (a
//! free-running camera that started a frame late, a file numbering that
//! starts at 1 in one folder and 0 in another). A shift that fits
//! [`RATIO`] times better than the grouping as given, which is off by at
//! least [`MIN_MISMATCH_DEG`], is an error naming the shift; a grouping off
//! by [`WARN_MISMATCH_DEG`] that no shift explains is a warning (frames not
//! taken at one moment: free-running cameras filming a moving board).
//!
//! Cost: at most [`MAX_PARTNERS`] motion pairs per frame, linear in the
//! frames.

use crate::geometry::{motion_partners, Pose};

/// Motions rotating less than this (both sides) are left out.
pub const MIN_ANGLE_DEG: f64 = 1.0;
/// A shift must fit this many times better than the grouping as given ...
pub const RATIO: f64 = 5.0;
/// ... and the grouping as given be off by at least this (degrees).
pub const MIN_MISMATCH_DEG: f64 = 0.5;
/// A grouping off by this much (degrees) that no shift explains is warned.
pub const WARN_MISMATCH_DEG: f64 = 1.0;
/// Shifts tried, in frames, either way.
pub const MAX_SHIFT: usize = 3;
/// Motion pairs per frame beyond which the pairs are thinned.
pub const MAX_PARTNERS: usize = 8;
/// Fewest paired frames a grouping needs to be judged.
const MIN_FRAMES: usize = 3;

/// One camera's board poses: `frames[i]` is the frame index of
/// `camera_from_target[i]` (at most one pose per frame).
#[derive(Clone, Copy, Debug)]
pub struct CameraFrames<'a> {
    /// Frame index of each pose.
    pub frames: &'a [usize],
    /// camera_from_target per pose.
    pub camera_from_target: &'a [Pose],
}

impl CameraFrames<'_> {
    fn pose_at(&self, frame: usize) -> Option<Pose> {
        self.frames
            .iter()
            .position(|&f| f == frame)
            .map(|i| self.camera_from_target[i])
    }
}

/// What the test found on one pair of cameras.
#[derive(Clone, Debug, PartialEq)]
pub enum FrameFinding {
    /// The child's frames fit only when shifted: its frame `f + shift`
    /// holds what the parent saw in frame `f`.
    Shifted {
        /// Frames, positive when the child's frames come late.
        shift: i64,
        /// The median angle mismatch shifted (degrees).
        shifted_deg: f64,
        /// As grouped (degrees).
        given_deg: f64,
        /// One pair of frames the shift joins: (parent's, child's).
        example: (usize, usize),
    },
    /// The grouping is off and no shift explains it.
    Disagree {
        /// The median angle mismatch as grouped (degrees).
        given_deg: f64,
    },
}

/// The median absolute difference of the rotation angles of the board's
/// motions seen by two cameras over paired poses, or `None` when fewer than
/// [`MIN_FRAMES`] are paired or no motion rotates.
pub fn angle_mismatch_deg(pairs: &[(Pose, Pose)]) -> Option<f64> {
    let n = pairs.len();
    if n < MIN_FRAMES {
        return None;
    }
    let mut diffs = Vec::new();
    for i in 0..n {
        for j in motion_partners(i, n, MAX_PARTNERS) {
            let a = (pairs[j].0 * pairs[i].0.inverse()).rotation.angle();
            let b = (pairs[j].1 * pairs[i].1.inverse()).rotation.angle();
            let (a, b) = (a.to_degrees(), b.to_degrees());
            if a.max(b) >= MIN_ANGLE_DEG && a.is_finite() && b.is_finite() {
                diffs.push((a - b).abs());
            }
        }
    }
    if diffs.is_empty() {
        return None;
    }
    diffs.sort_by(f64::total_cmp);
    Some(diffs[diffs.len() / 2])
}

/// The parent's and child's poses of the frames where the parent saw frame
/// `f` and the child frame `f + shift`.
fn paired(parent: &CameraFrames, child: &CameraFrames, shift: i64) -> Vec<(Pose, Pose)> {
    parent
        .frames
        .iter()
        .zip(parent.camera_from_target)
        .filter_map(|(&f, p)| {
            let g = usize::try_from(f as i64 + shift).ok()?;
            Some((*p, child.pose_at(g)?))
        })
        .collect()
}

/// The test of the module docs on one pair of cameras: `None` when the
/// grouping fits (or cannot be judged).
pub fn check_pair(parent: &CameraFrames, child: &CameraFrames) -> Option<FrameFinding> {
    let given_deg = angle_mismatch_deg(&paired(parent, child, 0))?;
    if given_deg < MIN_MISMATCH_DEG {
        return None;
    }
    let best = (1..=MAX_SHIFT as i64)
        .flat_map(|k| [k, -k])
        .filter_map(|k| angle_mismatch_deg(&paired(parent, child, k)).map(|d| (k, d)))
        .filter(|&(_, d)| d * RATIO < given_deg)
        .min_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((shift, shifted_deg)) = best {
        let example = parent
            .frames
            .iter()
            .find_map(|&f| {
                let g = usize::try_from(f as i64 + shift).ok()?;
                child.pose_at(g).map(|_| (f, g))
            })
            .unwrap_or((0, 0));
        return Some(FrameFinding::Shifted {
            shift,
            shifted_deg,
            given_deg,
            example,
        });
    }
    (given_deg >= WARN_MISMATCH_DEG).then_some(FrameFinding::Disagree { given_deg })
}

/// The message of a finding between cameras `parent` and `child`; frame
/// keys name the frames; `grouping` says how they were grouped.
pub fn message(
    finding: &FrameFinding,
    parent: &str,
    child: &str,
    frame_keys: &[String],
    grouping: &str,
) -> String {
    let key = |f: usize| frame_keys.get(f).map_or("?", String::as_str);
    match finding {
        FrameFinding::Shifted {
            shift,
            shifted_deg,
            given_deg,
            example: (p, c),
        } => {
            let n = shift.unsigned_abs();
            let frames = if n == 1 { "frame" } else { "frames" };
            let way = if *shift > 0 { "late" } else { "early" };
            format!(
                "cameras {parent} and {child}: the board's motions agree only when {child}'s \
                 frames are taken {n} {frames} {way} ({parent}'s frame '{}' with {child}'s frame \
                 '{}'): {shifted_deg:.3} deg (median) so, against {given_deg:.3} deg as grouped \
                 by {grouping}: {child}'s images sit in the wrong frames; rename them or \
                 choose another grouping rule so that each frame holds images taken at one \
                 moment",
                key(*p),
                key(*c)
            )
        }
        FrameFinding::Disagree { given_deg } => format!(
            "cameras {parent} and {child} disagree on how the board moved between frames by \
             {given_deg:.2} deg (median over motions): the images of a frame were not taken at \
             one moment (free-running cameras filming a moving board) or some frames are \
             grouped wrong; the rig's extrinsics and intrinsics absorb it. Hold the board \
             still for each frame, trigger the cameras together, or check the grouping \
             ({grouping})"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::rotation_from_rotvec;
    use crate::synth::Rng;
    use nalgebra::{Translation3, UnitQuaternion, Vector3};
    use wasm_bindgen_test::wasm_bindgen_test;

    /// Board poses of `n` frames in camera a and, through a fixed `X`, in
    /// camera b; b's poses carry `noise_deg` of rotation noise.
    fn two_cameras(n: usize, seed: u64, noise_deg: f64) -> (Vec<Pose>, Vec<Pose>) {
        let mut rng = Rng::new(seed);
        let x = Pose::from_parts(
            Translation3::new(0.3, 0.0, 0.05),
            UnitQuaternion::from_euler_angles(0.1, -0.6, 0.05),
        );
        let mut a = Vec::new();
        let mut b = Vec::new();
        for _ in 0..n {
            let r = rotation_from_rotvec(&Vector3::new(
                rng.range(-0.5, 0.5),
                rng.range(-0.5, 0.5),
                rng.range(-0.8, 0.8),
            ));
            let p = Pose::from_parts(
                Translation3::new(rng.range(-0.1, 0.1), rng.range(-0.1, 0.1), 1.0),
                r,
            );
            let e = rotation_from_rotvec(&Vector3::new(
                rng.gaussian(noise_deg.to_radians()),
                rng.gaussian(noise_deg.to_radians()),
                rng.gaussian(noise_deg.to_radians()),
            ));
            a.push(p);
            b.push(Pose::from_parts(Translation3::identity(), e) * x * p);
        }
        (a, b)
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn right_grouping_passes_a_shift_is_named_and_a_shuffle_warned() {
        let (a, b) = two_cameras(20, 3, 0.02);
        let frames: Vec<usize> = (0..20).collect();
        let parent = CameraFrames {
            frames: &frames,
            camera_from_target: &a,
        };
        let child = CameraFrames {
            frames: &frames,
            camera_from_target: &b,
        };
        assert_eq!(check_pair(&parent, &child), None);
        // The child's images numbered one frame late: its frame f + 1 holds
        // what the parent saw in frame f.
        let late: Vec<usize> = (1..21).collect();
        let shifted = CameraFrames {
            frames: &late,
            camera_from_target: &b,
        };
        match check_pair(&parent, &shifted) {
            Some(FrameFinding::Shifted {
                shift,
                shifted_deg,
                given_deg,
                example,
            }) => {
                assert_eq!(shift, 1);
                assert_eq!(example, (0, 1));
                assert!(shifted_deg < 0.1, "{shifted_deg}");
                assert!(given_deg > 5.0, "{given_deg}");
            }
            other => panic!("{other:?}"),
        }
        // A shuffle no shift explains: a warning, not a named shift.
        let shuffled: Vec<usize> = (0..20).map(|i| (i * 7) % 20).collect();
        let child = CameraFrames {
            frames: &shuffled,
            camera_from_target: &b,
        };
        assert!(matches!(
            check_pair(&parent, &child),
            Some(FrameFinding::Disagree { given_deg }) if given_deg > 5.0
        ));
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn messages_name_the_cameras_frames_and_the_fix() {
        let keys: Vec<String> = (0..5).map(|i| format!("{:03}", i)).collect();
        let m = message(
            &FrameFinding::Shifted {
                shift: 1,
                shifted_deg: 0.012,
                given_deg: 14.5,
                example: (0, 1),
            },
            "cam0",
            "cam1",
            &keys,
            "number",
        );
        assert_eq!(
            m,
            "cameras cam0 and cam1: the board's motions agree only when cam1's frames are taken \
             1 frame late (cam0's frame '000' with cam1's frame '001'): 0.012 deg (median) so, \
             against 14.500 deg as grouped by number: cam1's images sit in the wrong frames; \
             rename them or choose another grouping rule so that each frame holds images taken \
             at one moment"
        );
    }
}
