//! One file per pose, as ROS tools and teach-pendant exports write them: a
//! folder (or a list) of YAML, JSON or text files, each holding one robot
//! pose. The caller reads the files and passes each one's name and text; no
//! filesystem here.
//!
//! # What one file may hold
//! - Named numbers, at any depth: `position: {x, y, z}` with
//!   `orientation: {x, y, z, w}` (ROS `geometry_msgs/Pose`, also under
//!   `pose:`, as `rostopic echo` prints it), `translation`/`rotation` (ROS
//!   `Transform`), or flat names as a pose table's header has them (`x_mm`,
//!   `A`, `qw`, `rx_deg`, ...). Under `position`/`translation` the keys
//!   `x y z` are the translation; under `orientation`/`rotation`/`quaternion`
//!   the keys `x y z w` are the quaternion (`qx qy qz qw`). A unit on the
//!   parent (`position_mm:`) applies to its keys. Lists of three under a
//!   position key and of four under a quaternion key read as `x y z` and
//!   `qx qy qz qw` (ROS order). Other names (`seq`, `frame_id`) are ignored,
//!   and said so.
//! - A matrix: a 4x4 or 3x4 list of rows, or 16 or 12 numbers in one list,
//!   under any key (`matrix:`, OpenCV's `data:`) or alone.
//! - Text: a header line and one row (`x,y,z,qx,qy,qz,qw` then the
//!   numbers), or numbers alone over any number of lines (a 4x4 matrix as 4
//!   lines of 4).
//!
//! The files must agree: the same names, or the same count of numbers.
//! They are read in numeric order of their names
//! ([`super::pose_pairing::natural_cmp`]); each pose is named by its file's
//! stem, which pairs it with the image of the same stem. Errors name the
//! file and, for YAML and text, the line.

use serde::{Deserialize, Serialize};

use super::pose_candidates::{candidates_from_table, Candidate};
use super::pose_json::json_error;
use super::pose_pairing::natural_cmp;
use super::pose_table::{is_pose_column, number, split_unit, table_from_text, Origin, Row, Table};
use super::pose_yaml::{looks_like_yaml, parse_yaml, Node};
use super::poses::{read_rows, resolve, ParsedPoses, PoseFileOptions};
use crate::error::{Error, Result};

/// One pose file as the caller read it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseFileText {
    /// The file's name or path as the user gave it (named in errors; its
    /// stem names the pose).
    pub name: String,
    /// The file's text.
    pub text: String,
}

/// Keys whose `x y z` children are the translation.
const POSITION_KEYS: [&str; 7] = [
    "position",
    "translation",
    "pos",
    "trans",
    "location",
    "t",
    "xyz",
];

/// Keys whose `x y z w` children are a quaternion.
const QUATERNION_KEYS: [&str; 6] = ["orientation", "rotation", "quaternion", "quat", "q", "rot"];

/// The pose of one file before the files are put together: header names
/// (None = numbers by position), the fields and each field's line.
#[derive(Debug, Clone, PartialEq)]
struct OnePose {
    header: Option<Vec<String>>,
    fields: Vec<String>,
    lines: Vec<usize>,
}

/// The file's stem (`poses/pose_03.yaml` -> `pose_03`).
pub(crate) fn stem(name: &str) -> &str {
    let file = name.rsplit(['/', '\\']).next().unwrap_or(name);
    match file.rfind('.') {
        Some(dot) if dot > 0 => &file[..dot],
        _ => file,
    }
}

/// One file's pose (errors without the file's name). A `.json` file is JSON;
/// other text starting with `{` or `[` is JSON, else YAML flow.
fn one_pose(name: &str, text: &str) -> Result<OnePose> {
    let body = text.trim_start_matches('\u{feff}');
    let trimmed = body.trim_start();
    if trimmed.starts_with(['{', '[']) {
        return match serde_json::from_str::<serde_json::Value>(trimmed) {
            Ok(v) => from_tree(&Node::from_json(&v)),
            // `{x: 0.1, ...}` is YAML flow, not JSON.
            Err(e) if name.to_ascii_lowercase().ends_with(".json") => Err(json_error(&e)),
            Err(e) => match parse_yaml(body) {
                Ok(node) => from_tree(&node),
                Err(_) => Err(json_error(&e)),
            },
        };
    }
    if looks_like_yaml(body) {
        return from_tree(&parse_yaml(body)?);
    }
    from_text(body)
}

