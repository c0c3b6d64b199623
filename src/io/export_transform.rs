//! Transform exports: one rigid transform `a_from_b` written for the tools
//! and robot controllers people paste it into.
//!
//! A transform `parent_from_child` is the pose of the child frame in the
//! parent frame, which is what every format below expects (URDF joint
//! origin, ROS tf, robot tool/base frames).

use crate::error::{Error, Result};
use crate::geometry::{
    euler_from_rotation, matrix4_from_pose, quaternion_wxyz_from_rotation,
    quaternion_xyzw_from_rotation, rotvec_from_rotation, EulerKind, EulerOrder, Pose, PoseJson,
};
use crate::io::export_camera::float;
use crate::io::export_ros::{
    ros1_args, ros1_launch, ros2_args, ros2_launch, urdf_joint, urdf_robot,
};

/// The transform formats robocal writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransformFormat {
    /// 4x4 homogeneous matrix, row-major, translation in metres.
    Matrix4,
    /// `x y z qx qy qz qw` (metres).
    XyzQuaternionXyzw,
    /// `x y z qw qx qy qz` (metres).
    XyzQuaternionWxyz,
    /// Translation and Euler angles in the given order and kind.
    Euler {
        /// Axis order.
        order: EulerOrder,
        /// Rotating (intrinsic) or fixed (extrinsic) axes.
        kind: EulerKind,
        /// Degrees (true) or radians.
        degrees: bool,
    },
    /// URDF `<joint type="fixed">` with `origin xyz rpy` (rpy = extrinsic XYZ).
    UrdfJoint,
    /// A whole URDF file (`<robot>` with the two links and the fixed joint).
    UrdfRobot,
    /// `ros2 run tf2_ros static_transform_publisher ...` command line.
    Ros2StaticTransform,
    /// `rosrun tf2_ros static_transform_publisher x y z qx qy qz qw parent child` (ROS 1).
    Ros1StaticTransform,
    /// A ROS 1 launch file (XML) with the static_transform_publisher node.
    Ros1Launch,
    /// A ROS 2 launch file (Python) with the static_transform_publisher node.
    Ros2Launch,
    /// Universal Robots TCP / feature pose `p[x, y, z, rx, ry, rz]` (m, rotation vector).
    UrPose,
    /// KUKA TOOL_DATA / BASE_DATA frame `{X, Y, Z, A, B, C}` (mm, deg; A about Z, B about Y', C about X'').
    KukaFrame,
    /// ABB `tooldata` (mm, quaternion w first).
    AbbTooldata,
    /// ABB `wobjdata` user frame (mm, quaternion w first).
    AbbWobjdata,
    /// FANUC UTOOL / UFRAME `X Y Z W P R` (mm, deg; fixed axes X, Y, Z).
    FanucFrame,
}

/// The names of the two frames of a transform `parent_from_child`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameNames {
    /// The frame the pose is expressed in (`a` of `a_from_b`).
    pub parent: String,
    /// The frame whose pose it is (`b` of `a_from_b`).
    pub child: String,
    /// The transform's key in the report (`gripper_from_camera`), named in
    /// the comments of the output whatever the frames are called.
    pub key: String,
}

impl FrameNames {
    /// From a transform name such as `gripper_from_camera`.
    pub fn from_transform_name(name: &str) -> Result<FrameNames> {
        let (parent, child) = name.split_once("_from_").ok_or_else(|| {
            Error::invalid(
                "transform",
                format!("'{name}' is not named like parent_from_child"),
            )
        })?;
        Ok(FrameNames {
            parent: parent.into(),
            child: child.into(),
            key: name.into(),
        })
    }
}

const SIMPLE_FORMATS: [(&str, TransformFormat); 14] = [
    ("matrix4", TransformFormat::Matrix4),
    ("xyz-quat-xyzw", TransformFormat::XyzQuaternionXyzw),
    ("xyz-quat-wxyz", TransformFormat::XyzQuaternionWxyz),
    ("urdf", TransformFormat::UrdfJoint),
    ("urdf-robot", TransformFormat::UrdfRobot),
    ("ros2-static-tf", TransformFormat::Ros2StaticTransform),
    ("ros1-static-tf", TransformFormat::Ros1StaticTransform),
    ("ros1-launch", TransformFormat::Ros1Launch),
    ("ros2-launch", TransformFormat::Ros2Launch),
    ("ur", TransformFormat::UrPose),
    ("kuka", TransformFormat::KukaFrame),
    ("abb-tooldata", TransformFormat::AbbTooldata),
    ("abb-wobjdata", TransformFormat::AbbWobjdata),
    ("fanuc", TransformFormat::FanucFrame),
];

