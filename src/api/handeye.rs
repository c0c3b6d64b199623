//! The request and report of hand-eye calibration: the JSON entry point of
//! the wasm boundary and npm (`solve_handeye`, [`solve_handeye_json`]), and
//! [`solve_handeye`], the one orchestration (closed forms, then the
//! refinement over pixels or over the poses) it shares with `robocal
//! handeye`, whose pose files, images and pairing audit stay in the CLI.
//!
//! Input: `{"setup": "eye-in-hand" | "eye-to-hand", "base_from_gripper":
//! [pose...], "camera_from_target": [pose...], "method": "all" | NAME,
//! "bootstrap_samples": 100, "seed": 1, "strict_checks": true, "refine_poses":
//! true}` (`refine_poses`: the maximum-likelihood pose refinement of
//! [`crate::handeye::refine::over_poses`], on by default for pose input and for image
//! points under `refine` none, the default; unused by the other modes) where a pose
//! is a [`PoseInput`]: `{"matrix_row_major": [[4 numbers] x 4]}`,
//! `{"translation_m": [x, y, z], "quaternion_xyzw": [x, y, z, w]}` (metres)
//! or all three (a report's [`crate::geometry::PoseJson`]). Output: the
//! [`crate::handeye::report::HandEyeReport`] JSON.
//!
//! Image points (optional): `"camera"` (a camera JSON: the robocal camera
//! serde, a calibration report, or a string holding any format
//! [`crate::io::import_camera::import_camera`] reads), `"views": [{"object_m":
//! [[x, y, z]...], "image_px": [[u, v]...]}]` (one per pose, same order),
//! `"refine": "none" | "trusted" | "stochastic" | "joint_intrinsics"`
//! (default `none`: with views the maximum likelihood over the poses, each
//! view's PnP covariance from its points, see [`RefineMode`]) and
//! `"pixel_sigma_px"` (default 0.5), and `"camera_std"` (optional, `{"fx": std, ...}` in
//! pixels; read from `camera` when that is a calibration report): with it, a
//! joint refinement that moves an intrinsic by many standard deviations is
//! warned about ([`crate::handeye::quality::intrinsics_move`]). With views, `camera_from_target` may be
//! left out: it is then computed per view by [`crate::calib::pnp`]. Instead of
//! `"views"`, `"detections"` may give one detection JSON per pose (the
//! [`crate::target::Detection`] format, as `detect_target` returns it): the
//! board points then come from each detection's own target.
//!
//! Field checks (optional, [`crate::api::handeye_field`]): `"tcp_m"`,
//! `"holdout"`, `"touch"`.

use crate::calib::View;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::PoseInput;
use crate::handeye::quality::checks::{
    rank_pose_candidates, recommend_candidate, setup_advice, CandidateScore, SetupAdvice,
};
use crate::handeye::quality::intrinsics_move::{std_from_json, warn_intrinsic_move};
use crate::handeye::quality::trust::place_work_point;
use crate::handeye::quality::work_point::Placement;
use crate::handeye::refine::over_pixels::RefineMode;
use crate::handeye::report::HandEyeReport;
use crate::handeye::solve::{
    apply_refinement, calibrate, HandEyeInput, HandEyeOptions, DEFAULT_BOOTSTRAP_SAMPLES,
};
use crate::handeye::{HandEyeMethod, Pose, Setup};
use crate::target::Detection;
use nalgebra::{Point2, Point3, Vector3};
use serde::{Deserialize, Serialize};