/// A text file: a header and one row, or numbers alone on any lines.
fn from_text(text: &str) -> Result<OnePose> {
    let table = table_from_text(text);
    let lines_of = |row: &Row| vec![row.origin.number(); row.fields.len()];
    match (&table.header, table.rows.as_slice()) {
        (_, []) => Err(no_pose()),
        (Some((names, _)), [row]) if row.fields.len() != names.len() => Err(Error::parse(
            row.origin.number(),
            0,
            format!("{} values but the header names {}", row.fields.len(), names.len()),
        )),
        (Some((names, _)), [row]) => Ok(OnePose {
            header: Some(names.clone()),
            fields: row.fields.clone(),
            lines: lines_of(row),
        }),
        (Some(_), rows) => Err(Error::parse(
            rows[1].origin.number(),
            0,
            format!(
                "a second pose ({} rows under the header): a file in a folder of poses holds one pose; a table of poses is given alone",
                rows.len()
            ),
        )),
        (None, rows) => Ok(OnePose {
            header: None,
            fields: rows.iter().flat_map(|r| r.fields.clone()).collect(),
            lines: rows.iter().flat_map(lines_of).collect(),
        }),
    }
}

fn no_pose() -> Error {
    Error::invalid(
        "poses",
        "the file holds no pose: expected position and orientation keys, names such as x,y,z,qx,qy,qz,qw, or a 4x4 or 3x4 matrix",
    )
}

/// The numbers of a list that is a matrix: 4x4 or 3x4 rows, or 16 or 12
/// numbers; with their lines.
fn matrix_numbers(node: &Node) -> Option<Vec<(String, usize)>> {
    let Node::List(items) = node else { return None };
    let scalars = |items: &[Node]| -> Option<Vec<(String, usize)>> {
        items
            .iter()
            .map(|n| match n {
                Node::Scalar(s, l) if number(s).is_some() => Some((s.clone(), *l)),
                _ => None,
            })
            .collect()
    };
    if let Some(flat) = scalars(items) {
        return matches!(flat.len(), 12 | 16).then_some(flat);
    }
    if !matches!(items.len(), 3 | 4) {
        return None;
    }
    let mut out = Vec::new();
    for row in items {
        let Node::List(cells) = row else { return None };
        let cells = scalars(cells).filter(|c| c.len() == 4)?;
        out.extend(cells);
    }
    Some(out)
}

/// What the walk over a tree found.
#[derive(Default)]
struct Found {
    /// (path, numbers) of every matrix.
    matrices: Vec<(String, Vec<(String, usize)>)>,
    /// (path, numbers) of other lists of numbers.
    lists: Vec<(String, Vec<(String, usize)>)>,
    /// (name as a header names it, path, text, line) of every scalar.
    named: Vec<(String, String, String, usize)>,
}

/// A key's lowercase name and the unit it carries (`position_mm`).
fn key_unit(key: &str) -> (String, Option<&'static str>) {
    split_unit(key)
}

fn walk(node: &Node, path: &[&str], found: &mut Found) {
    let joined = path.join(".");
    match node {
        Node::Map(entries) => {
            for (k, v) in entries {
                let mut p = path.to_vec();
                p.push(k);
                walk(v, &p, found);
            }
        }
        Node::List(items) => {
            if let Some(m) = matrix_numbers(node) {
                found.matrices.push((joined, m));
                return;
            }
            let numbers: Option<Vec<(String, usize)>> = items
                .iter()
                .map(|n| match n {
                    Node::Scalar(s, l) if number(s).is_some() => Some((s.clone(), *l)),
                    _ => None,
                })
                .collect();
            let Some(numbers) = numbers else { return };
            let (parent, unit) = path.last().map_or((String::new(), None), |k| key_unit(k));
            let names: &[&str] = match numbers.len() {
                3 if POSITION_KEYS.contains(&parent.as_str()) => &["x", "y", "z"],
                4 if QUATERNION_KEYS.contains(&parent.as_str()) => &["qx", "qy", "qz", "qw"],
                _ => {
                    found.lists.push((joined, numbers));
                    return;
                }
            };
            for (name, (text, line)) in names.iter().zip(numbers) {
                let name = unit.map_or(name.to_string(), |u| format!("{name}_{u}"));
                found.named.push((name, format!("{joined}[]"), text, line));
            }
        }
        Node::Scalar(text, line) => {
            let Some(key) = path.last() else {
                found.lists.push((joined, vec![(text.clone(), *line)]));
                return;
            };
            let (own, own_unit) = key_unit(key);
            let (parent, parent_unit) = match path.len() {
                0 | 1 => (String::new(), None),
                n => key_unit(path[n - 2]),
            };
            let axis = matches!(own.as_str(), "x" | "y" | "z" | "w");
            let name = if QUATERNION_KEYS.contains(&parent.as_str()) && axis {
                format!("q{own}")
            } else if POSITION_KEYS.contains(&parent.as_str()) && axis && own != "w" {
                own.clone()
            } else {
                key.to_string()
            };
            let name = match (own_unit, parent_unit) {
                (None, Some(u)) => format!("{name}_{u}"),
                (Some(u), _) if name == own || name == format!("q{own}") => format!("{name}_{u}"),
                _ => name,
            };
            found.named.push((name, joined, text.clone(), *line));
        }
    }
}

