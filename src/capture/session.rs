//! The live-capture session: frame history, kept frames, coverage, the
//! running calibration and the suggestion.

use super::coverage::{
    cell_counts, guess_camera, pose_of, signature, Coverage, Novelty, Signature,
};
use super::handeye_guide::{handeye_guide, HandEyeGuide};
use super::suggest::{self, Candidate, Suggestion};
use super::{measure, CaptureConfig, Reason, Status};
use crate::calib::{calibrate, CalibrationOptions, CameraCalibration, View};
use crate::camera::Camera;
use crate::detect::{detect, DetectOptions};
use crate::error::{Error, Result};
use crate::geometry::Pose;
use crate::image::GrayImage;
use crate::target::placement::board_side_m;
use crate::target::{DetectedPoint, Detection, Target};
use nalgebra::Point2;
use serde::Serialize;
use std::collections::{HashMap, VecDeque};

/// Fewest kept frames the running calibration starts from.
pub const MIN_VIEWS_TO_CALIBRATE: usize = 4;

/// A kept frame.
#[derive(Debug, Clone)]
pub struct KeptFrame {
    /// Its detection.
    pub detection: Detection,
    /// Its frame time, ms.
    pub time_ms: f64,
    /// What it covers (through the camera of the moment it was kept, or
    /// the calibrated camera after [`CaptureSession::calibrate`]).
    pub signature: Signature,
    /// Its points per image cell.
    pub cells: Vec<usize>,
    /// The robot's `base_from_gripper` paired with it, if any.
    pub robot: Option<Pose>,
    /// Kept on request rather than by the automatic rule.
    pub manual: bool,
    /// Used by the coverage, the running calibration and the hand-eye
    /// guide (false while its card is excluded: [`CaptureSession::set_included`]).
    pub included: bool,
}

/// What the session says about one frame (the JSON of `push_frame`).
#[derive(Debug, Clone, Serialize)]
pub struct FrameReport {
    /// Found, partial or not found.
    pub status: Status,
    /// Detected pixels `[x, y]`, in id order.
    pub points: Vec<[f64; 2]>,
    /// The target's id of each point.
    pub ids: Vec<usize>,
    /// Whether the board is still.
    pub still: bool,
    /// The largest point motion over the compared frames, px.
    pub motion_px: Option<f64>,
    /// Whether the board is sharp.
    pub sharp: bool,
    /// The blur measure, px (equivalent Gaussian sigma).
    pub blur_px: Option<f64>,
    /// Whether it adds information.
    pub novel: bool,
    /// What it would add.
    pub novelty: Option<Novelty>,
    /// What it covers.
    pub signature: Option<Signature>,
    /// Whether it was kept.
    pub keep: bool,
    /// Why (kept or not).
    pub reason: Reason,
    /// The reason as a sentence.
    pub message: String,
    /// Frames kept so far (the next capture's index).
    pub kept: usize,
    /// Of those, the frames included (not excluded by the user).
    pub used: usize,
    /// The coverage after this frame.
    pub coverage: Coverage,
    /// The pose to suggest next (`None` once good enough).
    pub suggestion: Option<Suggestion>,
    /// Whether the running calibration is good enough.
    pub good_enough: bool,
}

/// One live-capture session (module docs of [`super`]).
#[derive(Debug, Clone)]
pub struct CaptureSession {
    target: Target,
    size: (u32, u32),
    config: CaptureConfig,
    side_m: f64,
    history: VecDeque<(f64, Vec<DetectedPoint>)>,
    last_time_ms: Option<f64>,
    last: Option<(f64, Detection)>,
    kept: Vec<KeptFrame>,
    coverage: Coverage,
    calibration: Option<CameraCalibration>,
    candidates: Vec<Candidate>,
    suggestion: Option<Suggestion>,
}

