//! A rig on a robot end to end, shared by `robocal rig --setup` and the
//! JSON boundary [`calibrate_rig_handeye_json`] (wasm and npm:
//! `calibrate_rig_handeye`).
//!
//! JSON input:
//!
//! ```json
//! {"setup": "eye-in-hand",
//!  "base_from_gripper": [{"translation_m": [...], "quaternion_xyzw": [...]}, ...],
//!  "calibration": {"target": "chessboard:9x6:30mm", "cameras": [...]},
//!  "rig": {...},
//!  "lenient": false}
//! ```
//!
//! `calibration` is the input of `calibrate_rig` ([`super::rig`]):
//! the cameras and their views keyed by frame. Without `rig` the rig is
//! calibrated from them first; with `rig` (a rig report, the output of
//! `robocal rig -o rig.json` or `calibrate_rig`) its intrinsics and
//! `camera_from_rig` are held, every `calibration.cameras[i].name` must be
//! one of its cameras, and `calibration`'s `model`, `options` and `rig_frame`
//! are not used. `base_from_gripper`: one robot pose per frame, in frame
//! (key) order, each a matrix or translation and quaternion as in
//! `solve_handeye`. `lenient` reports suspected pose mistakes as warnings.
//!
//! Output: the rig report (solved, or the one given) with `handeye`, the
//! JSON `robocal rig --setup ... -o rig.json` writes.

use super::rig::{calibrate_rig_input, rig_views, RigInput};
use crate::calib::multi::rig::RigCameraViews;
use crate::calib::multi::rig_report::RigCalibration;
use crate::error::{Error, Result};
use crate::geometry::PoseInput;
use crate::handeye::rig::uncertainty::{held_rig, rig_sigma_points};
use crate::handeye::rig::{add_rig_uncertainty, calibrate_rig_handeye, rig_handeye_report};
use crate::handeye::{HandEyeOptions, Pose, Setup};
use crate::report_kind::ReportKind;
use serde::Deserialize;
use serde_json::Value;

/// Where the rig came from, in the note on its uncertainty.
pub const SAME_RUN: &str = "the rig calibration of this run";

/// The whole input of [`calibrate_rig_handeye_json`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RigHandEyeInput {
    setup: Setup,
    base_from_gripper: Vec<PoseInput>,
    calibration: RigInput,
    #[serde(default)]
    rig: Option<RigCalibration>,
    #[serde(default)]
    lenient: bool,
}

/// The hand-eye of a calibrated rig: `inputs[k]` are the views of the
/// rig's camera `index[k]`, keyed into `keys`; one robot pose per key. The
/// rig's covariance, when it has one, widens the std (`source` says whose).
/// Returns the `handeye` report of [`rig_handeye_report`].
#[allow(clippy::too_many_arguments)]
pub fn solve_rig_on_robot(
    setup: Setup,
    report: &RigCalibration,
    inputs: &[RigCameraViews],
    index: &[usize],
    keys: &[String],
    base_from_gripper: &[Pose],
    options: &HandEyeOptions,
    source: &str,
) -> Result<Value> {
    let rig = held_rig(report)?;
    let mut frames = vec![Vec::new(); keys.len()];
    for (camera, &k) in inputs.iter().zip(index) {
        for (f, view) in &camera.views {
            let slot = frames.get_mut(*f).ok_or_else(|| {
                Error::invalid(
                    format!("camera {}", camera.name),
                    format!("frame index {f}, but there are {} frames", keys.len()),
                )
            })?;
            slot.push((k, view.clone()));
        }
    }
    let names: Vec<String> = report.cameras.iter().map(|c| c.name.clone()).collect();
    let mut solved = calibrate_rig_handeye(
        setup,
        &rig,
        &names,
        keys,
        &frames,
        base_from_gripper,
        options,
    )?;
    if let Some(sigma) = rig_sigma_points(report)? {
        add_rig_uncertainty(
            &mut solved,
            &sigma,
            source,
            &frames,
            base_from_gripper,
            options,
        )?;
    }
    Ok(rig_handeye_report(&solved, &rig, &names))
}

/// The rig camera of each named camera; a name not in the rig, or given
/// twice, is an error naming the field `{field}[i].name`.
pub fn rig_cameras_named(
    report: &RigCalibration,
    names: &[&str],
    field: &str,
) -> Result<Vec<usize>> {
    let all: Vec<&str> = report.cameras.iter().map(|c| c.name.as_str()).collect();
    names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            if names[..i].contains(name) {
                return Err(Error::invalid(
                    format!("{field}[{i}].name"),
                    format!("camera '{name}' is given twice: give each camera of the rig once"),
                ));
            }
            all.iter().position(|n| n == name).ok_or_else(|| {
                Error::invalid(
                    format!("{field}[{i}].name"),
                    format!(
                        "camera '{name}' is not in the rig (its cameras are {})",
                        all.join(", ")
                    ),
                )
            })
        })
        .collect()
}

/// The rig on a robot from the JSON input of the module docs; returns the
/// rig report with `handeye`.
pub fn calibrate_rig_handeye_json(input_json: &str) -> Result<String> {
    let mut input: RigHandEyeInput = serde_json::from_str(input_json)
        .map_err(|e| super::request_error("rig hand-eye input", e))?;
    let base_from_gripper = input
        .base_from_gripper
        .iter()
        .enumerate()
        .map(|(i, p)| {
            p.to_pose()
                .map_err(|e| within(&format!("base_from_gripper[{i}]"), e))
        })
        .collect::<Result<Vec<Pose>>>()?;
    let (report, index, source) = match input.rig.take() {
        Some(rig) => {
            let names: Vec<&str> = input
                .calibration
                .cameras
                .iter()
                .map(|c| c.name.as_str())
                .collect();
            let index = rig_cameras_named(&rig, &names, "calibration.cameras")?;
            // The rig's intrinsics give each camera's image size.
            for (c, &k) in input.calibration.cameras.iter_mut().zip(&index) {
                c.camera = Some(rig.cameras[k].calibration.camera.clone());
            }
            (rig, index, "the given rig's covariance")
        }
        None => {
            let report = calibrate_rig_input(&input.calibration)?;
            let index = (0..report.cameras.len()).collect();
            (report, index, SAME_RUN)
        }
    };
    let (inputs, keys) = rig_views(&input.calibration)?;
    let options = HandEyeOptions {
        strict_checks: !input.lenient,
        ..HandEyeOptions::default()
    };
    let handeye = solve_rig_on_robot(
        input.setup,
        &report,
        &inputs,
        &index,
        &keys,
        &base_from_gripper,
        &options,
        source,
    )?;
    serde_json::to_string(&with_handeye(&report, handeye)?)
        .map_err(|e| Error::invalid("report", format!("cannot serialise: {e}")))
}

/// The rig report with the hand-eye report `handeye` beside its keys and
/// `kind` `rig_handeye`: what `robocal rig --setup` and
/// [`calibrate_rig_handeye_json`] write.
pub fn with_handeye(report: &RigCalibration, handeye: Value) -> Result<Value> {
    let tagged = RigCalibration {
        kind: ReportKind::RigHandeye,
        ..report.clone()
    };
    let mut json = serde_json::to_value(&tagged)
        .map_err(|e| Error::invalid("report", format!("cannot serialise: {e}")))?;
    if let Some(o) = json.as_object_mut() {
        o.insert("handeye".into(), handeye);
    }
    Ok(json)
}

/// An error of a pose, its field prefixed.
fn within(field: &str, e: Error) -> Error {
    match e {
        Error::Invalid { field: f, message } => Error::invalid(format!("{field}.{f}"), message),
        other => other,
    }
}
