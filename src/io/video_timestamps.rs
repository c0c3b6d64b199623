//! Caliscope's `timestamps.csv`: which frame of each camera's recording
//! belongs to which synchronised frame (issue 36, recordings).
//!
//! # The format
//!
//! A CSV file with the header `sync_index,cam_id,frame_index,frame_time`
//! (any column order, other columns ignored): one row per recorded frame of
//! one camera. `sync_index` is the synchronised frame caliscope grouped the
//! frame under, `cam_id` the camera (the `N` of its `cam_N.mp4`),
//! `frame_index` the camera's own frame counter and `frame_time` its capture
//! time in seconds.
//!
//! # The rule
//!
//! Caliscope writes one video frame per row, so a camera's rows sorted by
//! `frame_index` are its video's frames in order: the `k`-th of them is the
//! video's frame `k` (its counter need not start at 0: the caliscope test
//! session's starts at 26). A camera appears at most once per sync index and
//! a frame index at most once per camera; the caller checks that a camera's
//! row count is its video's frame count ([`CameraFrames::frames`]).

use super::csv_table::CsvTable;
use crate::error::{Error, Result};
use std::collections::BTreeMap;

/// One camera's frames in video order.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraFrames {
    /// Per video frame (index 0, 1, ...): its sync index.
    pub sync_index: Vec<u64>,
    /// Per video frame: its capture time, s.
    pub time_s: Vec<f64>,
}

impl CameraFrames {
    /// The number of frames the timestamps list for this camera.
    pub fn frames(&self) -> usize {
        self.sync_index.len()
    }
}

/// A parsed timestamps file: every camera's frames.
#[derive(Debug, Clone, PartialEq)]
pub struct VideoTimestamps {
    /// By cam_id.
    pub cameras: BTreeMap<u64, CameraFrames>,
}

impl VideoTimestamps {
    /// The camera `cam_id`'s frames, or an error naming the ids there are.
    pub fn camera(&self, cam_id: u64) -> Result<&CameraFrames> {
        self.cameras.get(&cam_id).ok_or_else(|| {
            let ids: Vec<String> = self.cameras.keys().map(u64::to_string).collect();
            Error::invalid(
                "timestamps",
                format!(
                    "no row has cam_id {cam_id} (the file has cam_id {})",
                    ids.join(", ")
                ),
            )
        })
    }
}

/// A whole non-negative number of a field, or a parse error at its cell.
fn count(table: &CsvTable, row: usize, col: usize, name: &str) -> Result<u64> {
    let text = table.text(row, col);
    text.parse::<u64>().map_err(|_| {
        Error::parse(
            table.line_of(row),
            col + 1,
            format!("{name}: expected a whole number >= 0, got '{text}'"),
        )
    })
}

/// Parse caliscope's `timestamps.csv` (module docs).
pub fn parse_video_timestamps(text: &str) -> Result<VideoTimestamps> {
    let table = CsvTable::parse(text)?;
    let cols = table
        .require_columns(&["sync_index", "cam_id", "frame_index", "frame_time"])
        .map_err(|e| match e {
            Error::Parse { line, message, .. } => Error::parse(
                line,
                0,
                format!("{message} (caliscope's timestamps.csv: sync_index,cam_id,frame_index,frame_time)"),
            ),
            other => other,
        })?;
    if table.is_empty() {
        return Err(Error::parse(
            0,
            0,
            "the timestamps file has a header but no rows",
        ));
    }
    // Per camera: frame_index -> (sync_index, time, line).
    let mut rows: BTreeMap<u64, BTreeMap<u64, (u64, f64, usize)>> = BTreeMap::new();
    for r in 0..table.len() {
        let sync = count(&table, r, cols[0], "sync_index")?;
        let cam = count(&table, r, cols[1], "cam_id")?;
        let frame = count(&table, r, cols[2], "frame_index")?;
        let time = table.number(r, cols[3])?;
        let line = table.line_of(r);
        let frames = rows.entry(cam).or_default();
        if let Some((_, _, first)) = frames.get(&frame) {
            return Err(Error::parse(
                line,
                cols[2] + 1,
                format!("camera {cam}'s frame_index {frame} is also on line {first}"),
            ));
        }
        frames.insert(frame, (sync, time, line));
    }
    let mut cameras = BTreeMap::new();
    for (cam, frames) in rows {
        let mut seen: BTreeMap<u64, usize> = BTreeMap::new();
        for (sync, _, line) in frames.values() {
            if let Some(first) = seen.insert(*sync, *line) {
                return Err(Error::parse(
                    *line,
                    cols[0] + 1,
                    format!("camera {cam} has two frames of sync_index {sync} (lines {first} and {line})"),
                ));
            }
        }
        cameras.insert(
            cam,
            CameraFrames {
                sync_index: frames.values().map(|f| f.0).collect(),
                time_s: frames.values().map(|f| f.1).collect(),
            },
        );
    }
    Ok(VideoTimestamps { cameras })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: &str = "sync_index,cam_id,frame_index,frame_time
26,1,26,123.3348083
26,0,26,123.337921
27,0,27,123.5018745
28,0,29,123.67
27,1,28,123.5009203
";

    #[test]
    fn rows_sorted_by_frame_index_are_the_video_frames_in_order() {
        let t = parse_video_timestamps(SAMPLE).unwrap();
        assert_eq!(t.cameras.len(), 2);
        let c0 = t.camera(0).unwrap();
        assert_eq!(c0.sync_index, vec![26, 27, 28]);
        assert_eq!(c0.time_s, vec![123.337921, 123.5018745, 123.67]);
        let c1 = t.camera(1).unwrap();
        assert_eq!(c1.sync_index, vec![26, 27]);
        assert_eq!(c1.frames(), 2);
        let missing = t.camera(3).unwrap_err().to_string();
        assert!(
            missing.contains("cam_id 3") && missing.contains("0, 1"),
            "{missing}"
        );
    }

    #[test]
    fn columns_in_any_order_and_extra_columns_are_read() {
        let text = "frame_time,cam_id,note,frame_index,sync_index\n1.5,2,x,7,3\n";
        let t = parse_video_timestamps(text).unwrap();
        assert_eq!(t.camera(2).unwrap().sync_index, vec![3]);
    }

    #[test]
    fn errors_name_the_line_and_the_expected_format() {
        let e = parse_video_timestamps("sync,cam\n1,2\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("sync_index,cam_id,frame_index,frame_time"),
            "{e}"
        );
        let e = parse_video_timestamps("sync_index,cam_id,frame_index,frame_time\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no rows"), "{e}");
        let bad = "sync_index,cam_id,frame_index,frame_time\n1,-2,3,0.5\n";
        let e = parse_video_timestamps(bad).unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("cam_id"), "{e}");
        let twice = "sync_index,cam_id,frame_index,frame_time\n1,0,3,0.5\n2,0,3,0.6\n";
        let e = parse_video_timestamps(twice).unwrap_err().to_string();
        assert!(e.contains("frame_index 3") && e.contains("line 2"), "{e}");
        let sync = "sync_index,cam_id,frame_index,frame_time\n1,0,3,0.5\n1,0,4,0.6\n";
        let e = parse_video_timestamps(sync).unwrap_err().to_string();
        assert!(e.contains("two frames of sync_index 1"), "{e}");
    }
}