/// Default expected pixel noise of the refinement (px).
pub const DEFAULT_PIXEL_SIGMA_PX: f64 = 0.5;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ViewIn {
    object_m: Vec<[f64; 3]>,
    image_px: Vec<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InputJson {
    setup: Setup,
    base_from_gripper: Vec<PoseInput>,
    #[serde(default)]
    camera_from_target: Option<Vec<PoseInput>>,
    #[serde(default)]
    camera: Option<serde_json::Value>,
    #[serde(default)]
    camera_std: Option<std::collections::BTreeMap<String, f64>>,
    #[serde(default)]
    views: Option<Vec<ViewIn>>,
    #[serde(default)]
    detections: Option<Vec<Detection>>,
    #[serde(default)]
    refine: Option<String>,
    #[serde(default)]
    pixel_sigma_px: Option<f64>,
    #[serde(default)]
    method: Option<String>,
    #[serde(default)]
    bootstrap_samples: Option<usize>,
    #[serde(default)]
    seed: Option<u64>,
    #[serde(default)]
    strict_checks: Option<bool>,
    #[serde(default)]
    refine_poses: Option<bool>,
    #[serde(default)]
    tcp_m: Option<[f64; 3]>,
    #[serde(default)]
    holdout: Option<usize>,
    #[serde(default)]
    touch: Option<Vec<crate::handeye::quality::verify::TouchPoint>>,
}

fn to_pose(p: &PoseInput, field: &str, index: usize) -> Result<Pose> {
    p.to_pose()
        .map_err(|e| Error::invalid(format!("{field}[{index}]"), e.to_string()))
}

/// A camera from JSON: the [`Camera`] serde form, a calibration report
/// (`{"report": {...}}` or its inner object), an object with a `camera` key
/// (e.g. `robocal render`'s truth.json), or a string with any text
/// [`crate::io::import_camera::import_camera`] reads.
pub fn camera_from_json(value: &serde_json::Value) -> Result<Camera> {
    let located = |e: Error| Error::invalid("camera", e.to_string());
    match value {
        serde_json::Value::String(text) => crate::io::import_camera::import_camera(text)
            .map(|c| c.0)
            .map_err(located),
        serde_json::Value::Object(map) if map.get("report").is_some_and(|r| r.is_object()) => {
            camera_from_json(&map["report"])
        }
        serde_json::Value::Object(map) if map.get("camera").is_some_and(|c| c.is_object()) => {
            camera_from_json(&map["camera"])
        }
        // Through the text (as every JSON input is read) rather than
        // `from_value`: one deserializer instantiation per type in the wasm.
        serde_json::Value::Object(map) if map.contains_key("fx") => {
            serde_json::from_str(&value.to_string())
                .map_err(|e| Error::invalid("camera", e.to_string()))
        }
        other => crate::io::import_camera::import_camera(&other.to_string())
            .map(|c| c.0)
            .map_err(located),
    }
}

fn to_views(list: &[ViewIn]) -> Result<Vec<View>> {
    list.iter()
        .enumerate()
        .map(|(i, v)| {
            if v.object_m.len() != v.image_px.len() {
                return Err(Error::invalid(
                    format!("views[{i}]"),
                    format!(
                        "{} object points but {} pixels",
                        v.object_m.len(),
                        v.image_px.len()
                    ),
                ));
            }
            Ok(View::new(
                "",
                v.object_m.iter().map(|p| Point3::from(*p)).collect(),
                v.image_px.iter().map(|p| Point2::from(*p)).collect(),
            ))
        })
        .collect()
}

/// The board points and pixels of each detection, in id order.
fn views_from_detections(list: &[Detection]) -> Vec<View> {
    list.iter()
        .map(|d| {
            let (object_points, image_points) = d.correspondences();
            View::new("", object_points, image_points)
        })
        .collect()
}

/// Views whose planar board points cannot fix a pose (fewer than 4, or all
/// but one on a line: [`crate::calib::homography_problem`]) are left out
/// with their robot pose (and given camera pose), each with a warning.
/// A view list whose length differs from the poses' is kept whole, for the
/// solver to refuse with its own message.
fn leave_out_degenerate(views: Vec<View>, input: &mut InputJson) -> (Vec<View>, Vec<String>) {
    if views.len() != input.base_from_gripper.len() {
        return (views, Vec::new());
    }
    let problems: Vec<Option<String>> = views
        .iter()
        .map(|v| {
            let planar = v.object_m.iter().all(|p| p.z == 0.0);
            let board: Vec<Point2<f64>> = v.object_m.iter().map(|p| p.xy()).collect();
            crate::calib::homography_problem(&board).filter(|_| planar)
        })
        .collect();
    if problems.iter().all(Option::is_none) {
        return (views, Vec::new());
    }
    let keep = |list: &mut Vec<PoseInput>| {
        let mut i = 0;
        list.retain(|_| {
            i += 1;
            problems.get(i - 1).is_some_and(Option::is_none)
        });
    };
    keep(&mut input.base_from_gripper);
    if let Some(list) = input
        .camera_from_target
        .as_mut()
        .filter(|l| l.len() == problems.len())
    {
        keep(list);
    }
    let warnings = problems
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            p.as_ref()
                .map(|why| format!("view {i} left out with its robot pose: {why}"))
        })
        .collect();
    let kept = views
        .into_iter()
        .zip(&problems)
        .filter(|(_, p)| p.is_none())
        .map(|(v, _)| v)
        .collect();
    (kept, warnings)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CandidateIn {
    name: String,
    base_from_gripper: Vec<PoseInput>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RankInput {
    setup: Setup,
    candidates: Vec<CandidateIn>,
    camera_from_target: Vec<PoseInput>,
}

/// The answer of [`rank_candidates_json`].
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RankedCandidates {
    /// Every candidate scored against the camera motion, best first.
    pub scores: Vec<CandidateScore>,
    /// What to use and how clear the choice is, when any candidate scored.
    pub recommendation: Option<String>,
}

/// Rank candidate readings of the robot poses (e.g. the rotation conventions
/// a pose file could be in) by how well each fits the camera motion
/// ([`rank_pose_candidates`]). Input `{"setup", "candidates": [{"name",
/// "base_from_gripper": [pose...]}], "camera_from_target": [pose...]}`;
/// returns the [`RankedCandidates`] JSON.
pub fn rank_candidates_json(input_json: &str) -> Result<String> {
    let input: RankInput = serde_json::from_str(input_json)
        .map_err(|e| Error::parse(e.line(), e.column(), e.to_string()))?;
    if input.candidates.is_empty() {
        return Err(Error::too_few("pose candidates", 1, 0));
    }
    let camera = input
        .camera_from_target
        .iter()
        .enumerate()
        .map(|(i, p)| to_pose(p, "camera_from_target", i))
        .collect::<Result<Vec<Pose>>>()?;
    let candidates = input
        .candidates
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let field = format!("candidates[{k}].base_from_gripper");
            let poses = c
                .base_from_gripper
                .iter()
                .enumerate()
                .map(|(i, p)| to_pose(p, &field, i))
                .collect::<Result<Vec<Pose>>>()?;
            Ok((c.name.clone(), poses))
        })
        .collect::<Result<Vec<(String, Vec<Pose>)>>>()?;
    let scores = rank_pose_candidates(input.setup, &candidates, &camera);
    // A setup that fits better comes first: no reading fixes a wrong setup.
    let recommendation = match setup_advice(input.setup, &candidates, &camera, &scores) {
        Some(SetupAdvice::OtherFits(text)) => Some(text),
        Some(SetupAdvice::BothFit(note)) => {
            recommend_candidate(&scores).map(|r| format!("{r}; {note}"))
        }
        None => recommend_candidate(&scores),
    };
    serde_json::to_string(&RankedCandidates {
        scores,
        recommendation,
    })
    .map_err(|e| Error::invalid("ranking", e.to_string()))
}