/// A parsed YAML or JSON file's pose: one matrix, else named numbers, else
/// one list of numbers.
fn from_tree(node: &Node) -> Result<OnePose> {
    let mut found = Found::default();
    walk(node, &[], &mut found);
    let positional = |numbers: Vec<(String, usize)>| {
        let (fields, lines) = numbers.into_iter().unzip();
        OnePose {
            header: None,
            fields,
            lines,
        }
    };
    let at = |path: &str| {
        if path.is_empty() {
            "the file".to_string()
        } else {
            format!("'{path}'")
        }
    };
    match found.matrices.len() {
        0 => {}
        1 => return Ok(positional(found.matrices.remove(0).1)),
        _ => {
            let paths: Vec<String> = found.matrices.iter().map(|(p, _)| at(p)).collect();
            return Err(Error::invalid(
                "poses",
                format!(
                    "two matrices ({}): a pose file holds one pose",
                    paths.join(" and ")
                ),
            ));
        }
    }
    // Names no format reads (`seq`, `frame_id`, `covariance`) are dropped,
    // unless nothing else is named (then the error lists them).
    if found.named.iter().any(|(n, ..)| is_pose_column(n)) {
        found.named.retain(|(n, ..)| is_pose_column(n));
    }
    let numeric = found.named.iter().any(|(_, _, t, _)| number(t).is_some());
    if numeric {
        // A name given twice is an error when a format reads it; otherwise
        // (`secs` in two stamps, when nothing is a pose name) the later one
        // is kept under its path.
        for i in 0..found.named.len() {
            let (name, path) = (found.named[i].0.clone(), found.named[i].1.clone());
            let Some((_, other, _, _)) = found.named[..i].iter().find(|(n, ..)| *n == name) else {
                continue;
            };
            if is_pose_column(&name) {
                return Err(Error::invalid(
                    "poses",
                    format!("'{other}' and '{path}' both give {name}"),
                ));
            }
            found.named[i].0 = path;
        }
        let mut header = Vec::new();
        let mut fields = Vec::new();
        let mut lines = Vec::new();
        for (name, _, text, line) in found.named {
            header.push(name);
            fields.push(text);
            lines.push(line);
        }
        return Ok(OnePose {
            header: Some(header),
            fields,
            lines,
        });
    }
    match found.lists.len() {
        0 => Err(no_pose()),
        1 => Ok(positional(found.lists.remove(0).1)),
        _ => {
            let paths: Vec<String> = found.lists.iter().map(|(p, _)| at(p)).collect();
            Err(Error::invalid(
                "poses",
                format!(
                    "several lists of numbers ({}) and no named values: name the values (x, y, z, qx, ...) or give one matrix",
                    paths.join(", ")
                ),
            ))
        }
    }
}

/// An error about file `name`: `'name': <error>`.
fn in_file(name: &str, e: Error) -> Error {
    Error::parse(0, 0, format!("'{name}': {e}"))
}

/// The files in numeric order of their names, each read to one pose, put
/// together as a table (header from the first file, each row one file).
/// Returns the table and the names in the table's row order.
fn files_table(files: &[PoseFileText]) -> Result<(Table, Vec<&str>)> {
    if files.is_empty() {
        return Err(Error::invalid("poses", "no pose files were given"));
    }
    let mut order: Vec<&PoseFileText> = files.iter().collect();
    order.sort_by(|a, b| natural_cmp(&a.name, &b.name));
    let mut header: Option<Vec<String>> = None;
    let mut rows = Vec::with_capacity(order.len());
    for (i, file) in order.iter().enumerate() {
        let one = one_pose(&file.name, &file.text).map_err(|e| in_file(&file.name, e))?;
        let (fields, lines) = if i == 0 {
            header = one.header.clone();
            (one.fields, one.lines)
        } else {
            let first = (order[0].name.as_str(), rows_len(&rows));
            agree(header.as_deref(), one, first).map_err(|e| in_file(&file.name, e))?
        };
        rows.push(Row {
            origin: Origin::Line(lines.first().copied().unwrap_or(0)),
            fields,
            field_lines: lines,
        });
    }
    let names = order.iter().map(|f| f.name.as_str()).collect();
    Ok((
        Table {
            header: header.map(|h| (h, 0)),
            rows,
        },
        names,
    ))
}

