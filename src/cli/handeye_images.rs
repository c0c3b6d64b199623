//! The image path of `robocal handeye`: robot poses read with the pose-file
//! parser (ambiguous files ranked against the camera motion), images paired
//! with poses (by the pose file's image column, else by order), detected,
//! a target pose fitted per image with the known camera, and the pairing
//! audited.

use super::detect::{run_all, Outcome};
use super::CliError;
use robocal::camera::Camera;
use robocal::detect::DetectOptions;
use robocal::handeye::checks::{rank_pose_candidates, recommend_candidate};
use robocal::handeye::output::PairAudit;
use robocal::handeye::pnp::camera_from_target;
use robocal::handeye::reprojection_refine::ViewPoints;
use robocal::handeye::{Pose, Setup};
use robocal::io::pose_text::{parse_pose_text, PoseTextFormat};
use robocal::io::{parse_pose_candidates, parse_poses, PoseFileOptions, PoseFormat, RobotPose};
use robocal::target::Target;
use std::path::Path;

/// Robot poses as read: one reading, or ranked candidates of an ambiguous file.
pub(super) enum RobotPoses {
    /// The file's format is known.
    Known(Vec<RobotPose>),
    /// Several readings are plausible: (name, poses), most plausible first.
    Ambiguous(Vec<(String, Vec<RobotPose>)>),
}

impl RobotPoses {
    fn first(&self) -> &[RobotPose] {
        match self {
            RobotPoses::Known(p) => p,
            RobotPoses::Ambiguous(c) => c.first().map_or(&[], |c| &c.1),
        }
    }
}

/// Read robot poses: `--pose-format` names a pose-file format (`ur`,
/// `xyz_quat_xyzw`, `matrix4`, ...) or a line format of the camera-pose
/// reader (`matrix`, `xyz-quaternion-xyzw`); without it the file's header
/// or value count decides, and ambiguous files give candidates.
pub(super) fn read_robot_poses(text: &str, format: Option<&str>) -> Result<RobotPoses, CliError> {
    let plain = |poses: Vec<Pose>| {
        poses
            .into_iter()
            .enumerate()
            .map(|(i, p)| RobotPose {
                name: None,
                line: i + 1,
                base_from_gripper: p,
            })
            .collect()
    };
    if let Some(name) = format {
        if let Some(f) = PoseFormat::from_name(name) {
            let options = PoseFileOptions {
                format: Some(f),
                ..Default::default()
            };
            return Ok(RobotPoses::Known(parse_poses(text, &options)?.poses));
        }
        let Ok(f) = name.parse::<PoseTextFormat>() else {
            let named: Vec<String> = PoseFormat::all()
                .iter()
                .filter(|f| !matches!(f, PoseFormat::XyzEuler { .. }))
                .map(|f| f.name())
                .collect();
            return Err(CliError::usage(
                "handeye",
                format!(
                    "--pose-format: unknown pose format '{name}' (valid: {}, \
                     xyz_euler_intrinsic_ORDER or xyz_euler_extrinsic_ORDER with ORDER such as \
                     zyx, or the line formats matrix, xyz-quaternion-xyzw, xyz-quaternion-wxyz)",
                    named.join(", ")
                ),
            ));
        };
        return Ok(RobotPoses::Known(plain(parse_pose_text(text, Some(f))?)));
    }
    let options = PoseFileOptions::default();
    match parse_poses(text, &options) {
        Ok(parsed) => Ok(RobotPoses::Known(parsed.poses)),
        Err(first) => match parse_pose_candidates(text, &options) {
            Ok(c) if c.len() > 1 => Ok(RobotPoses::Ambiguous(
                c.into_iter()
                    .map(|c| {
                        let name = format!(
                            "{} ({}, {})",
                            c.format.name(),
                            c.length_unit.name(),
                            c.angle_unit.name()
                        );
                        (name, c.poses)
                    })
                    .collect(),
            )),
            Ok(mut c) if c.len() == 1 => Ok(RobotPoses::Known(c.remove(0).poses)),
            _ => parse_pose_text(text, None)
                .map(|p| RobotPoses::Known(plain(p)))
                .map_err(|_| first.into()),
        },
    }
}

/// What the images gave: the used pairs and the audit of every pose.
pub(super) struct ImagePairs {
    /// Robot poses of the used pairs (`base_from_gripper`).
    pub base_from_gripper: Vec<Pose>,
    /// Target poses fitted to the used images.
    pub camera_from_target: Vec<Pose>,
    /// Image points of the used images.
    pub views: Vec<ViewPoints>,
    /// Every pose with its image and fate.
    pub pairs: Vec<PairAudit>,
    /// Warnings about pairing and pose-format choice.
    pub warnings: Vec<String>,
}

fn file_name(path: &str) -> String {
    Path::new(path)
        .file_name()
        .map_or(path.to_string(), |n| n.to_string_lossy().into_owned())
}

