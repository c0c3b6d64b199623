//! Hand-eye calibration of a camera rig: where the whole rig sits on the
//! robot (eye-in-hand, `gripper_from_rig`) or in its world (eye-to-hand,
//! `base_from_rig`), from every camera's views together.
//!
//! The rig is held (its intrinsics and `camera_from_rig` from a rig
//! calibration). Each frame's board pose in the rig frame comes from all
//! cameras that saw the board in it ([`super::rig_pnp`]); the rig frame then
//! plays the camera of the single-camera problem: the closed forms
//! ([`super::calibrate`]) and the maximum-likelihood pose refinement with
//! each frame's multi-camera PnP covariance ([`CameraNoise::PerView`]).
//! Every camera's own transform follows as `x * camera_from_rig[k]^-1`.

use super::output::HandEyeReport;
use super::pose_noise::CameraNoise;
use super::refine_poses::apply_pose_refinement;
use super::reprojection_refine::ViewPoints;
use super::rig_pnp::{rig_from_target, HeldRig};
use super::{calibrate, HandEyeInput, HandEyeOptions, HandEyeResult, Pose, Setup};
use crate::error::{Error, Result};
use crate::geometry::PoseJson;
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
}

/// Solve the rig's hand-eye. `frames[f]` holds the views of frame `f`
/// (camera index, points), `keys[f]` its key, `base_from_gripper[f]` its
/// robot pose: one pose per frame, in frame order. Frames that no camera's
/// points pin down are left out with their pose (see `frames`).
pub fn calibrate_rig_handeye(
    setup: Setup,
    rig: &HeldRig,
    names: &[String],
    keys: &[String],
    frames: &[Vec<(usize, ViewPoints)>],
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
    })
}

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
    }
    report
}
