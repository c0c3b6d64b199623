//! The JSON boundary of the calibration health check and of the projection
//! difference, shared by the wasm functions `check_camera` and
//! `diff_cameras` and by `robocal check` / `robocal diff` (docs/check.md).
//!
//! Check request:
//!
//! ```json
//! {"calibration": "<the saved calibration file's text>",
//!  "views": [{"name": "new01.png", "detection": {...}}],
//!  "thresholds": {"shift_sigma": 3, "shift_floor_px": 1, "shift_px": null,
//!                 "param_sigma": 3, "param_floor_px": 0.5, "broken_rms_px": null,
//!                 "pose_mm": 2, "pose_deg": 0.2},
//!  "camera_from_target": null}
//! ```
//!
//! `calibration` is any camera file robocal reads back
//! ([`crate::io::import_camera`]: any camera format robocal exports, a
//! robocal report or camera JSON, OpenCV YAML/XML, ROS camera_info, Kalibr,
//! mrcal, HALCON, MATLAB, the text matrix); from a robocal report the check also takes
//! the saved `std`, `projection_uncertainty.max_std_px` and `rms_px`, which
//! set its thresholds. `thresholds` and `camera_from_target` (the pose of a
//! fixed target seen by a fixed camera at calibration time) are optional.
//! Out: a [`CheckReport`] (`"kind": "check"`).
//!
//! Diff request: `{"a": "<file text>", "b": "<file text>", "options":
//! {"grid": [60, 40], "fit_px": [], "focus_radius_px": null}}`; out: a
//! [`DiffReport`] (`"kind": "diff"`).

use super::camera::{check_size, views_of, JsonView};
use crate::calib::check::{check_calibration, CheckReport, CheckThresholds, SavedCalibration};
use crate::calib::projection_diff::{projection_diff, DiffOptions, ProjectionDiff};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::PoseInput;
use crate::io::import_camera::import_camera;
use crate::report_kind::ReportKind;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The input of [`check_json`].
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckRequest {
    /// The saved calibration file's text.
    pub calibration: String,
    /// Detections of the target in the new images (an empty list reads
    /// broken: the target was not found).
    #[serde(default)]
    pub views: Vec<JsonView>,
    /// Threshold overrides.
    #[serde(default)]
    pub thresholds: CheckThresholds,
    /// Where the fixed camera saw the fixed target when it was calibrated.
    #[serde(default)]
    pub camera_from_target: Option<PoseInput>,
}

/// The input of [`diff_json`].
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiffRequest {
    /// The first calibration file's text.
    pub a: String,
    /// The second calibration file's text.
    pub b: String,
    /// Grid and rotation-fit options.
    #[serde(default)]
    pub options: DiffOptions,
}

/// The projection difference of two calibrations.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DiffReport {
    /// `diff`.
    pub kind: ReportKind,
    /// robocal version that produced the report.
    pub robocal_version: String,
    /// The first camera.
    pub a: Camera,
    /// The second camera.
    pub b: Camera,
    /// How far a point A projects to a grid pixel lands in B, px.
    pub projection_shift_px: ProjectionDiff,
}

/// Check a saved calibration against new views (the module docs).
pub fn check_json(request_json: &str) -> Result<String> {
    let request: CheckRequest =
        serde_json::from_str(request_json).map_err(|e| super::request_error("check request", e))?;
    to_json(&check_request(&request)?)
}

/// [`check_json`] on the parsed request.
pub fn check_request(request: &CheckRequest) -> Result<CheckReport> {
    let mut saved = saved_calibration(&request.calibration)
        .map_err(|e| Error::invalid("calibration", e.to_string()))?;
    saved.camera_from_target = request
        .camera_from_target
        .as_ref()
        .map(PoseInput::to_pose)
        .transpose()?;
    check_thresholds(&request.thresholds)?;
    check_size("views", &request.views)?;
    let [w, h] = [saved.camera.width, saved.camera.height];
    for (i, v) in request.views.iter().enumerate() {
        if let Some(d) = &v.detection {
            let [dw, dh] = d.image_size_px;
            if [dw, dh] != [w, h] {
                return Err(Error::invalid(
                    format!("views[{i}] ({})", v.name),
                    format!(
                        "the image is {dw}x{dh} but the saved calibration is of {w}x{h} images: \
                         check with images of the calibrated camera at its resolution"
                    ),
                ));
            }
        }
    }
    let views = views_of(&request.views)?;
    check_calibration(&saved, &views, &request.thresholds)
}

/// The projection difference of two calibration files (the module docs).
pub fn diff_json(request_json: &str) -> Result<String> {
    let request: DiffRequest =
        serde_json::from_str(request_json).map_err(|e| super::request_error("diff request", e))?;
    to_json(&diff_request(&request)?)
}

/// [`diff_json`] on the parsed request.
pub fn diff_request(request: &DiffRequest) -> Result<DiffReport> {
    let (a, _) = import_camera(&request.a).map_err(|e| Error::invalid("a", e.to_string()))?;
    let (b, _) = import_camera(&request.b).map_err(|e| Error::invalid("b", e.to_string()))?;
    let projection_shift_px = projection_diff(&a, &b, &request.options)?;
    Ok(DiffReport {
        kind: ReportKind::Diff,
        robocal_version: crate::VERSION.to_string(),
        a,
        b,
        projection_shift_px,
    })
}

/// The camera of a calibration file and, from a robocal report, its saved
/// uncertainty (`std`, `projection_uncertainty.max_std_px`, `rms_px`).
pub fn saved_calibration(text: &str) -> Result<SavedCalibration> {
    let (camera, _) = import_camera(text)?;
    let mut saved = SavedCalibration {
        camera,
        std: BTreeMap::new(),
        projection_std_px: None,
        rms_px: None,
        camera_from_target: None,
    };
    if text.trim_start().starts_with('{') {
        let v: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| Error::parse(e.line(), e.column(), format!("invalid JSON: {e}")))?;
        if let Some(std) = v["std"].as_object() {
            for (name, value) in std {
                if let Some(s) = value.as_f64().filter(|s| s.is_finite() && *s >= 0.0) {
                    saved.std.insert(name.clone(), s);
                }
            }
        }
        saved.projection_std_px = v["projection_uncertainty"]["max_std_px"]
            .as_f64()
            .filter(|s| s.is_finite() && *s > 0.0);
        saved.rms_px = v["rms_px"].as_f64().filter(|s| s.is_finite() && *s >= 0.0);
    }
    Ok(saved)
}

/// Every threshold finite and >= 0.
fn check_thresholds(t: &CheckThresholds) -> Result<()> {
    let values = [
        ("shift_sigma", Some(t.shift_sigma)),
        ("shift_floor_px", Some(t.shift_floor_px)),
        ("shift_px", t.shift_px),
        ("param_sigma", Some(t.param_sigma)),
        ("param_floor_px", Some(t.param_floor_px)),
        ("broken_rms_px", t.broken_rms_px),
        ("pose_mm", Some(t.pose_mm)),
        ("pose_deg", Some(t.pose_deg)),
    ];
    for (name, value) in values {
        if let Some(v) = value {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    format!("thresholds.{name}"),
                    format!("must be a number >= 0, got {v}"),
                ));
            }
        }
    }
    Ok(())
}

fn to_json<T: Serialize>(value: &T) -> Result<String> {
    serde_json::to_string(value)
        .map_err(|e| Error::invalid("report", format!("cannot serialise: {e}")))
}