impl CaptureSession {
    /// A session for `target` in frames of `width x height` pixels.
    pub fn new(target: Target, width: u32, height: u32, config: CaptureConfig) -> Result<Self> {
        let target = target.validated()?;
        if width < 16 || height < 16 || (width as u64) * (height as u64) > 100_000_000 {
            return Err(Error::invalid(
                "frame size",
                format!(
                    "expected a frame of at least 16x16 and at most 100 MP, got {width}x{height}"
                ),
            ));
        }
        let camera = guess_camera(width, height);
        let candidates = suggest::candidates(&camera, &target);
        let mut session = CaptureSession {
            side_m: board_side_m(&target),
            target,
            size: (width, height),
            config,
            history: VecDeque::new(),
            last_time_ms: None,
            last: None,
            kept: vec![],
            coverage: Coverage::new(),
            calibration: None,
            candidates,
            suggestion: None,
        };
        session.update_suggestion();
        Ok(session)
    }

    /// The camera used for poses: the running calibration's, else a guess.
    pub fn camera(&self) -> Camera {
        self.calibration.as_ref().map_or_else(
            || guess_camera(self.size.0, self.size.1),
            |c| c.camera.clone(),
        )
    }

    /// Detect the board in `image` (taken at `time_ms`), measure its blur
    /// and decide ([`Self::push_detection`]).
    pub fn push_image(&mut self, image: &GrayImage, time_ms: f64) -> Result<FrameReport> {
        if (image.width, image.height) != self.size {
            return Err(Error::invalid(
                "frame",
                format!(
                    "expected a {}x{} frame (the session's size), got {}x{}: start a new session for a new resolution",
                    self.size.0, self.size.1, image.width, image.height
                ),
            ));
        }
        let detection = detect(image, &self.target, &DetectOptions::default()).ok();
        let blur = detection
            .as_ref()
            .and_then(|d| measure::blur_px(image, &d.points));
        self.push_detection(detection, blur, time_ms)
    }

    /// Decide on a frame from its detection (`None`: not found) and blur
    /// measure (px, [`measure::blur_px`]); frame times must increase.
    pub fn push_detection(
        &mut self,
        detection: Option<Detection>,
        blur_px: Option<f64>,
        time_ms: f64,
    ) -> Result<FrameReport> {
        let previous = self.last_time_ms;
        if !time_ms.is_finite() || previous.is_some_and(|t| time_ms <= t) {
            return Err(Error::invalid(
                "frame time",
                format!(
                    "expected a time in ms after the previous frame's {}, got {time_ms}",
                    previous.unwrap_or(f64::NEG_INFINITY)
                ),
            ));
        }
        self.last_time_ms = Some(time_ms);
        let detection = detection.filter(|d| !d.points.is_empty());
        let Some(detection) = detection else {
            self.history.clear();
            self.last = None;
            return Ok(self.report(Status::NotFound, None, Verdict::new(Reason::NotFound)));
        };
        let status = if detection.points.len() >= self.target.point_count() {
            Status::Found
        } else {
            Status::Partial
        };
        let mut verdict = self.judge(&detection, blur_px, time_ms);
        self.history.push_back((time_ms, detection.points.clone()));
        self.trim_history(time_ms);
        self.last = Some((time_ms, detection.clone()));
        if verdict.reason == Reason::Kept {
            if let Some((sig, cells)) = verdict.signature.clone().zip(verdict.cells.take()) {
                self.keep(detection.clone(), time_ms, sig, cells, false);
            }
        }
        verdict.keep = verdict.reason == Reason::Kept;
        Ok(self.report(status, Some(&detection), verdict))
    }

