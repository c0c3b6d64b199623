//! The rig on a robot for the web app's rig step and the npm package: the
//! JSON boundary of `robocal rig ... --setup SETUP --poses FILE`.

use super::js_error;
use wasm_bindgen::prelude::*;

/// A camera rig on a robot: the JSON input and output of
/// `robocal::api::rig_handeye::calibrate_rig_handeye_json` (`setup`,
/// `base_from_gripper` one per frame in key order, `calibration` the input
/// of `calibrate_rig`, optionally `rig` a calibrated rig report to hold,
/// `lenient`); returns the rig report with `handeye`: `gripper_from_rig`
/// or `base_from_rig` with its std, each camera's own transform, the
/// frames used and the warnings: what `robocal rig --setup ... --poses`
/// writes.
#[wasm_bindgen]
pub fn calibrate_rig_handeye(input_json: &str) -> Result<String, JsError> {
    crate::api::rig_handeye::calibrate_rig_handeye_json(input_json).map_err(js_error)
}
