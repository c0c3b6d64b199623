//! `export(report, format)`: the one entry point the CLI, node and the web
//! app share, so all three write byte-identical files.
//!
//! A report is the JSON of a camera calibration (top-level `image_size_px`,
//! `model`, `camera_matrix`, `distortion`, `rms_px`) or of a hand-eye
//! calibration (transforms such as `gripper_from_camera` in the one pose
//! shape, [`crate::geometry::PoseJson`]), or both; or a stereo or rig
//! report. The report's `kind` ([`ReportKind`]) says which; a report
//! written before `kind` existed is recognised by its keys, as then
//! (docs/report-json.md, "Migration").

use super::export_camera::{export_camera, CameraExportInfo, CameraFormat};
use super::export_laser::{export_plane_halcon, read_plane_report, HALCON_FORMAT, PLANE_FRAME};
use super::export_rig::{export_rig, is_rig_report, RigFormat};
pub use super::export_rig::{join_files, ExportFile};
use super::export_stereo::{export_stereo, is_stereo_report, not_a_stereo_format, StereoFormat};
use super::export_transform::{export_transform, FrameNames, TransformFormat};
use super::import_camera::import_camera;
use crate::calib::multi::rig_report::RigCalibration;
use crate::error::{Error, Result};
use crate::geometry::{Pose, PoseInput};
use crate::report_kind::ReportKind;
use serde::Deserialize;

/// Transforms looked for, in order, when the caller names none.
pub const DEFAULT_TRANSFORMS: [&str; 4] = [
    "gripper_from_camera",
    "base_from_camera",
    "right_from_left",
    "base_from_target",
];

/// The dense undistortion map for `cv2.remap` of any camera
/// ([`super::export_remap`]): not in [`format_names`] (the page's menus),
/// a map of a whole image is tens of megabytes.
pub const REMAP_FORMAT: &str = "remap";

/// What [`export`] can write: every camera format, `report` (the report
/// itself, pretty-printed) and every transform format.
pub fn format_names() -> Vec<String> {
    let mut names: Vec<String> = CameraFormat::ALL
        .iter()
        .map(|f| f.name().to_string())
        .collect();
    names.push("report".into());
    names.extend(TransformFormat::names().iter().map(|n| n.to_string()));
    names.push("euler-<intrinsic|extrinsic>-<order>-<deg|rad>".into());
    names
}

/// Write `report_json` in `format`; `transform` picks which transform of a
/// hand-eye report (default: the first of [`DEFAULT_TRANSFORMS`] present).
/// Frames are named as the report's `frame_names` say (see [`ExportOptions`]).
pub fn export(report_json: &str, format: &str, transform: Option<&str>) -> Result<String> {
    export_with(
        report_json,
        format,
        &ExportOptions {
            transform,
            ..ExportOptions::default()
        },
    )
}

/// Choices of [`export_with`].
#[derive(Debug, Clone, Default)]
pub struct ExportOptions<'a> {
    /// Which transform of the report (default: the first of [`DEFAULT_TRANSFORMS`] present).
    pub transform: Option<&'a str>,
    /// Names written for the frames of a transform, by role: the two parts
    /// of its key (`gripper` and `camera` of `gripper_from_camera`), e.g.
    /// `("gripper", "tool0")`. They override the report's `frame_names`
    /// object (same shape: `{"gripper": "tool0", "camera": "camera_optical_frame"}`);
    /// a role named by neither keeps its own name.
    pub frames: Vec<(String, String)>,
}

/// [`export`] with frame names. Formats of several files (a rig's `ros`
/// and `mrcal`) come as one text, see [`join_files`].
pub fn export_with(report_json: &str, format: &str, options: &ExportOptions) -> Result<String> {
    let report = parse_report(report_json)?;
    match Report::read(&report)? {
        Report::Rig if format != "report" => {
            export_rig_report(&report, format, options).map(|files| join_files(&files))
        }
        Report::Stereo if format != "report" => {
            match export_stereo_report(&report, format, options)? {
                Some(files) => Ok(join_files(&files)),
                None => export_value(report_json, &report, format, options),
            }
        }
        Report::Laser(kind) if format != "report" => {
            export_laser_report(&report, kind, format, options).map(|f| f.text)
        }
        _ => export_value(report_json, &report, format, options),
    }
}

