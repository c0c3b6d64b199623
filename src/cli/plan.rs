//! `robocal plan`: read the current robot pose, the camera's view of the
//! target from it and the camera, call the planner, write the plan.

use super::detect::Outcome;
use super::handeye_images::detect_images;
use super::robot_poses::{read_pose_source, read_robot_poses};
use super::{parse_target, CliError};
use robocal::api::handeye::camera_from_json;
use robocal::api::plan::plan_json_value;
use robocal::handeye::plan::{
    pixel_sigma_from_view, plan, PixelNoiseSource, PlanInput, PlanLimits, PlanNoise,
};
use robocal::handeye::{Pose, Setup};
use robocal::io::move_lists::plan_export;
use robocal::io::pose_text::parse_pose_text;

#[derive(clap::Args)]
#[command(
    about = "plan robot poses for a hand-eye calibration from one view of the target",
    long_about = "plan robot poses for a hand-eye calibration (docs/pose-plan.md)

  robocal plan --setup eye-in-hand|eye-to-hand --robot-pose FILE [--pose-format NAME]
               --camera camera.json --target SPEC (--image now.png | --camera-pose FILE)
               [--guess FILE] [--poses N] [--max-tilt DEG] [--max-roll DEG]
               [--distance MIN,MAX] [--flange-box X0,Y0,Z0,X1,Y1,Z1] [--margin PX]
               [--pixel-noise PX] [--export FILE --format NAME] [-o plan.json]",
    after_help = "Output JSON: poses [{base_from_gripper, camera_from_target, tilt_deg,
distance_m, roll_deg}] in visiting order from the current pose, predicted
(the hand-eye error at the work point these poses reach: bound95_mm, rms_mm,
verdict, shrink_by), motion, travel_m, candidates, notes, noise (the noise the
prediction assumed: pixel_sigma_px and where it comes from). Joint limits,
reachability and collisions are not modelled: check the poses in simulation.
--export writes the poses for the robot: a pose table in any --pose-format
robocal reads (ur, kuka, abb, fanuc, ...), or a program: ur-script, kuka-krl,
abb-rapid.

Examples:
  robocal plan --setup eye-in-hand --robot-pose now.csv --camera camera.json \\
               --target chessboard:9x6:30mm --image now.png --poses 15 \\
               --export plan.script --format ur-script -o plan.json",
    args_override_self = true
)]
pub struct PlanArgs {
    /// eye-in-hand (camera on the gripper) or eye-to-hand (camera beside the robot)
    #[arg(long, value_name = "SETUP")]
    setup: Option<String>,
    /// The robot's current pose base_from_gripper: a pose file (the first
    /// pose is used), as robocal handeye --poses reads
    #[arg(long, value_name = "FILE")]
    robot_pose: Option<String>,
    #[arg(long, value_name = "NAME", help = super::robot_poses::POSE_FORMAT_SHORT)]
    pose_format: Option<String>,
    /// Units of the pose file: mm or m, deg or rad, or both (mm,deg)
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
    /// An image of the target from the current pose
    #[arg(long, value_name = "FILE")]
    image: Option<String>,
    /// Instead of --image: camera_from_target of the current view (one line:
    /// 16 numbers of a row-major 4x4 matrix, metres)
    #[arg(long, value_name = "FILE")]
    camera_pose: Option<String>,
    /// A rough gripper_from_camera (eye-in-hand) or gripper_from_target
    /// (eye-to-hand), in the format of --camera-pose (default: identity)
    #[arg(long, value_name = "FILE")]
    guess: Option<String>,
    /// Number of poses
    #[arg(long, value_name = "N", default_value_t = 15)]
    poses: usize,
    /// Largest tilt of the board against the camera's view (degrees)
    #[arg(long, value_name = "DEG", default_value_t = 40.0)]
    max_tilt: f64,
    /// Largest roll about the optical axis from the current view (degrees)
    #[arg(long, value_name = "DEG", default_value_t = 60.0)]
    max_roll: f64,
    /// Working distance range, camera to board centre, with a unit, e.g.
    /// 0.4,0.6m or 400,600mm (default: the current distance -20 % .. +20 %)
    #[arg(long, value_name = "MIN,MAX")]
    distance: Option<String>,
    /// Box the flange stays in, base frame, with a unit:
    /// X0,Y0,Z0,X1,Y1,Z1mm (the two opposite corners)
    #[arg(long, value_name = "BOX")]
    flange_box: Option<String>,
    /// Every board point at least this far inside the image (px)
    #[arg(long, value_name = "PX", default_value_t = 20.0)]
    margin: f64,
    /// Corner noise the prediction assumes (px per axis; default: measured
    /// on --image, its PnP residual; 0.3 with --camera-pose)
    #[arg(long, value_name = "PX")]
    pixel_noise: Option<f64>,
    /// Write the poses for the robot there (with --format)
    #[arg(long, value_name = "FILE")]
    export: Option<String>,
    /// Format of --export: a pose format (ur, kuka, abb, fanuc, yaskawa,
    /// staubli, xyz-quaternion-xyzw, ...) or a program (ur-script, kuka-krl,
    /// abb-rapid)
    #[arg(long, value_name = "NAME")]
    format: Option<String>,
    /// Write the plan JSON there (default: standard output)
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<String>,
}