/// Solve from input JSON; returns the report JSON.
pub fn solve_handeye_json(input_json: &str) -> Result<String> {
    let mut input: InputJson = serde_json::from_str(input_json)
        .map_err(|e| Error::parse(e.line(), e.column(), e.to_string()))?;
    let poses = |list: &[PoseInput], field: &str| -> Result<Vec<Pose>> {
        list.iter()
            .enumerate()
            .map(|(i, p)| to_pose(p, field, i))
            .collect()
    };
    let mut options = HandEyeOptions {
        bootstrap_samples: input.bootstrap_samples.unwrap_or(DEFAULT_BOOTSTRAP_SAMPLES),
        seed: input.seed.unwrap_or(1),
        strict_checks: input.strict_checks.unwrap_or(true),
        ..Default::default()
    };
    // The pose refinement is the pose path's; with image points the
    // refinement over pixels (`refine`) takes its place.
    options.refine_poses =
        input.refine_poses.unwrap_or(true) && input.views.is_none() && input.detections.is_none();
    match input.method.as_deref() {
        None | Some("all") => {}
        Some(name) => options.methods = vec![name.parse::<HandEyeMethod>()?],
    }
    let views = match (&input.views, &input.detections) {
        (Some(_), Some(_)) => {
            return Err(Error::invalid(
                "detections",
                "give either 'views' or 'detections', not both",
            ))
        }
        (Some(list), None) => Some(to_views(list)?),
        (None, Some(list)) => Some(views_from_detections(list)),
        (None, None) => None,
    };
    let (views, left_out) = match views {
        Some(v) => {
            let (kept, left_out) = leave_out_degenerate(v, &mut input);
            (Some(kept), left_out)
        }
        None => (None, Vec::new()),
    };
    let camera = input.camera.as_ref().map(camera_from_json).transpose()?;
    // Default `none`: with image points the pose refinement with each
    // view's PnP covariance runs (below), the best estimate measured.
    let mode = match &input.refine {
        Some(name) => name.parse::<RefineMode>()?,
        None => RefineMode::None,
    };
    let needs_images = mode != RefineMode::None || input.camera_from_target.is_none();
    let images = match (views, camera) {
        (Some(v), Some(c)) => Some((v, c)),
        (v, c) if needs_images || v.is_some() || c.is_some() => {
            let missing = if v.is_none() { "views" } else { "camera" };
            let why = match input.camera_from_target {
                None => "camera_from_target is absent".to_string(),
                Some(_) if mode != RefineMode::None => format!("refine is {}", mode.name()),
                Some(_) => "image points were given".to_string(),
            };
            return Err(Error::invalid(
                missing,
                format!("'{missing}' is required because {why}"),
            ));
        }
        _ => None,
    };
    let camera_from_target = match (&input.camera_from_target, &images) {
        (Some(list), _) => poses(list, "camera_from_target")?,
        (None, Some((views, camera))) => views
            .iter()
            .enumerate()
            .map(|(i, v)| {
                crate::calib::pnp::camera_from_target(camera, v)
                    .map(|p| p.0)
                    .map_err(|e| Error::invalid(format!("views[{i}]"), e.to_string()))
            })
            .collect::<Result<Vec<Pose>>>()?,
        (None, None) => Vec::new(),
    };
    let request = HandEyeInput {
        setup: input.setup,
        base_from_gripper: poses(&input.base_from_gripper, "base_from_gripper")?,
        camera_from_target,
    };
    let std = (input.camera_std.clone()).or_else(|| input.camera.as_ref().and_then(std_from_json));
    let points = images.as_ref().map(|(views, camera)| ImagePoints {
        views,
        camera,
        camera_std: std.as_ref(),
        refine: mode,
        pixel_sigma_px: input.pixel_sigma_px.unwrap_or(DEFAULT_PIXEL_SIGMA_PX),
        refine_poses: input.refine_poses.unwrap_or(true),
    });
    let with_left_out = |e: Error| match e {
        Error::TooFew { .. } if !left_out.is_empty() => {
            Error::invalid("views", format!("{e}; {}", left_out.join(", ")))
        }
        other => other,
    };
    let field = crate::api::handeye_field::FieldRequest {
        tcp_m: input.tcp_m,
        holdout: input.holdout.unwrap_or(0),
        touch: input.touch.clone().unwrap_or_default(),
        camera: images.as_ref().map(|(_, c)| c.clone()),
    };
    let report = crate::api::handeye_field::solve_handeye_field(
        &request,
        &options,
        points.as_ref(),
        left_out.clone(),
        &field,
    )
    .map_err(with_left_out)?;
    serde_json::to_string(&report).map_err(|e| Error::invalid("report", e.to_string()))
}