/// What a report is for export: what its `kind` says or, without `kind`,
/// what its keys say.
enum Report {
    /// A rig report, with or without `handeye` (read as [`RigCalibration`]
    /// once the format is known to be a rig format).
    Rig,
    /// A stereo report.
    Stereo,
    /// A camera or hand-eye report (or a plain camera JSON), written from
    /// its keys.
    Other,
    /// A laser report (`laser_plane`, `laser_sphere`: its camera-frame
    /// plane as HALCON parameters or as a frame; `laser_points`: only
    /// `report`).
    Laser(ReportKind),
}

impl Report {
    fn read(report: &serde_json::Value) -> Result<Report> {
        let kind = match ReportKind::of_report(report)? {
            Some(kind) => kind,
            // Written before `kind` existed: recognised by its keys.
            None if is_rig_report(report) => ReportKind::Rig,
            None if is_stereo_report(report) => ReportKind::Stereo,
            None => ReportKind::Camera,
        };
        Ok(match kind {
            ReportKind::Rig | ReportKind::RigHandeye => Report::Rig,
            ReportKind::Stereo => Report::Stereo,
            ReportKind::Camera | ReportKind::Handeye => Report::Other,
            ReportKind::LaserPlane | ReportKind::LaserPoints | ReportKind::LaserSphere => {
                Report::Laser(kind)
            }
            ReportKind::Check | ReportKind::Diff => {
                return Err(Error::invalid(
                    "kind",
                    format!(
                        "a '{}' report compares calibrations and holds no camera to export: \
                         export the calibration itself",
                        kind.name()
                    ),
                ))
            }
        })
    }
}

/// [`export_with`] as files: several for a rig's `ros` and `mrcal`, else
/// one, named `export.<extension>` unless the format names it.
pub fn export_files(
    report_json: &str,
    format: &str,
    options: &ExportOptions,
) -> Result<Vec<ExportFile>> {
    let report = parse_report(report_json)?;
    match Report::read(&report)? {
        Report::Rig if format != "report" => return export_rig_report(&report, format, options),
        Report::Stereo if format != "report" => {
            if let Some(files) = export_stereo_report(&report, format, options)? {
                return Ok(files);
            }
        }
        Report::Laser(kind) if format != "report" => {
            return export_laser_report(&report, kind, format, options).map(|f| vec![f])
        }
        _ => {}
    }
    let text = export_value(report_json, &report, format, options)?;
    let extension = match CameraFormat::from_name(format) {
        Ok(f) => f.extension(),
        Err(_) if format == "report" => "json",
        Err(_) if format == REMAP_FORMAT => "yaml",
        Err(_) => "txt",
    };
    Ok(vec![ExportFile {
        name: format!("export.{extension}"),
        text,
    }])
}

fn parse_report(report_json: &str) -> Result<serde_json::Value> {
    serde_json::from_str(report_json).map_err(|e| {
        Error::parse(
            e.line(),
            e.column(),
            format!("the report is not valid JSON: {e}"),
        )
    })
}

fn export_rig_report(
    report: &serde_json::Value,
    format: &str,
    options: &ExportOptions,
) -> Result<Vec<ExportFile>> {
    let format = RigFormat::from_name(format)?;
    let rig = RigCalibration::deserialize(report)
        .map_err(|e| Error::invalid("report", format!("not a readable rig report: {e}")))?;
    export_rig(&rig, format, &options.frames)
}

