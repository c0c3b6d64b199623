//! Text and JSON pose files as a table: an optional header, then rows of
//! fields with their positions. Format detection from header names lives
//! here too.

use super::pose_formats::{AngleUnit, LengthUnit, PoseFormat};
use crate::error::{Error, Result};
use crate::geometry::{EulerKind, EulerOrder};

/// Where a row came from, for error messages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Origin {
    /// 1-based line of a text file.
    Line(usize),
    /// 1-based element of a JSON array.
    JsonElement(usize),
}

impl Origin {
    /// The number stored in `RobotPose::line`.
    pub fn number(self) -> usize {
        match self {
            Origin::Line(n) | Origin::JsonElement(n) => n,
        }
    }

    /// An error at field `column` (1-based; 0 = the whole row).
    pub fn error(self, column: usize, message: impl Into<String>) -> Error {
        match self {
            Origin::Line(l) => Error::parse(l, column, message),
            Origin::JsonElement(i) => {
                Error::parse(0, 0, format!("JSON pose {i}: {}", message.into()))
            }
        }
    }
}

/// One data row: raw fields (JSON numbers already printed back to text).
#[derive(Debug, Clone)]
pub(crate) struct Row {
    pub origin: Origin,
    pub fields: Vec<String>,
    /// For a row gathered from a whole file (one pose per file), the line
    /// of each field (0 = unknown); empty for a row that is one line.
    pub field_lines: Vec<usize>,
}

impl Row {
    /// An error at field `column` (1-based; 0 = the whole row): at the
    /// field's own line for a row gathered from a file, else at the row's
    /// line and column.
    pub fn error(&self, column: usize, message: impl Into<String>) -> Error {
        if self.field_lines.is_empty() {
            return self.origin.error(column, message);
        }
        let line = column
            .checked_sub(1)
            .and_then(|i| self.field_lines.get(i))
            .copied()
            .unwrap_or(self.origin.number());
        Error::parse(line, 0, message)
    }
}

/// A pose file as a table.
#[derive(Debug, Clone)]
pub(crate) struct Table {
    /// Header names and the header's line (0 for JSON keys).
    pub header: Option<(Vec<String>, usize)>,
    pub rows: Vec<Row>,
}

/// Header names that hold the pose's name or image file.
const NAME_COLUMNS: [&str; 8] = [
    "name",
    "image",
    "image_name",
    "image_file",
    "img",
    "file",
    "filename",
    "label",
];

/// Splits one line: comma if present, else semicolon, else tab, else
/// whitespace. Double quotes group a field (`""` is a literal quote).
pub(crate) fn split_fields(line: &str) -> Vec<String> {
    let delim = [',', ';', '\t'].into_iter().find(|d| line.contains(*d));
    let Some(delim) = delim else {
        return line.split_whitespace().map(str::to_string).collect();
    };
    let mut fields = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            c if c == delim && !quoted => fields.push(std::mem::take(&mut cur).trim().to_string()),
            c => cur.push(c),
        }
    }
    fields.push(cur.trim().to_string());
    // A trailing delimiter is not an empty last column.
    if fields.len() > 1 && fields.last().is_some_and(|f| f.is_empty()) {
        fields.pop();
    }
    fields
}

/// A finite number, or None.
pub(crate) fn number(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Text (CSV, TSV, whitespace) to a table; `#` comments and blank lines are
/// skipped. The first content line is a header when none of its fields is
/// a number.
pub(crate) fn table_from_text(text: &str) -> Table {
    let mut header = None;
    let mut rows = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim().trim_start_matches('\u{feff}');
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields = split_fields(line);
        if header.is_none() && rows.is_empty() && fields.iter().all(|f| number(f).is_none()) {
            header = Some((fields, i + 1));
            continue;
        }
        rows.push(Row {
            origin: Origin::Line(i + 1),
            fields,
            field_lines: Vec::new(),
        });
    }
    Table { header, rows }
}

