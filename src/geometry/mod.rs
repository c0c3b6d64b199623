//! Poses and rotations: the one pose type and every rotation convention the
//! crate reads or writes.
//!
//! A transform is a [`Pose`] named `a_from_b`: `a_from_b * p_b = p_a`, so
//! compositions cancel inner names (`base_from_camera = base_from_gripper *
//! gripper_from_camera`). Inside the crate rotations are
//! [`nalgebra::UnitQuaternion`] / [`nalgebra::Rotation3`], lengths in metres
//! and angles in radians. The functions here convert at the boundaries:
//!
//! - rotation vectors (axis * angle, radians): [`rotation_from_rotvec`],
//!   [`rotvec_from_rotation`], robust near 0 and near pi;
//! - quaternions with the component order in the name:
//!   [`rotation_from_quaternion_xyzw`], [`quaternion_xyzw_from_rotation`],
//!   [`rotation_from_quaternion_wxyz`], [`quaternion_wxyz_from_rotation`];
//! - Euler angles in all 12 axis orders, intrinsic or extrinsic:
//!   [`rotation_from_euler`], [`euler_from_rotation`];
//! - 4x4 homogeneous matrices with validation: [`pose_from_matrix4`],
//!   [`matrix4_from_pose`];
//! - the one JSON shape of a pose, [`PoseJson`] (written by every report)
//!   and [`PoseInput`] (what JSON inputs may give), in [`pose_serde`];
//! - dual quaternions ([`DualQuaternion`]) for screw-motion solvers;
//! - a [`Plane`] (unit normal, distance) and its change of frame with a
//!   propagated covariance ([`PlaneEstimate`]);
//! - [`nearest_rotation`] (SVD projection of a noisy 3x3),
//!   [`rotation_angle_between`], and rotation averaging
//!   ([`average_rotations_quaternion`], [`average_rotations_chordal`]).

mod average;
mod dual_quaternion;
mod euler;
mod motions;
mod plane;
pub mod pose_serde;
mod rotation;

pub use pose_serde::{PoseInput, PoseJson};

pub use average::{average_rotations_chordal, average_rotations_quaternion};
pub use dual_quaternion::DualQuaternion;
pub use euler::{euler_from_rotation, rotation_from_euler, EulerKind, EulerOrder};
pub use motions::motion_partners;
pub use plane::{tangent_basis, Plane, PlaneEstimate};
pub use rotation::{
    matrix4_from_pose, nearest_rotation, params_from_pose, pose_from_matrix4,
    pose_from_matrix4_with_tolerance, pose_from_params, quaternion_wxyz_from_rotation,
    quaternion_xyzw_from_rotation, rotation_angle_between, rotation_from_quaternion_wxyz,
    rotation_from_quaternion_xyzw, rotation_from_rotvec, rotvec_from_rotation, MATRIX4_TOLERANCE,
};

/// A rigid transform `a_from_b` (rotation then translation, metres):
/// `p_a = a_from_b * p_b`.
pub type Pose = nalgebra::Isometry3<f64>;

/// A rotation as a unit quaternion (the crate's internal rotation type).
pub type Rotation = nalgebra::UnitQuaternion<f64>;