impl TransformFormat {
    /// Parse a format name: the names of [`TransformFormat::names`], or
    /// `euler-<intrinsic|extrinsic>-<order>-<deg|rad>` (e.g. `euler-extrinsic-xyz-deg`).
    pub fn from_name(name: &str) -> Result<TransformFormat> {
        if let Some((_, f)) = SIMPLE_FORMATS.iter().find(|(n, _)| *n == name) {
            return Ok(*f);
        }
        let unknown = || {
            Error::invalid(
                "format",
                format!(
                    "unknown transform format '{name}' (known: {}, euler-<intrinsic|extrinsic>-<order>-<deg|rad>)",
                    TransformFormat::names().join(", ")
                ),
            )
        };
        let parts: Vec<&str> = name.split('-').collect();
        match parts.as_slice() {
            ["euler", kind, order, unit] => {
                let kind = match *kind {
                    "intrinsic" => EulerKind::Intrinsic,
                    "extrinsic" => EulerKind::Extrinsic,
                    _ => return Err(unknown()),
                };
                let order = EulerOrder::from_name(order).ok_or_else(unknown)?;
                let degrees = match *unit {
                    "deg" => true,
                    "rad" => false,
                    _ => return Err(unknown()),
                };
                Ok(TransformFormat::Euler {
                    order,
                    kind,
                    degrees,
                })
            }
            _ => Err(unknown()),
        }
    }

    /// The fixed format names (Euler formats are spelled out by [`TransformFormat::from_name`]).
    pub fn names() -> Vec<&'static str> {
        SIMPLE_FORMATS.iter().map(|(n, _)| *n).collect()
    }
}