/// A laser plane report (`kind`: `laser_plane`) as the HALCON-style
/// sheet-of-light parameter list (`halcon`) or its plane as the frame
/// `camera_from_laser_plane` in a transform format (frames `camera` and
/// `laser_plane`, renamed by `--frame` or the report's `frame_names`): the
/// same text as `robocal laser plane --format`. A `laser_points` report is
/// written only as `report`.
fn export_laser_report(
    report: &serde_json::Value,
    kind: ReportKind,
    format: &str,
    options: &ExportOptions,
) -> Result<ExportFile> {
    if kind == ReportKind::LaserPoints {
        return Err(Error::invalid(
            "kind",
            format!(
                "a '{}' report holds 3-D points: export it as 'report', or export its laser plane report",
                kind.name()
            ),
        ));
    }
    if let Some(t) = options.transform.filter(|t| *t != PLANE_FRAME) {
        return Err(Error::invalid(
            "transform",
            format!(
                "a laser plane report has one transform, {PLANE_FRAME}, not '{}'",
                shown(t)
            ),
        ));
    }
    let (plane, covariance) = read_plane_report(report)?;
    if format == HALCON_FORMAT {
        return Ok(ExportFile {
            name: "laser_plane_halcon.txt".into(),
            text: export_plane_halcon(&plane, &covariance),
        });
    }
    let transform = TransformFormat::from_name(format).map_err(|_| {
        Error::invalid(
            "format",
            format!(
                "a laser plane report is written as report, {HALCON_FORMAT} (HALCON-style sheet-of-light parameters) or a transform format of its plane frame {PLANE_FRAME} ({}), got '{}'",
                TransformFormat::names().join(", "),
                shown(format)
            ),
        )
    })?;
    let roles = FrameNames::from_transform_name(PLANE_FRAME)?;
    let names = FrameNames {
        parent: frame_name(report, &options.frames, &roles.parent)?,
        child: frame_name(report, &options.frames, &roles.child)?,
        key: roles.key,
    };
    Ok(ExportFile {
        name: "export.txt".into(),
        text: export_transform(&plane.a_from_plane(), &names, transform),
    })
}

/// A stereo report in a stereo format; `None` when `report` is not a
/// stereo report or `format` is a transform format (or `report`), which
/// write `right_from_left` as for any report. Camera formats that hold one
/// camera are refused: they would drop the other camera.
fn export_stereo_report(
    report: &serde_json::Value,
    format: &str,
    options: &ExportOptions,
) -> Result<Option<Vec<ExportFile>>> {
    match StereoFormat::from_name(format) {
        Some(f) => export_stereo(report, f, &options.frames).map(Some),
        None if CameraFormat::from_name(format).is_ok() => Err(not_a_stereo_format(format)),
        None => Ok(None),
    }
}

fn export_value(
    report_json: &str,
    report: &serde_json::Value,
    format: &str,
    options: &ExportOptions,
) -> Result<String> {
    let transform = options.transform;
    if format == "report" {
        return Ok(super::to_string_pretty(report) + "\n");
    }
    if format == REMAP_FORMAT {
        let (camera, _) = import_camera(report_json)?;
        return super::export_remap::remap_yaml(&camera);
    }
    if let Ok(camera_format) = CameraFormat::from_name(format) {
        let (camera, _) = import_camera(report_json).map_err(|e| match e {
            Error::Invalid { field, .. } if field == "image_size_px" => Error::invalid(
                "report",
                format!(
                    "format '{format}' needs a camera, and this report has none (no image_size_px)"
                ),
            ),
            other => other,
        })?;
        let name = report["name"].as_str().unwrap_or("camera");
        check_one_line("name", "camera name", name)?;
        let info = CameraExportInfo {
            name: name.to_string(),
            rms_px: report["rms_px"].as_f64(),
            ..CameraExportInfo::default()
        };
        return export_camera(&camera, &info, camera_format);
    }
    let transform_format = TransformFormat::from_name(format).map_err(|_| {
        Error::invalid(
            "format",
            format!(
                "unknown export format '{format}' (known: {})",
                format_names().join(", ")
            ),
        )
    })?;
    let name = match transform {
        Some(n) => n.to_string(),
        None => DEFAULT_TRANSFORMS
            .iter()
            .find(|n| report.get(**n).is_some())
            .map(|n| n.to_string())
            .ok_or_else(|| {
                Error::invalid(
                    "report",
                    format!(
                        "format '{format}' needs a transform, and this report has none of {}",
                        DEFAULT_TRANSFORMS.join(", ")
                    ),
                )
            })?,
    };
    let pose = pose_from_report(report, &name)?;
    let roles = FrameNames::from_transform_name(&name)?;
    // The key is written as the label of every format (comments, XML) and
    // its parts are the default frame names.
    for part in [&roles.parent, &roles.child] {
        if !is_ros_frame_name(part) {
            return Err(Error::invalid(
                "transform",
                format!(
                    "'{}' cannot be exported: the frames of a transform name are ROS frame names (letters, digits, _ and /, starting with a letter, _ or /), as in gripper_from_camera; '{}' is not one",
                    shown(&name),
                    shown(part)
                ),
            ));
        }
    }
    let names = FrameNames {
        parent: frame_name(report, &options.frames, &roles.parent)?,
        child: frame_name(report, &options.frames, &roles.child)?,
        key: name.clone(),
    };
    Ok(export_transform(&pose, &names, transform_format))
}

