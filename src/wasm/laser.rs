//! Laser-line sensors for the web app's laser step and the npm package: the
//! laser plane from board images with the stripe, a stripe image to 3-D
//! points, and one image's stripe for drawing. The JSON of
//! `robocal::api::laser_json` (docs/laser.md); the plane's exports are
//! `export_report` on the plane report (`halcon`, the transform formats).

use super::{decode_gray, decode_options, js_error};
use crate::api::laser_json::{laser_plane_request, laser_points_request, laser_stripe_request};
use serde::Serialize;
use wasm_bindgen::prelude::*;

fn to_json<T: Serialize>(value: &T) -> Result<String, JsError> {
    serde_json::to_string(value).map_err(|e| JsError::new(&e.to_string()))
}

/// The laser plane in the camera frame from images of a board with the
/// stripe on it, as `robocal laser plane` finds it: `request_json` is
/// `{"camera": "<camera file text>", "target": spec or target JSON,
/// "pairs": bool, "names": [...], "residual": "image_px" | "point_to_plane",
/// "stripe": {"extractor", "axis", "min_contrast", "max_width_px"}}`;
/// `images` the encoded images (PNG, JPEG, ...), one per pose or, with
/// `pairs`, board (laser off) then stripe (laser on) per pose. Returns the
/// `laser_plane` report (`laser_plane.normal_camera`, `distance_m`,
/// `covariance`, per-image residuals, warnings). `options_json`: see
/// `ImageOptions` (`{"max_pixels"}`).
#[wasm_bindgen]
pub fn laser_plane(
    request_json: &str,
    images: Vec<js_sys::Uint8Array>,
    options_json: Option<String>,
) -> Result<String, JsError> {
    let options = decode_options(options_json)?;
    let decoded = images
        .iter()
        .enumerate()
        .map(|(i, bytes)| {
            crate::image::decode(&bytes.to_vec(), &options)
                .map(|d| d.gray)
                .map_err(|e| JsError::new(&format!("image {}: {e}", i + 1)))
        })
        .collect::<Result<Vec<_>, JsError>>()?;
    to_json(&laser_plane_request(request_json, decoded).map_err(js_error)?)
}

/// A stripe image to 3-D points with a known plane, as `robocal laser
/// points`: `request_json` is `{"camera": "<camera file text>", "plane":
/// a laser_plane report, "gripper_from_camera"?: pose, "base_from_gripper"?:
/// pose, "stripe"?: {...}}`; `off` the same view with the laser off
/// (subtracted first), or undefined. Returns the `laser_points` report.
#[wasm_bindgen]
pub fn laser_points(
    request_json: &str,
    image: &[u8],
    off: Option<Vec<u8>>,
    options_json: Option<String>,
) -> Result<String, JsError> {
    let on = decode_gray(image, options_json.clone())?;
    let off = off.map(|b| decode_gray(&b, options_json)).transpose()?;
    to_json(&laser_points_request(request_json, &on, off.as_ref()).map_err(js_error)?)
}

/// One image's stripe, as the plane and the points extract it: `{"axis":
/// "columns" | "rows", "method", "points": [{"x_px", "y_px", "width_px",
/// "peak", "contrast", "std_px", "saturated"}], "gaps", "ends",
/// "noise_grey"}`. `off`: the laser-off image of the same view, or
/// undefined; `settings_json`: `{"extractor", "axis", "min_contrast",
/// "max_width_px"}` or empty.
#[wasm_bindgen]
pub fn laser_stripe(
    image: &[u8],
    off: Option<Vec<u8>>,
    settings_json: &str,
    options_json: Option<String>,
) -> Result<String, JsError> {
    let on = decode_gray(image, options_json.clone())?;
    let off = off.map(|b| decode_gray(&b, options_json)).transpose()?;
    to_json(&laser_stripe_request(settings_json, &on, off.as_ref()).map_err(js_error)?)
}
