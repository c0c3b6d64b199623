//! The WebAssembly boundary: the only module with `#[wasm_bindgen]` (this file,
//! and camera_file.rs, check.rs, demo.rs, laser.rs, lens_models.rs, live_capture.rs, plan.rs,
//! rig_frames.rs, rig_handeye.rs, targets.rs and video.rs beside it).
//!
//! A few stateless functions: bytes or JSON in, JSON (or plain bytes) out,
//! errors as `JsError` whose message is the library's error text. Pixels
//! come out as the host's `ImageData` (web-sys), ready for `putImageData`
//! and structured clone; node has no `ImageData`, so node callers set
//! `globalThis.ImageData` first (pkg-config/README.md) and get a clear
//! error otherwise.
//!
//! wasm32-unknown-unknown aborts on panic (a `RuntimeError: unreachable` in
//! JS). The module holds no state across calls, so the instance stays usable;
//! a panic hook writes the message to `console.error` and records it so the
//! JS side can show it ([`last_panic_message`]) instead of a dead worker.

mod camera_file;
mod check;
mod demo;
mod laser;
mod lens_models;
mod live_capture;
mod plan;
mod rig_frames;
mod rig_handeye;
mod targets;
mod video;
pub use camera_file::read_camera_file;
pub use check::{check_camera, diff_cameras};
pub use demo::{render_demo, DemoData};
pub use laser::{laser_plane, laser_points, laser_stripe};
pub use lens_models::lens_models;
pub use live_capture::LiveCapture;
pub use plan::{plan_handeye_poses, plan_move_list};
pub use rig_frames::rig_frame_keys;
pub use rig_handeye::calibrate_rig_handeye;
use targets::target_from;
pub use targets::{parse_target, read_kalibr_target, target_points, target_spec, target_svg};
pub use video::{video_frame_name, video_timestamps};

use crate::image::{decode, DecodeOptions, GrayImage};
use serde::Serialize;
use wasm_bindgen::prelude::*;
use web_sys::ImageData;

fn js_error(e: crate::Error) -> JsError {
    JsError::new(&e.to_string())
}

thread_local! {
    static LAST_PANIC: std::cell::RefCell<String> = const { std::cell::RefCell::new(String::new()) };
}

/// Installs the panic hook when the module is instantiated, in every host
/// (the page's worker, node, a bundler): no caller has to remember [`init`].
#[wasm_bindgen(start)]
fn start() {
    install_panic_hook();
}

/// Install the panic hook: it writes the panic message to `console.error`
/// and records it for [`last_panic_message`]. The module installs it itself
/// when instantiated; calling this again is harmless.
#[wasm_bindgen]
pub fn init() {
    install_panic_hook();
}

fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let text = info.to_string();
        web_sys::console::error_1(&JsValue::from_str(&format!("robocal panicked: {text}")));
        LAST_PANIC.with(|p| *p.borrow_mut() = text);
    }));
}

/// The message of the last panic, if any (empty when none). JS calls this
/// after catching a `RuntimeError` from any other function.
#[wasm_bindgen]
pub fn last_panic_message() -> String {
    LAST_PANIC.with(|p| p.borrow().clone())
}

/// The crate version.
#[wasm_bindgen]
pub fn version() -> String {
    crate::VERSION.to_string()
}

/// RGBA pixels (row-major, `4 * width * height` bytes) as the host's
/// `ImageData`. The bytes are copied into a JS-owned `Uint8ClampedArray`
/// first: an `ImageData` over a view of wasm memory (what
/// `new_with_u8_clamped_array_and_sh` makes) would be detached when the
/// memory grows, overwritten by the next call, and structured-clone the
/// whole wasm memory (wasm-bindgen issue 4815).
fn image_data(rgba: &[u8], width: u32, height: u32) -> Result<ImageData, JsError> {
    let global = js_sys::global();
    if !js_sys::Reflect::has(&global, &JsValue::from_str("ImageData")).unwrap_or(false) {
        return Err(JsError::new(
            "this JavaScript host has no ImageData (node has none): set globalThis.ImageData to a class whose constructor takes (data: Uint8ClampedArray, width, height) first, e.g. the ImageData of @napi-rs/canvas or the one in robocal's README",
        ));
    }
    let data = js_sys::Uint8ClampedArray::from(rgba);
    ImageData::new_with_js_u8_clamped_array_and_sh(&data, width, height).map_err(|e| {
        let why = e
            .dyn_ref::<js_sys::Error>()
            .map(|e| String::from(e.message()))
            .unwrap_or_else(|| format!("{e:?}"));
        JsError::new(&format!(
            "ImageData of {width}x{height} px could not be made: {why}"
        ))
    })
}

