//! The robot pose formats: vendor presets and generic layouts, their columns,
//! default units and the formula from numbers to a pose.

use nalgebra::{Matrix4, Translation3, Vector3};
use serde::{Deserialize, Serialize};

use crate::geometry::{
    euler_from_rotation, matrix4_from_pose, pose_from_matrix4, quaternion_wxyz_from_rotation,
    quaternion_xyzw_from_rotation, rotation_from_euler, rotation_from_quaternion_wxyz,
    rotation_from_quaternion_xyzw, rotation_from_rotvec, rotvec_from_rotation, EulerKind,
    EulerOrder, Pose, Rotation,
};

/// A layout of one robot pose as numbers. Translation first, then rotation.
///
/// Names (for options, JSON and the CLI) are given by [`PoseFormat::name`]:
/// `ur`, `kuka`, `abb`, `fanuc`, `yaskawa`, `staubli`, `xyz_quat_xyzw`,
/// `xyz_quat_wxyz`, `xyz_rotvec`, `xyz_euler_<kind>_<order>` (e.g.
/// `xyz_euler_intrinsic_zyx`, `xyz_euler_extrinsic_xyz`), `matrix4` and
/// `matrix3x4`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(into = "String", try_from = "String")]
pub enum PoseFormat {
    /// Universal Robots `x y z rx ry rz` (`get_actual_tcp_pose()`, the
    /// Polyscope "Rotation vector [rad]" view): metres, and `(rx, ry, rz)` a
    /// rotation vector in radians, `R = exp([r]×)` (axis `r/|r|`, angle
    /// `|r|`). Source: UR Script Manual, "p[x, y, z, ax, ay, az]".
    Ur,
    /// KUKA `X Y Z A B C` (KRL `E6POS`/`FRAME`): mm and degrees, A about Z,
    /// then B about the new Y', then C about the new X'' (intrinsic ZYX):
    /// `R = Rz(A) · Ry(B) · Rx(C)`. Source: KUKA System Software 8
    /// operating and programming instructions, "Orientation angles A, B, C";
    /// same as RoboDK `KUKA_2_Pose`.
    Kuka,
    /// ABB `x y z q1 q2 q3 q4` (RAPID `pose`/`robtarget`): mm, unit
    /// quaternion with the scalar first, `q1 = w`: `R = R(q1 + q2 i + q3 j +
    /// q4 k)`. Source: ABB RAPID reference manual, data type `orient`.
    Abb,
    /// FANUC `X Y Z W P R`: mm and degrees, W about the fixed X, then P about
    /// the fixed Y, then R about the fixed Z (extrinsic XYZ): `R = Rz(R) ·
    /// Ry(P) · Rx(W)`. Source: FANUC operator's manual, "user frame /
    /// position data (W, P, R) = yaw, pitch, roll about the fixed axes";
    /// same as RoboDK `Fanuc_2_Pose`.
    Fanuc,
    /// Yaskawa Motoman `X Y Z Rx Ry Rz` (robot/base coordinates as shown on
    /// the pendant): mm and degrees, rotations about the fixed X, then Y,
    /// then Z, like FANUC: `R = Rz(Rz) · Ry(Ry) · Rx(Rx)`. Source: RoboDK
    /// `Motoman_2_Pose` (identical to `Fanuc_2_Pose`); Yaskawa's manuals
    /// describe Rx, Ry, Rz as rotations about the fixed base axes. An
    /// assumption where a controller is set to another convention.
    Yaskawa,
    /// Stäubli `X Y Z Rx Ry Rz` (VAL3 `trsf`): mm and degrees, Rx about X,
    /// then Ry about the new Y', then Rz about the new Z'' (intrinsic XYZ):
    /// `R = Rx(Rx) · Ry(Ry) · Rz(Rz)`. Source: Stäubli VAL3 reference manual,
    /// type `trsf`; same as RoboDK `Staubli_2_Pose` (`TxyzRxyz_2_Pose`).
    Staubli,
    /// `x y z qx qy qz qw` (ROS `geometry_msgs/Pose` order); default metres.
    XyzQuatXyzw,
    /// `x y z qw qx qy qz`; default metres.
    XyzQuatWxyz,
    /// `x y z rx ry rz`, a rotation vector as for [`PoseFormat::Ur`];
    /// default metres and radians.
    XyzRotvec,
    /// `x y z e1 e2 e3`: Euler angles, `e1` about the first axis of `order`;
    /// see [`crate::geometry::rotation_from_euler`] for the products. Default
    /// metres and radians.
    XyzEuler {
        /// The axis sequence.
        order: EulerOrder,
        /// Intrinsic (rotating) or extrinsic (fixed) axes.
        kind: EulerKind,
    },
    /// 16 numbers, the 4x4 homogeneous matrix row by row (`m00 m01 m02 m03
    /// m10 ...`); default metres. Validated by
    /// [`crate::geometry::pose_from_matrix4`].
    Matrix4,
    /// 12 numbers, the top three rows of the 4x4 matrix row by row (`r11
    /// r12 r13 tx r21 r22 r23 ty r31 r32 r33 tz`); default metres. The
    /// bottom row `0 0 0 1` is implied.
    Matrix3x4,
}

