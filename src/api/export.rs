//! The request of `robocal export` and the page's export (`export_report`,
//! `export_report_files`): a report (any kind, read by its `kind`, see
//! [`crate::report_kind`]), a format, which transform and the names of the
//! frames. One reading of the frame names for both hosts: the CLI's
//! `--frame ROLE=NAME` and the page's `{"ROLE": "NAME"}` make the same
//! [`ExportRequest`]. The writers are in [`crate::io::export`].

use crate::error::{Error, Result};
pub use crate::io::export::ExportFile;
use crate::io::export::{export_files, ExportOptions};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// What to write a report as.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExportRequest {
    /// The format's name (`robocal export --help` lists them,
    /// [`crate::io::export::format_names`]).
    pub format: String,
    /// Which transform of the report (default: the first present, see
    /// [`crate::io::export::DEFAULT_TRANSFORMS`]).
    #[serde(default)]
    pub transform: Option<String>,
    /// Frame names by role, e.g. `{"gripper": "tool0"}`: they override the
    /// report's own `frame_names`.
    #[serde(default)]
    pub frames: BTreeMap<String, String>,
}

impl ExportRequest {
    /// Add the frame names of `--frame ROLE=NAME` arguments; an argument
    /// without `=` is an error that shows the form.
    pub fn with_frame_args<S: AsRef<str>>(mut self, args: &[S]) -> Result<ExportRequest> {
        for arg in args {
            let arg = arg.as_ref();
            let (role, name) = arg.split_once('=').ok_or_else(|| {
                Error::invalid(
                    "--frame",
                    format!("--frame takes ROLE=NAME (e.g. gripper=tool0), got '{arg}'"),
                )
            })?;
            self.frames.insert(role.to_string(), name.to_string());
        }
        Ok(self)
    }

    /// The frame names of a JSON object (`""` for none), as the page sends
    /// them.
    pub fn with_frames_json(mut self, frames_json: &str) -> Result<ExportRequest> {
        if frames_json.trim().is_empty() {
            return Ok(self);
        }
        let frames: BTreeMap<String, String> = serde_json::from_str(frames_json).map_err(|e| {
            Error::invalid(
                "frames",
                format!("expected an object of frame names by role, e.g. {{\"rig\": \"camera_rig\"}}: {e}"),
            )
        })?;
        self.frames.extend(frames);
        Ok(self)
    }
}

/// Write `report_json` as `request` says: one file, or several for a rig's
/// `ros` and `mrcal` and a stereo pair's `ros`.
pub fn export(report_json: &str, request: &ExportRequest) -> Result<Vec<ExportFile>> {
    let options = ExportOptions {
        transform: request.transform.as_deref(),
        frames: request
            .frames
            .iter()
            .map(|(role, name)| (role.clone(), name.clone()))
            .collect(),
    };
    export_files(report_json, &request.format, &options)
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    const HANDEYE: &str = r#"{"kind": "handeye", "robocal_version": "0",
        "gripper_from_camera": {"translation_m": [0.1, 0.0, 0.05],
        "quaternion_xyzw": [0.0, 0.0, 0.0, 1.0]}}"#;

    #[wasm_bindgen_test(unsupported = test)]
    fn frame_arguments_and_json_name_the_same_frames() {
        let base = ExportRequest {
            format: "ros2-static-tf".into(),
            ..ExportRequest::default()
        };
        let from_args = base.clone().with_frame_args(&["gripper=tool0"]).unwrap();
        let from_json = base.with_frames_json(r#"{"gripper": "tool0"}"#).unwrap();
        assert_eq!(from_args, from_json);
        let text = &export(HANDEYE, &from_args).unwrap()[0].text;
        assert!(text.contains("tool0"), "{text}");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn a_frame_argument_without_a_name_says_the_form() {
        let err = ExportRequest::default()
            .with_frame_args(&["gripper"])
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "--frame: --frame takes ROLE=NAME (e.g. gripper=tool0), got 'gripper'"
        );
    }
}
