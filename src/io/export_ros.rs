//! URDF and ROS text for one transform `parent_from_child`: the URDF joint
//! (and a whole URDF file around it), and tf2_ros's
//! static_transform_publisher as ROS 1 and ROS 2 spell it, on the command
//! line and in a launch file (what easy_handeye users paste).
//!
//! Argument order: ROS 1's tf2_ros takes `x y z qx qy qz qw frame_id
//! child_frame_id` (positional); ROS 2 (Humble and later) takes named
//! arguments `--x --y --z --qx --qy --qz --qw --frame-id --child-frame-id`.
//! The frame_id is the parent: the pose is the child's in the parent frame.

use crate::geometry::{
    euler_from_rotation, quaternion_xyzw_from_rotation, EulerKind, EulerOrder, Pose,
};
use crate::io::export_camera::float;
use crate::io::export_transform::FrameNames;

fn xyz_quaternion(pose: &Pose) -> [String; 7] {
    let t = pose.translation.vector;
    let q = quaternion_xyzw_from_rotation(&pose.rotation);
    [t.x, t.y, t.z, q[0], q[1], q[2], q[3]].map(float)
}

/// A ROS node name from the frame names (letters, digits and `_` only).
fn node_name(names: &FrameNames) -> String {
    format!("{}_to_{}", names.parent, names.child)
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// `x y z qx qy qz qw parent child` (ROS 1 tf2_ros, positional).
pub fn ros1_args(pose: &Pose, names: &FrameNames) -> String {
    format!(
        "{} {} {}",
        xyz_quaternion(pose).join(" "),
        names.parent,
        names.child
    )
}

/// `--x X ... --qw QW --frame-id parent --child-frame-id child` (ROS 2).
pub fn ros2_args(pose: &Pose, names: &FrameNames) -> String {
    let v = xyz_quaternion(pose);
    format!(
        "--x {} --y {} --z {} --qx {} --qy {} --qz {} --qw {} --frame-id {} --child-frame-id {}",
        v[0], v[1], v[2], v[3], v[4], v[5], v[6], names.parent, names.child
    )
}

/// A ROS 1 launch file publishing the transform.
pub fn ros1_launch(label: &str, args: &str, names: &FrameNames) -> String {
    ros1_launch_nodes(label, &[(args.to_string(), names.clone())])
}

/// A ROS 1 launch file with one static_transform_publisher node per
/// `(arguments, frames)`.
pub fn ros1_launch_nodes(label: &str, nodes: &[(String, FrameNames)]) -> String {
    let lines: String = nodes
        .iter()
        .map(|(args, names)| {
            format!(
                "  <node pkg=\"tf2_ros\" type=\"static_transform_publisher\" name=\"{}\" args=\"{args}\"/>\n",
                node_name(names)
            )
        })
        .collect();
    format!(
        "<!-- {label}: x y z (m) qx qy qz qw parent child (ROS 1 tf2_ros) -->\n<launch>\n{lines}</launch>\n"
    )
}

/// A ROS 2 Python launch file publishing the transform.
pub fn ros2_launch(label: &str, args: &str, names: &FrameNames) -> String {
    ros2_launch_nodes(label, &[(args.to_string(), names.clone())])
}

/// A ROS 2 Python launch file with one static_transform_publisher node per
/// `(arguments, frames)`.
pub fn ros2_launch_nodes(label: &str, nodes: &[(String, FrameNames)]) -> String {
    let blocks: String = nodes
        .iter()
        .map(|(args, names)| {
            let quoted: Vec<String> = args.split(' ').map(|a| format!("'{a}'")).collect();
            format!(
                "        Node(\n            package='tf2_ros',\n            executable='static_transform_publisher',\n            name='{}',\n            arguments=[{}],\n        ),\n",
                node_name(names),
                quoted.join(", ")
            )
        })
        .collect();
    format!(
        "# {label} (ROS 2): save as e.g. calibration.launch.py\nfrom launch import LaunchDescription\nfrom launch_ros.actions import Node\n\n\ndef generate_launch_description():\n    return LaunchDescription([\n{blocks}    ])\n"
    )
}

/// The URDF `<joint type="fixed">` (origin rpy = extrinsic XYZ angles, radians).
pub fn urdf_joint(pose: &Pose, names: &FrameNames) -> String {
    let t = pose.translation.vector;
    let rpy = euler_from_rotation(&pose.rotation, EulerOrder::XYZ, EulerKind::Extrinsic);
    let list = |v: [f64; 3]| v.map(float).join(" ");
    format!(
        "<joint name=\"{p}_to_{c}\" type=\"fixed\">\n  <parent link=\"{p}\"/>\n  <child link=\"{c}\"/>\n  <origin xyz=\"{}\" rpy=\"{}\"/>\n</joint>\n",
        list([t.x, t.y, t.z]),
        list(rpy),
        p = names.parent,
        c = names.child
    )
}

/// A whole URDF document: the two links and the joint between them.
pub fn urdf_robot(joint: &str, names: &FrameNames) -> String {
    let indented: String = joint.lines().map(|l| format!("  {l}\n")).collect();
    format!(
        "<?xml version=\"1.0\"?>\n<robot name=\"robocal_calibration\">\n  <link name=\"{}\"/>\n  <link name=\"{}\"/>\n{indented}</robot>\n",
        names.parent, names.child
    )
}
