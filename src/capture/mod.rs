//! Live capture (issue 21): decide for each new camera frame whether the
//! board is found, still, sharp and adds information, keep it or say why
//! not, track the coverage, run the running calibration on the kept frames
//! and suggest the next pose until the calibration is good enough.
//!
//! Pure: frame times come in as numbers (milliseconds, increasing), pixels
//! as a [`GrayImage`]; nothing here reads a clock, a file or the DOM.
//!
//! The decision for a frame, in order (the first failing test is the
//! reason):
//! 1. **found**: the detector found the board (`found` when every point,
//!    `partial` when some); a frame is usable with at least
//!    [`CaptureConfig::keep_min_fraction`] of the board's points whose
//!    pose can be estimated;
//! 2. **still**: the board was found in this frame and in the frames it is
//!    compared with: every earlier frame of the last
//!    [`CaptureConfig::still_window_ms`] and at least the 2 frames before
//!    it, the oldest of them at least [`CaptureConfig::still_min_span_ms`]
//!    earlier; no common point moved more than
//!    [`CaptureConfig::still_max_px`] between this frame and any of them;
//! 3. **sharp**: the blur measure ([`measure::blur_px`], the equivalent
//!    Gaussian sigma of the board's strongest edges relative to its own
//!    contrast) at most [`CaptureConfig::sharp_max_blur_px`];
//! 4. **not good enough yet**: once the running calibration is good enough
//!    ([`suggest`]) no frame is kept automatically;
//! 5. **novel**: it adds information ([`coverage::Novelty::adds_information`]:
//!    new image cells, a new tilt bin or a new distance bin, or, under a
//!    running calibration, a predicted worst projection uncertainty at
//!    least [`suggest::LOWERS_UNCERTAINTY_BY`] lower, not repeating a kept
//!    view);
//! 6. then it is kept.

pub mod coverage;
pub mod handeye_guide;
pub mod measure;
mod session;
pub mod suggest;
#[cfg(test)]
mod tests;

pub use coverage::{Coverage, Novelty, Signature};
pub use handeye_guide::{handeye_guide, HandEyeGuide};
pub use session::{CaptureSession, FrameReport, KeptFrame};
pub use suggest::{Rule, Suggestion};

use serde::Serialize;

/// The thresholds of the decision (module docs). Defaults in brackets.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaptureConfig {
    /// Largest point motion of a still board, px [1.5].
    pub still_max_px: f64,
    /// Window of earlier frames compared for stillness, ms [500].
    pub still_window_ms: f64,
    /// Shortest time the board must have been still, ms [250].
    pub still_min_span_ms: f64,
    /// Largest blur (equivalent Gaussian sigma) of a sharp frame, px [1.6].
    pub sharp_max_blur_px: f64,
    /// Fewest points, as a fraction of the board's, of a usable frame [0.5].
    pub keep_min_fraction: f64,
}

impl Default for CaptureConfig {
    fn default() -> Self {
        CaptureConfig {
            still_max_px: 1.5,
            still_window_ms: 500.0,
            still_min_span_ms: 250.0,
            sharp_max_blur_px: 1.6,
            keep_min_fraction: 0.5,
        }
    }
}

/// Whether the board was found in a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Every point of the board.
    Found,
    /// Some of its points (marker boards, partly visible).
    Partial,
    /// None.
    NotFound,
}

/// Why a frame was kept or not (the first test it failed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Reason {
    /// No board in the frame.
    NotFound,
    /// Too few points, or points that fix no pose.
    TooFewPoints,
    /// Found, but not yet seen long enough to judge stillness.
    Settling,
    /// The board moves.
    Moving,
    /// The board is blurred.
    Blurred,
    /// Still and sharp, but the running calibration is good enough already.
    GoodEnough,
    /// Still and sharp but adds nothing to the coverage.
    NothingNew,
    /// Kept by the automatic rule.
    Kept,
    /// Kept on the user's request.
    KeptManually,
}

impl Reason {
    /// A sentence for the page.
    pub fn message(&self) -> &'static str {
        match self {
            Reason::NotFound => "no board found",
            Reason::TooFewPoints => "too little of the board is visible",
            Reason::Settling => "hold the board still",
            Reason::Moving => "the board moves: hold it still",
            Reason::Blurred => "the board is blurred: focus, light or hold steadier",
            Reason::GoodEnough => "the calibration is good enough: no more captures are needed",
            Reason::NothingNew => "this view adds nothing new: move to the suggested pose",
            Reason::Kept => "captured",
            Reason::KeptManually => "captured (manual)",
        }
    }
}