/// A header name without its unit: `(name, unit)` for `x_mm`, `x [mm]`,
/// `x(mm)`, lowercased; `tx`/`px` become `x`.
pub(crate) fn split_unit(raw: &str) -> (String, Option<&'static str>) {
    let lower = raw.trim().to_ascii_lowercase();
    let units = ["mm", "m", "deg", "rad"];
    let mut name = lower.clone();
    let mut unit = None;
    for u in units {
        for (open, close) in [("_", ""), ("[", "]"), ("(", ")"), (" ", "")] {
            let suffix = format!("{open}{u}{close}");
            if let Some(stem) = lower.strip_suffix(&suffix) {
                let stem = stem.trim();
                if !stem.is_empty() && unit.is_none() {
                    name = stem.to_string();
                    unit = Some(u);
                }
            }
        }
    }
    let name = match name.as_str() {
        "tx" | "px" => "x".to_string(),
        "ty" | "py" => "y".to_string(),
        "tz" | "pz" => "z".to_string(),
        _ => name,
    };
    (name, unit)
}

/// What a header says.
#[derive(Debug, Clone)]
pub(crate) struct HeaderMap {
    /// For each format column, its field index.
    pub value_fields: Vec<usize>,
    /// The field index of the name column.
    pub name_field: Option<usize>,
    /// Header names that were not used.
    pub ignored: Vec<String>,
    pub length_unit: Option<LengthUnit>,
    pub angle_unit: Option<AngleUnit>,
}

/// The names a format's columns may have in a header (lowercase, units
/// removed as [`split_unit`] removes them: `tx` is `x`).
fn accepted_names(format: PoseFormat, column: usize) -> Vec<String> {
    let base = split_unit(format.columns()[column]).0;
    let mut names = vec![base];
    match format {
        PoseFormat::XyzEuler { order, kind } if column >= 3 => {
            let rpy = order == EulerOrder::XYZ && kind == EulerKind::Extrinsic;
            if rpy {
                names.push(["roll", "pitch", "yaw"][column - 3].to_string());
            }
            // `rx ry rz` name the axis each angle turns about; proper Euler
            // orders (zyz) repeat an axis, so only e1 e2 e3 name them.
            let axes: Vec<char> = order.name().chars().collect();
            if axes[0] != axes[2] {
                names.push(format!("r{}", axes[column - 3]));
            }
        }
        // `m00 .. m23` as the top rows of a 4x4.
        PoseFormat::Matrix3x4 => names.push(format!("m{}{}", column / 4, column % 4)),
        _ => {}
    }
    names
}

/// Maps header names onto `format`'s columns, by name. None when a column
/// is missing. Errors when units in the header disagree.
pub(crate) fn map_header(
    names: &[String],
    format: PoseFormat,
    line: usize,
) -> Result<Option<HeaderMap>> {
    let parsed: Vec<(String, Option<&str>)> = names.iter().map(|n| split_unit(n)).collect();
    let mut value_fields = Vec::new();
    for c in 0..format.value_count() {
        let accepted = accepted_names(format, c);
        match parsed.iter().position(|(n, _)| accepted.contains(n)) {
            Some(i) => value_fields.push(i),
            None => return Ok(None),
        }
    }
    let name_field = parsed
        .iter()
        .position(|(n, _)| NAME_COLUMNS.contains(&n.as_str()));
    let ignored = (0..names.len())
        .filter(|i| !value_fields.contains(i) && Some(*i) != name_field)
        .map(|i| names[i].clone())
        .collect();
    let mut length_unit = None;
    let mut angle_unit = None;
    for (c, &f) in value_fields.iter().enumerate() {
        let Some(u) = parsed[f].1 else { continue };
        let is_length = format.is_length_column(c);
        let clash = |what: &str| {
            Error::parse(
                line,
                f + 1,
                format!(
                    "header column '{}' disagrees with the {what} unit of an earlier column",
                    names[f]
                ),
            )
        };
        match (u, is_length) {
            ("mm" | "m", true) => {
                let unit = if u == "mm" {
                    LengthUnit::Millimetre
                } else {
                    LengthUnit::Metre
                };
                if length_unit.is_some_and(|l| l != unit) {
                    return Err(clash("length"));
                }
                length_unit = Some(unit);
            }
            ("deg" | "rad", false) => {
                let unit = if u == "deg" {
                    AngleUnit::Degree
                } else {
                    AngleUnit::Radian
                };
                if angle_unit.is_some_and(|a| a != unit) {
                    return Err(clash("angle"));
                }
                angle_unit = Some(unit);
            }
            _ => {
                return Err(Error::parse(
                    line,
                    f + 1,
                    format!(
                        "header column '{}' has a unit that does not fit it",
                        names[f]
                    ),
                ))
            }
        }
    }
    Ok(Some(HeaderMap {
        value_fields,
        name_field,
        ignored,
        length_unit,
        angle_unit,
    }))
}

