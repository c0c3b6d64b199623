//! The health check of a saved calibration and the projection difference
//! of two calibrations for the web app's check step and the npm package:
//! the JSON of `robocal::api::check` (docs/check.md).

use super::js_error;
use wasm_bindgen::prelude::*;

/// Check a saved calibration against detections in new images: the JSON
/// request and report of `robocal::api::check::check_json` (`{"calibration":
/// "<file text>", "views": [{"name", "detection"}], "thresholds": {...}}` ->
/// `{"kind": "check", "verdict": "ok" | "drifted" | "broken",
/// "projection_shift_px": {...}, "parameters": [...], "thresholds": {...},
/// ...}`).
#[wasm_bindgen]
pub fn check_camera(request_json: &str) -> Result<String, JsError> {
    crate::api::check::check_json(request_json).map_err(js_error)
}

/// The projection difference of two calibration files: the JSON request
/// and report of `robocal::api::check::diff_json` (`{"a": "<file text>",
/// "b": "<file text>", "options": {"grid": [60, 40]}}` -> `{"kind": "diff",
/// "projection_shift_px": {"worst", "median", "rms", "map", ...}}`).
#[wasm_bindgen]
pub fn diff_cameras(request_json: &str) -> Result<String, JsError> {
    crate::api::check::diff_json(request_json).map_err(js_error)
}
