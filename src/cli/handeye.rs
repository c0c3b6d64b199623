//! `robocal handeye`: read the pose files, call the library, write the report.

use super::args::{Args, Spec};
use super::{read_file, CliError};
use robocal::handeye::output::HandEyeReport;
use robocal::handeye::pose_text::{parse_pose_text, PoseTextFormat};
use robocal::handeye::{calibrate, HandEyeInput, HandEyeMethod, HandEyeOptions, Setup};

/// Help text.
pub const HELP: &str = "robocal handeye - hand-eye calibration (camera on or beside a robot)

Usage:
  robocal handeye --setup eye-in-hand|eye-to-hand --poses FILE [--pose-format NAME]
                  --camera-poses FILE [--camera-pose-format NAME]
                  [--method all|NAME] [--bootstrap N] [--seed N] [--lenient] -o handeye.json

  --poses FILE          robot poses base_from_gripper, one per view (metres)
  --pose-format NAME    matrix (16 or 12 numbers a line, row-major; default),
                        xyz-quaternion-xyzw, xyz-quaternion-wxyz
  --camera-poses FILE   camera_from_target per view, same line formats, paired by order
  --method NAME         all (default) or one of: tsai-lenz, park-martin, horaud, andreff,
                        daniilidis, chou-kamel, shah, li
  --bootstrap N         bootstrap resamples for repeatability (default 100, 0 = off)
  --lenient             report suspected input mistakes (units, inverted or shifted poses)
                        as warnings instead of failing
  -o FILE               write the JSON report there (default: standard output)

The image path (--camera camera.json IMAGES... --target SPEC) needs target detection
and a camera model; until those are wired, give the camera poses directly.

Output JSON: gripper_from_camera or base_from_camera, base_from_target or
gripper_from_target (each {matrix_row_major, translation_m, quaternion_xyzw}),
methods, errors {translation_rms_mm, translation_max_mm, rotation_rms_deg,
rotation_max_deg, reprojection_rms_px}, per_view, motion, repeatability, warnings.";

fn pose_format(args: &Args, flag: &str) -> Result<Option<PoseTextFormat>, CliError> {
    args.value(flag)
        .map(|v| v.parse::<PoseTextFormat>().map_err(CliError::from))
        .transpose()
}

fn read_text(path: &str) -> Result<String, CliError> {
    String::from_utf8(read_file(path)?)
        .map_err(|_| CliError::Io(format!("'{path}' is not UTF-8 text")))
}

/// Run `robocal handeye`.
pub fn run(raw: &[String]) -> Result<(), CliError> {
    let spec = Spec {
        command: "handeye",
        valued: &[
            "setup",
            "poses",
            "pose-format",
            "camera-poses",
            "camera-pose-format",
            "method",
            "bootstrap",
            "seed",
            "camera",
            "target",
            "output",
        ],
        switches: &["lenient"],
    };
    let args = Args::parse(raw, &spec)?;
    let setup: Setup = args
        .value("setup")
        .ok_or_else(|| CliError::usage("handeye", "--setup eye-in-hand|eye-to-hand is required"))?
        .parse()?;
    let poses_path = args
        .value("poses")
        .ok_or_else(|| CliError::usage("handeye", "--poses FILE is required"))?;
    let Some(camera_path) = args.value("camera-poses") else {
        return Err(CliError::usage(
            "handeye",
            "give --camera-poses FILE (the image path --camera/--target is not available yet)",
        ));
    };
    let base_from_gripper =
        parse_pose_text(&read_text(poses_path)?, pose_format(&args, "pose-format")?)?;
    let camera_from_target = parse_pose_text(
        &read_text(camera_path)?,
        pose_format(&args, "camera-pose-format")?,
    )?;
    let mut options = HandEyeOptions {
        strict_checks: !args.switch("lenient"),
        bootstrap_samples: args.parsed("handeye", "bootstrap", 100usize)?,
        seed: args.parsed("handeye", "seed", 1u64)?,
        ..Default::default()
    };
    match args.value("method") {
        None | Some("all") => {}
        Some(name) => options.methods = vec![name.parse::<HandEyeMethod>()?],
    }
    let input = HandEyeInput {
        setup,
        base_from_gripper,
        camera_from_target,
    };
    let result = calibrate(&input, &options)?;
    let json = serde_json::to_string_pretty(&HandEyeReport::new(&result))
        .map_err(|e| CliError::Io(format!("cannot serialise the report: {e}")))?;
    match args.value("output") {
        Some(path) => std::fs::write(path, json + "\n")
            .map_err(|e| CliError::Io(format!("cannot write '{path}': {e}")))?,
        None => println!("{json}"),
    }
    for w in &result.warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}
