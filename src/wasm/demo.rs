//! The demo session behind the web app's "load demo data" button: rendered
//! PNGs concatenated, with a JSON index and the scene's truth.

use super::js_error;
use serde::Serialize;
use wasm_bindgen::prelude::*;

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