    fn judge(&self, detection: &Detection, blur_px: Option<f64>, time_ms: f64) -> Verdict {
        let mut v = Verdict::new(Reason::TooFewPoints);
        v.blur_px = blur_px;
        v.sharp = blur_px.is_some_and(|b| b <= self.config.sharp_max_blur_px);
        // 1. Usable: enough points, and a pose.
        let enough = detection.points.len() as f64
            >= self.config.keep_min_fraction * self.target.point_count() as f64;
        let camera = self.camera();
        let pose = pose_of(detection, &camera);
        if let Some(pose) = &pose {
            let pixels: Vec<Point2<f64>> = detection
                .points
                .iter()
                .map(|p| Point2::new(p.x_px, p.y_px))
                .collect();
            let sig = signature(&pixels, pose, &camera, self.side_m);
            v.novelty = Some(self.coverage.novelty(&sig));
            v.cells = Some(cell_counts(&pixels, self.size.0, self.size.1));
            v.signature = Some(sig);
        }
        // 2. Still.
        let (settled, motion) = self.stillness(&detection.points, time_ms);
        v.motion_px = motion;
        v.still = settled && motion.is_some_and(|m| m <= self.config.still_max_px);
        // 3. What a still, sharp frame would do to the running calibration.
        if let (Some(novelty), Some(pose), true) = (&mut v.novelty, &pose, v.still && v.sharp) {
            self.predict(novelty, detection, pose);
        }
        v.novel = v.novelty.as_ref().is_some_and(|n| n.adds_information());
        let good_enough = self.good_enough();
        v.reason = if !enough || pose.is_none() {
            Reason::TooFewPoints
        } else if !settled {
            Reason::Settling
        } else if !v.still {
            Reason::Moving
        } else if !v.sharp {
            Reason::Blurred
        } else if good_enough {
            Reason::GoodEnough
        } else if !v.novel {
            Reason::NothingNew
        } else {
            Reason::Kept
        };
        v
    }

    /// The uncertainty part of `novelty` ([`suggest`] module docs): only
    /// under a running calibration that is not good enough, and not for a
    /// repeat of a kept view.
    fn predict(&self, novelty: &mut Novelty, detection: &Detection, pose: &Pose) {
        let Some(calibration) = self.calibration.as_ref().filter(|_| !self.good_enough()) else {
            return;
        };
        if self.repeats_a_kept_view(detection) {
            return;
        }
        let Some(predictor) = suggest::Predictor::new(calibration) else {
            return;
        };
        let (object_m, _) = detection.correspondences();
        novelty.predicted_max_std_px = predictor.with_view(&object_m, pose);
        let now = calibration.projection_uncertainty.max_std_px;
        novelty.lowers_uncertainty = novelty
            .predicted_max_std_px
            .is_some_and(|p| p <= (1.0 - suggest::LOWERS_UNCERTAINTY_BY) * now);
    }

    /// Every point of `detection` within [`suggest::SAME_VIEW_PX`] of the
    /// same point of one included kept frame.
    fn repeats_a_kept_view(&self, detection: &Detection) -> bool {
        let near = suggest::SAME_VIEW_PX * suggest::SAME_VIEW_PX;
        self.kept.iter().filter(|k| k.included).any(|k| {
            let at: HashMap<usize, (f64, f64)> = k
                .detection
                .points
                .iter()
                .map(|p| (p.id, (p.x_px, p.y_px)))
                .collect();
            detection.points.iter().all(|p| {
                at.get(&p.id)
                    .is_some_and(|(x, y)| (p.x_px - x).powi(2) + (p.y_px - y).powi(2) <= near)
            })
        })
    }

    /// (enough history to judge, the largest motion over the compared frames).
    fn stillness(&self, points: &[DetectedPoint], time_ms: f64) -> (bool, Option<f64>) {
        let n = self.history.len();
        let compared: Vec<&(f64, Vec<DetectedPoint>)> = self
            .history
            .iter()
            .enumerate()
            .filter(|(i, h)| *i + 2 >= n || h.0 >= time_ms - self.config.still_window_ms)
            .map(|(_, h)| h)
            .collect();
        let oldest = compared.iter().map(|h| h.0).fold(f64::INFINITY, f64::min);
        let settled = compared.len() >= 2 && time_ms - oldest >= self.config.still_min_span_ms;
        let mut worst: Option<f64> = None;
        for (_, earlier) in &compared {
            // A frame sharing no point with this one: the board jumped.
            let m = measure::motion_px(points, earlier).unwrap_or(f64::INFINITY);
            worst = Some(worst.map_or(m, |w| w.max(m)));
        }
        (settled, worst)
    }

    fn trim_history(&mut self, time_ms: f64) {
        while self.history.len() > 3
            && self
                .history
                .front()
                .is_some_and(|h| h.0 < time_ms - self.config.still_window_ms)
        {
            self.history.pop_front();
        }
    }

