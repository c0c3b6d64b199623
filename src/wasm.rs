//! The WebAssembly boundary: the only file with `#[wasm_bindgen]`.
//!
//! A few stateless functions: bytes or JSON in, JSON (or plain bytes) out,
//! errors as `JsError` whose message is the library's error text.
//!
//! wasm32-unknown-unknown aborts on panic (a `RuntimeError: unreachable` in
//! JS). The module holds no state across calls, so the instance stays usable;
//! a panic hook records the message so the JS side can show it
//! ([`last_panic_message`]) instead of a dead worker.

use crate::image::{decode, DecodeOptions};
use serde::Serialize;
use wasm_bindgen::prelude::*;

fn js_error(e: crate::Error) -> JsError {
    JsError::new(&e.to_string())
}

thread_local! {
    static LAST_PANIC: std::cell::RefCell<String> = const { std::cell::RefCell::new(String::new()) };
}

/// Install the panic hook that records panic messages. Called once by the JS
/// side after instantiating the module; calling it again is harmless.
#[wasm_bindgen]
pub fn init() {
    std::panic::set_hook(Box::new(|info| {
        let text = info.to_string();
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

/// A decoded image's description plus an RGBA preview for thumbnails.
#[wasm_bindgen]
pub struct ImagePreview {
    info_json: String,
    rgba: Vec<u8>,
    width: u32,
    height: u32,
}

#[wasm_bindgen]
impl ImagePreview {
    /// JSON: `{format, width, height, channels, bits_per_channel}`.
    #[wasm_bindgen(getter)]
    pub fn info_json(&self) -> String {
        self.info_json.clone()
    }
    /// Preview pixels, RGBA, row-major.
    #[wasm_bindgen(getter)]
    pub fn rgba(&self) -> Vec<u8> {
        self.rgba.clone()
    }
    /// Preview width in pixels.
    #[wasm_bindgen(getter)]
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Preview height in pixels.
    #[wasm_bindgen(getter)]
    pub fn height(&self) -> u32 {
        self.height
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
        }
    }
}

/// Decode image bytes (PNG, JPEG, TIFF, BMP, PNM, GIF); return its
/// description and a preview whose longer side is at most `max_side` px.
#[wasm_bindgen]
pub fn decode_image_preview(bytes: &[u8], max_side: u32) -> Result<ImagePreview, JsError> {
    let options = DecodeOptions {
        preview_max_side: Some(max_side),
        ..Default::default()
    };
    let decoded = decode(bytes, &options).map_err(js_error)?;
    let info_json = serde_json::to_string(&InfoJson::of(&decoded.info))
        .map_err(|e| JsError::new(&e.to_string()))?;
    let preview = decoded
        .preview
        .ok_or_else(|| JsError::new("no preview was produced"))?;
    Ok(ImagePreview {
        info_json,
        rgba: preview.pixels,
        width: preview.width,
        height: preview.height,
    })
}

/// Decode image bytes and return only the description as JSON.
#[wasm_bindgen]
pub fn image_info(bytes: &[u8]) -> Result<String, JsError> {
    let decoded = decode(bytes, &DecodeOptions::default()).map_err(js_error)?;
    serde_json::to_string(&InfoJson::of(&decoded.info)).map_err(|e| JsError::new(&e.to_string()))
}

/// Detect a calibration target in image bytes. `target_spec_or_json` is a
/// CLI spec (`chessboard:9x6:30mm`, `circles:4x11:20mm:asymmetric`,
/// `dots:7x7:25mm`, `circle:10mm`) or a target JSON object. Returns the
/// Detection JSON (see `docs/detection-json.md`).
#[wasm_bindgen]
pub fn detect_target(bytes: &[u8], target_spec_or_json: &str) -> Result<String, JsError> {
    let target = if target_spec_or_json.trim_start().starts_with('{') {
        serde_json::from_str::<crate::target::Target>(target_spec_or_json)
            .map_err(|e| JsError::new(&format!("target JSON: {e}")))?
            .validated()
            .map_err(js_error)?
    } else {
        crate::target::Target::parse_spec(target_spec_or_json).map_err(js_error)?
    };
    let image = crate::image::decode_gray(bytes).map_err(js_error)?;
    let detection =
        crate::detect::detect(&image, &target, &crate::detect::DetectOptions::default())
            .map_err(js_error)?;
    serde_json::to_string(&detection).map_err(|e| JsError::new(&e.to_string()))
}

/// Write a report (camera or hand-eye JSON) in an export format: the same
/// bytes as `robocal export REPORT --format FORMAT [--transform NAME]`.
/// `transform` may be empty for the default transform.
#[wasm_bindgen]
pub fn export_report(report_json: &str, format: &str, transform: &str) -> Result<String, JsError> {
    let transform = (!transform.is_empty()).then_some(transform);
    crate::io::export::export(report_json, format, transform).map_err(js_error)
}

/// The export format names, as a JSON array of strings.
#[wasm_bindgen]
pub fn export_formats() -> String {
    serde_json::to_string(&crate::io::export::format_names()).unwrap_or_else(|_| "[]".into())
}

/// Read a robot pose file: `{"parsed": {...} | null, "ambiguity": null |
/// "why", "candidates": [...]}` (see `robocal::io::poses_api`).
/// `options_json` may be empty or `{"format", "length_unit", "angle_unit", "direction"}`.
#[wasm_bindgen]
pub fn read_robot_poses(text: &str, options_json: &str) -> Result<String, JsError> {
    crate::io::poses_api::read_poses_json(text, options_json).map_err(js_error)
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
    json_call("planar_fit", json, crate::workflows::planar_api::planar_fit)
}

/// Planar calibration at any height from point pairs. JSON in:
/// `{"points": [{"height_mm", "image_px": [u, v], "robot_mm": [x, y]}],
/// "options"?: {"transform": "rigid"|"similarity"|"affine",
/// "reject_threshold": number|null, "plate_size_mm": [l, w]|null},
/// "predict"?: [...]}`; JSON out: per-height `heights`, `fit`,
/// `pixel_density`, `density_fit`, `predictions`.
#[wasm_bindgen]
pub fn planar_solve(json: &str) -> Result<String, JsError> {
    json_call(
        "planar_solve",
        json,
        crate::workflows::planar_api::planar_solve,
    )
}

/// XY-table calibration with one target. JSON in: `{"observations":
/// [{"stage_mm": [x, y, z], "image_px": [u, v]}], "verification"?: [4 such],
/// "still_target_px"?: [[u, v]], "measurement_noise_px2"?: [[a, b], [c, d]],
/// "kalman_mode"?: "extended"|"linearized"}`; JSON out: `batch`, `kalman`
/// (each with `projection_matrix` 3x4 row-major), `verification`.
#[wasm_bindgen]
pub fn xytable_solve(json: &str) -> Result<String, JsError> {
    json_call(
        "xytable_solve",
        json,
        crate::workflows::xytable::solve_xytable,
    )
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
        crate::workflows::known_motion::solve_known_motion,
    )
}

/// Hand-eye calibration: input JSON as documented in
/// `robocal::handeye::json_api` (setup, base_from_gripper,
/// camera_from_target, method, ...); returns the report JSON
/// (`gripper_from_camera` or `base_from_camera`, the target pose, `methods`,
/// `errors`, `warnings`, ...).
#[wasm_bindgen]
pub fn solve_handeye(input_json: &str) -> Result<String, JsError> {
    crate::handeye::json_api::solve_handeye_json(input_json).map_err(js_error)
}

/// Which reading of the robot poses fits the camera motion: input
/// `{"setup", "candidates": [{"name", "base_from_gripper": [pose...]}],
/// "camera_from_target": [pose...]}`; returns `{"scores": [{"name",
/// "consistency": {"rotation_rms_deg", "translation_rms_mm",
/// "robot_translation_scale"} | null}...] (best first), "recommendation":
/// text | null}` (see `robocal::handeye::json_api::rank_candidates_json`).
#[wasm_bindgen]
pub fn rank_pose_conventions(input_json: &str) -> Result<String, JsError> {
    crate::handeye::json_api::rank_candidates_json(input_json).map_err(js_error)
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
        matrices: Vec<crate::workflows::planar_api::HeightMatrix>,
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

/// The demo session: rendered images (PNG, concatenated) plus a JSON index.
#[wasm_bindgen]
pub struct DemoData {
    json: String,
    bytes: Vec<u8>,
}

#[wasm_bindgen]
impl DemoData {
    /// `{"target", "target_spec", "images": [{"name", "offset", "length"}],
    /// "poses_csv", "truth": {"camera", "gripper_from_camera", "base_from_target"}}`.
    #[wasm_bindgen(getter)]
    pub fn json(&self) -> String {
        self.json.clone()
    }
    /// The PNG files one after the other (see `images` in `json`).
    #[wasm_bindgen(getter)]
    pub fn bytes(&self) -> Vec<u8> {
        self.bytes.clone()
    }
}

/// Render the demo session (seeded, deterministic): what the web app's
/// "load demo data" button loads.
#[wasm_bindgen]
pub fn render_demo(seed: u32) -> Result<DemoData, JsError> {
    let demo = crate::synth::demo::demo_session(seed as u64).map_err(js_error)?;
    #[derive(Serialize)]
    struct Entry<'a> {
        name: &'a str,
        offset: usize,
        length: usize,
    }
    #[derive(Serialize)]
    struct Truth<'a> {
        camera: &'a crate::camera::Camera,
        gripper_from_camera: serde_json::Value,
        base_from_target: serde_json::Value,
    }
    #[derive(Serialize)]
    struct Index<'a> {
        target: &'a crate::target::Target,
        target_spec: &'static str,
        images: Vec<Entry<'a>>,
        poses_csv: &'a str,
        truth: Truth<'a>,
    }
    let mut bytes = Vec::new();
    let mut images = Vec::new();
    for (name, image) in &demo.images {
        let png = crate::image::encode_png(image).map_err(js_error)?;
        images.push(Entry {
            name,
            offset: bytes.len(),
            length: png.len(),
        });
        bytes.extend_from_slice(&png);
    }
    let transform = crate::io::export_transform::transform_json;
    let json = serde_json::to_string(&Index {
        target: &demo.target,
        target_spec: "chessboard:9x6:30mm",
        images,
        poses_csv: &demo.poses_csv,
        truth: Truth {
            camera: &demo.camera,
            gripper_from_camera: transform(&demo.gripper_from_camera),
            base_from_target: transform(&demo.base_from_target),
        },
    })
    .map_err(|e| JsError::new(&e.to_string()))?;
    Ok(DemoData { json, bytes })
}

