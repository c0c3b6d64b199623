//! `robocal rig` from recordings: a camera given as one video file
//! (`--camera cam0 cam_0.mp4`), with or without a timestamps file
//! (caliscope's `timestamps.csv`, `--timestamps`).
//!
//! Each camera's video is read and its frames chosen by the live capture's
//! rules ([`super::video_frames`]); a rig frame is a frame any camera kept,
//! and every camera's detection of that frame joins it. Frames are matched
//! across cameras by the timestamps file's `sync_index` (the camera's
//! `cam_id` is the number in its video's file name, `cam_0.mp4` -> 0, else
//! in the camera's name), or without one by the frame index (videos
//! started together at one rate).

use super::video::is_video;
use super::video_frames::{scan, VideoFlags};
use super::video_inputs::{pool, Inputs};
use super::CliError;
use robocal::detect::DetectOptions;
use robocal::io::pairing::number_in_name;
use robocal::io::video_timestamps::{parse_video_timestamps, VideoTimestamps};
use robocal::target::{Detection, Target};
use std::collections::{BTreeSet, HashMap};

/// The video cameras of a rig, their frames chosen.
pub struct RigVideos {
    /// Per video frame name: its rig frame key.
    keys: HashMap<String, String>,
    /// Per video frame name: its detection.
    frames: HashMap<String, (Detection, f64)>,
}

fn usage(message: impl Into<String>) -> CliError {
    CliError::usage("rig", message)
}

/// The timestamps' camera id of a camera: the number in its video's name,
/// else in its own name.
fn cam_id(name: &str, video: &str, stamps: &VideoTimestamps) -> Result<u64, CliError> {
    let id = number_in_name(video)
        .or_else(|| number_in_name(name))
        .and_then(|n| n.parse::<u64>().ok())
        .ok_or_else(|| {
            usage(format!(
                "camera {name}: no number in '{video}' or in the camera's name to find its \
                 cam_id in the timestamps (name the video cam_N.mp4, as caliscope does)"
            ))
        })?;
    stamps
        .camera(id)
        .map(|_| id)
        .map_err(|e| CliError::Io(format!("camera {name} ('{video}'): {e}")))
}

/// Read every camera given as one video (`images[k] == [video]`), choose
/// its frames and put their names in place of the video. `None` when no
/// camera is a video (nothing read, `--timestamps` refused).
pub fn expand(
    names: &[String],
    images: &mut [Vec<String>],
    target: &Target,
    options: &DetectOptions,
    flags: &VideoFlags,
    timestamps: Option<&str>,
    threads: Option<usize>,
) -> Result<Option<RigVideos>, CliError> {
    let is_video_camera = |list: &Vec<String>| list.iter().any(|f| is_video(f));
    if !images.iter().any(is_video_camera) {
        return match timestamps {
            Some(_) => Err(usage(
                "--timestamps goes with cameras given as videos (--camera cam0 cam_0.mp4 ...)",
            )),
            None => Ok(None),
        };
    }
    let stamps = timestamps
        .map(|path| {
            parse_video_timestamps(&super::read_text(path)?)
                .map_err(|e| CliError::from(e).in_file(path))
        })
        .transpose()?;
    let budget = flags.budget("rig")?;
    let config = flags.config("rig")?;
    let pool = pool(threads)?;
    // 1. Every video camera's frames and their sync keys.
    let mut scans = Vec::new();
    for (k, list) in images.iter().enumerate() {
        if !is_video_camera(list) {
            continue;
        }
        let [video] = list.as_slice() else {
            return Err(usage(format!(
                "camera {}: give one video per camera, or images, not {} files with a video",
                names[k],
                list.len()
            )));
        };
        let frames = match &stamps {
            Some(s) => Some(
                s.camera(cam_id(&names[k], video, s)?)
                    .map_err(CliError::from)?,
            ),
            None => None,
        };
        let times = frames.map(|f| f.time_s.as_slice());
        let found = scan(video, target, options, budget, &config, times, &pool)?;
        eprintln!("robocal rig: camera {}: {}", names[k], found.summary());
        let key = |index: usize| match frames {
            Some(f) => f.sync_index.get(index).map_or(index as u64, |s| *s),
            None => index as u64,
        };
        let keyed: Vec<_> = found
            .frames
            .into_iter()
            .map(|f| (key(f.index), f))
            .collect();
        scans.push((k, keyed));
    }
    // 2. The rig frames: every key a camera kept.
    let wanted: BTreeSet<u64> = scans
        .iter()
        .flat_map(|(_, frames)| frames.iter().filter(|(_, f)| f.kept).map(|(key, _)| *key))
        .collect();
    let mut videos = RigVideos {
        keys: HashMap::new(),
        frames: HashMap::new(),
    };
    for (k, frames) in scans {
        let mut list = Vec::new();
        for (key, frame) in frames {
            if let (true, Ok(d)) = (wanted.contains(&key), frame.detection) {
                videos.keys.insert(frame.name.clone(), key.to_string());
                videos
                    .frames
                    .insert(frame.name.clone(), (d, frame.detect_s));
                list.push(frame.name);
            }
        }
        images[k] = list;
    }
    eprintln!(
        "robocal rig: {} rig frames from the videos (a frame any camera kept, with every camera that found the board in it)",
        wanted.len()
    );
    Ok(Some(videos))
}

impl RigVideos {
    /// The rig frame key of a video frame, `None` for an image file.
    pub fn key(&self, name: &str) -> Option<String> {
        self.keys.get(name).cloned()
    }

    /// The inputs of every name in `all` (video frames already detected).
    pub fn inputs(&self, all: &[String]) -> Inputs {
        Inputs::with_frames(all.to_vec(), self.frames.clone())
    }
}
