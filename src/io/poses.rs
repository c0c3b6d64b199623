//! Robot pose files: parse `base_from_gripper` poses from text or JSON, with
//! the format and units named, read from a header, or taken from the
//! format's defaults, and say what was assumed.

use serde::{Deserialize, Serialize};

use super::pose_formats::{pose_from_values, AngleUnit, LengthUnit, PoseFormat, WHOLE_ROW};
use super::pose_json::table_from_json;
use super::pose_table::{
    degree_rxryrz_note, detect_header, header_has, map_header, number, table_from_text, HeaderMap,
    Row, Table, DEGREE_RXRYRZ,
};
use crate::error::{Error, Result};
use crate::geometry::Pose;

/// Which transform the file holds. Robot controllers report the TCP pose in
/// the base frame, `base_from_gripper`; some tools store the inverse.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PoseDirection {
    /// The file holds `base_from_gripper` (the default).
    #[default]
    #[serde(rename = "base_from_gripper")]
    BaseFromGripper,
    /// The file holds `gripper_from_base`; the parser inverts each pose.
    #[serde(rename = "gripper_from_base")]
    GripperFromBase,
}

/// What the caller knows about a pose file; `None` fields are read from the
/// header or taken from the format's defaults.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseFileOptions {
    /// The layout; `None` = from the header (or, without one, from the
    /// number of values when only one format has that many).
    pub format: Option<PoseFormat>,
    /// Length unit; `None` = header unit suffix, else the format's default.
    pub length_unit: Option<LengthUnit>,
    /// Angle unit; `None` = header unit suffix, else the format's default.
    pub angle_unit: Option<AngleUnit>,
    /// Which transform the file holds (default `base_from_gripper`).
    #[serde(default)]
    pub direction: PoseDirection,
}

/// One robot pose from a file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotPose {
    /// The `name`/`image` column, to pair the pose with an image.
    pub name: Option<String>,
    /// 1-based line in a text file, or 1-based element of a JSON array.
    pub line: usize,
    /// The gripper (TCP) pose in the robot base frame, metres.
    #[serde(with = "crate::geometry::pose_serde")]
    pub base_from_gripper: Pose,
}

/// Parsed poses and everything that was assumed to read them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParsedPoses {
    /// The poses in file order.
    pub poses: Vec<RobotPose>,
    /// The layout used.
    pub format: PoseFormat,
    /// The length unit used.
    pub length_unit: LengthUnit,
    /// The angle unit used (meaningless for quaternion and matrix formats).
    pub angle_unit: AngleUnit,
    /// What the file held (poses are always returned as `base_from_gripper`).
    pub direction: PoseDirection,
    /// Plain sentences on how format and units were chosen and what was
    /// ignored, for the user to check.
    pub notes: Vec<String>,
}

/// A resolved reading of a table: format, units and column mapping.
#[derive(Debug, Clone)]
pub(crate) struct Reading {
    pub format: PoseFormat,
    pub length_unit: LengthUnit,
    pub angle_unit: AngleUnit,
    pub header: Option<HeaderMap>,
    /// The header's field count, for count messages.
    pub header_len: Option<usize>,
    pub notes: Vec<String>,
}

/// Text, KUKA KRL or JSON to a table (KRL when it holds a KRL pose
/// aggregate, [`super::pose_krl`]; JSON when the text starts with `[` or `{`).
pub(crate) fn table_from_input(text: &str) -> Result<Table> {
    let trimmed = text.trim_start_matches('\u{feff}').trim_start();
    if let Some(krl) = super::pose_krl::table_from_krl(trimmed) {
        return krl;
    }
    if trimmed.starts_with('[') || trimmed.starts_with('{') {
        table_from_json(trimmed)
    } else {
        Ok(table_from_text(text))
    }
}

/// Parses a robot pose file (CSV, TSV, whitespace-separated text, or JSON)
/// into `base_from_gripper` poses.
///
/// The format comes from `options.format`, else from a header (`x,y,z,qx,qy,
/// qz,qw`, `X,Y,Z,A,B,C`, `X,Y,Z,W,P,R`, `x,y,z,q1,q2,q3,q4`, `x,y,z,rx,ry,
/// rz` = UR, `x,y,z,roll,pitch,yaw`, `m00..m33`), else from the number of
/// values when only one format fits (16 = `matrix4`). Otherwise the file is
/// ambiguous and this errors; [`super::parse_pose_candidates`] then lists
/// every plausible reading. Units come from the options, else from header
/// suffixes (`x_mm`, `A [deg]`), else from the format's defaults.
pub fn parse_poses(text: &str, options: &PoseFileOptions) -> Result<ParsedPoses> {
    let table = table_from_input(text)?;
    let reading = resolve(&table, options)?;
    let poses = read_rows(&table.rows, &reading, options.direction)?;
    let mut parsed = ParsedPoses {
        poses,
        format: reading.format,
        length_unit: reading.length_unit,
        angle_unit: reading.angle_unit,
        direction: options.direction,
        notes: reading.notes,
    };
    parsed.notes.extend(radians_read_as_degrees(&parsed));
    Ok(parsed)
}