    fn keep(
        &mut self,
        detection: Detection,
        time_ms: f64,
        sig: Signature,
        cells: Vec<usize>,
        manual: bool,
    ) {
        self.coverage.add(&sig, &cells);
        self.kept.push(KeptFrame {
            detection,
            time_ms,
            signature: sig,
            cells,
            robot: None,
            manual,
            included: true,
        });
        self.update_suggestion();
    }

    /// Keep the last frame with a usable detection whatever the automatic
    /// rule says (the manual capture button); returns its index.
    pub fn keep_last(&mut self) -> Result<usize> {
        let (time_ms, detection) = self.last.clone().ok_or_else(|| {
            Error::invalid(
                "capture",
                "no board in the last frame: show the board to the camera first",
            )
        })?;
        if self.kept.last().is_some_and(|k| k.time_ms == time_ms) {
            return Ok(self.kept.len() - 1);
        }
        let camera = self.camera();
        let pose = pose_of(&detection, &camera).ok_or_else(|| {
            Error::invalid(
                "capture",
                "the last frame's points fix no pose: show more of the board",
            )
        })?;
        let pixels: Vec<Point2<f64>> = detection
            .points
            .iter()
            .map(|p| Point2::new(p.x_px, p.y_px))
            .collect();
        let sig = signature(&pixels, &pose, &camera, self.side_m);
        let cells = cell_counts(&pixels, self.size.0, self.size.1);
        self.keep(detection, time_ms, sig, cells, true);
        Ok(self.kept.len() - 1)
    }

    /// Drop kept frame `index` (excluded by the user); coverage follows.
    pub fn remove(&mut self, index: usize) -> Result<()> {
        if index >= self.kept.len() {
            return Err(Error::invalid(
                "capture",
                format!(
                    "expected a capture index below {}, got {index}",
                    self.kept.len()
                ),
            ));
        }
        self.kept.remove(index);
        self.recount();
        Ok(())
    }

    /// Kept frame `index`, or the error naming the valid indices.
    fn kept_mut(&mut self, index: usize) -> Result<&mut KeptFrame> {
        let n = self.kept.len();
        self.kept.get_mut(index).ok_or_else(|| {
            Error::invalid(
                "capture",
                format!("expected a capture index below {n}, got {index}"),
            )
        })
    }

    /// Include or exclude kept frame `index` (its card's include box): an
    /// excluded frame keeps its index and its robot pose but leaves the
    /// coverage, the running calibration and the hand-eye guide until it
    /// is included again.
    pub fn set_included(&mut self, index: usize, included: bool) -> Result<()> {
        let kept = self.kept_mut(index)?;
        if kept.included != included {
            kept.included = included;
            self.recount();
        }
        Ok(())
    }

    /// The kept frames included (not excluded by the user).
    pub fn used(&self) -> usize {
        self.kept.iter().filter(|k| k.included).count()
    }

    /// Pair kept frame `index` with the robot's `base_from_gripper`.
    pub fn set_robot_pose(&mut self, index: usize, base_from_gripper: Pose) -> Result<()> {
        let kept = self.kept_mut(index)?;
        kept.robot = Some(base_from_gripper);
        Ok(())
    }

    /// Run the calibration (default options: Brown model) on the kept
    /// frames; the coverage is then recounted through the calibrated
    /// camera and the suggestion follows the uncertainty rule.
    pub fn calibrate(&mut self) -> Result<&CameraCalibration> {
        let used = self.used();
        if used < MIN_VIEWS_TO_CALIBRATE {
            let excluded = self.kept.len() - used;
            let also = if excluded > 0 {
                format!(" ({excluded} excluded)")
            } else {
                String::new()
            };
            return Err(Error::invalid(
                "captures",
                format!(
                    "the running calibration needs at least {MIN_VIEWS_TO_CALIBRATE} captures, got {used}{also}: keep capturing"
                ),
            ));
        }
        let views: Vec<View> = self
            .kept
            .iter()
            .enumerate()
            .filter(|(_, k)| k.included)
            .map(|(i, k)| {
                let (object_m, image_px) = k.detection.correspondences();
                View {
                    name: format!("capture_{i:03}"),
                    object_m,
                    image_px,
                    point_ids: k.detection.points.iter().map(|p| p.id).collect(),
                }
            })
            .collect();
        let calibration = calibrate(&views, self.size, &CalibrationOptions::default())?;
        self.candidates = suggest::candidates(&calibration.camera, &self.target);
        self.calibration = Some(calibration);
        self.recount();
        self.calibration
            .as_ref()
            .ok_or_else(|| Error::degenerate("the calibration was not stored"))
    }

