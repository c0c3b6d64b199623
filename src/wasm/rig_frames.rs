//! The frame grouping of the web app's rig step: the rule of `robocal rig`
//! (`robocal::io::pairing`).

use super::js_error;
use crate::calib::multi::rig::sort_frame_keys;
use crate::io::pairing::{default_grouping, frame_keys, FrameGrouping};
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraNames {
    name: String,
    images: Vec<String>,
}

#[derive(Serialize)]
struct Grouping {
    grouped_by: String,
    keys: Vec<Vec<String>>,
    frames: Vec<String>,
}

/// Group a rig's images into frames as `robocal rig` does. In:
/// `[{"name": "front", "images": ["front01.png", ...]}, ...]` and `group_by`
/// (`"number"`, `"last"`, `"first"`, `"order"`, a pattern with one `(\d+)`
/// such as `"sync(\d+)"` (see [`FrameGrouping`]), or empty: by number
/// unless no name has one).
/// Out: `{"grouped_by": the rule, "keys": [[key of each image] per
/// camera], "frames": [every key, sorted]}`; a name without a key, or a key
/// twice in one camera, is an error naming the files and the rules.
#[wasm_bindgen]
pub fn rig_frame_keys(cameras_json: &str, group_by: &str) -> Result<String, JsError> {
    let cameras: Vec<CameraNames> = serde_json::from_str(cameras_json).map_err(|e| {
        JsError::new(&format!(
            "cameras: expected [{{\"name\": ..., \"images\": [file names]}}, ...]: {e}"
        ))
    })?;
    let by = match group_by {
        "" => default_grouping(cameras.iter().flat_map(|c| &c.images).map(String::as_str)),
        rule => FrameGrouping::from_rule(rule).map_err(js_error)?,
    };
    let mut keys = Vec::with_capacity(cameras.len());
    for c in &cameras {
        let names: Vec<&str> = c.images.iter().map(String::as_str).collect();
        keys.push(frame_keys(&names, &by, &c.name).map_err(js_error)?);
    }
    let mut frames: Vec<String> = keys.iter().flatten().cloned().collect();
    sort_frame_keys(&mut frames);
    frames.dedup();
    serde_json::to_string(&Grouping {
        grouped_by: by.rule(),
        keys,
        frames,
    })
    .map_err(|e| JsError::new(&e.to_string()))
}
