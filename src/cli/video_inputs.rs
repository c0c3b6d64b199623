//! Image arguments that are videos: each becomes its kept frames
//! ([`super::video_frames`]), named `cam_0.mp4#frame0123`, in the place of
//! the video in the argument list; the other arguments stay as they are.
//! Without a video among the arguments nothing is spawned.

use super::detect::{run_all, Outcome};
use super::video::is_video;
use super::video_frames::{scan, VideoFlags};
use super::CliError;
use robocal::detect::DetectOptions;
use robocal::image::DecodeOptions;
use robocal::target::{Detection, Target};
use std::collections::HashMap;

/// The image arguments with every video replaced by its kept frames.
pub struct Inputs {
    /// Image files and video frame names, in argument order.
    pub names: Vec<String>,
    /// The detection of each kept video frame and the detector's seconds, by name.
    frames: HashMap<String, (Detection, f64)>,
}

/// A pool of `threads` workers (0 or 1: one; default: one per core).
pub fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool, CliError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.map_or(0, |n| n.max(1)))
        .build()
        .map_err(|e| CliError::Io(format!("cannot start the detection threads: {e}")))
}

/// Replace every video of `files` by its kept frames; a summary line per
/// video goes to standard error.
pub fn expand(
    command: &str,
    files: &[String],
    target: &Target,
    options: &DetectOptions,
    flags: &VideoFlags,
    threads: Option<usize>,
) -> Result<Inputs, CliError> {
    let mut inputs = Inputs {
        names: Vec::with_capacity(files.len()),
        frames: HashMap::new(),
    };
    if !files.iter().any(|f| is_video(f)) {
        inputs.names = files.to_vec();
        return Ok(inputs);
    }
    let budget = flags.budget(command)?;
    let config = flags.config(command)?;
    let pool = pool(threads)?;
    for file in files {
        if !is_video(file) {
            inputs.names.push(file.clone());
            continue;
        }
        let video = scan(file, target, options, budget, &config, None, &pool)?;
        eprintln!("robocal {command}: {}", video.summary());
        for frame in video.frames.into_iter().filter(|f| f.kept) {
            if let Ok(d) = frame.detection {
                inputs.names.push(frame.name.clone());
                inputs.frames.insert(frame.name, (d, frame.detect_s));
            }
        }
    }
    Ok(inputs)
}

impl Inputs {
    /// `names`, the video frames among them detected already.
    pub fn with_frames(names: Vec<String>, frames: HashMap<String, (Detection, f64)>) -> Inputs {
        Inputs { names, frames }
    }

    /// The detection of a kept video frame and the detector's seconds on it,
    /// `None` for an image file.
    pub fn frame(&self, name: &str) -> Option<&(Detection, f64)> {
        self.frames.get(name)
    }

    /// The outcome of every name: a video frame's detection as found while
    /// choosing it, an image file's from [`run_all`].
    pub fn detect(
        &self,
        target: &Target,
        options: &DetectOptions,
        decode: &DecodeOptions,
        threads: Option<usize>,
    ) -> Result<Vec<Outcome>, CliError> {
        let images: Vec<String> = self
            .names
            .iter()
            .filter(|n| !self.frames.contains_key(*n))
            .cloned()
            .collect();
        let mut detected = run_all(&images, target, options, decode, threads)?.into_iter();
        let mut outcomes = Vec::with_capacity(self.names.len());
        for name in &self.names {
            let outcome = match self.frames.get(name) {
                Some((d, seconds)) => Some(Outcome::Found(d.clone(), *seconds)),
                None => detected.next(),
            };
            outcomes.extend(outcome);
        }
        Ok(outcomes)
    }
}