/// Every pose within this rotation (degrees) of the base orientation, with
/// the angles read as degrees, suggests radians read as degrees: three
/// Euler angles within ±pi each, read as degrees, turn by at most 3 pi deg.
pub const RADIANS_AS_DEGREES_MAX_DEG: f64 = 3.0 * std::f64::consts::PI;

/// The suspicion that a reading in degrees holds radians: at least two
/// poses, every one within [`RADIANS_AS_DEGREES_MAX_DEG`] of the base
/// orientation (a robot's tool is rarely that close to the base axes in
/// every pose). Also in [`ParsedPoses::notes`].
pub fn radians_read_as_degrees(parsed: &ParsedPoses) -> Option<String> {
    if !parsed.format.uses_angles()
        || parsed.angle_unit != AngleUnit::Degree
        || parsed.poses.len() < 2
    {
        return None;
    }
    let largest = parsed
        .poses
        .iter()
        .map(|p| p.base_from_gripper.rotation.angle().to_degrees())
        .fold(0.0f64, f64::max);
    (largest > 0.0 && largest <= RADIANS_AS_DEGREES_MAX_DEG).then(|| {
        format!(
            "every pose is within {} deg of the base orientation with the angles read as degrees: radians read as degrees? If the file holds radians, say so (a _rad header, --pose-units rad, or Angles: radians on the page)",
            super::pose_formats::short(largest)
        )
    })
}

/// A format fixed by the options or the header, its mapping, and notes.
pub(crate) type FixedFormat = (PoseFormat, Option<HeaderMap>, Vec<String>);

/// The format named by the options or the header, with the header mapping.
pub(crate) fn header_reading(
    table: &Table,
    options: &PoseFileOptions,
) -> Result<Option<FixedFormat>> {
    let mut notes = Vec::new();
    let Some((names, line)) = &table.header else {
        return Ok(options.format.map(|f| (f, None, notes)));
    };
    let (format, map) = match options.format {
        Some(f) => match map_header(names, f, *line)? {
            Some(map) => (f, Some(map)),
            None => {
                let k = f.value_count();
                let value_names = names.iter().filter(|n| !super::pose_table::is_name_column(n)).count();
                if value_names != k {
                    return Err(Error::parse(*line, 0, format!(
                        "the header names {} columns ({}), the {} format needs {} ({})",
                        names.len(), names.join(" "), f.label(), k, f.columns().join(" ")
                    )));
                }
                notes.push(format!(
                    "header names '{}' are not the {} column names; columns read by position",
                    names.join(" "), f.label()
                ));
                (f, None)
            }
        },
        None => match detect_header(names, *line)? {
            Some((f, map)) => {
                notes.push(format!("format {} from the header", f.name()));
                if f == DEGREE_RXRYRZ && header_has(names, "rx") {
                    notes.push(degree_rxryrz_note());
                }
                (f, Some(map))
            }
            None => {
                return Err(Error::parse(*line, 0, format!(
                    "the header '{}' names no known pose format; name the format, or use column names such as x,y,z,qx,qy,qz,qw or X,Y,Z,A,B,C",
                    names.join(" ")
                )))
            }
        },
    };
    if let Some(m) = &map {
        if !m.ignored.is_empty() {
            notes.push(format!("ignored columns: {}", m.ignored.join(" ")));
        }
    }
    Ok(Some((format, map, notes)))
}

/// How many values the first data row has, not counting a leading name.
pub(crate) fn first_row_value_count(table: &Table) -> Option<usize> {
    let row = table.rows.first()?;
    let named = row.fields.first().is_some_and(|f| number(f).is_none());
    Some(row.fields.len() - usize::from(named))
}

/// The error for a pose file without a single pose.
pub(crate) fn no_poses() -> Error {
    Error::invalid(
        "poses",
        "the file holds no poses (it is empty, or only a header and comments): give one pose \
         per line, e.g. x,y,z,qx,qy,qz,qw",
    )
}

