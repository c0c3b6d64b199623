//! Hand-eye capture guidance: how diverse the robot's rotations between the
//! kept frames are, with the core's motion-diversity measure
//! ([`crate::handeye::closed_form::motion::axis_spread`]).

use crate::geometry::Pose;
use crate::handeye::closed_form::motion::axis_spread;
use crate::handeye::MIN_MOTION_ROTATION_DEG;
use serde::Serialize;

/// Enough diversity: the motion axes spread at least this far (degrees)
/// from their dominant axis.
pub const GOOD_AXIS_SPREAD_DEG: f64 = 30.0;
/// Enough diversity: at least this many motions rotating more than
/// [`MIN_MOTION_ROTATION_DEG`].
pub const GOOD_MOTIONS: usize = 3;

/// The robot-motion diversity of the captures paired with robot poses.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HandEyeGuide {
    /// Captures with a robot pose.
    pub poses: usize,
    /// Pairs of them whose relative rotation exceeds the core's minimum.
    pub motions: usize,
    /// Largest angle of a motion axis from the dominant axis, degrees
    /// (0: all about one axis).
    pub axis_spread_deg: f64,
    /// The dominant rotation axis, in the robot's motion frame (unit).
    pub dominant_axis: [f64; 3],
    /// Whether the motions are diverse enough ([`GOOD_MOTIONS`] motions,
    /// spread of at least [`GOOD_AXIS_SPREAD_DEG`]).
    pub enough: bool,
    /// What to do next, one sentence.
    pub advice: String,
}

/// The guide for robot poses `base_from_gripper` of the captures (in
/// capture order; captures without one are left out).
pub fn handeye_guide(robot: &[Pose]) -> HandEyeGuide {
    let min = MIN_MOTION_ROTATION_DEG.to_radians();
    let mut axes = Vec::new();
    for i in 0..robot.len() {
        for j in i + 1..robot.len() {
            let motion = robot[j].inverse() * robot[i];
            if motion.rotation.angle() >= min {
                if let Some(a) = motion.rotation.axis() {
                    axes.push(a.into_inner());
                }
            }
        }
    }
    let (dominant, spread) = if axes.is_empty() {
        (nalgebra::Vector3::zeros(), 0.0)
    } else {
        axis_spread(&axes)
    };
    let enough = axes.len() >= GOOD_MOTIONS && spread >= GOOD_AXIS_SPREAD_DEG;
    let advice = if robot.len() < 2 {
        "pair captures with robot poses: at least 3, rotated about different axes".to_string()
    } else if axes.is_empty() {
        format!(
            "rotate the robot's tool by more than {MIN_MOTION_ROTATION_DEG} deg between captures"
        )
    } else if spread < GOOD_AXIS_SPREAD_DEG {
        format!(
            "rotate the tool about an axis away from ({:.2}, {:.2}, {:.2}): the motions so far spread only {spread:.0} deg",
            dominant.x, dominant.y, dominant.z
        )
    } else if axes.len() < GOOD_MOTIONS {
        "one more capture rotated about another axis".to_string()
    } else {
        "the robot motions are diverse enough for hand-eye".to_string()
    };
    HandEyeGuide {
        poses: robot.len(),
        motions: axes.len(),
        axis_spread_deg: spread,
        dominant_axis: [dominant.x, dominant.y, dominant.z],
        enough,
        advice,
    }
}
