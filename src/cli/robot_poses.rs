//! The robot poses of `robocal handeye` and `robocal rig`: `--poses` names a
//! pose table, a folder of one-pose files, or several one-pose files; this
//! reads them (file I/O only) and hands names and texts to the library's
//! parsers with `--pose-format` and `--pose-units`.

use super::CliError;
use robocal::handeye::Pose;
use robocal::io::pose_pairing::natural_cmp;
use robocal::io::pose_text::{parse_pose_text, PoseTextFormat};
use robocal::io::{
    parse_pose_candidates, parse_pose_file_candidates, parse_pose_files, parse_poses,
    radians_read_as_degrees, AngleUnit, Candidate, LengthUnit, PoseFileOptions, PoseFileText,
    PoseFormat, RobotPose,
};

/// The help of `--pose-format`, listing every name (checked against
/// `PoseFormat::all()` by a test).
pub const POSE_FORMAT_HELP: &str = "The layout of the pose files (default: from the header or \
the names in the file, else from the number of values; an ambiguous file is read every \
plausible way and the reading that fits the camera motion is used, with a warning). \
Vendors: ur (x y z rx ry rz: m, rotation vector in rad), kuka (X Y Z A B C: mm, deg, intrinsic \
ZYX), abb (x y z q1 q2 q3 q4: mm, quaternion w first), fanuc (X Y Z W P R: mm, deg, extrinsic \
XYZ), yaskawa or motoman (X Y Z Rx Ry Rz: mm, deg, extrinsic XYZ), staubli (X Y Z Rx Ry Rz: \
mm, deg, intrinsic XYZ). Generic (default m, rad): xyz_quat_xyzw, xyz_quat_wxyz, xyz_rotvec, \
matrix4 (16 numbers, row-major 4x4), matrix3x4 (12 numbers, r11 r12 r13 tx r21 ... tz), \
xyz_euler_intrinsic_ORDER and xyz_euler_extrinsic_ORDER with ORDER one of xyz xzy yxz yzx zxy \
zyx xyx xzx yxy yzy zxz zyz. A header x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg is read as \
xyz_euler_extrinsic_xyz (R = Rz·Ry·Rx); x,y,z,rx,ry,rz without units as ur. Line formats (a \
table only): matrix (16 or 12 numbers), xyz-quaternion-xyzw, xyz-quaternion-wxyz. \
docs/pose-formats.md has every form";

/// The one-line help of `--pose-format` (`-h`).
pub const POSE_FORMAT_SHORT: &str = "The layout of the pose files: ur, kuka, abb, fanuc, yaskawa, \
staubli, xyz_quat_xyzw, xyz_quat_wxyz, xyz_rotvec, matrix4, matrix3x4, xyz_euler_KIND_ORDER, or \
a line format (--help lists them with their conventions)";

/// The file extensions read from a folder of pose files.
pub const POSE_FILE_EXTENSIONS: [&str; 7] = ["yaml", "yml", "json", "txt", "csv", "tsv", "dat"];

/// What `--poses` named.
pub enum PoseSource {
    /// One pose table (a pose a line, or JSON).
    Table { path: String, text: String },
    /// One pose per file: a folder's files or several files; `label` names
    /// them in messages (the folder, or the first file).
    Files {
        label: String,
        files: Vec<PoseFileText>,
    },
}

impl PoseSource {
    /// The name used for errors about the poses as a whole (pairing).
    pub fn label(&self) -> &str {
        match self {
            PoseSource::Table { path, .. } => path,
            PoseSource::Files { label, .. } => label,
        }
    }
}

/// Read `--poses`: one file (a table), one folder (its pose files, in
/// numeric order of their names), or several files (one pose each).
pub fn read_pose_source(command: &str, paths: &[String]) -> Result<PoseSource, CliError> {
    let text = |p: &str| super::read_pose_text(p);
    match paths {
        [] => Err(CliError::usage(command, "--poses FILE is required")),
        [one] if std::path::Path::new(one).is_dir() => {
            let files = folder_files(one)?
                .into_iter()
                .map(|name| {
                    Ok(PoseFileText {
                        text: text(&name)?,
                        name,
                    })
                })
                .collect::<Result<Vec<_>, CliError>>()?;
            Ok(PoseSource::Files {
                label: one.clone(),
                files,
            })
        }
        [one] => Ok(PoseSource::Table {
            path: one.clone(),
            text: text(one)?,
        }),
        many => {
            if let Some(dir) = many.iter().find(|p| std::path::Path::new(p).is_dir()) {
                return Err(CliError::usage(
                    command,
                    format!("--poses: '{dir}' is a folder: give one folder, or files"),
                ));
            }
            let files = many
                .iter()
                .map(|name| {
                    Ok(PoseFileText {
                        text: text(name)?,
                        name: name.clone(),
                    })
                })
                .collect::<Result<Vec<_>, CliError>>()?;
            Ok(PoseSource::Files {
                label: many[0].clone(),
                files,
            })
        }
    }
}