    fn recount(&mut self) {
        let camera = self.camera();
        self.coverage = Coverage::new();
        for k in self.kept.iter_mut().filter(|k| k.included) {
            if let Some(pose) = pose_of(&k.detection, &camera) {
                let pixels: Vec<Point2<f64>> = k
                    .detection
                    .points
                    .iter()
                    .map(|p| Point2::new(p.x_px, p.y_px))
                    .collect();
                k.signature = signature(&pixels, &pose, &camera, self.side_m);
            }
            self.coverage.add(&k.signature, &k.cells);
        }
        self.update_suggestion();
    }

    fn update_suggestion(&mut self) {
        self.suggestion = match &self.calibration {
            Some(c) if suggest::good_enough(c, self.used()) => None,
            Some(c) => suggest::by_uncertainty(&self.candidates, c, &self.target)
                .or_else(|| suggest::by_coverage(&self.candidates, &self.coverage)),
            None => suggest::by_coverage(&self.candidates, &self.coverage),
        };
    }

    /// Whether the running calibration is good enough ([`suggest`] docs).
    pub fn good_enough(&self) -> bool {
        self.calibration
            .as_ref()
            .is_some_and(|c| suggest::good_enough(c, self.used()))
    }

    /// The kept frames.
    pub fn kept(&self) -> &[KeptFrame] {
        &self.kept
    }
    /// The coverage of the kept frames.
    pub fn coverage(&self) -> &Coverage {
        &self.coverage
    }
    /// The current suggestion.
    pub fn suggestion(&self) -> Option<&Suggestion> {
        self.suggestion.as_ref()
    }
    /// The running calibration, once [`Self::calibrate`] succeeded.
    pub fn calibration(&self) -> Option<&CameraCalibration> {
        self.calibration.as_ref()
    }
    /// The target.
    pub fn target(&self) -> &Target {
        &self.target
    }
    /// The hand-eye guide over the kept frames paired with robot poses.
    pub fn handeye_guide(&self) -> HandEyeGuide {
        let robot: Vec<Pose> = self
            .kept
            .iter()
            .filter(|k| k.included)
            .filter_map(|k| k.robot)
            .collect();
        handeye_guide(&robot)
    }

    fn report(&self, status: Status, detection: Option<&Detection>, v: Verdict) -> FrameReport {
        let points = detection.map_or(&[][..], |d| &d.points[..]);
        FrameReport {
            status,
            points: points.iter().map(|p| [p.x_px, p.y_px]).collect(),
            ids: points.iter().map(|p| p.id).collect(),
            still: v.still,
            motion_px: v.motion_px.filter(|m| m.is_finite()),
            sharp: v.sharp,
            blur_px: v.blur_px,
            novel: v.novel,
            novelty: v.novelty,
            signature: v.signature,
            keep: v.keep,
            reason: v.reason,
            message: v.reason.message().to_string(),
            kept: self.kept.len(),
            used: self.used(),
            coverage: self.coverage.clone(),
            suggestion: self.suggestion.clone(),
            good_enough: self.good_enough(),
        }
    }
}

/// The tests' outcome for one frame.
struct Verdict {
    reason: Reason,
    still: bool,
    motion_px: Option<f64>,
    sharp: bool,
    blur_px: Option<f64>,
    novel: bool,
    novelty: Option<Novelty>,
    signature: Option<Signature>,
    cells: Option<Vec<usize>>,
    keep: bool,
}

impl Verdict {
    fn new(reason: Reason) -> Verdict {
        Verdict {
            reason,
            still: false,
            motion_px: None,
            sharp: false,
            blur_px: None,
            novel: false,
            novelty: None,
            signature: None,
            cells: None,
            keep: false,
        }
    }
}
