//! Relative motions `A = robot[j]^-1 * robot[i]`, `B = camera[j] *
//! camera[i]^-1` for AX = XB, their filtering and their diversity statistics.

use crate::handeye::{Chain, Pose, MIN_MOTION_ROTATION_DEG};
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

/// Which view pairs become motions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum MotionPairs {
    /// Every pair `i < j`: n(n-1)/2 motions, the most constraints (OpenCV does the same).
    #[default]
    All,
    /// Only consecutive views `(i, i+1)`: n-1 motions.
    Consecutive,
}

/// One relative motion between views `from` and `to`.
#[derive(Debug, Clone)]
pub struct Motion {
    /// First view index.
    pub from: usize,
    /// Second view index.
    pub to: usize,
    /// `A = robot[to]^-1 * robot[from]`.
    pub robot: Pose,
    /// `B = camera[to] * camera[from]^-1`.
    pub camera: Pose,
}

impl Motion {
    /// Robot rotation angle (radians).
    pub fn robot_angle(&self) -> f64 {
        self.robot.rotation.angle()
    }
    /// Camera rotation angle (radians).
    pub fn camera_angle(&self) -> f64 {
        self.camera.rotation.angle()
    }
}

/// Motions kept and the number discarded for too little rotation.
#[derive(Debug, Clone)]
pub struct MotionSet {
    /// Motions with enough rotation on both sides.
    pub kept: Vec<Motion>,
    /// Motion pairs dropped because a rotation was below [`MIN_MOTION_ROTATION_DEG`].
    pub discarded: usize,
    /// Largest robot rotation among all candidate pairs (degrees).
    pub largest_rotation_deg: f64,
}

/// Build the motions of `chain` for the chosen view pairs.
pub fn build_motions(chain: &Chain, pairs: MotionPairs) -> MotionSet {
    let n = chain.len();
    let mut index_pairs = Vec::new();
    match pairs {
        MotionPairs::All => {
            for i in 0..n {
                for j in i + 1..n {
                    index_pairs.push((i, j));
                }
            }
        }
        MotionPairs::Consecutive => {
            for i in 1..n {
                index_pairs.push((i - 1, i));
            }
        }
    }
    let min = MIN_MOTION_ROTATION_DEG.to_radians();
    let mut kept = Vec::with_capacity(index_pairs.len());
    let mut discarded = 0;
    let mut largest: f64 = 0.0;
    // Each pose's inverse once, not once per pair (half a million pairs at
    // 1,000 poses): the same values, so the same motions.
    let robot_inverse: Vec<Pose> = chain.robot.iter().map(|p| p.inverse()).collect();
    let camera_inverse: Vec<Pose> = chain.camera.iter().map(|p| p.inverse()).collect();
    for (i, j) in index_pairs {
        let m = Motion {
            from: i,
            to: j,
            robot: robot_inverse[j] * chain.robot[i],
            camera: chain.camera[j] * camera_inverse[i],
        };
        let robot_angle = m.robot_angle();
        largest = largest.max(robot_angle);
        if robot_angle < min || m.camera_angle() < min {
            discarded += 1;
        } else {
            kept.push(m);
        }
    }
    MotionSet {
        kept,
        discarded,
        largest_rotation_deg: largest.to_degrees(),
    }
}

/// How diverse the robot motions are: the angles and the spread of the axes.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct MotionStats {
    /// Motions used.
    pub motions: usize,
    /// Motion pairs discarded for too little rotation.
    pub discarded_small_rotation: usize,
    /// Smallest robot rotation angle among used motions (degrees).
    pub angle_min_deg: f64,
    /// Median robot rotation angle (degrees).
    pub angle_median_deg: f64,
    /// Largest robot rotation angle (degrees).
    pub angle_max_deg: f64,
    /// Largest angle between a motion axis and the dominant axis (degrees,
    /// sign-insensitive, 0..90): near 0 means all axes are parallel.
    pub axis_spread_deg: f64,
    /// Dominant rotation axis of the robot motions (unit, robot-motion frame).
    pub dominant_axis: [f64; 3],
}

/// The dominant axis (principal direction of `sum k k^T`) and the largest
/// angle of any axis from it, in degrees.
pub fn axis_spread(axes: &[Vector3<f64>]) -> (Vector3<f64>, f64) {
    let scatter = axes
        .iter()
        .fold(Matrix3::zeros(), |acc, k| acc + k * k.transpose());
    let eig = SymmetricEigen::new(scatter);
    let imax = eig.eigenvalues.imax();
    let dominant: Vector3<f64> = eig.eigenvectors.column(imax).into_owned();
    let spread = axes
        .iter()
        .map(|k| k.dot(&dominant).abs().clamp(0.0, 1.0).acos())
        .fold(0.0, f64::max);
    (dominant, spread.to_degrees())
}

/// Unit rotation axes of the robot motions.
pub fn robot_axes(motions: &[Motion]) -> Vec<Vector3<f64>> {
    motions
        .iter()
        .filter_map(|m| m.robot.rotation.axis().map(|a| a.into_inner()))
        .collect()
}

/// Statistics of a motion set.
pub fn motion_stats(set: &MotionSet) -> MotionStats {
    let mut angles: Vec<f64> = set
        .kept
        .iter()
        .map(|m| m.robot_angle().to_degrees())
        .collect();
    angles.sort_by(f64::total_cmp);
    let (dominant, spread) = axis_spread(&robot_axes(&set.kept));
    MotionStats {
        motions: set.kept.len(),
        discarded_small_rotation: set.discarded,
        angle_min_deg: angles.first().copied().unwrap_or(0.0),
        angle_median_deg: if angles.is_empty() {
            0.0
        } else {
            angles[angles.len() / 2]
        },
        angle_max_deg: angles.last().copied().unwrap_or(0.0),
        axis_spread_deg: spread,
        dominant_axis: [dominant.x, dominant.y, dominant.z],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn parallel_axes_have_zero_spread_and_orthogonal_ones_ninety() {
        let z = Vector3::z();
        let (_, s) = axis_spread(&[z, -z, z]);
        assert!(s < 1e-6, "spread {s} deg");
        let (_, s) = axis_spread(&[Vector3::x(), Vector3::y(), Vector3::x()]);
        assert!((s - 90.0).abs() < 1e-9, "spread {s} deg");
    }
}