/// The image points of a hand-eye calibration and what to do with them.
#[derive(Clone, Copy, Debug)]
pub struct ImagePoints<'a> {
    /// The board points and pixels of each pose pair's view, in pair order.
    pub views: &'a [View],
    /// The camera that took them (held unless `refine` moves it).
    pub camera: &'a Camera,
    /// The camera calibration's standard deviations (`{"fx": std, ...}`,
    /// px), when known: a joint refinement that moves an intrinsic by many
    /// of them is warned about.
    pub camera_std: Option<&'a std::collections::BTreeMap<String, f64>>,
    /// The refinement over pixels ([`RefineMode::None`]: none).
    pub refine: RefineMode,
    /// Expected pixel noise of that refinement, px.
    pub pixel_sigma_px: f64,
    /// Without a refinement over pixels: the pose refinement with each
    /// view's PnP covariance from its image points.
    pub refine_poses: bool,
}

/// The one hand-eye orchestration of `solve_handeye` (wasm, npm) and
/// `robocal handeye`: the closed forms and checks of [`calibrate`], then,
/// with image points, the refinement over pixels or the pose refinement
/// from each view's PnP covariance; `warnings_first` (views or images left
/// out before the solve) lead the report's warnings.
pub fn solve_handeye(
    input: &HandEyeInput,
    options: &HandEyeOptions,
    images: Option<&ImagePoints>,
    warnings_first: Vec<String>,
) -> Result<HandEyeReport> {
    let mut result = calibrate(input, options)?;
    if let Some(points) = images {
        apply_refinement(
            &mut result,
            input,
            points.views,
            points.camera,
            points.refine,
            options.motion_pairs,
            points.pixel_sigma_px,
        )?;
        warn_intrinsic_move(&mut result, points.camera, points.camera_std);
        // No refinement over pixels: the pose refinement, with each view's
        // PnP covariance from its image points.
        if points.refine == RefineMode::None && points.refine_poses {
            crate::handeye::solve::apply_pose_refinement_from_views(
                &mut result,
                input,
                points.views,
                (
                    points.camera,
                    points.camera_std.and_then(|s| s.get("fx").copied()),
                ),
                options.motion_pairs,
            )?;
        }
    }
    if let (Some(points), Some(summary)) = (images, result.pose_refinement.as_mut()) {
        // The board points are known: the default work point is their
        // centre, not the target frame's origin.
        if let Some(centre) = board_centre(points.views) {
            place_work_point(
                summary,
                &result.x,
                &input.camera_from_target,
                &centre,
                Placement::BoardCentre,
            );
        }
    }
    result.warnings.splice(0..0, warnings_first);
    HandEyeReport::checked(&result)
}

/// The centre of the board points of every view (target frame; a point
/// seen in several views counts as often), `None` without points.
pub fn board_centre(views: &[View]) -> Option<Point3<f64>> {
    let all: Vec<&Point3<f64>> = views.iter().flat_map(|v| &v.object_m).collect();
    if all.is_empty() {
        return None;
    }
    let sum = all.iter().fold(Vector3::zeros(), |a, p| a + p.coords);
    Some(Point3::from(sum / all.len() as f64))
}