/// The formats a header can select by its names alone, most specific first.
/// `x y z rx ry rz` selects UR (rotation vector) unless the angles carry
/// `_deg` ([`DEGREE_RXRYRZ`]); Yaskawa and Stäubli files use the same names
/// and need the format named explicitly.
const HEADER_FORMATS: [PoseFormat; 9] = [
    PoseFormat::Matrix4,
    PoseFormat::Matrix3x4,
    PoseFormat::XyzQuatXyzw,
    PoseFormat::Abb,
    PoseFormat::Kuka,
    PoseFormat::Fanuc,
    PoseFormat::Ur,
    PoseFormat::XyzEuler {
        order: EulerOrder::XYZ,
        kind: EulerKind::Extrinsic,
    },
    PoseFormat::XyzQuatWxyz,
];

/// What `x y z rx ry rz` with angles in degrees (`rx_deg`) is read as:
/// Euler angles about the fixed x, then y, then z axes, `R = Rz(rz) ·
/// Ry(ry) · Rx(rx)` (ROS roll-pitch-yaw, the UR pendant's RPY view, FANUC W
/// P R, Yaskawa Rx Ry Rz). A rotation vector is never written in degrees by
/// the tools that write one (UR, OpenCV), while teach pendants show Euler
/// angles in degrees under these names.
pub const DEGREE_RXRYRZ: PoseFormat = PoseFormat::XyzEuler {
    order: EulerOrder::XYZ,
    kind: EulerKind::Extrinsic,
};

/// The note said when [`DEGREE_RXRYRZ`] was assumed.
pub(crate) fn degree_rxryrz_note() -> String {
    format!(
        "rx ry rz in degrees read as Euler angles about the fixed x, then y, then z axes \
         (R = Rz·Ry·Rx, format {}); name another convention with the format, e.g. staubli \
         (xyz_euler_intrinsic_xyz) or xyz_euler_intrinsic_zyx",
        DEGREE_RXRYRZ.name()
    )
}

/// The format a header names, with its mapping. For quaternions, `qw`
/// before `qx` selects `xyz_quat_wxyz`; `rx ry rz` in degrees selects
/// [`DEGREE_RXRYRZ`].
pub(crate) fn detect_header(
    names: &[String],
    line: usize,
) -> Result<Option<(PoseFormat, HeaderMap)>> {
    for format in HEADER_FORMATS {
        if let Some(map) = map_header(names, format, line)? {
            if format == PoseFormat::Ur && map.angle_unit == Some(AngleUnit::Degree) {
                return Ok(map_header(names, DEGREE_RXRYRZ, line)?.map(|m| (DEGREE_RXRYRZ, m)));
            }
            if format == PoseFormat::XyzQuatXyzw && map.value_fields[6] < map.value_fields[3] {
                let wxyz = PoseFormat::XyzQuatWxyz;
                return Ok(map_header(names, wxyz, line)?.map(|m| (wxyz, m)));
            }
            return Ok(Some((format, map)));
        }
    }
    Ok(None)
}

/// Whether a header field is a name column.
pub(crate) fn is_name_column(name: &str) -> bool {
    NAME_COLUMNS.contains(&split_unit(name).0.as_str())
}

/// Whether a header names `name` (units removed, case ignored).
pub(crate) fn header_has(names: &[String], name: &str) -> bool {
    names.iter().any(|n| split_unit(n).0 == name)
}

/// Whether some format reads a header field of this name (`x_mm`, `qw`,
/// `A`, `roll`, `r11`, ...).
pub(crate) fn is_pose_column(name: &str) -> bool {
    let own = split_unit(name).0;
    PoseFormat::all()
        .into_iter()
        .any(|f| (0..f.value_count()).any(|c| accepted_names(f, c).contains(&own)))
}
