//! `robocal handeye`: read the pose files, call the library, write the report.

use super::detections_file::read_detections;
use super::handeye_images::{
    detect_images, image_pairs, pair_images, PairBy, PosePairs, RobotPoses,
};
use super::robot_poses::{read_pose_source, read_robot_poses};
use super::{parse_target, CliError};
use robocal::api::handeye::{camera_from_json, ImagePoints, DEFAULT_PIXEL_SIGMA_PX};
use robocal::api::handeye_field::{solve_handeye_field, FieldRequest};
use robocal::handeye::quality::intrinsics_move::std_from_json;
use robocal::handeye::refine::over_pixels::RefineMode;
use robocal::handeye::{HandEyeInput, HandEyeMethod, HandEyeOptions, Setup};
use robocal::io::pose_text::{parse_pose_text, PoseTextFormat};

#[derive(clap::Args)]
#[command(
    about = "hand-eye calibration from robot poses and camera poses",
    long_about = "hand-eye calibration (camera on or beside a robot)

  robocal handeye --setup eye-in-hand|eye-to-hand --poses FILE|FOLDER|FILES... [--pose-format NAME]
                  --camera camera.json --target SPEC IMAGES... [--refine MODE] [--threads N]
                  [--method all|NAME] [--bootstrap N] [--seed N] [--lenient] -o handeye.json
  robocal handeye --setup ... --poses FILE --camera camera.json --detections detections.json [...]
  robocal handeye --setup ... --poses FILE [--pose-format NAME]
                  --camera-poses FILE [--camera-pose-format NAME] [--no-refine] [...] -o handeye.json",
    after_help = "Output JSON: gripper_from_camera or base_from_camera, base_from_target or
gripper_from_target (each {matrix_row_major, translation_m, quaternion_xyzw}),
methods, errors {translation_rms_mm, translation_max_mm, rotation_rms_deg,
rotation_max_deg, reprojection_rms_px}, per_view, motion, repeatability, warnings,
and with images: pairs [{pose_index, image, used, view, reason, pose_fit_rms_px}] and
refinement. With refinement the main transform is the refined one (method
'refined from <closed form>'); methods still lists every closed form.
With --camera-poses the closed forms are refined by maximum likelihood over
the poses (robot and camera pose noise estimated from the data; --no-refine
keeps the closed form): pose_refinement {started_from, cost, noise,
camera_transform_std, target_transform_std, covariance, outlier_views} and a
pose_cost per method. With images (default --refine none) the same refinement
runs on the PnP poses with each view's PnP covariance (camera_noise_model
per_view) and errors.reprojection_rms_px is that of the refined transforms
(each view's points through x^-1 * robot_i^-1 * y; also pose_refinement
{reprojection_rms_px, per_view_reprojection_rms_px,
closed_form_reprojection_rms_px}); --refine trusted|stochastic|joint_intrinsics
refines over the pixels.
A detection may hold any subset of the board's points (a marker board partly out
of view): each view's pose is fitted to its own points, and a view whose points
cannot fix a pose (fewer than 4, or all but one on a line) is dropped with its
robot pose (pairs says why).

A camera rig on a robot (gripper_from_rig or base_from_rig from all cameras'
views together): robocal rig ... --setup SETUP --poses FILE (docs/rig.md).