/// The unit of lengths in a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum LengthUnit {
    /// Millimetres.
    #[serde(rename = "mm")]
    Millimetre,
    /// Metres.
    #[serde(rename = "m")]
    Metre,
}

/// The unit of angles in a file (not used by quaternion and matrix formats).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum AngleUnit {
    /// Degrees.
    #[serde(rename = "deg")]
    Degree,
    /// Radians.
    #[serde(rename = "rad")]
    Radian,
}

impl LengthUnit {
    /// Metres per unit.
    pub fn to_metres(self) -> f64 {
        match self {
            LengthUnit::Millimetre => 1e-3,
            LengthUnit::Metre => 1.0,
        }
    }

    /// `"mm"` or `"m"`.
    pub fn name(self) -> &'static str {
        match self {
            LengthUnit::Millimetre => "mm",
            LengthUnit::Metre => "m",
        }
    }
}

impl AngleUnit {
    /// Radians per unit.
    pub fn to_radians(self) -> f64 {
        match self {
            AngleUnit::Degree => std::f64::consts::PI / 180.0,
            AngleUnit::Radian => 1.0,
        }
    }

    /// `"deg"` or `"rad"`.
    pub fn name(self) -> &'static str {
        match self {
            AngleUnit::Degree => "deg",
            AngleUnit::Radian => "rad",
        }
    }
}

/// How a format stores the rotation (internal to the io module).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum RotationLayout {
    Rotvec,
    Euler(EulerOrder, EulerKind),
    QuatXyzw,
    QuatWxyz,
    Matrix,
}

const NAMED: [PoseFormat; 11] = [
    PoseFormat::Ur,
    PoseFormat::Kuka,
    PoseFormat::Abb,
    PoseFormat::Fanuc,
    PoseFormat::Yaskawa,
    PoseFormat::Staubli,
    PoseFormat::XyzQuatXyzw,
    PoseFormat::XyzQuatWxyz,
    PoseFormat::XyzRotvec,
    PoseFormat::Matrix4,
    PoseFormat::Matrix3x4,
];

impl PoseFormat {
    /// Every format: the named ones, then the 24 generic Euler layouts.
    pub fn all() -> Vec<PoseFormat> {
        let mut all = NAMED.to_vec();
        for kind in [EulerKind::Intrinsic, EulerKind::Extrinsic] {
            for order in EulerOrder::ALL {
                all.push(PoseFormat::XyzEuler { order, kind });
            }
        }
        all
    }