/// Pair poses with images: by the pose file's image column when every pose
/// names an image that was given, else by order (equal counts required).
fn pair_images(poses: &[RobotPose], images: &[String]) -> Result<Vec<Option<usize>>, CliError> {
    let names: Option<Vec<&str>> = poses.iter().map(|p| p.name.as_deref()).collect();
    if let Some(names) = names {
        let lookup = |n: &str| {
            images.iter().position(|img| {
                let f = file_name(img);
                f == n
                    || Path::new(&f)
                        .file_stem()
                        .is_some_and(|s| s.to_string_lossy() == n)
            })
        };
        let found: Vec<Option<usize>> = names.iter().map(|n| lookup(n)).collect();
        if found.iter().any(Option::is_some) {
            return Ok(found);
        }
    }
    if poses.len() != images.len() {
        return Err(CliError::usage(
            "handeye",
            format!(
                "{} robot poses but {} images: give one image per pose in the same order, \
                 or add an image column to the pose file",
                poses.len(),
                images.len()
            ),
        ));
    }
    Ok((0..poses.len()).map(Some).collect())
}

/// Detect the target in every image (on `threads` workers).
pub(super) fn detect_images(
    images: &[String],
    target: &Target,
    limits: &super::ImageLimits,
    threads: Option<usize>,
) -> Result<Vec<Outcome>, CliError> {
    run_all(
        images,
        target,
        &DetectOptions::default(),
        &limits.decode_options(),
        threads,
    )
}

/// Fit the target's pose in every detected image (`outcomes`, one per
/// image; a detection may hold any subset of the board's points) with the
/// known camera, pair with the robot poses and audit.
pub(super) fn image_pairs(
    setup: Setup,
    robot: RobotPoses,
    images: &[String],
    outcomes: Vec<Outcome>,
    camera: &Camera,
) -> Result<ImagePairs, CliError> {
    let mut warnings = Vec::new();
    let pairing = pair_images(robot.first(), images)?;
    let mut fitted: Vec<Result<(ViewPoints, Pose, f64), String>> = Vec::new();
    for outcome in outcomes {
        fitted.push(match outcome {
            Outcome::Found(detection, _) => {
                let (object, image) = detection.correspondences();
                let view = ViewPoints {
                    object_points: object,
                    image_points: image,
                };
                camera_from_target(camera, &view)
                    .map(|(pose, rms)| (view, pose, rms))
                    .map_err(|e| format!("target pose failed: {e}"))
            }
            Outcome::Failed(_, message) => Err(format!("detection failed: {message}")),
        });
    }
    let used: Vec<(usize, usize)> = pairing
        .iter()
        .enumerate()
        .filter_map(|(p, img)| img.filter(|&i| fitted[i].is_ok()).map(|i| (p, i)))
        .collect();
    let camera_from_target: Vec<Pose> = used
        .iter()
        .filter_map(|&(_, i)| fitted[i].as_ref().ok().map(|f| f.1))
        .collect();
    let chosen: Vec<RobotPose> = match robot {
        RobotPoses::Known(p) => p,
        RobotPoses::Ambiguous(candidates) => {
            let scored: Vec<(String, Vec<Pose>)> = candidates
                .iter()
                .map(|(name, poses)| {
                    let sub = used.iter().map(|&(p, _)| poses[p].base_from_gripper);
                    (name.clone(), sub.collect())
                })
                .collect();
            let ranked = rank_pose_candidates(setup, &scored, &camera_from_target);
            let best = ranked.first().map(|s| s.name.clone());
            let index = best
                .and_then(|b| candidates.iter().position(|c| c.0 == b))
                .unwrap_or(0);
            if let Some(text) = recommend_candidate(&ranked) {
                warnings.push(format!(
                    "the pose file's format is ambiguous; {text}: using it (pass --pose-format to choose)"
                ));
            }
            candidates
                .into_iter()
                .nth(index)
                .map_or(Vec::new(), |c| c.1)
        }
    };
    let mut pairs = Vec::new();
    let mut views = Vec::new();
    for (p, img) in pairing.iter().enumerate() {
        let mut audit = PairAudit {
            pose_index: p,
            image: img.map(|i| images[i].clone()),
            used: false,
            view: None,
            reason: None,
            pose_fit_rms_px: None,
        };
        match img.map(|i| &fitted[i]) {
            None => audit.reason = Some("no image names this pose".to_string()),
            Some(Err(why)) => audit.reason = Some(why.clone()),
            Some(Ok((view, _, rms))) => {
                audit.used = true;
                audit.view = Some(views.len());
                audit.pose_fit_rms_px = Some(*rms);
                views.push(view.clone());
            }
        }
        pairs.push(audit);
    }
    let dropped = pairs.iter().filter(|p| !p.used).count();
    if dropped > 0 {
        warnings.push(format!(
            "{dropped} of {} poses were dropped with their image (see pairs)",
            pairs.len()
        ));
    }
    let unpaired = images.len() - pairing.iter().flatten().count();
    if unpaired > 0 {
        warnings.push(format!(
            "{unpaired} images were not named in the pose file and were ignored"
        ));
    }
    Ok(ImagePairs {
        base_from_gripper: used
            .iter()
            .map(|&(p, _)| chosen[p].base_from_gripper)
            .collect(),
        camera_from_target,
        views,
        pairs,
        warnings,
    })
}
