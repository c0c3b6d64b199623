//! The pose plan for hand-eye for the web app's plan panel and the npm
//! package: the JSON of `robocal::api::plan` (docs/pose-plan.md) and the
//! robot program or pose table of a plan's poses.

use super::js_error;
use crate::error::Error;
use crate::geometry::PoseInput;
use serde::Deserialize;
use wasm_bindgen::prelude::*;

/// Plan robot poses for a hand-eye calibration from one view of the
/// target: the JSON request and report of `robocal::api::plan::plan_json`
/// (`{"setup", "base_from_gripper", "camera_from_target", "camera",
/// "board_m", "poses": 15, "max_tilt_deg", "distance_m", "view_px", ...}`
/// -> `{"kind": "handeye-plan", "poses": [{"base_from_gripper",
/// "camera_from_target", "tilt_deg", "distance_m", "roll_deg"}],
/// "predicted": {"bound95_mm", "rms_mm", "verdict", ...}, "motion",
/// "travel_m", "candidates", "notes", "noise"}`).
#[wasm_bindgen]
pub fn plan_handeye_poses(request_json: &str) -> Result<String, JsError> {
    crate::api::plan::plan_json(request_json).map_err(js_error)
}

#[derive(Deserialize)]
struct PlannedPose {
    base_from_gripper: PoseInput,
}

#[derive(Deserialize)]
struct PlanReport {
    poses: Vec<PlannedPose>,
}

/// The text that makes the robot visit a plan's poses in order, in the
/// format `format` as `robocal plan --export --format` names it: a program
/// (`ur-script`, `kuka-krl`, `abb-rapid`) or a pose table in any pose
/// format robocal reads (`ur`, `kuka`, `abb`, `fanuc`, `yaskawa`, `staubli`,
/// `xyz_quat_xyzw`, ...). `report_json` is [`plan_handeye_poses`]'s answer
/// (only its `poses[].base_from_gripper` is read).
#[wasm_bindgen]
pub fn plan_move_list(report_json: &str, format: &str) -> Result<String, JsError> {
    let report: PlanReport = serde_json::from_str(report_json)
        .map_err(|e| js_error(Error::parse(e.line(), e.column(), e.to_string())))?;
    let poses = report
        .poses
        .iter()
        .enumerate()
        .map(|(i, p)| {
            p.base_from_gripper
                .to_pose()
                .map_err(|e| Error::invalid(format!("poses[{i}].base_from_gripper"), e.to_string()))
        })
        .collect::<crate::Result<Vec<_>>>()
        .map_err(js_error)?;
    crate::io::move_lists::plan_export(&poses, format).ok_or_else(|| {
        js_error(Error::invalid(
            "format",
            format!(
                "'{format}': not a pose format robocal reads nor a program \
                 (ur-script, kuka-krl, abb-rapid)"
            ),
        ))
    })
}
