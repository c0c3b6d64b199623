//! `LiveCapture`: the one stateful object of the boundary, because live
//! capture is a session by nature (frame history, kept frames, running
//! calibration). It wraps [`crate::capture::CaptureSession`]; every method
//! returns JSON (docs/live-capture.md has the shapes) or a `JsError` whose
//! message is the library's error text. Frame times come from the page
//! (`performance.now()` or the video frame's timestamp), in milliseconds.

use super::{js_error, target_from};
use crate::capture::{CaptureConfig, CaptureSession};
use crate::image::GrayImage;
use serde::Serialize;
use wasm_bindgen::prelude::*;
use web_sys::ImageData;

/// A live-capture session for one target and one frame size.
#[wasm_bindgen]
pub struct LiveCapture {
    session: CaptureSession,
}

fn to_json<T: Serialize>(value: &T) -> Result<String, JsError> {
    serde_json::to_string(value).map_err(|e| JsError::new(&e.to_string()))
}

/// Grey from RGBA with `image`'s luma conversion, as decoded files get:
/// `(2126 R + 7152 G + 722 B) / 10000` in integers, truncated.
fn grey_from_rgba(rgba: &[u8], width: u32, height: u32) -> Result<GrayImage, JsError> {
    let n = width as usize * height as usize;
    if rgba.len() != 4 * n {
        return Err(JsError::new(&format!(
            "expected {} RGBA bytes for a {width}x{height} frame, got {}",
            4 * n,
            rgba.len()
        )));
    }
    let grey = rgba
        .chunks_exact(4)
        .map(|p| {
            let sum = 2126 * u32::from(p[0]) + 7152 * u32::from(p[1]) + 722 * u32::from(p[2]);
            (sum / 10_000) as u8
        })
        .collect();
    GrayImage::new(width, height, grey).map_err(js_error)
}

#[derive(Serialize)]
struct State<'a> {
    kept: usize,
    used: usize,
    coverage: &'a crate::capture::Coverage,
    suggestion: Option<&'a crate::capture::Suggestion>,
    good_enough: bool,
    handeye: crate::capture::HandEyeGuide,
}

#[derive(Serialize)]
struct Calibrated<'a> {
    calibration: &'a crate::calib::CameraCalibration,
    max_std_px: f64,
    #[serde(flatten)]
    state: State<'a>,
}

#[wasm_bindgen]
impl LiveCapture {
    /// A session for a target (spec or JSON, as `parse_target` takes) in
    /// frames of `width x height` pixels.
    #[wasm_bindgen(constructor)]
    pub fn new(target_spec_or_json: &str, width: u32, height: u32) -> Result<LiveCapture, JsError> {
        let target = target_from(target_spec_or_json)?;
        let session = CaptureSession::new(target, width, height, CaptureConfig::default())
            .map_err(js_error)?;
        Ok(LiveCapture { session })
    }

    /// Decide on a frame given as `ImageData` (RGBA, converted to grey):
    /// the frame report JSON (docs/live-capture.md).
    pub fn push_frame(&mut self, image: &ImageData, time_ms: f64) -> Result<String, JsError> {
        let rgba = image.data().0;
        self.push_rgba(&rgba, image.width(), image.height(), time_ms)
    }

    /// [`LiveCapture::push_frame`] on RGBA bytes (a transferred buffer).
    pub fn push_rgba(
        &mut self,
        rgba: &[u8],
        width: u32,
        height: u32,
        time_ms: f64,
    ) -> Result<String, JsError> {
        let image = grey_from_rgba(rgba, width, height)?;
        let report = self.session.push_image(&image, time_ms).map_err(js_error)?;
        to_json(&report)
    }

    /// [`LiveCapture::push_frame`] on grey bytes (`width * height`, row-major).
    pub fn push_grey(
        &mut self,
        grey: &[u8],
        width: u32,
        height: u32,
        time_ms: f64,
    ) -> Result<String, JsError> {
        let image = GrayImage::new(width, height, grey.to_vec()).map_err(js_error)?;
        let report = self.session.push_image(&image, time_ms).map_err(js_error)?;
        to_json(&report)
    }

    /// Manual capture: keep the last frame with the board whatever the
    /// automatic rule says. Returns `{"index", ...state}`.
    pub fn capture(&mut self) -> Result<String, JsError> {
        let index = self.session.keep_last().map_err(js_error)?;
        let mut value =
            serde_json::to_value(self.state_of()).map_err(|e| JsError::new(&e.to_string()))?;
        value["index"] = index.into();
        Ok(value.to_string())
    }

    /// Drop kept frame `index` (its card removed; later indices move down
    /// by one); returns the state.
    pub fn remove(&mut self, index: u32) -> Result<String, JsError> {
        self.session.remove(index as usize).map_err(js_error)?;
        self.state()
    }

    /// Include (`true`) or exclude kept frame `index` (its card's include
    /// box): an excluded frame keeps its index but leaves the coverage, the
    /// running calibration and the hand-eye guide until included again.
    /// Returns the state.
    pub fn set_included(&mut self, index: u32, included: bool) -> Result<String, JsError> {
        self.session
            .set_included(index as usize, included)
            .map_err(js_error)?;
        self.state()
    }

    /// Pair kept frame `index` with the robot's `base_from_gripper`, a
    /// pose JSON (`{"matrix_row_major"}` or `{"translation_m",
    /// "quaternion_xyzw"}`, metres); returns the state (with the hand-eye
    /// guide).
    pub fn set_robot_pose(&mut self, index: u32, pose_json: &str) -> Result<String, JsError> {
        let input: crate::geometry::PoseInput = serde_json::from_str(pose_json)
            .map_err(|e| JsError::new(&format!("robot pose JSON: {e}")))?;
        let pose = input.to_pose().map_err(js_error)?;
        self.session
            .set_robot_pose(index as usize, pose)
            .map_err(js_error)?;
        self.state()
    }

    /// Run the running calibration on the kept frames: `{"calibration"
    /// (the camera report, as calibrate_camera's), "max_std_px", ...state}`.
    pub fn calibrate(&mut self) -> Result<String, JsError> {
        self.session.calibrate().map_err(js_error)?;
        let calibration = self
            .session
            .calibration()
            .ok_or_else(|| JsError::new("the calibration was not stored"))?;
        to_json(&Calibrated {
            calibration,
            max_std_px: calibration.projection_uncertainty.max_std_px,
            state: self.state_of(),
        })
    }

    /// Whether the running calibration is good enough (docs/live-capture.md).
    pub fn good_enough(&self) -> bool {
        self.session.good_enough()
    }

    /// `{"kept", "used", "coverage", "suggestion", "good_enough", "handeye"}`.
    pub fn state(&self) -> Result<String, JsError> {
        to_json(&self.state_of())
    }

    /// The kept frames' detections (detection JSON, docs/detection-json.md),
    /// as an array in capture order: what the page stores as cards.
    pub fn kept_detections(&self) -> Result<String, JsError> {
        let detections: Vec<&crate::target::Detection> =
            self.session.kept().iter().map(|k| &k.detection).collect();
        to_json(&detections)
    }
}

impl LiveCapture {
    fn state_of(&self) -> State<'_> {
        State {
            kept: self.session.kept().len(),
            used: self.session.used(),
            coverage: self.session.coverage(),
            suggestion: self.session.suggestion(),
            good_enough: self.session.good_enough(),
            handeye: self.session.handeye_guide(),
        }
    }
}