/// A decoded image's description plus a preview for thumbnails, and its
/// grey image when [`decode_image_preview`] was asked to keep it (then the
/// target is detected in it without decoding the file again).
#[wasm_bindgen]
pub struct ImagePreview {
    info_json: String,
    image: ImageData,
    gray: Option<GrayImage>,
}

#[wasm_bindgen]
impl ImagePreview {
    /// JSON: `{format, format_name, width, height, channels,
    /// bits_per_channel}` of the full image, plus `exif_orientation` (2-8)
    /// when the file's EXIF Orientation was applied (width and height are
    /// then the size after it).
    #[wasm_bindgen(getter)]
    pub fn info_json(&self) -> String {
        self.info_json.clone()
    }
    /// The preview as `ImageData` (RGBA; its own `width` and `height`, px).
    #[wasm_bindgen(getter)]
    pub fn image(&self) -> ImageData {
        self.image.clone()
    }
    /// Whether the grey image was kept (`keep_grey`): the detections below
    /// need it.
    #[wasm_bindgen(getter)]
    pub fn keeps_grey(&self) -> bool {
        self.gray.is_some()
    }
    /// [`detect_target`] on the kept grey image: the same Detection JSON or
    /// error, without a second decode.
    pub fn detect_target(&self, target_spec_or_json: &str) -> Result<String, JsError> {
        let request = target_request(target_spec_or_json)?;
        detect_with(self.kept_gray()?, &request)
    }
    /// [`detect_boards`] on the kept grey image.
    pub fn detect_boards(&self, target_spec_or_json: &str) -> Result<String, JsError> {
        let request = crate::api::detect::DetectRequest::from_spec_or_json(target_spec_or_json)
            .map_err(js_error)?;
        boards_with(self.kept_gray()?, &request)
    }
}

impl ImagePreview {
    fn kept_gray(&self) -> Result<&GrayImage, JsError> {
        self.gray.as_ref().ok_or_else(|| {
            JsError::new(
                "this preview kept no grey image: call decode_image_preview with keep_grey = true",
            )
        })
    }
}

/// `ImageInfo`'s fields plus `format_name`, written as one plain struct
/// (serde's `flatten` goes through a map serializer: more wasm).
#[derive(Serialize)]
struct InfoJson {
    format: crate::image::ImageFormat,
    width: u32,
    height: u32,
    channels: u8,
    bits_per_channel: u8,
    format_name: &'static str,
    /// The EXIF Orientation applied (2-8), absent when none was.
    #[serde(skip_serializing_if = "Option::is_none")]
    exif_orientation: Option<u8>,
}

impl InfoJson {
    fn of(info: &crate::image::ImageInfo) -> InfoJson {
        InfoJson {
            format: info.format,
            width: info.width,
            height: info.height,
            channels: info.channels,
            bits_per_channel: info.bits_per_channel,
            format_name: info.format.name(),
            exif_orientation: info.exif_orientation,
        }
    }
}

/// The options JSON of the image entries ([`decode_image_preview`],
/// [`image_info`], [`detect_target`], [`undistort_preview`]): absent, empty
/// or `{"max_pixels": N}`. `max_pixels` is the largest image accepted, in
/// pixels; default `robocal::image::DEFAULT_MAX_PIXELS` (64 MP in wasm).
/// Over the limit the error names the image size and the limit.
#[derive(serde::Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct ImageOptions {
    max_pixels: Option<u64>,
}

fn decode_options(options_json: Option<String>) -> Result<DecodeOptions, JsError> {
    let text = options_json.unwrap_or_default();
    let options: ImageOptions = if text.trim().is_empty() {
        ImageOptions::default()
    } else {
        serde_json::from_str(&text)
            .map_err(|e| JsError::new(&format!("image options JSON: {e}")))?
    };
    let mut decode = DecodeOptions::default();
    if let Some(max_pixels) = options.max_pixels {
        if max_pixels == 0 {
            return Err(JsError::new(
                "image options JSON: max_pixels must be at least 1",
            ));
        }
        decode.max_pixels = max_pixels;
    }
    Ok(decode)
}

