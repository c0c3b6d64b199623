//! Every plausible reading of a pose file whose format or units are not
//! known, ranked, so that a solver can pick the one that fits the camera
//! motion.

use serde::{Deserialize, Serialize};

use super::pose_formats::{short, AngleUnit, LengthUnit, PoseFormat, RotationLayout};
use super::pose_table::Table;
use super::poses::{
    first_row_value_count, header_reading, no_poses, read_rows, table_from_input, PoseFileOptions,
    Reading, RobotPose,
};
use crate::error::Result;
use crate::geometry::rotation_angle_between;

/// One reading of a pose file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// The layout of this reading.
    pub format: PoseFormat,
    /// Its length unit.
    pub length_unit: LengthUnit,
    /// Its angle unit (meaningless for quaternion and matrix formats).
    pub angle_unit: AngleUnit,
    /// The poses under this reading, as `base_from_gripper`.
    pub poses: Vec<RobotPose>,
    /// Other format names giving exactly the same poses.
    pub same_as: Vec<String>,
    /// Implausibility, 0 = nothing suspicious; candidates are sorted by it.
    pub penalty: f64,
    /// Why the penalty is what it is, in plain words.
    pub reasons: Vec<String>,
}

/// Robot workspaces: a median TCP distance from the base outside this range
/// (metres) suggests the wrong length unit.
const PLAUSIBLE_REACH_M: (f64, f64) = (0.05, 5.0);

/// All readings of `text` that parse without error, most plausible first.
///
/// Format and units fixed by `options` or a header are kept; the others
/// are enumerated: every format with the file's number of values, and both
/// units of each kind. Readings that fail (a rotation vector over 2 pi in
/// radians, quaternion norms far from 1, a non-rotation matrix) are dropped;
/// readings giving identical poses are merged (`same_as`). The ranking uses
/// the median reach (mm vs m), whether all angles fit in ±pi when read as
/// degrees (suggests radians), quaternion norms, and preset defaults. When
/// no reading parses, the error of the first one tried is returned.
pub fn parse_pose_candidates(text: &str, options: &PoseFileOptions) -> Result<Vec<Candidate>> {
    candidates_from_table(&table_from_input(text)?, options)
}

/// [`parse_pose_candidates`] of a table.
pub(crate) fn candidates_from_table(
    table: &Table,
    options: &PoseFileOptions,
) -> Result<Vec<Candidate>> {
    let fixed = header_reading(table, options)?;
    let header_len = table.header.as_ref().map(|(n, _)| n.len());
    let mut readings = Vec::new();
    match fixed {
        Some((format, header, notes)) => {
            let hl = header.as_ref().and_then(|h| h.length_unit);
            let ha = header.as_ref().and_then(|h| h.angle_unit);
            for (l, a) in unit_choices(
                format,
                options.length_unit.or(hl),
                options.angle_unit.or(ha),
            ) {
                readings.push(Reading {
                    format,
                    length_unit: l,
                    angle_unit: a,
                    header: header.clone(),
                    header_len,
                    notes: notes.clone(),
                });
            }
        }
        None => {
            let Some(n) = first_row_value_count(table) else {
                return Err(no_poses());
            };
            for format in PoseFormat::all()
                .into_iter()
                .filter(|f| f.value_count() == n)
            {
                for (l, a) in unit_choices(format, options.length_unit, options.angle_unit) {
                    readings.push(Reading {
                        format,
                        length_unit: l,
                        angle_unit: a,
                        header: None,
                        header_len,
                        notes: Vec::new(),
                    });
                }
            }
            if readings.is_empty() {
                return Err(table.rows[0].error(
                    0,
                    format!("{n} values, but pose formats have 6, 7, 12 or 16 values a line"),
                ));
            }
        }
    }
    rank(table, &readings, options)
}

/// The unit pairs to try: a fixed unit alone, else the default then the other.
fn unit_choices(
    format: PoseFormat,
    length: Option<LengthUnit>,
    angle: Option<AngleUnit>,
) -> Vec<(LengthUnit, AngleUnit)> {
    let (dl, da) = format.default_units();
    let other_l = match dl {
        LengthUnit::Metre => LengthUnit::Millimetre,
        LengthUnit::Millimetre => LengthUnit::Metre,
    };
    let other_a = match da {
        AngleUnit::Radian => AngleUnit::Degree,
        AngleUnit::Degree => AngleUnit::Radian,
    };
    let ls = length.map_or(vec![dl, other_l], |l| vec![l]);
    let angs = match angle {
        Some(a) => vec![a],
        None if format.uses_angles() => vec![da, other_a],
        None => vec![da],
    };
    ls.iter()
        .flat_map(|&l| angs.iter().map(move |&a| (l, a)))
        .collect()
}

