//! The image path of `robocal handeye`: robot poses read with the pose-file
//! parser (ambiguous files ranked against the camera motion), images paired
//! with poses (by the pose file's image column, else by order), detected,
//! a target pose fitted per image with the known camera, and the pairing
//! audited.

use super::detect::{run_all, Outcome};
pub(super) use super::robot_poses::RobotPoses;
use super::CliError;
use robocal::calib::pnp::camera_from_target;
use robocal::calib::View;
use robocal::camera::Camera;
use robocal::detect::DetectOptions;
use robocal::handeye::quality::checks::{rank_pose_candidates, recommend_candidate};
use robocal::handeye::quality::pairing::better_rule;
use robocal::handeye::report::PairAudit;
use robocal::handeye::{Pose, Setup};
use robocal::io::pose_pairing::{alternatives, numeric_order, pair_poses};
use robocal::io::RobotPose;
use robocal::target::Target;

/// What the images gave: the used pairs and the audit of every pose.
pub(super) struct ImagePairs {
    /// Robot poses of the used pairs (`base_from_gripper`).
    pub base_from_gripper: Vec<Pose>,
    /// Target poses fitted to the used images.
    pub camera_from_target: Vec<Pose>,
    /// Image points of the used images.
    pub views: Vec<View>,
    /// Every pose with its image and fate.
    pub pairs: Vec<PairAudit>,
    /// Warnings about pairing and pose-format choice.
    pub warnings: Vec<String>,
}

/// How poses pair with images (`--pair-by`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum PairBy {
    /// By the pose file's image column when it has one, else numeric order.
    Auto,
    /// Pose i with the i-th image in numeric order of the file names.
    Numeric,
    /// Pose i with the i-th image in byte order of the file names.
    Lexicographic,
    /// Pose i with the i-th image as given on the command line.
    Given,
}

impl std::str::FromStr for PairBy {
    type Err = CliError;
    fn from_str(s: &str) -> Result<Self, CliError> {
        match s {
            "auto" => Ok(PairBy::Auto),
            "numeric" => Ok(PairBy::Numeric),
            "lexicographic" => Ok(PairBy::Lexicographic),
            "given" => Ok(PairBy::Given),
            other => Err(CliError::usage(
                "handeye",
                format!(
                    "--pair-by: unknown rule '{other}' (valid: auto, numeric, lexicographic, given)"
                ),
            )),
        }
    }
}

impl PairBy {
    fn describe(self) -> &'static str {
        match self {
            PairBy::Auto => "as paired",
            PairBy::Numeric => "in numeric order of the file names",
            PairBy::Lexicographic => "in lexicographic order of the file names",
            PairBy::Given => "in the order the images were given",
        }
    }
}

/// Poses paired with images by `rule` (module docs of
/// `robocal::io::pose_pairing`): for each pose its image, how it was
/// paired, and the images no pose names.
pub(super) fn pair_images(
    poses: &[RobotPose],
    images: &[String],
    rule: PairBy,
) -> Result<(Vec<usize>, &'static str, Vec<usize>), CliError> {
    let paths: Vec<&str> = images.iter().map(String::as_str).collect();
    let order: Vec<usize> = match rule {
        PairBy::Auto => {
            let names: Vec<Option<&str>> = poses.iter().map(|p| p.name.as_deref()).collect();
            let rows: Vec<usize> = poses.iter().map(|p| p.line).collect();
            let p = pair_poses(&names, &rows, &paths)?;
            return Ok((p.image_of_pose, p.paired_by.describe(), p.unnamed_images));
        }
        PairBy::Numeric => numeric_order(&paths),
        PairBy::Lexicographic => {
            let mut o: Vec<usize> = (0..paths.len()).collect();
            o.sort_by(|&a, &b| paths[a].cmp(paths[b]));
            o
        }
        PairBy::Given => (0..paths.len()).collect(),
    };
    if poses.len() != images.len() {
        return Err(CliError::usage(
            "handeye",
            format!(
                "{} robot poses but {} images: --pair-by {} pairs one image per pose",
                poses.len(),
                images.len(),
                match rule {
                    PairBy::Numeric => "numeric",
                    PairBy::Lexicographic => "lexicographic",
                    _ => "given",
                }
            ),
        ));
    }
    Ok((order, rule.describe(), Vec::new()))
}

