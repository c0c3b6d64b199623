//! Hand-eye calibration of a camera rig: where the whole rig sits on the
//! robot (eye-in-hand, `gripper_from_rig`) or in its world (eye-to-hand,
//! `base_from_rig`), from every camera's views together.
//!
//! The rig is held (its intrinsics and `camera_from_rig` from a rig
//! calibration). Each frame's board pose in the rig frame comes from all
//! cameras that saw the board in it ([`crate::handeye::rig::pnp`]); the rig frame then
//! plays the camera of the single-camera problem: the closed forms
//! ([`crate::handeye::calibrate`]) and the maximum-likelihood pose refinement with
//! each frame's multi-camera PnP covariance ([`CameraNoise::PerView`]).
//! Every camera's own transform follows as `x * camera_from_rig[k]^-1`.
//!
//! The refinement's std hold the rig fixed; [`add_rig_uncertainty`] adds
//! the rig calibration's own covariance ([`crate::handeye::rig::uncertainty`]).

pub mod pnp;
pub mod uncertainty;

use crate::calib::View;
use crate::error::{Error, Result};
use crate::geometry::{rotvec_from_rotation, PoseJson};
use crate::handeye::refine::pose_noise::CameraNoise;
use crate::handeye::refine::pose_problem::Covariance12;
use crate::handeye::refine::pose_summary::{transform_std, TransformStd};
use crate::handeye::report::HandEyeReport;
use crate::handeye::rig::pnp::{rig_from_target, HeldRig};
use crate::handeye::solve::apply_pose_refinement;
use crate::handeye::{calibrate, HandEyeInput, HandEyeOptions, HandEyeResult, Pose, Setup};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// One frame of the rig hand-eye: its robot pose and what became of it.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RigHandEyeFrame {
    /// The frame's key (the number in the image names, or the position).
    pub key: String,
    /// Index of its robot pose in the pose file (0-based, data rows).
    pub pose_index: usize,
    /// Whether the frame entered the hand-eye calibration.
    pub used: bool,
    /// The cameras whose points fixed the board pose.
    pub cameras: Vec<String>,
    /// Reprojection RMS of the board pose over those cameras (px).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub pose_fit_rms_px: Option<f64>,
    /// Why the frame was left out.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub reason: Option<String>,
}

/// The solved rig hand-eye: the single-camera result with the rig frame as
/// the camera, and the per-frame audit.
#[derive(Debug, Clone)]
pub struct RigHandEyeResult {
    /// `x` is `gripper_from_rig` (eye-in-hand) or `base_from_rig`.
    pub result: HandEyeResult,
    /// Every frame, used or not.
    pub frames: Vec<RigHandEyeFrame>,
    /// Whether the std include the rig's own uncertainty.
    pub rig_uncertainty: RigUncertainty,
}

/// What the reported std of the rig transform rest on (the report's
/// `rig_uncertainty`).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RigUncertainty {
    /// Whether `pose_refinement`'s std and covariance include the rig
    /// calibration's uncertainty (`false`: conditional on the rig).
    pub included: bool,
    /// In words: what the std include, or why not the rig's uncertainty.
    pub note: String,
    /// Hand-eye solutions evaluated at the rig moved along its covariance.
    pub sigma_points: usize,
    /// The std with the rig held (the pose refinement's own), when the
    /// rig's uncertainty was added.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub conditional_camera_transform_std: Option<TransformStd>,
    /// Likewise for the target transform.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub conditional_target_transform_std: Option<TransformStd>,
}

/// The note when no rig covariance is at hand.
pub const CONDITIONAL_NOTE: &str = "the std are conditional on the rig: its intrinsics and \
    camera_from_rig are held as exact (the rig carries no covariance)";