    /// The format's name, as accepted by [`PoseFormat::from_name`].
    pub fn name(&self) -> String {
        match self {
            PoseFormat::Ur => "ur".into(),
            PoseFormat::Kuka => "kuka".into(),
            PoseFormat::Abb => "abb".into(),
            PoseFormat::Fanuc => "fanuc".into(),
            PoseFormat::Yaskawa => "yaskawa".into(),
            PoseFormat::Staubli => "staubli".into(),
            PoseFormat::XyzQuatXyzw => "xyz_quat_xyzw".into(),
            PoseFormat::XyzQuatWxyz => "xyz_quat_wxyz".into(),
            PoseFormat::XyzRotvec => "xyz_rotvec".into(),
            PoseFormat::XyzEuler { order, kind } => {
                let k = match kind {
                    EulerKind::Intrinsic => "intrinsic",
                    EulerKind::Extrinsic => "extrinsic",
                };
                format!("xyz_euler_{k}_{}", order.name())
            }
            PoseFormat::Matrix4 => "matrix4".into(),
            PoseFormat::Matrix3x4 => "matrix3x4".into(),
        }
    }

    /// The format of a name (case-insensitive; `motoman` = `yaskawa`).
    pub fn from_name(name: &str) -> Option<PoseFormat> {
        let lower = name.trim().to_ascii_lowercase();
        if lower == "motoman" {
            return Some(PoseFormat::Yaskawa);
        }
        PoseFormat::all().into_iter().find(|f| f.name() == lower)
    }

    /// The name used in messages (`KUKA`, `UR`, `xyz_quat_wxyz`).
    pub fn label(&self) -> String {
        match self {
            PoseFormat::Ur => "UR".into(),
            PoseFormat::Kuka => "KUKA".into(),
            PoseFormat::Abb => "ABB".into(),
            PoseFormat::Fanuc => "FANUC".into(),
            PoseFormat::Yaskawa => "Yaskawa".into(),
            PoseFormat::Staubli => "Stäubli".into(),
            other => other.name(),
        }
    }

