//! Recordings in the web app (issue 36): caliscope's `timestamps.csv`
//! read by the core parser (`robocal::io::video_timestamps`), so the page
//! groups several cameras' video frames into rig frames by `sync_index`
//! as `robocal rig --timestamps` does; and the name of a frame taken from
//! a video (`robocal::io::video_frames`), the CLI's.

use super::js_error;
use crate::io::video_frames;
use crate::io::video_timestamps::parse_video_timestamps;
use serde::Serialize;
use std::collections::BTreeMap;
use wasm_bindgen::prelude::*;

#[derive(Serialize)]
struct CameraRows<'a> {
    /// Per video frame (0, 1, ...): its sync index.
    sync_index: &'a [u64],
    /// Per video frame: its capture time, s.
    time_s: &'a [f64],
}

#[derive(Serialize)]
struct Timestamps<'a> {
    /// By cam_id (the N of `cam_N.mp4`), as a decimal string.
    cameras: BTreeMap<String, CameraRows<'a>>,
}

/// Read caliscope's `timestamps.csv` (`sync_index,cam_id,frame_index,frame_time`,
/// any column order). Out: `{"cameras": {"0": {"sync_index": [...],
/// "time_s": [...]}, ...}}`, each camera's rows in video frame order (the
/// `k`-th entry is the video's frame `k`); a malformed file is an error
/// naming its line.
#[wasm_bindgen]
pub fn video_timestamps(text: &str) -> Result<String, JsError> {
    let stamps = parse_video_timestamps(text).map_err(js_error)?;
    let cameras = stamps
        .cameras
        .iter()
        .map(|(id, c)| {
            (
                id.to_string(),
                CameraRows {
                    sync_index: &c.sync_index,
                    time_s: &c.time_s,
                },
            )
        })
        .collect();
    serde_json::to_string(&Timestamps { cameras }).map_err(|e| JsError::new(&e.to_string()))
}

/// The name of frame `index` (0 first) of the video file `video`:
/// `cam_0.mp4#frame0123`, as `robocal` names the frames it takes from a
/// video (plain text, not JSON).
#[wasm_bindgen]
pub fn video_frame_name(video: &str, index: u32) -> String {
    video_frames::video_frame_name(video, index as usize)
}