/// Solve the rig's hand-eye. `frames[f]` holds the views of frame `f`
/// (camera index, points), `keys[f]` its key, `base_from_gripper[f]` its
/// robot pose: one pose per frame, in frame order. Frames that no camera's
/// points pin down are left out with their pose (see `frames`).
pub fn calibrate_rig_handeye(
    setup: Setup,
    rig: &HeldRig,
    names: &[String],
    keys: &[String],
    frames: &[Vec<(usize, View)>],
    base_from_gripper: &[Pose],
    options: &HandEyeOptions,
) -> Result<RigHandEyeResult> {
    if base_from_gripper.len() != frames.len() {
        return Err(Error::invalid(
            "poses",
            format!(
                "{} robot poses but {} frames: give one robot pose per frame, in frame order",
                base_from_gripper.len(),
                frames.len()
            ),
        ));
    }
    let mut audit = Vec::with_capacity(frames.len());
    let mut input = HandEyeInput {
        setup,
        base_from_gripper: Vec::new(),
        camera_from_target: Vec::new(),
    };
    let mut covariances = Vec::new();
    for (f, views) in frames.iter().enumerate() {
        let mut entry = RigHandEyeFrame {
            key: keys.get(f).cloned().unwrap_or_else(|| f.to_string()),
            pose_index: f,
            used: false,
            cameras: views
                .iter()
                .map(|(k, _)| names.get(*k).cloned().unwrap_or_else(|| k.to_string()))
                .collect(),
            pose_fit_rms_px: None,
            reason: None,
        };
        if views.is_empty() {
            entry.reason = Some("no camera saw the board".into());
        } else {
            match rig_from_target(rig, views) {
                Ok(p) => {
                    entry.used = true;
                    entry.pose_fit_rms_px = Some(p.rms_px);
                    input.base_from_gripper.push(base_from_gripper[f]);
                    input.camera_from_target.push(p.rig_from_target);
                    covariances.push(p.covariance);
                }
                Err(e) => entry.reason = Some(e.to_string()),
            }
        }
        audit.push(entry);
    }
    let closed = HandEyeOptions {
        refine_poses: false,
        ..options.clone()
    };
    let mut result = calibrate(&input, &closed).map_err(|e| match e {
        Error::TooFew { .. } => {
            let left: Vec<String> = audit
                .iter()
                .filter(|a| !a.used)
                .map(|a| format!("frame {} ({})", a.key, a.reason.as_deref().unwrap_or("")))
                .collect();
            if left.is_empty() {
                e
            } else {
                Error::invalid(
                    "frames",
                    format!("{e}; left out with their pose: {}", left.join(", ")),
                )
            }
        }
        other => other,
    })?;
    if options.refine_poses {
        apply_pose_refinement(
            &mut result,
            &input,
            CameraNoise::PerView(covariances),
            options.motion_pairs,
        )?;
    }
    Ok(RigHandEyeResult {
        result,
        frames: audit,
        rig_uncertainty: RigUncertainty {
            included: false,
            note: CONDITIONAL_NOTE.into(),
            sigma_points: 0,
            conditional_camera_transform_std: None,
            conditional_target_transform_std: None,
        },
    })
}

/// Widen the pose refinement's covariance by the rig's own: re-solve at
/// every sigma point of the rig ([`crate::handeye::rig::uncertainty::rig_sigma_points`])
/// with the frames and poses `solved` came from, and add `sum d d^T`. The
/// conditional std move to `rig_uncertainty`. Without a pose refinement, or
/// when a re-solve fails, the std stay conditional and the note says why.
#[allow(clippy::too_many_arguments)]
pub fn add_rig_uncertainty(
    solved: &mut RigHandEyeResult,
    sigma_points: &[[HeldRig; 2]],
    source: &str,
    frames: &[Vec<(usize, View)>],
    base_from_gripper: &[Pose],
    options: &HandEyeOptions,
) -> Result<()> {
    let Some(summary) = solved.result.pose_refinement.clone() else {
        solved.rig_uncertainty.note =
            "no pose refinement ran: no std to widen by the rig's uncertainty".into();
        return Ok(());
    };
    let used: Vec<usize> = (0..solved.frames.len())
        .filter(|&f| solved.frames[f].used)
        .collect();
    let base = &solved.result;
    let mut spread = Covariance12::zeros();
    for pair in sigma_points {
        let mut ends = Vec::with_capacity(2);
        for rig in pair {
            match resolve(base, rig, &used, frames, base_from_gripper, options) {
                Ok(end) => ends.push(end),
                Err(e) => {
                    solved.rig_uncertainty.note = format!(
                        "{CONDITIONAL_NOTE}: a re-solve at the rig moved by one std failed ({e})"
                    );
                    return Ok(());
                }
            }
        }
        let d = (ends[0] - ends[1]) * 0.5;
        spread += d * d.transpose();
    }
    let conditional = Covariance12::from_fn(|r, c| summary.covariance[r][c]);
    let total = conditional + spread;
    let refinement = solved
        .result
        .pose_refinement
        .as_mut()
        .ok_or_else(|| Error::degenerate("the pose refinement vanished"))?;
    refinement.camera_transform_std = transform_std(&total, 0);
    refinement.target_transform_std = transform_std(&total, 6);
    refinement.covariance = (0..12)
        .map(|r| std::array::from_fn(|c| total[(r, c)]))
        .collect();
    solved.rig_uncertainty = RigUncertainty {
        included: true,
        note: format!(
            "the std include the rig's own uncertainty ({source}), propagated through {} \
             re-solves at the rig moved by one std along each principal axis",
            2 * sigma_points.len()
        ),
        sigma_points: 2 * sigma_points.len(),
        conditional_camera_transform_std: Some(summary.camera_transform_std),
        conditional_target_transform_std: Some(summary.target_transform_std),
    };
    Ok(())
}