/// How many fields the first row has.
fn rows_len(rows: &[Row]) -> usize {
    rows.first().map_or(0, |r| r.fields.len())
}

/// A later file's fields in the first file's header order; `first` is the
/// first file's name and field count.
fn agree(
    header: Option<&[String]>,
    one: OnePose,
    (first, first_count): (&str, usize),
) -> Result<(Vec<String>, Vec<usize>)> {
    let differ = |theirs: String, ours: String| {
        Error::invalid(
            "poses",
            format!("its values ({ours}) are not those of '{first}' ({theirs}): every pose file must have the same layout"),
        )
    };
    match (header, one.header) {
        (None, None) => Ok((one.fields, one.lines)),
        (Some(h), Some(names)) => {
            let mut sorted_h = h.to_vec();
            let mut sorted_n = names.clone();
            sorted_h.sort();
            sorted_n.sort();
            if sorted_h != sorted_n {
                return Err(differ(h.join(" "), names.join(" ")));
            }
            let pick = |want: &String| names.iter().position(|n| n == want).unwrap_or(0);
            Ok((
                h.iter().map(|n| one.fields[pick(n)].clone()).collect(),
                h.iter().map(|n| one.lines[pick(n)]).collect(),
            ))
        }
        (Some(h), None) => Err(differ(
            h.join(" "),
            format!("{} numbers without names", one.fields.len()),
        )),
        (None, Some(names)) => Err(differ(
            format!("{first_count} numbers without names"),
            names.join(" "),
        )),
    }
}

/// Names and lines of the poses as one pose per file: the stem, and the
/// file's 1-based place in the sorted list.
fn name_poses(poses: &mut [super::RobotPose], names: &[&str]) {
    for (i, (pose, name)) in poses.iter_mut().zip(names).enumerate() {
        pose.name = Some(stem(name).to_string());
        pose.line = i + 1;
    }
}

/// Parses one pose per file into `base_from_gripper` poses, with the format
/// and units chosen as [`super::parse_poses`] chooses them for a table
/// whose header is the first file's names (or, without names, by the
/// number of values). The poses are in numeric order of the file names,
/// each named by its file's stem, `line` its place in that order.
pub fn parse_pose_files(files: &[PoseFileText], options: &PoseFileOptions) -> Result<ParsedPoses> {
    let (table, names) = files_table(files)?;
    let first = names[0];
    let reading = resolve(&table, options).map_err(|e| in_file(first, e))?;
    let mut poses = Vec::with_capacity(table.rows.len());
    for (row, name) in table.rows.iter().zip(&names) {
        let one = read_rows(std::slice::from_ref(row), &reading, options.direction)
            .map_err(|e| in_file(name, e))?;
        poses.extend(one);
    }
    name_poses(&mut poses, &names);
    let mut notes = reading.notes;
    notes.insert(
        0,
        format!(
            "{} pose files, one pose each, in numeric order of their names; each pose named by its file's stem",
            names.len()
        ),
    );
    let mut parsed = ParsedPoses {
        poses,
        format: reading.format,
        length_unit: reading.length_unit,
        angle_unit: reading.angle_unit,
        direction: options.direction,
        notes,
    };
    parsed
        .notes
        .extend(super::poses::radians_read_as_degrees(&parsed));
    Ok(parsed)
}

/// Every plausible reading of one-pose-per-file files (see
/// [`super::parse_pose_candidates`]), each pose named as by
/// [`parse_pose_files`].
pub fn parse_pose_file_candidates(
    files: &[PoseFileText],
    options: &PoseFileOptions,
) -> Result<Vec<Candidate>> {
    let (table, names) = files_table(files)?;
    let mut candidates =
        candidates_from_table(&table, options).map_err(|e| in_file(names[0], e))?;
    for c in &mut candidates {
        name_poses(&mut c.poses, &names);
    }
    Ok(candidates)
}

#[cfg(test)]
#[path = "pose_files_tests.rs"]
mod tests;