fn rank(table: &Table, readings: &[Reading], options: &PoseFileOptions) -> Result<Vec<Candidate>> {
    let mut first_error = None;
    let mut out: Vec<Candidate> = Vec::new();
    for reading in readings {
        let poses = match read_rows(&table.rows, reading, options.direction) {
            Ok(p) => p,
            Err(e) => {
                first_error.get_or_insert(e);
                continue;
            }
        };
        let (penalty, reasons) = score(table, reading, &poses);
        let candidate = Candidate {
            format: reading.format,
            length_unit: reading.length_unit,
            angle_unit: reading.angle_unit,
            poses,
            same_as: Vec::new(),
            penalty,
            reasons,
        };
        match out
            .iter_mut()
            .find(|c| same_poses(&c.poses, &candidate.poses))
        {
            // Identical poses: keep the less penalised reading as the name.
            Some(same) if same.penalty <= candidate.penalty => {
                same.same_as.push(candidate_name(&candidate))
            }
            Some(same) => {
                let mut names = std::mem::take(&mut same.same_as);
                names.push(candidate_name(same));
                *same = Candidate {
                    same_as: names,
                    ..candidate
                };
            }
            None => out.push(candidate),
        }
    }
    if out.is_empty() {
        return Err(first_error.unwrap_or_else(no_poses));
    }
    // Equal penalties: the order of PoseFormat::all() (vendor presets first).
    let all = PoseFormat::all();
    let order = |f: PoseFormat| all.iter().position(|g| *g == f).unwrap_or(all.len());
    out.sort_by(|a, b| {
        a.penalty
            .total_cmp(&b.penalty)
            .then(order(a.format).cmp(&order(b.format)))
    });
    Ok(out)
}

fn candidate_name(c: &Candidate) -> String {
    if c.format.uses_angles() {
        format!(
            "{} ({}, {})",
            c.format.name(),
            c.length_unit.name(),
            c.angle_unit.name()
        )
    } else {
        format!("{} ({})", c.format.name(), c.length_unit.name())
    }
}

fn same_poses(a: &[RobotPose], b: &[RobotPose]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| {
            let (p, q) = (&p.base_from_gripper, &q.base_from_gripper);
            (p.translation.vector - q.translation.vector).norm() < 1e-9
                && rotation_angle_between(&p.rotation, &q.rotation) < 1e-9
        })
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

/// The raw rotation numbers of every row (columns 4.. of the reading).
fn rotation_numbers(table: &Table, reading: &Reading) -> Vec<Vec<f64>> {
    table
        .rows
        .iter()
        .map(|row| {
            let idx: Vec<usize> = match &reading.header {
                Some(h) => h.value_fields[3..].to_vec(),
                None => {
                    let k = reading.format.value_count();
                    let start = row.fields.len().saturating_sub(k) + 3;
                    (start..row.fields.len()).collect()
                }
            };
            idx.iter()
                .filter_map(|&i| row.fields.get(i).and_then(|f| super::pose_table::number(f)))
                .collect()
        })
        .collect()
}

fn score(table: &Table, reading: &Reading, poses: &[RobotPose]) -> (f64, Vec<String>) {
    let mut penalty = 0.0;
    let mut reasons = Vec::new();
    let (dl, da) = reading.format.default_units();
    let reach = median(
        poses
            .iter()
            .map(|p| p.base_from_gripper.translation.vector.norm())
            .collect(),
    );
    let (lo, hi) = PLAUSIBLE_REACH_M;
    if reach > hi {
        penalty += 2.0 * (reach / hi).log10();
        reasons.push(format!(
            "median reach {} m is beyond robot workspaces",
            short(reach)
        ));
    } else if reach > 0.0 && reach < lo {
        penalty += 2.0 * (lo / reach).log10();
        reasons.push(format!(
            "median reach {} m is tiny for a robot",
            short(reach)
        ));
    }
    if reading.length_unit != dl {
        penalty += 0.1;
        reasons.push(format!(
            "{} is not the {} default length unit",
            reading.length_unit.name(),
            reading.format.label()
        ));
    }
    let numbers = rotation_numbers(table, reading);
    match reading.format.layout() {
        RotationLayout::Rotvec | RotationLayout::Euler(..) => {
            let largest = numbers.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            if reading.angle_unit == AngleUnit::Degree
                && largest > 1e-6
                && largest <= std::f64::consts::PI + 1e-6
            {
                penalty += 1.0;
                reasons.push(format!(
                    "every angle is within ±{} deg: looks like radians",
                    short(largest)
                ));
            }
            if reading.angle_unit != da {
                penalty += 0.1;
                reasons.push(format!(
                    "{} is not the {} default angle unit",
                    reading.angle_unit.name(),
                    reading.format.label()
                ));
            }
        }
        RotationLayout::QuatXyzw | RotationLayout::QuatWxyz => {
            let dev: f64 = numbers
                .iter()
                .map(|q| (q.iter().map(|v| v * v).sum::<f64>().sqrt() - 1.0).abs())
                .sum::<f64>()
                / numbers.len().max(1) as f64;
            if dev > 1e-6 {
                penalty += 100.0 * dev;
                reasons.push(format!(
                    "quaternion norms differ from 1 by {} on average",
                    short(dev)
                ));
            }
        }
        RotationLayout::Matrix => {}
    }
    (penalty, reasons)
}