Examples:
  robocal handeye --setup eye-in-hand --poses robot.csv --camera camera.json \\
                  --target chessboard:9x6:30mm view*.png -o handeye.json
  robocal handeye --setup eye-in-hand --poses robot.csv --camera-poses cam.txt -o handeye.json
  robocal handeye --setup eye-in-hand --poses poses/ --camera camera.json \\
                  --target chessboard:9x6:30mm images/*.png -o handeye.json   # one pose file per image
  robocal export handeye.json --format urdf",
    args_override_self = true
)]
pub struct HandeyeArgs {
    /// eye-in-hand (camera on the gripper) or eye-to-hand (camera beside the robot)
    #[arg(long, value_name = "SETUP")]
    setup: Option<String>,
    /// Robot poses base_from_gripper, one per view: a pose table
    /// (CSV/TSV/text/JSON with a header such as x,y,z,rx,ry,rz; 16 numbers a
    /// line = row-major 4x4 in metres; an 'image' column pairs poses with
    /// images by file name, otherwise poses and images pair by order), or a
    /// folder or several files of one pose each (YAML such as ROS
    /// position/orientation, JSON, text; a 4x4 or 3x4 matrix or x y z and a
    /// quaternion), each paired with the image of the same file stem. Several
    /// files take the values up to the next option: put IMAGES after another
    /// option or after --
    #[arg(long, value_name = "FILE|FOLDER", num_args = 1.., action = clap::ArgAction::Set)]
    poses: Vec<String>,
    #[arg(long, value_name = "NAME", help = super::robot_poses::POSE_FORMAT_SHORT, long_help = super::robot_poses::POSE_FORMAT_HELP)]
    pose_format: Option<String>,
    /// Units of the pose files, overriding the header and the format's
    /// defaults: mm or m, deg or rad, or both (mm,deg)
    #[arg(long, value_name = "UNITS")]
    pose_units: Option<String>,
    /// The camera: any camera format robocal exports (robocal camera JSON or
    /// calibration report, OpenCV YAML/XML, ROS camera_info, Kalibr, mrcal,
    /// HALCON, MATLAB, text)
    #[arg(long, value_name = "FILE")]
    camera: Option<String>,
    /// The board, e.g. chessboard:9x6:30mm
    #[arg(long, value_name = "SPEC")]
    target: Option<String>,
    /// Detections instead of images: a 'robocal detect' output, its file
    /// names paired with the poses as images are (a detection may hold any
    /// subset of the board's points)
    #[arg(long, value_name = "FILE")]
    detections: Option<String>,
    /// none (default: with images the maximum-likelihood pose refinement,
    /// each view's PnP covariance, robot noise estimated), trusted
    /// (reprojection error, robot poses exact), stochastic (robot pose noise
    /// estimated) or joint_intrinsics (camera refined too)
    #[arg(long, value_name = "MODE")]
    refine: Option<String>,
    /// Images detected in parallel (default: all cores)
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    #[command(flatten)]
    limits: super::ImageLimits,
    /// camera_from_target per view instead of images (line formats of
    /// --pose-format), paired by order
    #[arg(long, value_name = "FILE")]
    camera_poses: Option<String>,
    /// The line format of --camera-poses (matrix, xyz-quaternion-xyzw,
    /// xyz-quaternion-wxyz)
    #[arg(long, value_name = "NAME")]
    camera_pose_format: Option<String>,
    /// all (default) or one of: tsai-lenz, park-martin, horaud, andreff,
    /// daniilidis, chou-kamel, shah, li
    #[arg(long, value_name = "NAME")]
    method: Option<String>,
    /// Bootstrap resamples for repeatability (0 = off)
    #[arg(long, value_name = "N", default_value_t = 100)]
    bootstrap: usize,
    /// Seed of the bootstrap resampling
    #[arg(long, value_name = "N", default_value_t = 1)]
    seed: u64,
    /// Report the closed form chosen by the fixed rule instead of the
    /// maximum-likelihood pose refinement (on by default with pose input and
    /// with images under --refine none, the default)
    #[arg(long)]
    no_refine: bool,
    /// Report suspected input mistakes (units, inverted or shifted poses) as
    /// warnings instead of failing
    #[arg(long)]
    lenient: bool,
    /// How poses pair with images: auto (default: by the pose file's image
    /// column when it has one, matched by path, path suffix, file name or
    /// stem; else pose i with the i-th image in numeric order of the file
    /// names), numeric, lexicographic or given (the order of IMAGES). The
    /// pairing is then checked against the camera motion: a pairing that
    /// another of these rules explains better is an error naming the rule
    #[arg(long, value_name = "RULE", default_value = "auto")]
    pair_by: String,
    /// The tool centre point in the flange frame, X,Y,Z with a unit (mm, cm
    /// or m), e.g. 0,0,150mm: the report's tcp_error gives the hand-eye
    /// error there (docs/handeye-field.md)
    #[arg(long, value_name = "X,Y,Z")]
    tcp: Option<String>,
    /// Hold the last N pose pairs out of the solve and report how well the
    /// calibration predicts the target in them (the report's holdout)
    #[arg(long, value_name = "N", default_value_t = 0)]
    holdout: usize,
    /// Touch test: a JSON list of points touched with the tool centre point,
    /// [{"base_m": [x, y, z], "image_px": [u, v], "view": i}] (needs --camera)
    #[arg(long, value_name = "FILE")]
    touch: Option<String>,
    /// Write the JSON report there (default: standard output)
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<String>,
    /// One image per pose; images whose detection fails are dropped with their
    /// pose (the report's 'pairs' lists every pair and why)
    #[arg(value_name = "IMAGES")]
    images: Vec<String>,
}

fn pose_format(value: Option<&str>) -> Result<Option<PoseTextFormat>, CliError> {
    value
        .map(|v| v.parse::<PoseTextFormat>().map_err(CliError::from))
        .transpose()
}

fn read_text(path: &str) -> Result<String, CliError> {
    super::read_pose_text(path)
}

/// Run `robocal handeye`.
pub fn run(args: HandeyeArgs) -> Result<(), CliError> {
    super::check_optional_bounds("handeye", "--threads", args.threads, super::bounds::THREADS)?;
    super::check_bounds(
        "handeye",
        "--bootstrap",
        args.bootstrap,
        super::bounds::BOOTSTRAP,
    )?;
    let setup: Setup = args
        .setup
        .as_deref()
        .ok_or_else(|| CliError::usage("handeye", "--setup eye-in-hand|eye-to-hand is required"))?
        .parse()?;
    if args.poses.is_empty() {
        return Err(CliError::usage("handeye", "--poses FILE is required"));
    }
    let mut options = HandEyeOptions {
        strict_checks: !args.lenient,
        bootstrap_samples: args.bootstrap,
        seed: args.seed,
        refine_poses: !args.no_refine,
        ..Default::default()
    };
    match args.method.as_deref() {
        None | Some("all") => {}
        Some(name) => options.methods = vec![name.parse::<HandEyeMethod>()?],
    }
    // Every pose file is read before any image (and checked just below).
    let poses_source = read_pose_source("handeye", &args.poses)?;
    let poses_path = poses_source.label().to_string();
    let read_poses = || {
        read_robot_poses(
            "handeye",
            &poses_source,
            args.pose_format.as_deref(),
            args.pose_units.as_deref(),
        )
    };
    let mut pairs = Vec::new();
    let mut pre_warnings = Vec::new();
    // The camera calibration's standard deviations, when --camera is a report.
    let mut camera_std = None;
    let (input, images) = match (args.camera_poses.as_deref(), args.camera.as_deref()) {
        (Some(camera_path), None) => {
            if !args.images.is_empty() || args.detections.is_some() {
                return Err(CliError::usage(
                    "handeye",
                    "images need --camera and --target, not --camera-poses",
                ));
            }
            let robot = match read_poses()? {
                RobotPoses::Known(p) => p,
                RobotPoses::Ambiguous(_) => {
                    return Err(CliError::usage(
                        "handeye",
                        "the pose file's format is ambiguous: pass --pose-format NAME",
                    ))
                }
            };
            let camera_from_target = parse_pose_text(
                &read_text(camera_path)?,
                pose_format(args.camera_pose_format.as_deref())?,
            )
            .map_err(|e| CliError::from(e).in_file(camera_path))?;
            let input = HandEyeInput {
                setup,
                base_from_gripper: robot.iter().map(|p| p.base_from_gripper).collect(),
                camera_from_target,
            };
            (input, None)
        }
        (None, Some(camera_path)) => {
            let camera_text = read_text(camera_path)?;
            let value = serde_json::from_str(&camera_text)
                .unwrap_or(serde_json::Value::String(camera_text));
            let camera = camera_from_json(&value)?;
            camera_std = std_from_json(&value);
            let target = args
                .target
                .as_deref()
                .map(|t| parse_target("handeye", t))
                .transpose()?;
            let pair_by: PairBy = args.pair_by.parse()?;
            // The pose file is read and paired with the image names before
            // any image is detected: its mistakes come first.
            let robot = read_poses()?;
            let pair = |images: &[String]| -> Result<PosePairs, CliError> {
                let (image_of_pose, how, unnamed_images) =
                    pair_images(robot.first(), images, pair_by)
                        .map_err(|e| e.in_file(&poses_path))?;
                Ok(PosePairs {
                    image_of_pose,
                    how,
                    unnamed_images,
                })
            };
            let (images, outcomes, pairing) = match (&args.detections, &target) {
                (Some(_), _) if !args.images.is_empty() => {
                    return Err(CliError::usage(
                        "handeye",
                        "give either IMAGES or --detections FILE, not both",
                    ))
                }
                (Some(file), _) => {
                    let (images, outcomes) = read_detections("handeye", file, target.as_ref())?;
                    let pairing = pair(&images)?;
                    (images, outcomes, pairing)
                }
                (None, None) => {
                    return Err(CliError::usage(
                        "handeye",
                        "--target SPEC is required with images, e.g. chessboard:9x6:30mm",
                    ))
                }
                (None, Some(_)) if args.images.is_empty() => {
                    return Err(CliError::usage(
                        "handeye",
                        "give the images after the options",
                    ))
                }
                (None, Some(t)) => {
                    let pairing = pair(&args.images)?;
                    let outcomes = detect_images(
                        &args.images,
                        t,
                        &super::detect_options_of(args.target.as_deref()),
                        &args.limits,
                        args.threads,
                    )?;
                    (args.images.clone(), outcomes, pairing)
                }
            };
            let found = image_pairs(
                setup,
                robot,
                &images,
                outcomes,
                &camera,
                &pairing,
                !args.lenient,
            )?;
            pairs = found.pairs;
            pre_warnings = found.warnings;
            let input = HandEyeInput {
                setup,
                base_from_gripper: found.base_from_gripper,
                camera_from_target: found.camera_from_target,
            };
            // The refinement over image points (--refine) replaces the pose one.
            options.refine_poses = false;
            (input, Some((found.views, camera)))
        }
        (Some(_), Some(_)) => {
            return Err(CliError::usage(
                "handeye",
                "give either --camera with images or --camera-poses, not both",
            ))
        }
        (None, None) => {
            return Err(CliError::usage(
                "handeye",
                "give --camera camera.json --target SPEC IMAGES..., or --camera-poses FILE",
            ))
        }
    };
    // Default: no refinement over pixels; with images the pose refinement
    // below (each view's PnP covariance, robot noise estimated) is the
    // estimate that measured best (BENCHMARKS.md, ChArUco hand-eye).
    let mode = match args.refine.as_deref() {
        Some(name) => name.parse::<RefineMode>()?,
        None => RefineMode::None,
    };
    if images.is_none() && mode != RefineMode::None {
        return Err(CliError::usage(
            "handeye",
            "--refine needs images (--camera, --target, IMAGES)",
        ));
    }
    let points = images.as_ref().map(|(views, camera)| ImagePoints {
        views,
        camera,
        camera_std: camera_std.as_ref(),
        refine: mode,
        pixel_sigma_px: DEFAULT_PIXEL_SIGMA_PX,
        refine_poses: !args.no_refine,
    });
    let touch = match args.touch.as_deref() {
        Some(path) => serde_json::from_str(&read_text(path)?).map_err(|e| {
            CliError::from(robocal::Error::parse(e.line(), e.column(), e.to_string())).in_file(path)
        })?,
        None => Vec::new(),
    };
    let field = FieldRequest {
        tcp_m: args.tcp.as_deref().map(parse_tcp).transpose()?,
        holdout: args.holdout,
        touch,
        camera: images.as_ref().map(|(_, c)| c.clone()),
    };
    let mut report = solve_handeye_field(&input, &options, points.as_ref(), pre_warnings, &field)
        .map_err(|e| with_dropped(e, &pairs))?;
    report.pairs = pairs;
    let json = serde_json::to_string_pretty(&report)
        .map_err(|e| CliError::Io(format!("cannot serialise the report: {e}")))?;
    super::write_output(args.output.as_deref(), &(json + "\n"))?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    for line in field_summary(&report) {
        eprintln!("{line}");
    }
    Ok(())
}

/// `--tcp X,Y,Z` with a unit (mm, cm or m) on the last number, in metres.
fn parse_tcp(text: &str) -> Result<[f64; 3], CliError> {
    let flag = super::values::LengthsFlag {
        command: "handeye",
        flag: "--tcp",
        count: 3,
        expected: "expected three numbers X,Y,Z",
        unit_example: " (e.g. 0,0,150mm)",
    };
    let v = super::values::lengths_m(&flag, text)?;
    Ok([v[0], v[1], v[2]])
}

/// The report's field answers, one line each (standard error).
fn field_summary(report: &robocal::handeye::report::HandEyeReport) -> Vec<String> {
    let mut out = Vec::new();
    for e in [&report.work_point_error, &report.tcp_error]
        .into_iter()
        .flatten()
    {
        out.push(e.verdict.clone());
        if let Some(first) = e.shrink_by.first() {
            out.push(format!("  to shrink it: {first}"));
        }
    }
    if let Some(h) = &report.holdout {
        out.push(format!("holdout: {}", h.verdict));
    }
    if let Some(t) = &report.touch_test {
        out.push(format!(
            "touch test: {} points, RMS {:.2} mm, largest {:.2} mm",
            t.points.len(),
            t.rms_mm,
            t.max_mm
        ));
    }
    out
}

/// Too few pose pairs after images were dropped: the error lists them and
/// why (the report that would say so is not written).
fn with_dropped(e: robocal::Error, pairs: &[robocal::handeye::report::PairAudit]) -> CliError {
    let dropped: Vec<String> = pairs
        .iter()
        .filter(|p| !p.used)
        .map(|p| {
            format!(
                "{} ({})",
                p.image.as_deref().unwrap_or("no image"),
                p.reason.as_deref().unwrap_or("unused")
            )
        })
        .collect();
    match e {
        robocal::Error::TooFew { .. } if !dropped.is_empty() => CliError::Io(format!(
            "{e}; dropped with their pose: {}",
            dropped.join(", ")
        )),
        other => other.into(),
    }
}