/// The hand-eye at a moved rig, from the solution `base`: each used frame's
/// pose, then the pose refinement; returns `[x, y]`'s difference from
/// `base` (rotation in the left frame, rad; translation, m).
fn resolve(
    base: &HandEyeResult,
    rig: &HeldRig,
    used: &[usize],
    frames: &[Vec<(usize, View)>],
    base_from_gripper: &[Pose],
    options: &HandEyeOptions,
) -> Result<Vector12> {
    let mut input = HandEyeInput {
        setup: base.setup,
        base_from_gripper: Vec::with_capacity(used.len()),
        camera_from_target: Vec::with_capacity(used.len()),
    };
    let mut covariances = Vec::with_capacity(used.len());
    for &f in used {
        let p = rig_from_target(rig, &frames[f])?;
        input.base_from_gripper.push(base_from_gripper[f]);
        input.camera_from_target.push(p.rig_from_target);
        covariances.push(p.covariance);
    }
    let mut moved = base.clone();
    moved.repeatability = None;
    moved.pose_refinement = None;
    apply_pose_refinement(
        &mut moved,
        &input,
        CameraNoise::PerView(covariances),
        options.motion_pairs,
    )?;
    if moved.pose_refinement.is_none() {
        return Err(Error::degenerate(
            moved.warnings.last().cloned().unwrap_or_default(),
        ));
    }
    let mut d = Vector12::zeros();
    for (o, (got, at)) in [(0, (&moved.x, &base.x)), (6, (&moved.y, &base.y))] {
        let r = rotvec_from_rotation(&(got.rotation * at.rotation.inverse()));
        let t = got.translation.vector - at.translation.vector;
        d.fixed_rows_mut::<3>(o).copy_from(&r);
        d.fixed_rows_mut::<3>(o + 3).copy_from(&t);
    }
    Ok(d)
}

type Vector12 = nalgebra::SVector<f64, 12>;

/// The report: the single-camera hand-eye report with the rig in its keys
/// (`gripper_from_rig` or `base_from_rig`, also in `methods`), plus
/// `cameras` (each camera's own `gripper_from_camera` or `base_from_camera`)
/// and `frames` (the per-frame audit).
pub fn rig_handeye_report(solved: &RigHandEyeResult, rig: &HeldRig, names: &[String]) -> Value {
    let setup = solved.result.setup;
    let (old, new) = match setup {
        Setup::EyeInHand => ("gripper_from_camera", "gripper_from_rig"),
        Setup::EyeToHand => ("base_from_camera", "base_from_rig"),
    };
    let rename = |v: &mut Value| {
        if let Some(o) = v.as_object_mut() {
            if let Some(x) = o.remove(old) {
                o.insert(new.to_string(), x);
            }
        }
    };
    let mut report =
        serde_json::to_value(HandEyeReport::new(&solved.result)).unwrap_or(Value::Null);
    rename(&mut report);
    if let Some(methods) = report.get_mut("methods").and_then(Value::as_array_mut) {
        methods.iter_mut().for_each(rename);
    }
    let cameras: Vec<Value> = names
        .iter()
        .zip(&rig.camera_from_rig)
        .map(|(name, c)| {
            let pose: PoseJson = (&(solved.result.x * c.inverse())).into();
            serde_json::json!({ "name": name, (old): pose })
        })
        .collect();
    if let Some(o) = report.as_object_mut() {
        o.insert("cameras".into(), Value::Array(cameras));
        o.insert(
            "frames".into(),
            serde_json::to_value(&solved.frames).unwrap_or(Value::Null),
        );
        o.insert(
            "rig_uncertainty".into(),
            serde_json::to_value(&solved.rig_uncertainty).unwrap_or(Value::Null),
        );
    }
    report
}