/// Numbers separated by commas with one unit (mm, cm or m) at the end.
fn lengths(flag: &str, text: &str, count: usize) -> Result<Vec<f64>, CliError> {
    let expected = format!("expected {count} numbers");
    let flag = super::values::LengthsFlag {
        command: "plan",
        flag,
        count,
        expected: &expected,
        unit_example: "",
    };
    super::values::lengths_m(&flag, text)
}

fn one_pose(flag: &str, path: &str) -> Result<Pose, CliError> {
    let text = super::read_pose_text(path)?;
    let poses = parse_pose_text(&text, None).map_err(|e| CliError::from(e).in_file(path))?;
    poses
        .first()
        .copied()
        .ok_or_else(|| CliError::usage("plan", format!("{flag} {path}: no pose in the file")))
}

/// Run `robocal plan`.
pub fn run(args: PlanArgs) -> Result<(), CliError> {
    let setup: Setup = args
        .setup
        .as_deref()
        .ok_or_else(|| CliError::usage("plan", "--setup eye-in-hand|eye-to-hand is required"))?
        .parse()?;
    let robot_path = args
        .robot_pose
        .as_deref()
        .ok_or_else(|| CliError::usage("plan", "--robot-pose FILE is required"))?;
    let source = read_pose_source("plan", &[robot_path.to_string()])?;
    let robot = read_robot_poses(
        "plan",
        &source,
        args.pose_format.as_deref(),
        args.pose_units.as_deref(),
    )?;
    let base_from_gripper = robot
        .first()
        .first()
        .map(|p| p.base_from_gripper)
        .ok_or_else(|| CliError::usage("plan", "--robot-pose holds no pose"))?;
    let camera_path = args
        .camera
        .as_deref()
        .ok_or_else(|| CliError::usage("plan", "--camera FILE is required"))?;
    let camera_text = super::read_pose_text(camera_path)?;
    let value =
        serde_json::from_str(&camera_text).unwrap_or(serde_json::Value::String(camera_text));
    let camera = camera_from_json(&value)?;
    let spec = args
        .target
        .as_deref()
        .ok_or_else(|| CliError::usage("plan", "--target SPEC is required"))?;
    let target = parse_target("plan", spec)?;
    let board_m = target.object_points().into_iter().map(|(_, p)| p).collect();
    let (camera_from_target, measured_sigma) =
        match (args.image.as_deref(), args.camera_pose.as_deref()) {
            (Some(image), None) => {
                let outcomes = detect_images(
                    &[image.to_string()],
                    &target,
                    &super::detect_options_of(Some(spec)),
                    &super::ImageLimits::default(),
                    Some(1),
                )?;
                match outcomes.into_iter().next() {
                    Some(Outcome::Found(detection, _)) => {
                        let (object, pixels) = detection.correspondences();
                        let view = robocal::calib::View::new("", object, pixels);
                        let (pose, sigma) = pixel_sigma_from_view(&camera, &view)
                            .map_err(|e| CliError::from(e).in_file(image))?;
                        (pose, Some(sigma))
                    }
                    Some(Outcome::Failed(_, message)) => {
                        return Err(CliError::Io(format!(
                            "{image}: detection failed: {message}"
                        )))
                    }
                    None => return Err(CliError::Io(format!("{image}: not read"))),
                }
            }
            (None, Some(path)) => (one_pose("--camera-pose", path)?, None),
            _ => {
                return Err(CliError::usage(
                    "plan",
                    "give the current view: --image FILE or --camera-pose FILE (one of them)",
                ))
            }
        };
    let guess = match args.guess.as_deref() {
        Some(path) => one_pose("--guess", path)?,
        None => Pose::identity(),
    };
    let distance_m = match args.distance.as_deref() {
        Some(t) => {
            let v = lengths("--distance", t, 2)?;
            Some((v[0], v[1]))
        }
        None => None,
    };
    let flange_box_m = match args.flange_box.as_deref() {
        Some(t) => {
            let v = lengths("--flange-box", t, 6)?;
            let lo = [v[0].min(v[3]), v[1].min(v[4]), v[2].min(v[5])];
            let hi = [v[0].max(v[3]), v[1].max(v[4]), v[2].max(v[5])];
            Some((lo, hi))
        }
        None => None,
    };
    let input = PlanInput {
        setup,
        base_from_gripper,
        camera_from_target,
        camera,
        board_m,
        guess,
    };
    let limits = PlanLimits {
        poses: args.poses,
        max_tilt_deg: args.max_tilt,
        max_roll_deg: args.max_roll,
        distance_m,
        flange_box_m,
        margin_px: args.margin,
    };
    let noise = match (args.pixel_noise, measured_sigma) {
        (Some(sigma), _) if !(sigma > 0.0 && sigma.is_finite()) => {
            return Err(CliError::usage(
                "plan",
                format!("--pixel-noise {sigma}: a positive number of pixels"),
            ))
        }
        (Some(sigma), _) => PlanNoise {
            pixel_sigma_px: sigma,
            pixel_sigma_from: PixelNoiseSource::Given,
            ..PlanNoise::default()
        },
        (None, Some(sigma)) => PlanNoise {
            pixel_sigma_px: sigma,
            pixel_sigma_from: PixelNoiseSource::MeasuredOnView,
            ..PlanNoise::default()
        },
        (None, None) => PlanNoise::default(),
    };
    let planned = plan(&input, &limits, &noise)?;
    if let Some(path) = args.export.as_deref() {
        let name = args.format.as_deref().ok_or_else(|| {
            CliError::usage("plan", "--export needs --format NAME (e.g. ur, kuka-krl)")
        })?;
        let robot: Vec<Pose> = planned.poses.iter().map(|p| p.base_from_gripper).collect();
        let text = plan_export(&robot, name).ok_or_else(|| {
            CliError::usage(
                "plan",
                format!(
                    "--format '{name}': not a pose format robocal reads nor a program \
                     (ur-script, kuka-krl, abb-rapid)"
                ),
            )
        })?;
        super::write_output(Some(path), &text)?;
    }
    let json = serde_json::to_string_pretty(&plan_json_value(&planned))
        .map_err(|e| CliError::Io(format!("cannot serialise the plan: {e}")))?;
    super::write_output(args.output.as_deref(), &(json + "\n"))?;
    eprintln!("{}", planned.predicted.verdict);
    for n in &planned.notes {
        eprintln!("note: {n}");
    }
    Ok(())
}