/// Calibrate a camera from views (detections or point pairs) with one
/// method or all of them: the JSON input and output of
/// `robocal::calib::json_api::calibrate_json`.
#[wasm_bindgen]
pub fn calibrate_camera(input_json: &str) -> Result<String, JsError> {
    crate::calib::json_api::calibrate_json(input_json).map_err(js_error)
}

/// Calibrate a stereo pair: the JSON input and output of
/// `robocal::calib::stereo_json::calibrate_stereo_json` (`left` and `right`
/// views paired by index; returns `left`, `right`, `right_from_left`,
/// `baseline_m`, `rms_px`, ...).
#[wasm_bindgen]
pub fn calibrate_stereo(input_json: &str) -> Result<String, JsError> {
    crate::calib::stereo_json::calibrate_stereo_json(input_json).map_err(js_error)
}

/// An undistorted preview of image bytes taken by `camera_json` (the
/// `camera` object of a calibration report): resampled through the same
/// camera without distortion, longer side at most `max_side` px. `info_json`
/// is `{"width", "height"}` of the preview.
#[wasm_bindgen]
pub fn undistort_preview(
    bytes: &[u8],
    camera_json: &str,
    max_side: u32,
) -> Result<ImagePreview, JsError> {
    let camera: crate::camera::Camera = serde_json::from_str(camera_json)
        .map_err(|e| JsError::new(&format!("camera JSON: {e}")))?;
    let image = crate::image::decode_gray(bytes).map_err(js_error)?;
    let preview = camera.pinhole_preview(max_side).map_err(js_error)?;
    let out = crate::camera::undistort_image(&image, &camera, &preview).map_err(js_error)?;
    let rgba = out.pixels.iter().flat_map(|&g| [g, g, g, 255]).collect();
    Ok(ImagePreview {
        info_json: format!(r#"{{"width":{},"height":{}}}"#, out.width, out.height),
        rgba,
        width: out.width,
        height: out.height,
    })
}