/// The grey image of uploaded bytes, decoded under the caller's options.
fn decode_gray(bytes: &[u8], options_json: Option<String>) -> Result<GrayImage, JsError> {
    Ok(decode(bytes, &decode_options(options_json)?)
        .map_err(js_error)?
        .gray)
}

/// Decode image bytes (PNG, JPEG, TIFF, BMP, PNM, GIF, WebP); return its
/// description and a preview (`ImageData`) whose longer side is at most
/// `max_side` px. `options_json`: see [`ImageOptions`] (`{"max_pixels"}`).
/// `keep_grey`: the preview also holds the grey image (width x height
/// bytes of wasm memory until `free()`), for its `detect_target` and
/// `detect_boards`: the page decodes each file once for its card and its
/// detection.
#[wasm_bindgen]
pub fn decode_image_preview(
    bytes: &[u8],
    max_side: u32,
    options_json: Option<String>,
    keep_grey: Option<bool>,
) -> Result<ImagePreview, JsError> {
    let options = DecodeOptions {
        preview_max_side: Some(max_side),
        ..decode_options(options_json)?
    };
    let decoded = decode(bytes, &options).map_err(js_error)?;
    let info_json = serde_json::to_string(&InfoJson::of(&decoded.info))
        .map_err(|e| JsError::new(&e.to_string()))?;
    let preview = decoded
        .preview
        .ok_or_else(|| JsError::new("no preview was produced"))?;
    let image = image_data(&preview.pixels, preview.width, preview.height)?;
    let gray = keep_grey.unwrap_or(false).then_some(decoded.gray);
    Ok(ImagePreview {
        info_json,
        image,
        gray,
    })
}

/// Decode image bytes and return only the description as JSON.
/// `options_json`: see [`ImageOptions`] (`{"max_pixels"}`).
#[wasm_bindgen]
pub fn image_info(bytes: &[u8], options_json: Option<String>) -> Result<String, JsError> {
    let decoded = decode(bytes, &decode_options(options_json)?).map_err(js_error)?;
    serde_json::to_string(&InfoJson::of(&decoded.info)).map_err(|e| JsError::new(&e.to_string()))
}

/// Pair stereo images by file name, the rule of `robocal stereo`
/// (`robocal::io::pairing`): the last run of digits in each stem pairs left
/// `n` with right `n`; when no name has a number, by order; otherwise an
/// error naming the files. In: two JSON arrays of file names; out:
/// `{"paired_by": "number" | "order", "pairs": [[left_index, right_index], ...]}`
/// in left order.
#[wasm_bindgen]
pub fn pair_images(left_names_json: &str, right_names_json: &str) -> Result<String, JsError> {
    let names = |what: &str, json: &str| -> Result<Vec<String>, JsError> {
        serde_json::from_str(json).map_err(|e| {
            JsError::new(&format!(
                "{what} names: expected a JSON array of file names: {e}"
            ))
        })
    };
    let (left, right) = (
        names("left", left_names_json)?,
        names("right", right_names_json)?,
    );
    let left: Vec<&str> = left.iter().map(String::as_str).collect();
    let right: Vec<&str> = right.iter().map(String::as_str).collect();
    let pairing = crate::io::pairing::pair_by_number(&left, &right).map_err(js_error)?;
    serde_json::to_string(&pairing).map_err(|e| JsError::new(&e.to_string()))
}

/// Detect a calibration target in image bytes. `target_spec_or_json` is a
/// CLI spec (see [`parse_target`]; `:dark-on-light` / `:light-on-dark`
/// force that print, else either is found) or a target JSON object. Returns the
/// Detection JSON (see `docs/detection-json.md`). ChArUco boards and
/// AprilGrids give the corners seen (any subset) of the board whose
/// markers carry the target's ids; another board in the same image (its
/// own block of ids, `detect::detect_all`) is found by asking again with
/// its `first_id`: one target, one detection, as the page's cards and the
/// solvers' views take them.
#[wasm_bindgen]
pub fn detect_target(
    bytes: &[u8],
    target_spec_or_json: &str,
    options_json: Option<String>,
) -> Result<String, JsError> {
    // The target is read first: a bad spec is reported before a bad file.
    let request = target_request(target_spec_or_json)?;
    let image = decode_gray(bytes, options_json)?;
    detect_with(&image, &request)
}

