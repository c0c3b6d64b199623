//! Writing robot poses in any [`PoseFormat`], so that files round-trip
//! through [`super::parse_poses`].

use super::pose_formats::{values_from_pose, AngleUnit, LengthUnit, PoseFormat};
use super::poses::RobotPose;

fn quote(name: &str) -> String {
    if name.contains([',', '"']) || name.starts_with('#') || name.trim() != name {
        format!("\"{}\"", name.replace('"', "\"\""))
    } else {
        name.to_string()
    }
}

/// CSV text of `poses` (their `base_from_gripper`) in `format` and units: a
/// header line with the format's column names (with a unit suffix such as
/// `x_m` where a unit differs from the format's default, and a leading
/// `name` column when any pose has a name), then one line per pose with
/// numbers printed to full precision.
///
/// Parsing the text back with the same format gives the same poses (to
/// ~1e-15). Without a format option, the header alone selects the format for
/// every format except `yaskawa`, `staubli` (their `X Y Z Rx Ry Rz` reads as
/// UR) and the generic Euler layouts (`x y z e1 e2 e3`).
pub fn format_poses(
    poses: &[RobotPose],
    format: PoseFormat,
    length_unit: LengthUnit,
    angle_unit: AngleUnit,
) -> String {
    let (dl, da) = format.default_units();
    let named = poses.iter().any(|p| p.name.is_some());
    let mut header: Vec<String> = Vec::new();
    if named {
        header.push("name".into());
    }
    for (i, col) in format.columns().iter().enumerate() {
        let is_length = format.is_length_column(i);
        let suffix = if is_length && length_unit != dl {
            format!("_{}", length_unit.name())
        } else if !is_length && i >= 3 && format.uses_angles() && angle_unit != da {
            format!("_{}", angle_unit.name())
        } else {
            String::new()
        };
        header.push(format!("{col}{suffix}"));
    }
    let mut out = header.join(",");
    out.push('\n');
    for pose in poses {
        let mut fields = Vec::new();
        if named {
            fields.push(quote(pose.name.as_deref().unwrap_or("")));
        }
        let values = values_from_pose(format, &pose.base_from_gripper, length_unit, angle_unit);
        fields.extend(values.iter().map(|v| format!("{v}")));
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}