    /// The column names, in file order.
    pub fn columns(&self) -> Vec<&'static str> {
        let cols: &[&str] = match self {
            PoseFormat::Ur | PoseFormat::XyzRotvec => &["x", "y", "z", "rx", "ry", "rz"],
            PoseFormat::Kuka => &["X", "Y", "Z", "A", "B", "C"],
            PoseFormat::Abb => &["x", "y", "z", "q1", "q2", "q3", "q4"],
            PoseFormat::Fanuc => &["X", "Y", "Z", "W", "P", "R"],
            PoseFormat::Yaskawa | PoseFormat::Staubli => &["X", "Y", "Z", "Rx", "Ry", "Rz"],
            PoseFormat::XyzQuatXyzw => &["x", "y", "z", "qx", "qy", "qz", "qw"],
            PoseFormat::XyzQuatWxyz => &["x", "y", "z", "qw", "qx", "qy", "qz"],
            PoseFormat::XyzEuler { .. } => &["x", "y", "z", "e1", "e2", "e3"],
            PoseFormat::Matrix4 => &[
                "m00", "m01", "m02", "m03", "m10", "m11", "m12", "m13", "m20", "m21", "m22", "m23",
                "m30", "m31", "m32", "m33",
            ],
            PoseFormat::Matrix3x4 => &[
                "r11", "r12", "r13", "tx", "r21", "r22", "r23", "ty", "r31", "r32", "r33", "tz",
            ],
        };
        cols.to_vec()
    }

    /// How many numbers one pose has (6, 7, 12 or 16).
    pub fn value_count(&self) -> usize {
        self.columns().len()
    }

    /// The units the format uses unless told otherwise.
    pub fn default_units(&self) -> (LengthUnit, AngleUnit) {
        match self {
            PoseFormat::Kuka
            | PoseFormat::Abb
            | PoseFormat::Fanuc
            | PoseFormat::Yaskawa
            | PoseFormat::Staubli => (LengthUnit::Millimetre, AngleUnit::Degree),
            PoseFormat::Ur
            | PoseFormat::XyzQuatXyzw
            | PoseFormat::XyzQuatWxyz
            | PoseFormat::XyzRotvec
            | PoseFormat::XyzEuler { .. }
            | PoseFormat::Matrix4
            | PoseFormat::Matrix3x4 => (LengthUnit::Metre, AngleUnit::Radian),
        }
    }

    /// Whether column `c` (0-based, in [`PoseFormat::columns`] order) is a
    /// length: the first three, or a matrix's last column.
    pub fn is_length_column(&self, c: usize) -> bool {
        match self.layout() {
            RotationLayout::Matrix => c % 4 == 3 && c < 12,
            _ => c < 3,
        }
    }

    /// Whether the angle unit matters (false for quaternions and matrices).
    pub fn uses_angles(&self) -> bool {
        matches!(
            self.layout(),
            RotationLayout::Rotvec | RotationLayout::Euler(..)
        )
    }

    pub(crate) fn layout(&self) -> RotationLayout {
        match *self {
            PoseFormat::Ur | PoseFormat::XyzRotvec => RotationLayout::Rotvec,
            PoseFormat::Kuka => RotationLayout::Euler(EulerOrder::ZYX, EulerKind::Intrinsic),
            PoseFormat::Fanuc | PoseFormat::Yaskawa => {
                RotationLayout::Euler(EulerOrder::XYZ, EulerKind::Extrinsic)
            }
            PoseFormat::Staubli => RotationLayout::Euler(EulerOrder::XYZ, EulerKind::Intrinsic),
            PoseFormat::XyzEuler { order, kind } => RotationLayout::Euler(order, kind),
            PoseFormat::Abb | PoseFormat::XyzQuatWxyz => RotationLayout::QuatWxyz,
            PoseFormat::XyzQuatXyzw => RotationLayout::QuatXyzw,
            PoseFormat::Matrix4 | PoseFormat::Matrix3x4 => RotationLayout::Matrix,
        }
    }
}

impl From<PoseFormat> for String {
    fn from(f: PoseFormat) -> String {
        f.name()
    }
}

impl TryFrom<String> for PoseFormat {
    type Error = String;
    fn try_from(s: String) -> Result<PoseFormat, String> {
        PoseFormat::from_name(&s).ok_or_else(|| format!("unknown pose format '{s}'"))
    }
}

/// Why a row of numbers is not a pose (before the line is known).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ValueError {
    /// 0-based index of the first value concerned, or [`WHOLE_ROW`].
    pub index: usize,
    pub message: String,
}

/// `ValueError::index` of an error about the whole row (a matrix).
pub(crate) const WHOLE_ROW: usize = usize::MAX;

/// Quaternions whose norm is off by more than this are rejected as "not a
/// rotation"; within it they are normalised (covers 2-3 printed decimals).
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-2;

