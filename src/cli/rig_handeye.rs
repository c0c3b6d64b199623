//! `robocal rig ... --setup SETUP --poses FILE`: the rig on a robot. After
//! the rig calibration, each frame's board pose in the rig frame from every
//! camera that saw it (the calibrated rig held), then the hand-eye closed
//! forms and the pose refinement: `gripper_from_rig` or `base_from_rig`,
//! written into the rig report under `handeye`.

use super::robot_poses::{read_pose_source, read_robot_poses, RobotPoses};
use super::CliError;
use robocal::api::rig_handeye::solve_rig_on_robot;
use robocal::calib::multi::rig::RigCameraViews;
use robocal::calib::multi::rig_report::RigCalibration;
use robocal::handeye::{HandEyeOptions, Setup};
use robocal::io::pairing::FrameGrouping;
use robocal::io::RobotPose;
use serde_json::Value;

/// The hand-eye flags of `robocal rig`.
#[derive(clap::Args, Default)]
pub struct RigHandEyeFlags {
    /// The rig on a robot: eye-in-hand (the rig on the gripper, solves
    /// gripper_from_rig) or eye-to-hand (the rig fixed, base_from_rig); needs --poses
    #[arg(long, value_name = "SETUP", overrides_with = "setup")]
    setup: Option<String>,
    /// Robot poses base_from_gripper, one per frame in frame order, or with
    /// an 'image' column naming a file of each frame (any robot pose file, as
    /// 'robocal handeye --poses'), or a folder or several files of one pose
    /// each (named by their stems)
    #[arg(long, value_name = "FILE|FOLDER", num_args = 1.., action = clap::ArgAction::Set, overrides_with = "poses")]
    poses: Vec<String>,
    #[arg(long, value_name = "NAME", overrides_with = "pose_format", help = super::robot_poses::POSE_FORMAT_SHORT, long_help = super::robot_poses::POSE_FORMAT_HELP)]
    pose_format: Option<String>,
    /// Units of the pose files, overriding the header and the format's
    /// defaults: mm or m, deg or rad, or both (mm,deg)
    #[arg(long, value_name = "UNITS", overrides_with = "pose_units")]
    pose_units: Option<String>,
    /// Report suspected pose mistakes (units, inverted or shifted poses) as
    /// warnings instead of failing
    #[arg(long)]
    lenient: bool,
}

impl RigHandEyeFlags {
    /// Whether a hand-eye was asked for; both flags or neither.
    pub fn wanted(&self) -> Result<bool, CliError> {
        match (&self.setup, !self.poses.is_empty()) {
            (Some(_), true) => Ok(true),
            (None, false) => Ok(false),
            (Some(_), false) => Err(CliError::usage("rig", "--setup needs --poses FILE")),
            (None, true) => Err(CliError::usage(
                "rig",
                "--poses needs --setup eye-in-hand|eye-to-hand",
            )),
        }
    }
}

/// The rig hand-eye report of a calibrated rig: `index[k]` is the rig
/// camera of input camera `k`; `source` names where the rig came from (for
/// the note on its uncertainty).
pub fn rig_handeye(
    flags: &RigHandEyeFlags,
    report: &RigCalibration,
    inputs: &[RigCameraViews],
    index: &[usize],
    keys: &[String],
    grouping: &FrameGrouping,
    source: &str,
) -> Result<Value, CliError> {
    let setup: Setup = flags.setup.as_deref().unwrap_or_default().parse()?;
    let pose_source = read_pose_source("rig", &flags.poses)?;
    let path = pose_source.label();
    let poses = match read_robot_poses(
        "rig",
        &pose_source,
        flags.pose_format.as_deref(),
        flags.pose_units.as_deref(),
    )? {
        RobotPoses::Known(p) => p,
        RobotPoses::Ambiguous(_) => {
            return Err(CliError::usage(
                "rig",
                "the pose file's format is ambiguous: pass --pose-format NAME",
            ))
        }
    };
    let base_from_gripper = per_frame(&poses, keys, grouping, path)?;
    let options = HandEyeOptions {
        strict_checks: !flags.lenient,
        ..HandEyeOptions::default()
    };
    Ok(solve_rig_on_robot(
        setup,
        report,
        inputs,
        index,
        keys,
        &base_from_gripper,
        &options,
        source,
    )?)
}

/// One robot pose per frame: by the frame numbers of the pose file's image
/// names when it has them (keyed by the same rule as the images), else in
/// order (grouping by order).
fn per_frame(
    poses: &[RobotPose],
    keys: &[String],
    grouping: &FrameGrouping,
    path: &str,
) -> Result<Vec<robocal::geometry::Pose>, CliError> {
    let named = *grouping != FrameGrouping::Order && poses.iter().all(|p| p.name.is_some());
    if !named || poses.is_empty() {
        return Ok(poses.iter().map(|p| p.base_from_gripper).collect());
    }
    let mut out = vec![None; keys.len()];
    for p in poses {
        let name = p.name.as_deref().unwrap_or_default();
        let Some(number) = grouping.key(name) else {
            return Err(CliError::Io(format!(
                "'{path}': line {}: the image '{name}' has no frame number (the frames are {})",
                p.line,
                keys.join(", ")
            )));
        };
        // A pose of a frame none of the given images is in (a pose file of
        // the whole rig used with some of its cameras) is not needed.
        if let Some(f) = keys.iter().position(|k| *k == number) {
            out[f] = Some(p.base_from_gripper);
        }
    }
    let missing: Vec<&str> = keys
        .iter()
        .zip(&out)
        .filter(|(_, p)| p.is_none())
        .map(|(k, _)| k.as_str())
        .collect();
    if !missing.is_empty() {
        return Err(CliError::Io(format!(
            "'{path}': no robot pose for frame(s) {}: give a pose for every frame, or \
             leave those frames' images out",
            missing.join(", ")
        )));
    }
    Ok(out.into_iter().flatten().collect())
}

/// The summary on standard error: the rig transform with its std, frames used.
pub fn summary(h: &Value) -> String {
    let key = if h.get("gripper_from_rig").is_some() {
        "gripper_from_rig"
    } else {
        "base_from_rig"
    };
    let t = &h[key]["translation_m"];
    let frames = h["frames"].as_array().map_or(&[][..], Vec::as_slice);
    let used = frames.iter().filter(|f| f["used"] == true).count();
    let mut s = format!(
        "robocal rig: {key} translation_m [{}, {}, {}] ({} method), {used} of {} frames used\n",
        t[0],
        t[1],
        t[2],
        h["method"].as_str().unwrap_or(""),
        frames.len()
    );
    if let Some(sd) = h["pose_refinement"].get("camera_transform_std") {
        s += &format!(
            "  std: translation_mm {} rotation_deg {}\n",
            sd["translation_mm"], sd["rotation_deg"]
        );
    }
    if h["rig_uncertainty"]["included"] == false {
        s += &format!(
            "robocal rig: note: {}\n",
            h["rig_uncertainty"]["note"].as_str().unwrap_or("")
        );
    }
    for w in h["warnings"].as_array().map_or(&[][..], Vec::as_slice) {
        s += &format!(
            "robocal rig: hand-eye warning: {}\n",
            w.as_str().unwrap_or("")
        );
    }
    s
}