fn list(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| float(*v))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Round to `digits` decimals for controller formats (they take fixed
/// precision; 1e-6 mm and 1e-6 deg are far below any robot's resolution).
fn fixed(values: &[f64], digits: usize) -> Vec<String> {
    values
        .iter()
        .map(|v| {
            format!(
                "{:.*}",
                digits,
                if v.abs() < 0.5 * 10f64.powi(-(digits as i32)) {
                    0.0
                } else {
                    *v
                }
            )
        })
        .collect()
}

/// Write `parent_from_child` in `format`.
pub fn export_transform(pose: &Pose, names: &FrameNames, format: TransformFormat) -> String {
    let t = pose.translation.vector;
    let xyz = [t.x, t.y, t.z];
    let mm = [t.x * 1000.0, t.y * 1000.0, t.z * 1000.0];
    let deg = |a: [f64; 3]| a.map(f64::to_degrees);
    let label = &names.key;
    match format {
        TransformFormat::Matrix4 => {
            let m = matrix4_from_pose(pose);
            let rows: Vec<String> = (0..4)
                .map(|r| list(&[m[(r, 0)], m[(r, 1)], m[(r, 2)], m[(r, 3)]]))
                .collect();
            format!(
                "# {label}: 4x4 row-major, translation in metres\n{}\n",
                rows.join("\n")
            )
        }
        TransformFormat::XyzQuaternionXyzw => {
            let q = quaternion_xyzw_from_rotation(&pose.rotation);
            format!(
                "# {label}: x y z (m) qx qy qz qw\n{} {}\n",
                list(&xyz),
                list(&q)
            )
        }
        TransformFormat::XyzQuaternionWxyz => {
            let q = quaternion_wxyz_from_rotation(&pose.rotation);
            format!(
                "# {label}: x y z (m) qw qx qy qz\n{} {}\n",
                list(&xyz),
                list(&q)
            )
        }
        TransformFormat::Euler {
            order,
            kind,
            degrees,
        } => {
            let angles = euler_from_rotation(&pose.rotation, order, kind);
            let (angles, unit) = if degrees {
                (deg(angles), "deg")
            } else {
                (angles, "rad")
            };
            let kind_name = match kind {
                EulerKind::Intrinsic => "intrinsic",
                EulerKind::Extrinsic => "extrinsic",
            };
            format!(
                "# {label}: x y z (m), Euler {kind_name} {} angles ({unit})\n{} {}\n",
                order.name().to_ascii_uppercase(),
                list(&xyz),
                list(&angles)
            )
        }
        TransformFormat::UrdfJoint => urdf_joint(pose, names),
        TransformFormat::UrdfRobot => urdf_robot(&urdf_joint(pose, names), names),
        TransformFormat::Ros2StaticTransform => {
            format!("ros2 run tf2_ros static_transform_publisher {}\n", ros2_args(pose, names))
        }
        TransformFormat::Ros1StaticTransform => format!(
            "# {label} (ROS 1): x y z (m) qx qy qz qw parent child\nrosrun tf2_ros static_transform_publisher {}\n",
            ros1_args(pose, names)
        ),
        TransformFormat::Ros1Launch => ros1_launch(label, &ros1_args(pose, names), names),
        TransformFormat::Ros2Launch => ros2_launch(label, &ros2_args(pose, names), names),
        TransformFormat::UrPose => {
            let r = rotvec_from_rotation(&pose.rotation);
            let v = fixed(&[xyz[0], xyz[1], xyz[2], r.x, r.y, r.z], 6);
            format!(
                "# {label} for set_tcp() or a feature: metres, rotation vector (rad)\np[{}]\n",
                v.join(", ")
            )
        }
        TransformFormat::KukaFrame => {
            let zyx = deg(euler_from_rotation(
                &pose.rotation,
                EulerOrder::ZYX,
                EulerKind::Intrinsic,
            ));
            let v = fixed(&[mm[0], mm[1], mm[2], zyx[0], zyx[1], zyx[2]], 4);
            format!(
                "; {label} for TOOL_DATA / BASE_DATA: mm, deg (A about Z, B about Y', C about X'')\n{{X {}, Y {}, Z {}, A {}, B {}, C {}}}\n",
                v[0], v[1], v[2], v[3], v[4], v[5]
            )
        }
        TransformFormat::AbbTooldata | TransformFormat::AbbWobjdata => {
            let q = quaternion_wxyz_from_rotation(&pose.rotation);
            let p = fixed(&mm, 4);
            let qs = fixed(&q, 9);
            let frame = format!("[[{}],[{}]]", p.join(","), qs.join(","));
            if format == TransformFormat::AbbTooldata {
                format!(
                    "! {label}: mm, quaternion q1..q4 = w x y z. Set the load data (mass kg, centre of gravity mm) to the camera's before use.\nPERS tooldata t_{c}:=[TRUE,{frame},[0.001,[0,0,0.001],[1,0,0,0],0,0,0]];\n",
                    c = names.child
                )
            } else {
                format!(
                    "! {label}: user frame, mm, quaternion q1..q4 = w x y z\nPERS wobjdata wobj_{c}:=[FALSE,TRUE,\"\",{frame},[[0,0,0],[1,0,0,0]]];\n",
                    c = names.child
                )
            }
        }
        TransformFormat::FanucFrame => {
            let wpr = deg(euler_from_rotation(
                &pose.rotation,
                EulerOrder::XYZ,
                EulerKind::Extrinsic,
            ));
            let v = fixed(&[mm[0], mm[1], mm[2], wpr[0], wpr[1], wpr[2]], 3);
            format!(
                "! {label} for UTOOL / UFRAME: mm, deg (W about X, P about Y, R about Z, fixed axes)\nX {} Y {} Z {} W {} P {} R {}\n",
                v[0], v[1], v[2], v[3], v[4], v[5]
            )
        }
    }
}

/// The transform's [`PoseJson`] (the one pose shape of every report) as a
/// JSON value, for building documents with `serde_json::json!`.
pub fn transform_json(pose: &Pose) -> serde_json::Value {
    // A struct of numbers serialises to a `Value` without error (non-finite
    // numbers become null, as `json!` would write them).
    serde_json::to_value(PoseJson::from(pose)).unwrap_or(serde_json::Value::Null)
}