pub(crate) fn resolve(table: &Table, options: &PoseFileOptions) -> Result<Reading> {
    let (format, header, mut notes) = match header_reading(table, options)? {
        Some(found) => found,
        None => {
            let Some(n) = first_row_value_count(table) else {
                return Err(no_poses());
            };
            let fits: Vec<PoseFormat> = PoseFormat::all()
                .into_iter()
                .filter(|f| f.value_count() == n)
                .collect();
            let line = table.rows[0].origin.number();
            match fits.as_slice() {
                [only] => (
                    *only,
                    None,
                    vec![format!("format {} from {n} values a line", only.name())],
                ),
                [] => {
                    return Err(table.rows[0].error(
                        0,
                        format!("{n} values, but pose formats have 6, 7, 12 or 16 values a line"),
                    ))
                }
                many => {
                    let names: Vec<String> = many.iter().take(8).map(|f| f.name()).collect();
                    return Err(Error::parse(line, 0, format!(
                        "{n} values a line and no header: ambiguous between {}{}; name the format or add a header",
                        names.join(", "),
                        if many.len() > 8 { ", ..." } else { "" }
                    )));
                }
            }
        }
    };
    let (default_l, default_a) = format.default_units();
    let header_l = header.as_ref().and_then(|h| h.length_unit);
    let header_a = header.as_ref().and_then(|h| h.angle_unit);
    let length_unit = options.length_unit.or(header_l).unwrap_or(default_l);
    let angle_unit = options.angle_unit.or(header_a).unwrap_or(default_a);
    if options.length_unit.is_none() && header_l.is_none() {
        notes.push(format!(
            "lengths in {} (the {} default)",
            length_unit.name(),
            format.label()
        ));
    }
    if format.uses_angles() && options.angle_unit.is_none() && header_a.is_none() {
        notes.push(format!(
            "angles in {} (the {} default)",
            angle_unit.name(),
            format.label()
        ));
    }
    let header_len = table.header.as_ref().map(|(n, _)| n.len());
    Ok(Reading {
        format,
        length_unit,
        angle_unit,
        header,
        header_len,
        notes,
    })
}

/// The values and name of one row under a reading.
fn row_values(row: &Row, reading: &Reading) -> Result<(Vec<f64>, Option<String>)> {
    let f = reading.format;
    let k = f.value_count();
    let n = row.fields.len();
    let needs = format!(
        "the {} format needs {k} ({})",
        f.label(),
        f.columns().join(" ")
    );
    let parse = |i: usize| -> Result<f64> {
        let text = &row.fields[i];
        number(text).ok_or_else(|| {
            let shown: String = text.chars().take(24).collect();
            let msg = if text.is_empty() {
                "empty field".to_string()
            } else {
                format!("'{shown}' is not a number")
            };
            row.error(i + 1, msg)
        })
    };
    if let Some(h) = &reading.header {
        let hn = reading.header_len.unwrap_or(n);
        if n != hn {
            return Err(row
                .origin
                .error(0, format!("{n} values, {needs} but the header names {hn}")));
        }
        let values = h
            .value_fields
            .iter()
            .map(|&i| parse(i))
            .collect::<Result<Vec<f64>>>()?;
        let name = h
            .name_field
            .map(|i| row.fields[i].clone())
            .filter(|s| !s.is_empty());
        return Ok((values, name));
    }
    if let Some(hn) = reading.header_len {
        // Positional header (names did not match the format).
        if n != hn {
            return Err(row
                .origin
                .error(0, format!("{n} values, {needs} but the header names {hn}")));
        }
    }
    let named = n == k + 1 && number(&row.fields[0]).is_none();
    if n != k && !named {
        return Err(row.error(0, format!("{n} values, {needs}")));
    }
    let start = usize::from(named);
    let values = (start..n).map(parse).collect::<Result<Vec<f64>>>()?;
    Ok((values, named.then(|| row.fields[0].clone())))
}

/// All rows under a reading, as `base_from_gripper`.
pub(crate) fn read_rows(
    rows: &[Row],
    reading: &Reading,
    direction: PoseDirection,
) -> Result<Vec<RobotPose>> {
    if rows.is_empty() {
        return Err(no_poses());
    }
    let mut poses = Vec::with_capacity(rows.len());
    for row in rows {
        let (values, name) = row_values(row, reading)?;
        let pose = pose_from_values(
            reading.format,
            &values,
            reading.length_unit,
            reading.angle_unit,
        )
        .map_err(|e| {
            let column = match &reading.header {
                _ if e.index == WHOLE_ROW => 0,
                Some(h) => h.value_fields.get(e.index).map_or(0, |i| i + 1),
                None => e.index + 1 + usize::from(row.fields.len() > values.len()),
            };
            row.error(column, e.message)
        })?;
        let base_from_gripper = match direction {
            PoseDirection::BaseFromGripper => pose,
            PoseDirection::GripperFromBase => pose.inverse(),
        };
        poses.push(RobotPose {
            name,
            line: row.origin.number(),
            base_from_gripper,
        });
    }
    Ok(poses)
}