/// The pose files of a folder (not hidden, with a pose-file extension), as
/// paths, in numeric order.
fn folder_files(dir: &str) -> Result<Vec<String>, CliError> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| CliError::Io(format!("cannot read the folder '{dir}': {e}")))?;
    let mut out = Vec::new();
    for entry in entries {
        let entry =
            entry.map_err(|e| CliError::Io(format!("cannot read the folder '{dir}': {e}")))?;
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if name.starts_with('.') || !path.is_file() || !POSE_FILE_EXTENSIONS.contains(&ext.as_str())
        {
            continue;
        }
        out.push(path.to_string_lossy().into_owned());
    }
    if out.is_empty() {
        return Err(CliError::Io(format!(
            "'{dir}': no pose files in the folder (files ending .{})",
            POSE_FILE_EXTENSIONS.join(", .")
        )));
    }
    out.sort_by(|a, b| natural_cmp(a, b));
    Ok(out)
}

/// Robot poses as read: one reading, or ranked candidates of an ambiguous file.
pub(super) enum RobotPoses {
    /// The file's format is known.
    Known(Vec<RobotPose>),
    /// Several readings are plausible: (name, poses), most plausible first.
    Ambiguous(Vec<(String, Vec<RobotPose>)>),
}

impl RobotPoses {
    pub(super) fn first(&self) -> &[RobotPose] {
        match self {
            RobotPoses::Known(p) => p,
            RobotPoses::Ambiguous(c) => c.first().map_or(&[], |c| &c.1),
        }
    }
}

/// `--pose-units`: `mm`, `m`, `deg`, `rad`, or a length and an angle
/// (`mm,deg`).
fn pose_units(
    command: &str,
    units: Option<&str>,
) -> Result<(Option<LengthUnit>, Option<AngleUnit>), CliError> {
    let (mut length, mut angle) = (None, None);
    for unit in units
        .unwrap_or_default()
        .split(',')
        .map(str::trim)
        .filter(|u| !u.is_empty())
    {
        match unit.to_ascii_lowercase().as_str() {
            "mm" => length = Some(LengthUnit::Millimetre),
            "m" => length = Some(LengthUnit::Metre),
            "deg" => angle = Some(AngleUnit::Degree),
            "rad" => angle = Some(AngleUnit::Radian),
            _ => {
                return Err(CliError::usage(
                    command,
                    format!(
                        "--pose-units: unknown unit '{unit}' (valid: mm, m, deg, rad, e.g. mm,deg)"
                    ),
                ))
            }
        }
    }
    Ok((length, angle))
}

fn unknown_format(command: &str, name: &str, files: bool) -> CliError {
    let named: Vec<String> = PoseFormat::all()
        .iter()
        .filter(|f| !matches!(f, PoseFormat::XyzEuler { .. }))
        .map(|f| f.name())
        .collect();
    let lines = if files {
        ""
    } else {
        ", or the line formats matrix, xyz-quaternion-xyzw, xyz-quaternion-wxyz"
    };
    CliError::usage(
        command,
        format!(
            "--pose-format: unknown pose format '{name}' (valid: {}, \
             xyz_euler_intrinsic_ORDER or xyz_euler_extrinsic_ORDER with ORDER such as \
             zyx{lines})",
            named.join(", ")
        ),
    )
}

