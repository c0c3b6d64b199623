//! Choosing a video's frames by the live capture's rules (issue 36).
//!
//! Every frame (or every `--every`th) is detected and given to a
//! [`CaptureSession`], exactly as the page's live capture does with camera
//! frames: a frame is kept when the board is found, still, sharp and adds
//! coverage (the rules of [`robocal::capture`], not repeated here). Frame
//! times are the timestamps file's when given, else the frame index over
//! the stream's rate. At most `--max-frames` frames are kept per video;
//! reading stops there.

use super::video::{FrameReader, VideoInfo};
use super::CliError;
use rayon::prelude::*;
use robocal::capture::{measure, CaptureConfig, CaptureSession, Reason};
use robocal::detect::{detect, DetectOptions};
use robocal::image::GrayImage;
use robocal::io::video_frames::video_frame_name;
use robocal::target::{Detection, Target};
use std::collections::BTreeMap;

/// The frame budget of video inputs (the flags of every command that
/// reads images).
#[derive(clap::Args, Clone, Debug, Default)]
pub struct VideoFlags {
    /// Video inputs (.mp4 .m4v .mov .avi .mkv .webm, read through ffmpeg):
    /// look at every Nth frame only (default 1: every frame)
    #[arg(long, value_name = "N")]
    every: Option<usize>,
    /// Video inputs: keep at most N frames per video (default 60); frames
    /// are kept by the live capture's rules: board found, still, sharp,
    /// adding coverage
    #[arg(long, value_name = "N")]
    max_frames: Option<usize>,
    /// Video inputs: the still rule's largest board motion between frames,
    /// px (default 1.5, the live capture's), or 'any' to keep moving boards
    /// (a recording of a board in motion at a low frame rate; the sharp rule
    /// still leaves out blurred frames)
    #[arg(long, value_name = "PX|any")]
    still_px: Option<String>,
    /// Video inputs: which frames the capture's rules keep: capture (found,
    /// still, sharp and adding coverage, default) or sharp (found, still and
    /// sharp: the coverage rule off, for a rig whose cameras need the frames
    /// they share more than each camera's own coverage)
    #[arg(long, value_name = "RULE", value_parser = ["capture", "sharp"])]
    video_keep: Option<String>,
}

/// The bounds of `--every` and `--max-frames`.
const EVERY: (usize, usize) = (1, 100_000);
const MAX_FRAMES: (usize, usize) = (1, 10_000);
/// `--max-frames` when not given.
pub const DEFAULT_MAX_FRAMES: usize = 60;
/// The frame rate assumed when the stream states none.
const FALLBACK_FPS: f64 = 30.0;

impl VideoFlags {
    /// The capture thresholds these flags ask for.
    pub fn config(&self, command: &str) -> Result<CaptureConfig, CliError> {
        let mut config = CaptureConfig::default();
        match self.still_px.as_deref() {
            None => {}
            Some("any") => config.still_max_px = f64::INFINITY,
            Some(text) => match text.parse::<f64>() {
                Ok(px) if px.is_finite() && px > 0.0 => config.still_max_px = px,
                _ => {
                    return Err(CliError::usage(
                        command,
                        format!("--still-px takes a number of pixels > 0 or 'any', got '{text}'"),
                    ))
                }
            },
        }
        Ok(config)
    }

    /// `(every, max_frames, coverage rule on)`, checked.
    pub fn budget(&self, command: &str) -> Result<Budget, CliError> {
        super::check_optional_bounds(command, "--every", self.every, EVERY)?;
        super::check_optional_bounds(command, "--max-frames", self.max_frames, MAX_FRAMES)?;
        Ok(Budget {
            every: self.every.unwrap_or(1),
            max_frames: self.max_frames.unwrap_or(DEFAULT_MAX_FRAMES),
            coverage: self.video_keep.as_deref() != Some("sharp"),
        })
    }
}

/// Which frames of a video are looked at and kept.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    /// Every Nth frame is looked at.
    pub every: usize,
    /// Reading stops once this many are kept.
    pub max_frames: usize,
    /// The capture's coverage rule on (off: a frame that passed found,
    /// still and sharp is kept whatever it adds).
    pub coverage: bool,
}

/// One frame looked at.
#[derive(Debug, Clone)]
pub struct VideoFrame {
    /// Its index in the video (0 first).
    pub index: usize,
    /// `cam_0.mp4#frame0123` ([`video_frame_name`]).
    pub name: String,
    /// The board found, or why not.
    pub detection: Result<Detection, (String, String)>,
    /// Seconds the detector took on this frame (its `detect_ms` in `robocal detect`).
    pub detect_s: f64,
    /// Kept by the capture rules.
    pub kept: bool,
    /// The capture's reason (kept or the first rule it failed).
    pub reason: Reason,
}

/// What one video gave.
#[derive(Debug, Clone)]
pub struct VideoScan {
    pub path: String,
    pub info: VideoInfo,
    /// Frames read from the video (all of them unless stopped early).
    pub frames_read: usize,
    /// The frames looked at, in video order.
    pub frames: Vec<VideoFrame>,
    /// The coverage rule was on.
    pub coverage: bool,
}