/// Detect the target in every image (on `threads` workers).
pub(super) fn detect_images(
    images: &[String],
    target: &Target,
    options: &DetectOptions,
    limits: &super::ImageLimits,
    threads: Option<usize>,
) -> Result<Vec<Outcome>, CliError> {
    run_all(images, target, options, &limits.decode_options(), threads)
}

/// The pairing of poses with images, made before any image is detected.
pub(super) struct PosePairs {
    /// For each pose, the index of its image.
    pub image_of_pose: Vec<usize>,
    /// How the pairing was made, for messages.
    pub how: &'static str,
    /// Images no pose names.
    pub unnamed_images: Vec<usize>,
}

/// Fit the target's pose in every detected image (`outcomes`, one per
/// image; a detection may hold any subset of the board's points) with the
/// known camera, pair with the robot poses, prove the pairing against the
/// camera motion and audit. `strict`: a pairing that another simple rule
/// explains better is an error (else a warning).
pub(super) fn image_pairs(
    setup: Setup,
    robot: RobotPoses,
    images: &[String],
    outcomes: Vec<Outcome>,
    camera: &Camera,
    pairing: &PosePairs,
    strict: bool,
) -> Result<ImagePairs, CliError> {
    let mut warnings = Vec::new();
    let mut fitted: Vec<Result<(View, Pose, f64), String>> = Vec::new();
    for outcome in outcomes {
        fitted.push(match outcome {
            Outcome::Found(detection, _) => {
                let (object, image) = detection.correspondences();
                let view = View::new("", object, image);
                camera_from_target(camera, &view)
                    .map(|(pose, rms)| (view, pose, rms))
                    .map_err(|e| format!("target pose failed: {e}"))
            }
            Outcome::Failed(_, message) => Err(format!("detection failed: {message}")),
        });
    }
    let used: Vec<(usize, usize)> = pairing
        .image_of_pose
        .iter()
        .enumerate()
        .filter(|&(_, &i)| fitted[i].is_ok())
        .map(|(p, &i)| (p, i))
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
    if let Some(message) = check_pairing(setup, &chosen, images, &fitted, pairing, &used) {
        if strict {
            return Err(robocal::Error::invalid("pairing", message).into());
        }
        warnings.push(format!("pairing: {message}"));
    }
    let mut pairs = Vec::new();
    let mut views = Vec::new();
    for (p, &i) in pairing.image_of_pose.iter().enumerate() {
        let mut audit = PairAudit {
            pose_index: p,
            image: Some(images[i].clone()),
            used: false,
            view: None,
            reason: None,
            pose_fit_rms_px: None,
        };
        match &fitted[i] {
            Err(why) => audit.reason = Some(why.clone()),
            Ok((view, _, rms)) => {
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
    let unpaired = pairing.unnamed_images.len();
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

/// Prove the pairing against the camera motion: when another simple rule
/// (numeric or lexicographic order, the order given) fits the rotation
/// angles of the motions and the pairing made does not, say which
/// (`robocal::handeye::quality::pairing`).
fn check_pairing(
    setup: Setup,
    robot: &[RobotPose],
    images: &[String],
    fitted: &[Result<(View, Pose, f64), String>],
    pairing: &PosePairs,
    used: &[(usize, usize)],
) -> Option<String> {
    let paths: Vec<&str> = images.iter().map(String::as_str).collect();
    let given: Vec<(usize, usize)> = pairing.image_of_pose.iter().copied().enumerate().collect();
    let fits = |i: usize| fitted[i].is_ok();
    let rules: Vec<_> = alternatives(robot.len(), &paths, &given)
        .into_iter()
        .map(|mut r| {
            r.pairs.retain(|&(_, i)| fits(i));
            r
        })
        .collect();
    let base: Vec<Pose> = robot.iter().map(|p| p.base_from_gripper).collect();
    let cameras: Vec<Pose> = fitted
        .iter()
        .map(|f| f.as_ref().map_or(Pose::identity(), |f| f.1))
        .collect();
    let fit = better_rule(setup, &base, &cameras, used, &rules)?;
    Some(format!(
        "{}: the rotation angles of the robot and camera motions agree to {:.3} deg (median) \
         when paired {}, against {:.3} deg as paired {}: {}",
        fit.rule.finding,
        fit.mismatch_deg,
        fit.rule
            .name
            .trim_start_matches("robot pose i with the i-th image "),
        fit.given_mismatch_deg,
        pairing.how,
        fit.rule.fix
    ))
}