/// A number in messages: up to 3 decimals, trailing zeros dropped.
pub(crate) fn short(x: f64) -> String {
    let s = format!("{x:.3}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

/// The pose `base_from_gripper` of one row of `format.value_count()` numbers.
pub(crate) fn pose_from_values(
    format: PoseFormat,
    values: &[f64],
    length: LengthUnit,
    angle: AngleUnit,
) -> Result<Pose, ValueError> {
    let err = |index: usize, message: String| ValueError { index, message };
    if values.len() != format.value_count() {
        return Err(err(WHOLE_ROW, format!("{} values", values.len())));
    }
    let lm = length.to_metres();
    let t = Translation3::new(values[0] * lm, values[1] * lm, values[2] * lm);
    let r = &values[3..];
    let ar = angle.to_radians();
    let rotation: Rotation = match format.layout() {
        RotationLayout::Rotvec => {
            let v = Vector3::new(r[0], r[1], r[2]);
            let n = v.norm();
            if angle == AngleUnit::Radian && n > 2.0 * std::f64::consts::PI + 1e-9 {
                return Err(err(
                    3,
                    format!(
                    "rotation vector angle {} deg looks like degrees; this format expects radians",
                    short(n)
                ),
                ));
            }
            rotation_from_rotvec(&(v * ar))
        }
        RotationLayout::Euler(order, kind) => {
            if angle == AngleUnit::Radian {
                if let Some(i) = (0..3).find(|&i| r[i].abs() > 2.0 * std::f64::consts::PI + 1e-9) {
                    return Err(err(
                        3 + i,
                        format!(
                            "Euler angle {} looks like degrees; this format expects radians",
                            short(r[i])
                        ),
                    ));
                }
            }
            rotation_from_euler(order, kind, [r[0] * ar, r[1] * ar, r[2] * ar])
        }
        RotationLayout::QuatXyzw | RotationLayout::QuatWxyz => {
            let q = [r[0], r[1], r[2], r[3]];
            let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
            if (n - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
                return Err(err(
                    3,
                    format!("quaternion has norm {}: not a rotation", short(n)),
                ));
            }
            let parsed = if format.layout() == RotationLayout::QuatXyzw {
                rotation_from_quaternion_xyzw(q)
            } else {
                rotation_from_quaternion_wxyz(q)
            };
            parsed.map_err(|e| err(3, e.to_string()))?
        }
        RotationLayout::Matrix => return matrix_pose(values, lm),
    };
    Ok(Pose::from_parts(t, rotation))
}

fn matrix_pose(values: &[f64], metres_per_unit: f64) -> Result<Pose, ValueError> {
    // A 3x4 matrix is the 4x4 without its bottom row `0 0 0 1`.
    let full: Vec<f64> = if values.len() == 12 {
        values.iter().copied().chain([0.0, 0.0, 0.0, 1.0]).collect()
    } else {
        values.to_vec()
    };
    let mut m = Matrix4::from_row_slice(&full);
    m.fixed_view_mut::<3, 1>(0, 3).scale_mut(metres_per_unit);
    pose_from_matrix4(&m).map_err(|e| ValueError {
        index: WHOLE_ROW,
        message: match e {
            crate::Error::Invalid { message, .. } if values.len() == 12 => {
                format!("3x4 matrix {message}")
            }
            crate::Error::Invalid { message, .. } => format!("4x4 matrix {message}"),
            other => other.to_string(),
        },
    })
}

/// The numbers of a pose in `format` and units (the inverse of
/// `pose_from_values`).
pub(crate) fn values_from_pose(
    format: PoseFormat,
    pose: &Pose,
    length: LengthUnit,
    angle: AngleUnit,
) -> Vec<f64> {
    let inv_l = 1.0 / length.to_metres();
    let inv_a = 1.0 / angle.to_radians();
    let t = pose.translation.vector * inv_l;
    let mut out = vec![t.x, t.y, t.z];
    match format.layout() {
        RotationLayout::Rotvec => {
            out.extend((rotvec_from_rotation(&pose.rotation) * inv_a).iter());
        }
        RotationLayout::Euler(order, kind) => {
            let e = euler_from_rotation(&pose.rotation, order, kind);
            out.extend(e.iter().map(|v| v * inv_a));
        }
        RotationLayout::QuatXyzw => out.extend(quaternion_xyzw_from_rotation(&pose.rotation)),
        RotationLayout::QuatWxyz => out.extend(quaternion_wxyz_from_rotation(&pose.rotation)),
        RotationLayout::Matrix => {
            let mut m = matrix4_from_pose(pose);
            m.fixed_view_mut::<3, 1>(0, 3).scale_mut(inv_l);
            out = m.transpose().iter().copied().collect();
            out.truncate(format.value_count());
        }
    }
    out
}
