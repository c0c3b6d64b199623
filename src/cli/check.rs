//! `robocal check` (has the camera changed since its calibration?) and
//! `robocal diff` (the projection difference of two calibrations): files
//! in, a request to `robocal::api::check`, JSON out.

use super::detect::{run_all, Outcome};
use super::{read_text, write_output, CliError};
use robocal::api::camera::JsonView;
use robocal::api::check::{check_request, diff_request, CheckRequest, DiffRequest};
use robocal::calib::check::CheckThresholds;
use robocal::calib::projection_diff::{DiffOptions, DEFAULT_GRID};

#[derive(clap::Args)]
#[command(
    about = "check a saved calibration against new images: ok, drifted or broken",
    long_about = "check a saved calibration against new images of the same target

Poses every image with the saved camera (the reprojection RMS), refits fx,
fy, cx, cy with the lens model held, and compares the two models' projection
over the image (implied rotation compensated, as mrcal's projection diff).
The verdict, with thresholds from the saved calibration's own uncertainty
(docs/check.md):
  broken   no image could be posed, or the saved model reprojects the new
           images with an RMS above --broken-rms-px (default max(10 x the
           saved RMS, 3 px))
  drifted  the worst projection shift exceeds --shift-px (default max(3 x
           the projection std, 1 px)), or fx, fy, cx or cy moved more than
           max(3 x its std, 0.5 px), or (with --pose) the camera moved more
           than 2 mm or 0.2 deg against the fixed target
  ok       otherwise
The exit code is 0 for every verdict: the verdict is data.

--camera reads any camera file robocal reads back: a robocal report or
camera JSON (with its std and projection uncertainty, which set the
thresholds), OpenCV YAML/XML, ROS camera_info, Kalibr, mrcal, HALCON (.dat
or tuple), MATLAB, the text matrix (thresholds then from the refit's
uncertainty and the floors only).",
    after_help = "Examples:
  robocal check --camera camera.json --target chessboard:9x6:30mm new/*.png
  robocal check --camera camera.yaml --target chessboard:9x6:30mm new/*.png -o check.json
  robocal check --camera camera.json --target chessboard:9x6:30mm --param-sigma 5 new/*.png",
    args_override_self = true
)]
pub struct CheckArgs {
    /// The saved calibration: any camera format robocal exports (robocal JSON,
    /// OpenCV YAML/XML, ROS camera_info, Kalibr, mrcal, HALCON, MATLAB, text)
    #[arg(long, value_name = "FILE")]
    camera: String,
    /// The target, as for 'robocal detect' (chessboard:9x6:30mm, ...)
    #[arg(long, value_name = "SPEC")]
    target: String,
    /// A JSON file with the pose where the fixed camera saw the fixed target
    /// at calibration time ({"camera_from_target": {...}} or the pose itself)
    #[arg(long, value_name = "FILE")]
    pose: Option<String>,
    /// Drifted above this projection shift, px (instead of the rule)
    #[arg(long, value_name = "PX")]
    shift_px: Option<f64>,
    /// The projection-shift rule: this many projection std (default 3)
    #[arg(long, value_name = "K")]
    shift_sigma: Option<f64>,
    /// The projection-shift rule: at least this, px (default 1)
    #[arg(long, value_name = "PX")]
    shift_floor_px: Option<f64>,
    /// A parameter moved beyond this many of its std (default 3)
    #[arg(long, value_name = "K")]
    param_sigma: Option<f64>,
    /// ... and at least this, px (default 0.5)
    #[arg(long, value_name = "PX")]
    param_floor_px: Option<f64>,
    /// Broken above this reprojection RMS of the saved model, px
    #[arg(long, value_name = "PX")]
    broken_rms_px: Option<f64>,
    /// With --pose: moved beyond this translation, mm (default 2)
    #[arg(long, value_name = "MM")]
    pose_mm: Option<f64>,
    /// With --pose: moved beyond this rotation, degrees (default 0.2)
    #[arg(long, value_name = "DEG")]
    pose_deg: Option<f64>,
    #[command(flatten)]
    limits: super::ImageLimits,
    /// Images detected in parallel (default: all cores)
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Write the report to FILE instead of standard output
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<String>,
    /// The new images
    #[arg(value_name = "IMAGES", required = true)]
    images: Vec<String>,
}

pub fn run(args: CheckArgs) -> Result<(), CliError> {
    super::check_optional_bounds("check", "--threads", args.threads, super::bounds::THREADS)?;
    let target = super::parse_target("check", &args.target)?;
    let calibration = read_text(&args.camera)?;
    for file in &args.images {
        std::fs::metadata(file).map_err(|e| CliError::Io(format!("cannot read '{file}': {e}")))?;
    }
    let camera_from_target = match &args.pose {
        Some(file) => Some(read_pose(file)?),
        None => None,
    };
    let outcomes = run_all(
        &args.images,
        &target,
        &super::detect_options_of(Some(&args.target)),
        &args.limits.decode_options(),
        args.threads,
    )?;
    let mut views = Vec::new();
    for (file, outcome) in args.images.iter().zip(outcomes) {
        match outcome {
            Outcome::Found(detection, _) => views.push(JsonView {
                name: file.clone(),
                detection: Some(detection),
                object_m: None,
                image_px: None,
            }),
            Outcome::Failed(_, message) => {
                eprintln!("robocal check: {file}: {message}; skipped")
            }
        }
    }
    let defaults = CheckThresholds::default();
    let request = CheckRequest {
        calibration,
        views,
        thresholds: CheckThresholds {
            shift_sigma: args.shift_sigma.unwrap_or(defaults.shift_sigma),
            shift_floor_px: args.shift_floor_px.unwrap_or(defaults.shift_floor_px),
            shift_px: args.shift_px,
            param_sigma: args.param_sigma.unwrap_or(defaults.param_sigma),
            param_floor_px: args.param_floor_px.unwrap_or(defaults.param_floor_px),
            broken_rms_px: args.broken_rms_px,
            pose_mm: args.pose_mm.unwrap_or(defaults.pose_mm),
            pose_deg: args.pose_deg.unwrap_or(defaults.pose_deg),
        },
        camera_from_target,
    };
    let report = check_request(&request).map_err(|e| match e {
        robocal::Error::Invalid { field, message } if field == "calibration" => {
            CliError::Io(format!("'{}': {message}", args.camera))
        }
        e => CliError::Robocal(e),
    })?;
    let worst = report
        .projection_shift_px
        .as_ref()
        .map_or("-".to_string(), |d| format!("{:.2} px", d.worst));
    eprintln!(
        "robocal check: {} ({} of {} images posed, projection shift worst {worst}{})",
        serde_json::to_value(report.verdict)
            .ok()
            .and_then(|v| v.as_str().map(str::to_uppercase))
            .unwrap_or_default(),
        report.views.iter().filter(|v| v.error.is_none()).count(),
        args.images.len(),
        if report.moved.is_empty() {
            String::new()
        } else {
            format!(", moved: {}", report.moved.join(" "))
        }
    );
    for reason in &report.reasons {
        eprintln!("robocal check: {reason}");
    }
    for warning in &report.warnings {
        eprintln!("robocal check: warning: {warning}");
    }
    write_json(args.output.as_deref(), &report)
}

/// A pose file: `{"camera_from_target": POSE}` or the pose itself.
fn read_pose(file: &str) -> Result<robocal::geometry::PoseInput, CliError> {
    let text = read_text(file)?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| CliError::Io(format!("'{file}': invalid JSON: {e}")))?;
    let pose = value.get("camera_from_target").unwrap_or(&value);
    let input: robocal::geometry::PoseInput =
        serde_json::from_value(pose.clone()).map_err(|e| CliError::Io(format!("'{file}': {e}")))?;
    input
        .to_pose()
        .map_err(|e| CliError::Io(format!("'{file}': {e}")))?;
    Ok(input)
}

#[derive(clap::Args)]
#[command(
    about = "the projection difference of two calibrations of one camera",
    long_about = "the projection difference of two calibrations of one camera

A grid of pixels over the image is unprojected with A, the rotation that best
maps A's rays onto B's is fitted (the implied rotation: a shift a rotation
explains is no difference), and the rotated rays are projected through B: the
shift of every grid point, px, with its worst, median and RMS (mrcal's
projection diff). A and B are any camera files robocal reads back. Used as
cross-validation: calibrate two halves of a data set and diff them.",
    after_help = "Examples:
  robocal diff monday.json friday.json
  robocal diff half1.json half2.json --grid 30x20 -o diff.json",
    args_override_self = true
)]
pub struct DiffArgs {
    /// The first calibration
    #[arg(value_name = "A")]
    a: String,
    /// The second calibration
    #[arg(value_name = "B")]
    b: String,
    /// Grid columns x rows (default 60x40)
    #[arg(long, value_name = "COLSxROWS")]
    grid: Option<String>,
    /// Fit the implied rotation only within this distance of the image
    /// centre, px (default: the whole image)
    #[arg(long, value_name = "PX")]
    focus_radius_px: Option<f64>,
    /// Write the report to FILE instead of standard output
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<String>,
}

pub fn run_diff(args: DiffArgs) -> Result<(), CliError> {
    let grid = match &args.grid {
        Some(text) => parse_grid(text)?,
        None => DEFAULT_GRID,
    };
    // Each file read as a camera first, so that its errors name it.
    let read = |path: &str| -> Result<String, CliError> {
        let text = read_text(path)?;
        robocal::io::import_camera::import_camera(&text)
            .map_err(|e| CliError::Io(format!("'{path}': {e}")))?;
        Ok(text)
    };
    let request = DiffRequest {
        a: read(&args.a)?,
        b: read(&args.b)?,
        options: DiffOptions {
            grid,
            focus_radius_px: args.focus_radius_px,
            ..DiffOptions::default()
        },
    };
    let report = diff_request(&request)?;
    let d = &report.projection_shift_px;
    eprintln!(
        "robocal diff: projection shift worst {:.3} px at ({:.0}, {:.0}), median {:.3} px, rms {:.3} px, implied rotation {:.4} deg",
        d.worst, d.worst_at_px[0], d.worst_at_px[1], d.median, d.rms, d.implied_rotation_deg
    );
    write_json(args.output.as_deref(), &report)
}

fn parse_grid(text: &str) -> Result<[usize; 2], CliError> {
    let bad = || {
        CliError::usage(
            "diff",
            format!("--grid '{text}': give columns x rows, e.g. 60x40"),
        )
    };
    super::values::by_pair(text, true).ok_or_else(bad)
}

fn write_json<T: serde::Serialize>(path: Option<&str>, value: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| CliError::Io(format!("cannot serialise the report: {e}")))?;
    write_output(path, &(text + "\n"))
}
