//! `robocal rig`: calibrate a camera rig (every camera and its
//! camera_from_rig) from synchronised images of a board.

use super::detect::{run_all, Outcome};
use super::{read_text, write_output, CliError};
use robocal::api::camera::{JsonOptions, LensModel};
use robocal::api::rig::{calibrate_rig_input, rig_views, RigInput, RigJsonCamera, RigJsonView};
use robocal::api::rig_handeye::{rig_cameras_named, with_handeye};
use robocal::calib::multi::rig::{sort_frame_keys, RigCameraViews};
use robocal::calib::multi::rig_report::RigCalibration;
use robocal::camera::Camera;
use robocal::io::import_camera::import_camera;
use robocal::io::pairing::{default_grouping, frame_keys, FrameGrouping};
use robocal::target::Target;
use serde::Deserialize;
use std::path::Path;

#[derive(clap::Args)]
#[command(
    about = "calibrate a camera rig (N cameras, partial overlap): every camera and its camera_from_rig",
    long_about = "calibrate a camera rig: N cameras that saw one board in synchronised frames

Each --camera takes a name and that camera's images (every argument up to the
next option, so shell globs work). Images are grouped into frames by the number
in their file names (the last run of digits in the name without folders and
extension: front07.png and side/7.jpg are one frame), or as --group-by says:
first (the first number: sync036_cam0.jpg is frame 36), last (as number),
order (the position in each camera's list), or a pattern: literal text with
one (\\d+), matched in the name without folders, such as 'sync(\\d+)'
(sync036_cam0.jpg and cam1_sync36.png are frame 36). Any camera may miss the board in any frame; a detection may
hold any subset of the board's points (marker boards partly out of view).

Each camera is calibrated alone (Zhang), or its intrinsics are given and held
with --camera-file NAME=FILE (any camera format robocal exports: a robocal
camera JSON or report, OpenCV YAML/XML, ROS camera_info, Kalibr, mrcal, HALCON,
MATLAB, text). The cameras are chained along a spanning tree of the pairs
that saw the board together most often (rotations averaged over the shared
frames), then one bundle adjustment refines every intrinsic, every
camera_from_rig and every frame's board pose. When no frame links two groups of
cameras, the error names the groups.

Instead of --camera, --input reads a rig file:
  {\"target\": \"chessboard:9x6:30mm\", \"group_by\": \"number\", \"rig_frame\": \"front\",
   \"cameras\": [{\"name\": \"front\", \"images\": [\"front/01.png\", ...]},
               {\"name\": \"side\", \"images\": [...], \"camera_file\": \"side.json\"}]}
(paths relative to the rig file's folder; every key but cameras optional; the
flags override the file).

The report (JSON; the rig frame is the rig camera's, camera 0 unless
--rig-frame): cameras (name, calibration, intrinsics_held, camera_from_rig
{matrix_row_major, translation_m, quaternion_xyzw}, camera_from_rig_std,
rms_px, frames_seen), frames (key, rig_from_target, cameras, rms_px),
co_observation (cameras, frames: the matrix of frames seen together,
spanning_tree), rms_px, warnings. A summary goes to standard error.

A rig on a robot: with --setup eye-in-hand|eye-to-hand --poses FILE (one
robot pose base_from_gripper per frame, in frame order, or paired by the frame
number of an 'image' column), each frame's board pose in the rig frame is
fitted to every camera that saw it (the calibrated rig held), then the
hand-eye closed forms and the maximum-likelihood pose refinement give
gripper_from_rig (eye-in-hand) or base_from_rig (eye-to-hand). The report
gets 'handeye': the 'robocal handeye' report with the rig in its keys
(gripper_from_rig or base_from_rig, base_from_target or gripper_from_target,
methods, errors, pose_refinement with camera_transform_std), cameras (each
camera's own gripper_from_camera or base_from_camera) and frames (key,
pose_index, used, cameras, pose_fit_rms_px, reason) and rig_uncertainty
(included, note, sigma_points, conditional_camera_transform_std,
conditional_target_transform_std): the std include the rig calibration's own
uncertainty, propagated from its covariance (the report's 'covariance').

An already calibrated rig: --rig rig.json (the report of 'robocal rig -o
rig.json') with --setup and --poses holds that rig's intrinsics and
camera_from_rig and solves only the hand-eye from the images given with
--camera (each NAME one of the rig's cameras, any subset of them; --target
defaults to the rig's). The output is the given rig report with 'handeye'; its
std include the rig's uncertainty when the file carries 'covariance', else
rig_uncertainty.included is false and the std are conditional on the rig.",
    after_help = "Examples:
  robocal rig --target chessboard:9x6:30mm --camera left left*.png --camera right right*.png -o rig.json
  robocal rig --target charuco:12x9:20mm:15mm:DICT_5X5_100 --camera front f/*.png \\
      --camera back b/*.png --camera top t/*.png --camera-file top=top.json --rig-frame top -o rig.json
  robocal rig --input rig-files.json -o rig.json
  robocal rig --target chessboard:9x6:30mm --camera left left*.png --camera right right*.png \\
      --setup eye-in-hand --poses robot.csv -o rig.json
  robocal rig --target chessboard:9x6:30mm --camera left left*.png --camera right right*.png \\
      --fix k3 -o rig.json && robocal export rig.json --format kalibr
  robocal rig --rig rig.json --camera left l2/*.png --camera right r2/*.png \\
      --setup eye-to-hand --poses robot2.csv -o rig_on_robot.json"
)]
pub struct RigArgs {
    /// The target, as for 'robocal detect' (chessboard:9x6:30mm, ...)
    #[arg(long, value_name = "SPEC", overrides_with = "target")]
    target: Option<String>,
    #[command(flatten)]
    camera: CameraFlags,
    /// A rig file listing the cameras and their images (instead of --camera)
    #[arg(long, value_name = "FILE", overrides_with = "input")]
    input: Option<String>,
    /// Hold a camera's intrinsics at those of FILE: NAME=FILE (repeatable)
    #[arg(long, value_name = "NAME=FILE", action = clap::ArgAction::Append)]
    camera_file: Vec<String>,
    /// The camera whose frame is the rig frame (default: the first)
    #[arg(long, value_name = "NAME", overrides_with = "rig_frame")]
    rig_frame: Option<String>,
    /// How images form frames: number or last (the last number in the file
    /// names, default), first (the first number), order (the position in
    /// each camera's list), or a pattern with one (\d+) such as 'sync(\d+)'
    #[arg(long, value_name = "RULE", overrides_with = "group_by")]
    group_by: Option<String>,
    #[arg(long, value_name = "NAME", overrides_with = "model", help = robocal::camera::model_help("the solved cameras"))]
    model: Option<String>,
    /// Hold a distortion coefficient of every solved camera at 0
    /// (repeatable: --fix k3 gives Kalibr's radtan k1 k2 p1 p2)
    #[arg(long, value_name = "NAME")]
    fix: Vec<String>,
    /// Images detected in parallel (default: all cores)
    #[arg(long, value_name = "N", overrides_with = "threads")]
    threads: Option<usize>,
    #[command(flatten)]
    limits: super::ImageLimits,
    #[command(flatten)]
    video: super::video_frames::VideoFlags,
    /// Cameras given as videos (--camera cam0 cam_0.mp4): caliscope's
    /// timestamps.csv (sync_index,cam_id,frame_index,frame_time) matching
    /// their frames by sync_index (default: by frame index)
    #[arg(long, value_name = "FILE", overrides_with = "timestamps")]
    timestamps: Option<String>,
    #[command(flatten)]
    handeye: super::rig_handeye::RigHandEyeFlags,
    /// A calibrated rig (the report of 'robocal rig -o rig.json'): its
    /// intrinsics and camera_from_rig are held and only the hand-eye is
    /// solved; needs --setup and --poses; every --camera NAME must be one of
    /// its cameras
    #[arg(long, value_name = "FILE", overrides_with = "rig")]
    rig: Option<String>,
    /// Write the report there (default: standard output)
    #[arg(short = 'o', long, value_name = "FILE", overrides_with = "output")]
    output: Option<String>,
}

/// `--camera NAME IMAGES...`, repeatable, each occurrence kept apart
/// (clap's derive groups occurrences only under its unstable-v5 feature,
/// so this one argument reads `ArgMatches::get_occurrences` itself).
#[derive(Clone, Debug, Default)]
struct CameraFlags(Vec<Vec<String>>);

impl clap::FromArgMatches for CameraFlags {
    fn from_arg_matches(m: &clap::ArgMatches) -> Result<Self, clap::Error> {
        let groups = m
            .get_occurrences::<String>("camera")
            .map(|o| o.map(|v| v.cloned().collect()).collect())
            .unwrap_or_default();
        Ok(CameraFlags(groups))
    }

    fn update_from_arg_matches(&mut self, m: &clap::ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl clap::Args for CameraFlags {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        cmd.arg(
            clap::Arg::new("camera")
                .long("camera")
                .value_names(["NAME", "IMAGES"])
                .num_args(2..)
                .action(clap::ArgAction::Append)
                .help(
                    "A camera: its name, then its images (every argument up to the next \
                     option); give one --camera per camera",
                ),
        )
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

/// The rig file of `--input`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RigFile {
    #[serde(default)]
    target: Option<String>,
    #[serde(default)]
    group_by: Option<String>,
    #[serde(default)]
    rig_frame: Option<String>,
    #[serde(default)]
    model: Option<String>,
    /// Distortion coefficients held at 0, as `--fix` (which replaces them).
    #[serde(default)]
    fix: Vec<String>,
    cameras: Vec<RigFileCamera>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RigFileCamera {
    name: String,
    images: Vec<String>,
    #[serde(default)]
    camera_file: Option<String>,
}

/// One camera of the command line: name, images, held intrinsics file.
struct CameraArg {
    name: String,
    images: Vec<String>,
    camera_file: Option<String>,
}

fn usage(message: impl Into<String>) -> CliError {
    CliError::usage("rig", message)
}

pub fn run(args: RigArgs) -> Result<(), CliError> {
    super::check_optional_bounds("rig", "--threads", args.threads, super::bounds::THREADS)?;
    let handeye = args.handeye.wanted()?;
    let given = args
        .rig
        .as_deref()
        .map(|path| given_rig(path, &args, handeye))
        .transpose()?;
    // 1. The cameras, from the flags or the rig file.
    let (mut cameras, file) = match (&args.input, args.camera.0.is_empty()) {
        (Some(_), false) => {
            return Err(usage("give either --camera ... or --input FILE, not both"))
        }
        (None, true) => {
            return Err(usage(
                "give one --camera NAME IMAGES... per camera (at least 2), or --input FILE",
            ))
        }
        (None, false) => (cameras_of_flags(&args.camera.0), None),
        (Some(path), true) => {
            let file: RigFile = serde_json::from_str(&read_text(path)?).map_err(|e| {
                CliError::Io(format!("'{path}': line {}: not a rig file: {e}", e.line()))
            })?;
            let dir = Path::new(path).parent().unwrap_or(Path::new(""));
            let within = |p: &str| dir.join(p).to_string_lossy().into_owned();
            let cameras = file
                .cameras
                .iter()
                .map(|c| CameraArg {
                    name: c.name.clone(),
                    images: c.images.iter().map(|i| within(i)).collect(),
                    camera_file: c.camera_file.as_deref().map(within),
                })
                .collect();
            (cameras, Some(file))
        }
    };
    for spec in &args.camera_file {
        let Some((name, path)) = spec.split_once('=') else {
            return Err(usage(format!(
                "--camera-file takes NAME=FILE, got '{spec}'"
            )));
        };
        let Some(c) = cameras.iter_mut().find(|c| c.name == name) else {
            return Err(usage(format!(
                "--camera-file {spec}: no --camera is named '{name}'"
            )));
        };
        c.camera_file = Some(path.to_string());
    }
    let pick = |flag: &Option<String>, f: fn(&RigFile) -> &Option<String>| {
        flag.clone()
            .or_else(|| file.as_ref().and_then(|r| f(r).clone()))
    };
    let target_spec = pick(&args.target, |r| &r.target)
        .or_else(|| given.as_ref().map(|(r, _)| r.target.clone()))
        .ok_or_else(|| usage("--target is required, e.g. --target chessboard:9x6:30mm"))?;
    let target = Target::parse_spec(&target_spec).map_err(|e| usage(e.to_string()))?;
    let grouping = grouping(pick(&args.group_by, |r| &r.group_by).as_deref(), &cameras)?;
    let model = pick(&args.model, |r| &r.model);
    let mut held = cameras
        .iter()
        .map(|c| c.camera_file.as_deref().map(held_camera).transpose())
        .collect::<Result<Vec<Option<Camera>>, CliError>>()?;
    let index = match &given {
        Some((rig, path)) => {
            let index = rig_cameras(rig, &cameras, path)?;
            for (h, &k) in held.iter_mut().zip(&index) {
                *h = Some(rig.cameras[k].calibration.camera.clone());
            }
            index
        }
        None => (0..cameras.len()).collect(),
    };
    // 2. Videos into their chosen frames, frame keys, then detection in
    // every image at once.
    let options = super::detect_options_of(Some(&target_spec));
    let videos = video_cameras(&mut cameras, &target, &options, &args)?;
    let mut keys_per_camera = Vec::with_capacity(cameras.len());
    for c in &cameras {
        let names: Vec<&str> = c.images.iter().map(String::as_str).collect();
        keys_per_camera.push(match &videos {
            Some(v) if c.images.iter().all(|i| v.key(i).is_some()) => {
                c.images.iter().filter_map(|i| v.key(i)).collect()
            }
            _ => frame_keys(&names, &grouping, &c.name).map_err(|e| usage(plain(e)))?,
        });
    }
    let mut keys: Vec<String> = keys_per_camera.iter().flatten().cloned().collect();
    sort_frame_keys(&mut keys);
    keys.dedup();
    let all: Vec<String> = cameras.iter().flat_map(|c| c.images.clone()).collect();
    let decode = args.limits.decode_options();
    let mut outcomes = match &videos {
        Some(v) => v
            .inputs(&all)
            .detect(&target, &options, &decode, args.threads)?,
        None => run_all(&all, &target, &options, &decode, args.threads)?,
    }
    .into_iter();
    let mut request_cameras = Vec::with_capacity(cameras.len());
    for ((c, camera_keys), held) in cameras.iter().zip(&keys_per_camera).zip(held) {
        let mut views = Vec::new();
        let mut size: Option<(u32, u32)> = None;
        for (file, key) in c.images.iter().zip(camera_keys) {
            match outcomes.next() {
                Some(Outcome::Found(d, _)) => {
                    let s = (d.image_size_px[0], d.image_size_px[1]);
                    if size.is_some_and(|p| p != s) {
                        return Err(usage(format!(
                            "camera {}: '{file}' is {}x{} but its earlier images are not",
                            c.name, s.0, s.1
                        )));
                    }
                    if let (Some(_), Some(h)) = (&given, &held) {
                        if (h.width, h.height) != s {
                            return Err(usage(format!(
                                "camera {}: '{file}' is {}x{} but the rig's camera {} is {}x{}",
                                c.name, s.0, s.1, c.name, h.width, h.height
                            )));
                        }
                    }
                    size = Some(s);
                    views.push(RigJsonView {
                        key: key.clone(),
                        name: file.clone(),
                        detection: Some(d),
                        object_m: None,
                        image_px: None,
                    });
                }
                Some(Outcome::Failed(_, m)) => {
                    eprintln!("robocal rig: camera {}: {file} left out: {m}", c.name)
                }
                None => {}
            }
        }
        if size.is_none() && held.is_none() {
            return Err(CliError::Io(format!(
                "rig: the target was found in no image of camera {}",
                c.name
            )));
        }
        request_cameras.push(RigJsonCamera {
            name: c.name.clone(),
            views,
            image_size_px: size.map(|(w, h)| [w, h]),
            camera: held,
        });
    }
    // The request `calibrate_rig` takes, with every image's frame key (a
    // robot pose pairs with each frame, the board found in it or not).
    let request = RigInput {
        model: LensModel::from_name(model.as_deref().unwrap_or("brown"))?,
        options: JsonOptions {
            // The flags replace the file's list (as every flag overrides its key).
            fixed_coefficients: match &file {
                Some(f) if args.fix.is_empty() => f.fix.clone(),
                _ => args.fix.clone(),
            },
            ..JsonOptions::default()
        },
        cameras: request_cameras,
        target: target.to_spec(),
        rig_frame: pick(&args.rig_frame, |r| &r.rig_frame),
        grouping: grouping.rule(),
        frame_keys: Some(keys),
    };
    let (inputs, keys) = rig_views(&request)?;
    // 3. Solve (or hold the given rig), summarise, write.
    if let Some((report, path)) = given {
        eprintln!(
            "robocal rig: the rig of '{path}' held ({} cameras, images of {})",
            report.cameras.len(),
            cameras
                .iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
        let source = format!("the covariance in '{path}'");
        return write_with_handeye(&args, &report, &inputs, &index, &keys, &grouping, &source);
    }
    let report = calibrate_rig_input(&request)?;
    eprint!("{}", super::rig_summary::summary(&report));
    if !handeye {
        return write_report(&args, &report, None);
    }
    let source = "the rig calibration of this run".to_string();
    write_with_handeye(&args, &report, &inputs, &index, &keys, &grouping, &source)
}

/// The hand-eye of the rig, then the report with it under `handeye`.
fn write_with_handeye(
    args: &RigArgs,
    report: &RigCalibration,
    inputs: &[RigCameraViews],
    index: &[usize],
    keys: &[String],
    grouping: &FrameGrouping,
    source: &str,
) -> Result<(), CliError> {
    let h = super::rig_handeye::rig_handeye(
        &args.handeye,
        report,
        inputs,
        index,
        keys,
        grouping,
        source,
    )?;
    eprint!("{}", super::rig_handeye::summary(&h));
    write_report(args, report, Some(h))
}

fn write_report(
    args: &RigArgs,
    report: &RigCalibration,
    handeye: Option<serde_json::Value>,
) -> Result<(), CliError> {
    let json = match handeye {
        Some(h) => with_handeye(report, h)?,
        None => serde_json::to_value(report)
            .map_err(|e| CliError::Io(format!("cannot serialise the report: {e}")))?,
    };
    let text = serde_json::to_string_pretty(&json)
        .map_err(|e| CliError::Io(format!("cannot serialise the report: {e}")))?;
    write_output(args.output.as_deref(), &(text + "\n"))
}

/// The rig of `--rig FILE`, with the flags it cannot go with refused.
fn given_rig(
    path: &str,
    args: &RigArgs,
    handeye: bool,
) -> Result<(RigCalibration, String), CliError> {
    if !handeye {
        return Err(usage(
            "--rig holds a calibrated rig for the hand-eye: give --setup eye-in-hand|eye-to-hand \
             and --poses FILE with it",
        ));
    }
    let conflicts = [
        (!args.camera_file.is_empty(), "--camera-file"),
        (args.model.is_some(), "--model"),
        (!args.fix.is_empty(), "--fix"),
        (args.rig_frame.is_some(), "--rig-frame"),
    ];
    if let Some((_, flag)) = conflicts.iter().find(|(on, _)| *on) {
        return Err(usage(format!(
            "{flag} cannot go with --rig: the rig file holds every camera's intrinsics and the \
             rig frame"
        )));
    }
    let text = read_text(path)?;
    let rig: RigCalibration = serde_json::from_str(&text).map_err(|e| {
        CliError::Io(format!(
            "'{path}': line {}: not a rig report (the output of 'robocal rig -o rig.json'): {e}",
            e.line()
        ))
    })?;
    Ok((rig, path.to_string()))
}

/// The rig camera of each `--camera`, by name; every name must be in the rig.
fn rig_cameras(
    rig: &RigCalibration,
    cameras: &[CameraArg],
    path: &str,
) -> Result<Vec<usize>, CliError> {
    let names: Vec<&str> = cameras.iter().map(|c| c.name.as_str()).collect();
    rig_cameras_named(rig, &names, "--camera").map_err(|e| usage(format!("'{path}': {}", plain(e))))
}

/// The cameras given as videos replaced by their chosen frames
/// ([`super::rig_video`]).
fn video_cameras(
    cameras: &mut [CameraArg],
    target: &Target,
    options: &robocal::detect::DetectOptions,
    args: &RigArgs,
) -> Result<Option<super::rig_video::RigVideos>, CliError> {
    let names: Vec<String> = cameras.iter().map(|c| c.name.clone()).collect();
    let mut lists: Vec<Vec<String>> = cameras.iter().map(|c| c.images.clone()).collect();
    let videos = super::rig_video::expand(
        &names,
        &mut lists,
        target,
        options,
        &args.video,
        args.timestamps.as_deref(),
        args.threads,
    )?;
    for (c, list) in cameras.iter_mut().zip(lists) {
        c.images = list;
    }
    Ok(videos)
}

fn cameras_of_flags(flags: &[Vec<String>]) -> Vec<CameraArg> {
    flags
        .iter()
        .map(|v| CameraArg {
            name: v[0].clone(),
            images: v[1..].to_vec(),
            camera_file: None,
        })
        .collect()
}

/// The grouping rule: given, or by number unless no file name has one.
fn grouping(rule: Option<&str>, cameras: &[CameraArg]) -> Result<FrameGrouping, CliError> {
    match rule {
        Some(rule) => {
            FrameGrouping::from_rule(rule).map_err(|e| usage(format!("--group-by {}", plain(e))))
        }
        None => {
            let by = default_grouping(cameras.iter().flat_map(|c| &c.images).map(String::as_str));
            if by == FrameGrouping::Order {
                eprintln!("robocal rig: no file name has a number: frames grouped by order");
            }
            Ok(by)
        }
    }
}

fn held_camera(path: &str) -> Result<Camera, CliError> {
    Ok(import_camera(&read_text(path)?)
        .map_err(|e| CliError::from(e).in_file(path))?
        .0)
}

/// A library error's message without its field (for usage errors).
fn plain(e: robocal::Error) -> String {
    match e {
        robocal::Error::Invalid { message, .. } => message,
        other => other.to_string(),
    }
}