fn target_request(target_spec_or_json: &str) -> Result<crate::api::detect::DetectRequest, JsError> {
    Ok(crate::api::detect::DetectRequest {
        other_boards: false,
        ..crate::api::detect::DetectRequest::from_spec_or_json(target_spec_or_json)
            .map_err(js_error)?
    })
}

/// [`detect_target`] after the decode.
fn detect_with(
    image: &GrayImage,
    request: &crate::api::detect::DetectRequest,
) -> Result<String, JsError> {
    let detection = crate::api::detect::detect_target(image, request)
        .detection
        .map_err(js_error)?;
    serde_json::to_string(&detection).map_err(|e| JsError::new(&e.to_string()))
}

/// Every board of the target's layout in image bytes (`detect::detect_all`):
/// a JSON array of Detection JSON, the target's own board first when it is
/// in view, then boards printed with other blocks of ids (each detection's
/// `target.first_id` says which). Other targets give their one detection.
/// Errors as [`detect_target`] when no board is found.
#[wasm_bindgen]
pub fn detect_boards(
    bytes: &[u8],
    target_spec_or_json: &str,
    options_json: Option<String>,
) -> Result<String, JsError> {
    let request = crate::api::detect::DetectRequest::from_spec_or_json(target_spec_or_json)
        .map_err(js_error)?;
    let image = decode_gray(bytes, options_json)?;
    boards_with(&image, &request)
}

/// [`detect_boards`] after the decode.
fn boards_with(
    image: &GrayImage,
    request: &crate::api::detect::DetectRequest,
) -> Result<String, JsError> {
    let detections = crate::api::detect::detect_boards(image, request).map_err(js_error)?;
    serde_json::to_string(&detections).map_err(|e| JsError::new(&e.to_string()))
}

/// Write a report (camera or hand-eye JSON) in an export format: the same
/// bytes as `robocal export REPORT --format FORMAT [--transform NAME]`.
/// `transform` may be empty for the default transform.
#[wasm_bindgen]
pub fn export_report(report_json: &str, format: &str, transform: &str) -> Result<String, JsError> {
    let files = crate::api::export::export(report_json, &export_request(format, transform))
        .map_err(js_error)?;
    Ok(crate::io::export::join_files(&files))
}

/// The export request of a format and a transform (`""`: the default).
fn export_request(format: &str, transform: &str) -> crate::api::export::ExportRequest {
    crate::api::export::ExportRequest {
        format: format.to_string(),
        transform: (!transform.is_empty()).then(|| transform.to_string()),
        frames: Default::default(),
    }
}

/// [`export_report`] as files, a JSON array of `{"name", "text"}`: several
/// for a rig report's `ros` and `mrcal` (the files `robocal export -o DIR`
/// writes), else one. `frames_json` may be empty or an object naming frames
/// by role, e.g. `{"rig": "camera_rig", "front": "front_optical_frame"}`
/// (`--frame ROLE=NAME`).
#[wasm_bindgen]
pub fn export_report_files(
    report_json: &str,
    format: &str,
    transform: &str,
    frames_json: &str,
) -> Result<String, JsError> {
    let request = export_request(format, transform)
        .with_frames_json(frames_json)
        .map_err(js_error)?;
    let files = crate::api::export::export(report_json, &request).map_err(js_error)?;
    serde_json::to_string(&files).map_err(|e| JsError::new(&e.to_string()))
}

/// The rig report's export format names, as a JSON array of strings.
#[wasm_bindgen]
pub fn rig_export_formats() -> String {
    serde_json::to_string(&crate::io::export_rig::rig_format_names())
        .unwrap_or_else(|_| "[]".into())
}

/// The export format names, as a JSON array of strings.
#[wasm_bindgen]
pub fn export_formats() -> String {
    serde_json::to_string(&crate::io::export::format_names()).unwrap_or_else(|_| "[]".into())
}

/// Read a robot pose file: `{"parsed": {...} | null, "ambiguity": null |
/// "why", "candidates": [...]}` (see `robocal::api::poses`).
/// `options_json` may be empty or `{"format", "length_unit", "angle_unit", "direction"}`.
#[wasm_bindgen]
pub fn read_robot_poses(text: &str, options_json: &str) -> Result<String, JsError> {
    crate::api::poses::read_poses_json(text, options_json).map_err(js_error)
}