/// The name written for the frame of `role`: from `frames`, else the
/// report's `frame_names`, else the role itself. Names go into XML, shell
/// and Python text, so they are held to what ROS and URDF accept.
fn frame_name(
    report: &serde_json::Value,
    frames: &[(String, String)],
    role: &str,
) -> Result<String> {
    let given = match frames.iter().rev().find(|(r, _)| r == role) {
        Some((_, name)) => Some(name.clone()),
        None => match report.get("frame_names").and_then(|m| m.get(role)) {
            None | Some(serde_json::Value::Null) => None,
            Some(serde_json::Value::String(name)) => Some(name.clone()),
            Some(other) => {
                return Err(Error::invalid(
                    "frame_names",
                    format!("'{role}' should name a frame as a string, got {other}"),
                ))
            }
        },
    };
    let Some(name) = given else {
        return Ok(role.to_string());
    };
    if !is_ros_frame_name(&name) {
        return Err(Error::invalid(
            "frame_names",
            format!("the {role} frame name '{}' is not a ROS frame name: use letters, digits, _ and / (starting with a letter, _ or /), e.g. tool0", shown(&name)),
        ));
    }
    Ok(name)
}

/// Whether `name` is a frame name ROS and URDF accept (letters, digits,
/// `_` and `/`, starting with a letter, `_` or `/`): names go into XML,
/// shell and Python text unquoted.
pub(crate) fn is_ros_frame_name(name: &str) -> bool {
    name.chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_' || c == '/')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '/')
}

/// A name written into an export as text (a camera's, a rig frame's) must
/// be one line of printable text: a newline would start a new key or
/// element in the file. `field` and `what` name it in the error.
pub(crate) fn check_one_line(field: &str, what: &str, name: &str) -> Result<()> {
    match name.chars().find(|c| c.is_control()) {
        None => Ok(()),
        Some(c) => Err(Error::invalid(
            field,
            format!(
                "the {what} '{}' holds a control character ({}): a name is one line of printable text",
                shown(name),
                c.escape_default()
            ),
        )),
    }
}

/// `name` for an error message: as it is, its control characters escaped
/// (`\n`), so the message stays one line.
fn shown(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// `text` as a YAML scalar that reads back as the same string: as it is
/// when it is a plain name (letters, digits, `_`, `-`, `.`, `/`, not a
/// number, boolean or null), else double-quoted with JSON's escapes (a
/// JSON string is a YAML double-quoted scalar).
pub(crate) fn yaml_scalar(text: &str) -> String {
    let plain = text
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_' || c == '/')
        && text
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.' | '/'))
        && !matches!(
            text.to_ascii_lowercase().as_str(),
            "true" | "false" | "yes" | "no" | "on" | "off" | "y" | "n" | "null" | "nan" | "inf"
        );
    if plain {
        text.to_string()
    } else {
        serde_json::Value::String(text.to_string()).to_string()
    }
}

/// Read the transform `name` from a report: any [`PoseInput`] (the matrix
/// as 4 rows of 4 or 16 numbers, translation and quaternion, or all three).
pub fn pose_from_report(report: &serde_json::Value, name: &str) -> Result<Pose> {
    let entry = report
        .get(name)
        .ok_or_else(|| Error::invalid("transform", format!("the report has no '{name}'")))?;
    let located = |message: String| Error::invalid(name, message);
    PoseInput::deserialize(entry)
        .map_err(|e| located(e.to_string()))?
        .to_pose()
        .map_err(|e| located(e.to_string()))
}
