//! Camera files for the web app (a rig camera's held intrinsics) and the
//! npm package: the reader of `robocal rig --camera-file NAME=FILE`.

use super::js_error;
use crate::camera::Camera;
use crate::io::import_camera::{import_camera, CameraSource};
use serde::Serialize;
use wasm_bindgen::prelude::*;

#[derive(Serialize)]
struct CameraFile {
    camera: Camera,
    format: &'static str,
}

/// The name of a camera file's format in [`read_camera_file`]'s answer.
fn format_name(source: CameraSource) -> &'static str {
    match source {
        CameraSource::Json => "json",
        CameraSource::OpencvYaml => "opencv-yaml",
        CameraSource::OpencvXml => "opencv-xml",
        CameraSource::RosYaml => "ros-yaml",
        CameraSource::Kalibr => "kalibr",
        CameraSource::Mrcal => "mrcal",
        CameraSource::Halcon => "halcon",
        CameraSource::Matlab => "matlab",
        CameraSource::Text => "text",
    }
}

/// Read a camera file's text: any camera format robocal exports (robocal
/// JSON or a calibration report, OpenCV FileStorage YAML or XML, ROS
/// `camera_info` YAML, Kalibr, mrcal, HALCON's tuple or `.dat`, MATLAB,
/// the text matrix), recognised from the content as `robocal rig
/// --camera-file` reads it. Out: `{"camera": {...}, "format": "json" |
/// "opencv-yaml" | "opencv-xml" | "ros-yaml" | "kalibr" | "mrcal" |
/// "halcon" | "matlab" | "text"}`; `camera` is what a rig
/// input's `cameras[i].camera` takes to hold that camera's intrinsics.
#[wasm_bindgen]
pub fn read_camera_file(text: &str) -> Result<String, JsError> {
    let (camera, source) = import_camera(text).map_err(js_error)?;
    serde_json::to_string(&CameraFile {
        camera,
        format: format_name(source),
    })
    .map_err(|e| JsError::new(&e.to_string()))
}