/// Read one robot pose per file (a folder of ROS YAML, JSON or text files):
/// `files_json` is `[{"name", "text"}, ...]`, the answer as
/// [`read_robot_poses`], each pose named by its file's stem; errors name the
/// file (see `robocal::api::poses::read_pose_files_json`).
#[wasm_bindgen]
pub fn read_robot_pose_files(files_json: &str, options_json: &str) -> Result<String, JsError> {
    crate::api::poses::read_pose_files_json(files_json, options_json).map_err(js_error)
}

/// Parse a JSON request, run `solve`, return the JSON report.
fn json_call<Req: serde::de::DeserializeOwned, Rep: Serialize>(
    what: &str,
    json: &str,
    solve: impl Fn(&Req) -> crate::Result<Rep>,
) -> Result<String, JsError> {
    let request: Req =
        serde_json::from_str(json).map_err(|e| JsError::new(&format!("{what} request: {e}")))?;
    let report = solve(&request).map_err(js_error)?;
    serde_json::to_string(&report).map_err(|e| JsError::new(&e.to_string()))
}

/// Planar calibration at any height from per-height matrices. JSON in:
/// `{"matrices": [{"height_mm", "a11", "a12", "tx", "a21", "a22", "ty"}],
/// "reject_threshold"?: number, "predict"?: [{"height_mm", "image_px": [u, v]}]}`;
/// JSON out: `{fit: {a11..ty: {intercept, slope, r2, pearson_r, adj_r2, rss,
/// ...}}, rejected_heights_mm, predictions, input}`.
#[wasm_bindgen]
pub fn planar_fit(json: &str) -> Result<String, JsError> {
    json_call("planar_fit", json, crate::api::planar::planar_fit)
}

/// Planar calibration at any height from point pairs. JSON in:
/// `{"points": [{"height_mm", "image_px": [u, v], "robot_mm": [x, y]}],
/// "options"?: {"transform": "rigid"|"similarity"|"affine",
/// "reject_threshold": number|null, "plate_size_mm": [l, w]|null},
/// "predict"?: [...]}`; JSON out: per-height `heights`, `fit`,
/// `pixel_density`, `density_fit`, `predictions`.
#[wasm_bindgen]
pub fn planar_solve(json: &str) -> Result<String, JsError> {
    json_call("planar_solve", json, crate::api::planar::planar_solve)
}

/// XY-table calibration with one target. JSON in: `{"observations":
/// [{"stage_mm": [x, y, z], "image_px": [u, v]}], "verification"?: [4 such],
/// "still_target_px"?: [[u, v]], "measurement_noise_px2"?: [[a, b], [c, d]],
/// "kalman_mode"?: "extended"|"linearized"}`; JSON out: `batch`, `kalman`
/// (each with `projection_matrix` 3x4 row-major), `verification`.
#[wasm_bindgen]
pub fn xytable_solve(json: &str) -> Result<String, JsError> {
    json_call("xytable_solve", json, crate::api::xytable::xytable)
}

/// Camera-to-reference frame from known motions of one point (seed 000).
/// JSON in: `{"increments_mm": [[dx, dy, dz]], "points_camera_mm": [[x, y, z]],
/// "start_reference_mm"?: [x, y, z]}`; JSON out: `camera_from_reference`,
/// `start_camera_mm`, `residuals_mm`, `rms_mm`.
#[wasm_bindgen]
pub fn known_motion_solve(json: &str) -> Result<String, JsError> {
    json_call(
        "known_motion_solve",
        json,
        crate::api::xytable::known_motion,
    )
}

/// Hand-eye calibration: input JSON as documented in
/// `robocal::api::handeye` (setup, base_from_gripper,
/// camera_from_target, method, ...); returns the report JSON
/// (`gripper_from_camera` or `base_from_camera`, the target pose, `methods`,
/// `errors`, `warnings`, ...).
#[wasm_bindgen]
pub fn solve_handeye(input_json: &str) -> Result<String, JsError> {
    crate::api::handeye::solve_handeye_json(input_json).map_err(js_error)
}

/// Which reading of the robot poses fits the camera motion: input
/// `{"setup", "candidates": [{"name", "base_from_gripper": [pose...]}],
/// "camera_from_target": [pose...]}`; returns `{"scores": [{"name",
/// "consistency": {"rotation_rms_deg", "translation_rms_mm",
/// "robot_translation_scale"} | null}...] (best first), "recommendation":
/// text | null}` (see `robocal::api::handeye::rank_candidates_json`).
#[wasm_bindgen]
pub fn rank_pose_conventions(input_json: &str) -> Result<String, JsError> {
    crate::api::handeye::rank_candidates_json(input_json).map_err(js_error)
}