impl VideoScan {
    /// The kept frames.
    pub fn kept(&self) -> impl Iterator<Item = &VideoFrame> {
        self.frames.iter().filter(|f| f.kept)
    }

    /// One line for standard error: frames read, found, kept and why the
    /// others were left out.
    pub fn summary(&self) -> String {
        let found = self.frames.iter().filter(|f| f.detection.is_ok()).count();
        let mut reasons: BTreeMap<&'static str, usize> = BTreeMap::new();
        for f in self.frames.iter().filter(|f| !f.kept) {
            *reasons.entry(f.reason.message()).or_default() += 1;
        }
        let left: Vec<String> = reasons.iter().map(|(m, n)| format!("{n} {m}")).collect();
        format!(
            "{}: {} frames read ({} {}x{}), {} looked at, board in {found}, {} kept ({}){}",
            self.path,
            self.frames_read,
            self.info.codec,
            self.info.width,
            self.info.height,
            self.frames.len(),
            self.kept().count(),
            if self.coverage {
                "still, sharp, adding coverage"
            } else {
                "still and sharp"
            },
            if left.is_empty() {
                String::new()
            } else {
                format!("; not kept: {}", left.join(", "))
            }
        )
    }
}

/// The detection of one frame, the detector's seconds and the blur.
type Looked = (Result<Detection, (String, String)>, f64, Option<f64>);

/// The detection, the detector's time and the blur of one frame.
fn look(image: &GrayImage, target: &Target, options: &DetectOptions) -> Looked {
    let started = std::time::Instant::now();
    let found = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        detect(image, target, options)
    }))
    .unwrap_or_else(|_| {
        Err(robocal::Error::invalid(
            "detector",
            "the detector crashed on this frame",
        ))
    });
    let seconds = started.elapsed().as_secs_f64();
    match found {
        Ok(d) => {
            let blur = measure::blur_px(image, &d.points);
            (Ok(d), seconds, blur)
        }
        Err(e) => (Err((e.kind().to_string(), e.to_string())), seconds, None),
    }
}

/// Read `path`, detect the board in every `every`th frame on `pool` and
/// keep frames by the capture rules, at most `max_frames`. `times_s` gives
/// each video frame's time (a timestamps file); its length must be the
/// video's frame count, checked at the end.
pub fn scan(
    path: &str,
    target: &Target,
    options: &DetectOptions,
    budget: Budget,
    config: &CaptureConfig,
    times_s: Option<&[f64]>,
    pool: &rayon::ThreadPool,
) -> Result<VideoScan, CliError> {
    let Budget {
        every,
        max_frames,
        coverage,
    } = budget;
    let mut reader = FrameReader::open(path)?;
    let info = reader.info().clone();
    let mut session = CaptureSession::new(target.clone(), info.width, info.height, config.clone())
        .map_err(|e| CliError::Io(format!("'{path}': {e}")))?;
    let fps = if info.fps > 0.0 {
        info.fps
    } else {
        FALLBACK_FPS
    };
    let batch_len = pool.current_num_threads().max(1) * 2;
    let mut frames = Vec::new();
    let mut read = 0;
    let mut kept = 0;
    let mut last_ms = f64::NEG_INFINITY;
    'video: loop {
        let mut batch = Vec::with_capacity(batch_len);
        while batch.len() < batch_len {
            let Some((index, image)) = reader.next_frame()? else {
                break;
            };
            read = index + 1;
            if index % every == 0 {
                batch.push((index, image));
            }
        }
        if batch.is_empty() {
            break;
        }
        let looked: Vec<_> = pool.install(|| {
            batch
                .par_iter()
                .map(|(_, image)| look(image, target, options))
                .collect()
        });
        for ((index, _), (detection, detect_s, blur)) in batch.iter().zip(looked) {
            let time_ms = match times_s {
                Some(t) => t.get(*index).map_or(f64::NAN, |s| s * 1e3),
                None => *index as f64 * 1e3 / fps,
            };
            // A frame without a later time than the last (a timestamps file
            // out of order) is looked at but not given to the session.
            let report = if time_ms > last_ms {
                last_ms = time_ms;
                let r = session.push_detection(detection.clone().ok(), blur, time_ms);
                r.map_err(|e| CliError::Io(format!("'{path}' frame {index}: {e}")))?
                    .reason
            } else {
                Reason::NotFound
            };
            let passed = matches!(report, Reason::NothingNew | Reason::GoodEnough);
            let keep = report == Reason::Kept || (!coverage && passed);
            kept += usize::from(keep);
            frames.push(VideoFrame {
                index: *index,
                name: video_frame_name(path, *index),
                detection,
                detect_s,
                kept: keep,
                reason: report,
            });
            if kept >= max_frames {
                break 'video;
            }
        }
    }
    let stopped = kept >= max_frames;
    if let Some(t) = times_s.filter(|t| !stopped && t.len() != read) {
        return Err(CliError::Io(format!(
            "'{path}' has {read} frames but the timestamps list {} for its camera",
            t.len()
        )));
    }
    Ok(VideoScan {
        path: path.to_string(),
        info,
        frames_read: read,
        frames,
        coverage,
    })
}