/// Read robot poses: `--pose-format` names a pose-file format (`ur`,
/// `xyz_quat_xyzw`, `matrix4`, ...) or, for a table, a line format of the
/// camera-pose reader (`matrix`, `xyz-quaternion-xyzw`); without it the
/// header, the names in the files or the value count decides, and an
/// ambiguous layout gives candidates. Errors name the file.
pub(super) fn read_robot_poses(
    command: &str,
    source: &PoseSource,
    format: Option<&str>,
    units: Option<&str>,
) -> Result<RobotPoses, CliError> {
    let (length_unit, angle_unit) = pose_units(command, units)?;
    let files = matches!(source, PoseSource::Files { .. });
    let mut options = PoseFileOptions {
        length_unit,
        angle_unit,
        ..Default::default()
    };
    // A reading in degrees that looks like radians is said on stderr (the
    // hand-eye checks then refuse or warn about the tiny rotations).
    let parse = |options: &PoseFileOptions| {
        let parsed = match source {
            PoseSource::Table { path, text } => {
                parse_poses(text, options).map_err(|e| CliError::from(e).in_file(path))
            }
            PoseSource::Files { files, .. } => Ok(parse_pose_files(files, options)?),
        }?;
        if let Some(w) = radians_read_as_degrees(&parsed) {
            eprintln!("warning: '{}': {w}", source.label());
        }
        Ok::<_, CliError>(parsed)
    };
    if let Some(name) = format {
        if let Some(f) = PoseFormat::from_name(name) {
            options.format = Some(f);
            return Ok(RobotPoses::Known(parse(&options)?.poses));
        }
        let (PoseSource::Table { path, text }, Ok(f)) = (source, name.parse::<PoseTextFormat>())
        else {
            return Err(unknown_format(command, name, files));
        };
        let poses = parse_pose_text(text, Some(f)).map_err(|e| CliError::from(e).in_file(path))?;
        return Ok(RobotPoses::Known(plain(poses)));
    }
    let first = match parse(&options) {
        Ok(parsed) => return Ok(RobotPoses::Known(parsed.poses)),
        Err(e) => e,
    };
    let candidates = match source {
        PoseSource::Table { text, .. } => parse_pose_candidates(text, &options),
        PoseSource::Files { files, .. } => parse_pose_file_candidates(files, &options),
    };
    match candidates {
        Ok(c) if c.len() > 1 => Ok(RobotPoses::Ambiguous(c.into_iter().map(named).collect())),
        Ok(mut c) if c.len() == 1 => Ok(RobotPoses::Known(c.remove(0).poses)),
        _ => match source {
            PoseSource::Table { text, .. } => parse_pose_text(text, None)
                .map(|p| RobotPoses::Known(plain(p)))
                .map_err(|_| first),
            PoseSource::Files { .. } => Err(first),
        },
    }
}

fn named(c: Candidate) -> (String, Vec<RobotPose>) {
    let name = format!(
        "{} ({}, {})",
        c.format.name(),
        c.length_unit.name(),
        c.angle_unit.name()
    );
    (name, c.poses)
}

fn plain(poses: Vec<Pose>) -> Vec<RobotPose> {
    poses
        .into_iter()
        .enumerate()
        .map(|(i, p)| RobotPose {
            name: None,
            line: i + 1,
            base_from_gripper: p,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_help_names_every_format() {
        for f in PoseFormat::all() {
            let name = f.name();
            let listed = match f {
                PoseFormat::XyzEuler { order, .. } => {
                    POSE_FORMAT_HELP.contains(order.name())
                        && POSE_FORMAT_HELP.contains("xyz_euler_intrinsic_ORDER")
                }
                _ => {
                    POSE_FORMAT_HELP.contains(&format!("{name} "))
                        || POSE_FORMAT_HELP.contains(&format!("{name},"))
                }
            };
            assert!(listed, "--pose-format help lacks {name}");
        }
    }

    #[test]
    fn units_parse_and_unknown_units_are_named() {
        assert_eq!(
            pose_units("handeye", Some("mm,deg")).unwrap(),
            (Some(LengthUnit::Millimetre), Some(AngleUnit::Degree))
        );
        assert_eq!(
            pose_units("handeye", Some("rad")).unwrap(),
            (None, Some(AngleUnit::Radian))
        );
        let CliError::Usage(e) = pose_units("rig", Some("mm,grad")).unwrap_err() else {
            panic!()
        };
        assert_eq!(
            e,
            "rig: --pose-units: unknown unit 'grad' (valid: mm, m, deg, rad, e.g. mm,deg) (see 'robocal rig --help')"
        );
    }
}