/// Read a workflow CSV (the files of `robocal planar` / `robocal xytable`)
/// into the request JSON of the matching solver: `kind` is
/// `planar-matrices` (-> `{"matrices"}` for `planar_fit`), `planar-points`
/// (-> `{"points"}` for `planar_solve`), `xytable` (-> the `xytable_solve`
/// request) or `known-motion` (-> the `known_motion_solve` request).
#[wasm_bindgen]
pub fn workflow_csv(kind: &str, text: &str) -> Result<String, JsError> {
    use crate::io::workflow_csv as csv;
    // Each request serialised straight to text (no `serde_json::Value` in
    // between: one serializer instantiation per type in the wasm).
    #[derive(Serialize)]
    struct Matrices {
        matrices: Vec<crate::api::planar::HeightMatrix>,
    }
    #[derive(Serialize)]
    struct Points {
        points: Vec<crate::workflows::planar_solve::HeightPoint>,
    }
    fn to_text<T: Serialize>(what: &str, value: &T) -> crate::Result<String> {
        serde_json::to_string(value).map_err(|e| crate::Error::invalid(what, e.to_string()))
    }
    match kind {
        "planar-matrices" => csv::parse_planar_matrices(text)
            .and_then(|matrices| to_text("matrices", &Matrices { matrices })),
        "planar-points" => csv::parse_planar_points(text)
            .and_then(|points| to_text("points", &Points { points })),
        "xytable" => csv::parse_xytable(text).and_then(|r| to_text("xytable", &r)),
        "known-motion" => csv::parse_known_motion(text).and_then(|r| to_text("known-motion", &r)),
        other => Err(crate::Error::invalid(
            "kind",
            format!("unknown workflow file '{other}' (known: planar-matrices, planar-points, xytable, known-motion)"),
        )),
    }
    .map_err(js_error)
}

/// Calibrate a camera from views (detections or point pairs) with one
/// method or all of them: the JSON input and output of
/// `robocal::api::camera::calibrate_json`.
#[wasm_bindgen]
pub fn calibrate_camera(input_json: &str) -> Result<String, JsError> {
    crate::api::camera::calibrate_json(input_json).map_err(js_error)
}

/// Calibrate a stereo pair: the JSON input and output of
/// `robocal::api::stereo::calibrate_stereo_json` (`left` and `right`
/// views paired by index; returns `left`, `right`, `right_from_left`,
/// `baseline_m`, `rms_px`, ...).
#[wasm_bindgen]
pub fn calibrate_stereo(input_json: &str) -> Result<String, JsError> {
    crate::api::stereo::calibrate_stereo_json(input_json).map_err(js_error)
}

/// Calibrate a camera rig: the JSON input and output of
/// `robocal::api::rig::calibrate_rig_json` (`cameras`, each with
/// `views` keyed by frame; returns every camera's `camera_from_rig` with
/// its std, the frames, the co-observation graph, `rms_px`, ...).
#[wasm_bindgen]
pub fn calibrate_rig(input_json: &str) -> Result<String, JsError> {
    crate::api::rig::calibrate_rig_json(input_json).map_err(js_error)
}

/// An undistorted preview of image bytes taken by `camera_json` (the
/// `camera` object of a calibration report): resampled through the same
/// camera without distortion, longer side at most `max_side` px, as grey
/// `ImageData` (RGBA with r = g = b, alpha 255). `options_json`: see
/// [`ImageOptions`] (`{"max_pixels"}`).
#[wasm_bindgen]
pub fn undistort_preview(
    bytes: &[u8],
    camera_json: &str,
    max_side: u32,
    options_json: Option<String>,
) -> Result<ImageData, JsError> {
    let camera: crate::camera::Camera = serde_json::from_str(camera_json)
        .map_err(|e| JsError::new(&format!("camera JSON: {e}")))?;
    let image = decode_gray(bytes, options_json)?;
    let preview = camera.pinhole_preview(max_side).map_err(js_error)?;
    let out = crate::image::undistort_image(&image, &camera, &preview).map_err(js_error)?;
    let rgba: Vec<u8> = out.pixels.iter().flat_map(|&g| [g, g, g, 255]).collect();
    image_data(&rgba, out.width, out.height)
}
