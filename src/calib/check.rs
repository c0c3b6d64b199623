//! The health check of a saved calibration against new images of the same
//! target: has the camera changed since it was calibrated?
//!
//! 1. Every new view is posed with the saved camera ([`super::pnp`]): the
//!    reprojection RMS of the saved model on new data.
//! 2. fx, fy, cx, cy are refitted on the new views with the lens model and
//!    skew held at their saved values (the calibration's own bundle
//!    adjustment with a fixed-parameter mask), each with its std.
//! 3. The projection difference between the saved and the refitted camera
//!    ([`super::projection_diff`], implied rotation compensated).
//! 4. With a saved `camera_from_target` (a fixed camera looking at a fixed
//!    target: a rig camera, an eye-to-hand camera), the pose shift.
//!
//! The verdict (docs/check.md):
//! - `broken`: no new view could be posed, the refit failed, or the saved
//!   model reprojects the new views with an RMS above `broken_rms_px`
//!   (default max(10 x the saved RMS, 3 px));
//! - `drifted`: the worst projection shift exceeds `shift_px` (default
//!   max(3 x the projection std, 1 px), the projection std combining the
//!   saved calibration's and the refit's worst 1-sigma), or a refitted
//!   parameter moved more than max(3 x its std, 0.5 px) (its std combining
//!   the saved and the refit std), or the pose moved more than 2 mm or
//!   0.2 deg;
//! - `ok` otherwise.

use super::evaluate::refine_from;
use super::pnp::camera_from_target;
use super::projection_diff::{projection_diff, DiffOptions, ProjectionDiff};
use super::{CalibrationOptions, View};
use crate::camera::Camera;
use crate::error::Result;
use crate::geometry::{rotation_angle_between, Pose};
use crate::report_kind::ReportKind;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The parameters the check refits, in the order of [`Camera::params`].
pub const REFIT_PARAMS: [&str; 4] = ["fx", "fy", "cx", "cy"];
/// Most solver iterations of the refit.
const REFIT_ITERATIONS: usize = 100;

/// What the check knows of the saved calibration.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedCalibration {
    /// The saved camera.
    pub camera: Camera,
    /// The saved std of each parameter by name (a robocal report's `std`);
    /// empty when the file has none (OpenCV, ROS, ...).
    pub std: BTreeMap<String, f64>,
    /// The saved worst projection 1-sigma, px (a report's
    /// `projection_uncertainty.max_std_px`).
    pub projection_std_px: Option<f64>,
    /// The saved calibration's RMS, px.
    pub rms_px: Option<f64>,
    /// Where the (fixed) camera saw the (fixed) target when it was calibrated.
    pub camera_from_target: Option<Pose>,
}

/// The thresholds of the verdict; every one can be overridden.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CheckThresholds {
    /// Drifted when the worst projection shift exceeds this many
    /// projection std.
    pub shift_sigma: f64,
    /// ... or this many px, whichever is larger.
    pub shift_floor_px: f64,
    /// The projection-shift threshold itself, px (replaces the two above).
    pub shift_px: Option<f64>,
    /// A parameter moved when its shift exceeds this many of its std.
    pub param_sigma: f64,
    /// ... or this many px, whichever is larger.
    pub param_floor_px: f64,
    /// Broken when the saved model reprojects the new views with a larger
    /// RMS, px (default max(10 x the saved RMS, 3 px)).
    pub broken_rms_px: Option<f64>,
    /// The pose moved when its translation changed more than this, mm.
    pub pose_mm: f64,
    /// ... or its rotation more than this, degrees.
    pub pose_deg: f64,
}

impl Default for CheckThresholds {
    fn default() -> Self {
        CheckThresholds {
            shift_sigma: 3.0,
            shift_floor_px: 1.0,
            shift_px: None,
            param_sigma: 3.0,
            param_floor_px: 0.5,
            broken_rms_px: None,
            pose_mm: 2.0,
            pose_deg: 0.2,
        }
    }
}

/// Default broken RMS: this many times the saved RMS ...
const BROKEN_RMS_FACTOR: f64 = 10.0;
/// ... and at least this, px.
const BROKEN_RMS_FLOOR_PX: f64 = 3.0;

/// The thresholds the verdict used, resolved against the uncertainty.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct UsedThresholds {
    /// Projection shift above which the camera drifted, px.
    pub shift_px: f64,
    /// The projection std it came from (saved and refit worst 1-sigma
    /// combined), px; `None` when neither is known.
    pub projection_std_px: Option<f64>,
    /// See [`CheckThresholds::shift_sigma`].
    pub shift_sigma: f64,
    /// See [`CheckThresholds::shift_floor_px`].
    pub shift_floor_px: f64,
    /// See [`CheckThresholds::param_sigma`].
    pub param_sigma: f64,
    /// See [`CheckThresholds::param_floor_px`].
    pub param_floor_px: f64,
    /// Reprojection RMS above which the check reads broken, px.
    pub broken_rms_px: f64,
    /// See [`CheckThresholds::pose_mm`].
    pub pose_mm: f64,
    /// See [`CheckThresholds::pose_deg`].
    pub pose_deg: f64,
}

/// The verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The new images agree with the saved calibration.
    Ok,
    /// The camera changed beyond the saved calibration's uncertainty.
    Drifted,
    /// The saved calibration does not describe the camera of the images
    /// (or the images cannot be checked).
    Broken,
}

/// One new view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CheckedView {
    /// The image name.
    pub name: String,
    /// Target points seen.
    pub n_points: usize,
    /// The saved model's reprojection RMS on the view after posing it, px.
    pub rms_px: Option<f64>,
    /// Why the view could not be posed.
    pub error: Option<String>,
}

/// One refitted parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParameterShift {
    /// `fx`, `fy`, `cx` or `cy`.
    pub name: String,
    /// The saved value, px.
    pub saved: f64,
    /// The refitted value, px.
    pub refit: f64,
    /// refit - saved, px.
    pub shift_px: f64,
    /// The saved std, px (`None`: the file has none).
    pub saved_std_px: Option<f64>,
    /// The refit's std, px (`None`: the new views do not determine it).
    pub refit_std_px: Option<f64>,
    /// The shift in std (saved and refit std combined); `None` without any.
    pub shift_std: Option<f64>,
    /// Whether it moved beyond the threshold.
    pub moved: bool,
}

/// The refitted camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Refit {
    /// The saved camera with fx, fy, cx, cy refitted.
    pub camera: Camera,
    /// The refit's RMS on the new views, px.
    pub rms_px: f64,
    /// Its worst projection 1-sigma, px (0 when not determined).
    pub projection_std_px: f64,
}

/// The camera pose change of a fixed camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoseShift {
    /// Translation change (median over the views), mm.
    pub translation_mm: f64,
    /// Rotation change (median over the views), degrees.
    pub rotation_deg: f64,
    /// Whether it moved beyond the thresholds.
    pub moved: bool,
}

/// The result of [`check_calibration`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CheckReport {
    /// `check`.
    pub kind: ReportKind,
    /// robocal version that produced the report.
    pub robocal_version: String,
    /// `ok`, `drifted` or `broken`.
    pub verdict: Verdict,
    /// Why, one line per rule that fired (empty for `ok`).
    pub reasons: Vec<String>,
    /// Image width and height, px.
    pub image_size_px: [u32; 2],
    /// Every new view.
    pub views: Vec<CheckedView>,
    /// The saved model's reprojection RMS over the posed views, px.
    pub reprojection_rms_px: Option<f64>,
    /// The refitted camera.
    pub refit: Option<Refit>,
    /// fx, fy, cx, cy: saved, refitted, shift in px and in std.
    pub parameters: Vec<ParameterShift>,
    /// The names of the parameters that moved.
    pub moved: Vec<String>,
    /// Saved vs refitted projection, implied rotation compensated.
    pub projection_shift_px: Option<ProjectionDiff>,
    /// With a saved camera_from_target: how far the camera moved.
    pub pose_shift: Option<PoseShift>,
    /// The thresholds used.
    pub thresholds: UsedThresholds,
    /// Things to know (few views, undetermined parameters).
    pub warnings: Vec<String>,
}

/// Check `saved` against new `views` of the same target (at the saved
/// image size; the caller checks it).
pub fn check_calibration(
    saved: &SavedCalibration,
    views: &[View],
    thresholds: &CheckThresholds,
) -> Result<CheckReport> {
    let camera = &saved.camera;
    let broken_rms_px = thresholds.broken_rms_px.unwrap_or_else(|| {
        (BROKEN_RMS_FACTOR * saved.rms_px.unwrap_or(0.0)).max(BROKEN_RMS_FLOOR_PX)
    });
    let mut report = CheckReport {
        kind: ReportKind::Check,
        robocal_version: crate::VERSION.to_string(),
        verdict: Verdict::Ok,
        reasons: Vec::new(),
        image_size_px: [camera.width, camera.height],
        views: Vec::new(),
        reprojection_rms_px: None,
        refit: None,
        parameters: Vec::new(),
        moved: Vec::new(),
        projection_shift_px: None,
        pose_shift: None,
        thresholds: used_thresholds(thresholds, saved.projection_std_px, broken_rms_px),
        warnings: Vec::new(),
    };
    // 1. Pose every view with the saved camera.
    let mut posed = Vec::new();
    let mut poses = Vec::new();
    let (mut squared, mut count) = (0.0, 0usize);
    for view in views {
        let mut checked = CheckedView {
            name: view.name.clone(),
            n_points: view.object_m.len(),
            rms_px: None,
            error: None,
        };
        match camera_from_target(camera, view) {
            Ok((pose, rms)) => {
                checked.rms_px = Some(rms);
                squared += rms * rms * view.object_m.len() as f64;
                count += view.object_m.len();
                posed.push(view.clone());
                poses.push(pose);
            }
            Err(e) => checked.error = Some(e.to_string()),
        }
        report.views.push(checked);
    }
    if posed.is_empty() {
        report.verdict = Verdict::Broken;
        report.reasons.push(if views.is_empty() {
            "the target was not found in any image: check the target and that it is in view"
                .to_string()
        } else {
            "no image could be posed with the saved camera".to_string()
        });
        return Ok(report);
    }
    let rms = (squared / count.max(1) as f64).sqrt();
    report.reprojection_rms_px = Some(rms);
    if rms > broken_rms_px {
        report.verdict = Verdict::Broken;
        report.reasons.push(format!(
            "the saved camera reprojects the new images with an RMS of {rms:.2} px (threshold \
             {broken_rms_px:.2} px): it does not describe this camera (another camera, lens, \
             focus or resolution?)"
        ));
    }
    if posed.len() < 3 {
        report.warnings.push(format!(
            "only {} posed views: 3 or more with the target tilted separate the focal length \
             from the distance",
            posed.len()
        ));
    }
    // 2. Refit fx, fy, cx, cy with everything else held.
    let mut fixed = vec![true; camera.params().len()];
    fixed[..REFIT_PARAMS.len()].fill(false);
    let options = CalibrationOptions {
        model: camera.distortion.clone(),
        ..CalibrationOptions::default()
    };
    let refit = match refine_from(
        &posed,
        camera,
        &poses,
        fixed,
        None,
        REFIT_ITERATIONS,
        &options,
    ) {
        Ok(r) => r,
        Err(e) => {
            report.verdict = Verdict::Broken;
            report
                .reasons
                .push(format!("fx, fy, cx, cy could not be refitted: {e}"));
            return Ok(report);
        }
    };
    if refit.std.is_empty() {
        report.warnings.push(
            "the new views do not determine fx, fy, cx, cy (singular normal equations): the \
             shifts are compared with the saved std only; add views with the target tilted"
                .to_string(),
        );
    }
    let refit_std = refit.projection_uncertainty.max_std_px;
    let projection_std = match (saved.projection_std_px, refit.std.is_empty()) {
        (None, true) => None,
        (s, _) => Some((s.unwrap_or(0.0).powi(2) + refit_std.powi(2)).sqrt()),
    };
    report.thresholds = used_thresholds(thresholds, projection_std, broken_rms_px);
    let used = report.thresholds.clone();
    // 3. Which parameters moved.
    let saved_values = camera.params();
    let refit_values = refit.camera.params();
    for (i, name) in REFIT_PARAMS.iter().enumerate() {
        let shift_px = refit_values[i] - saved_values[i];
        let saved_std_px = saved.std.get(*name).copied().filter(|s| *s > 0.0);
        let refit_std_px = refit.std.get(*name).copied().filter(|s| *s > 0.0);
        let sigma =
            (saved_std_px.unwrap_or(0.0).powi(2) + refit_std_px.unwrap_or(0.0).powi(2)).sqrt();
        let shift_std = (sigma > 0.0).then(|| shift_px / sigma);
        let moved = shift_px.abs() > (used.param_sigma * sigma).max(used.param_floor_px);
        if moved {
            report.moved.push(name.to_string());
            report.reasons.push(format!(
                "{name} moved {shift_px:+.2} px ({}) from {:.2} to {:.2}",
                match shift_std {
                    Some(z) => format!("{z:+.1} std"),
                    None => "no std known".to_string(),
                },
                saved_values[i],
                refit_values[i]
            ));
        }
        report.parameters.push(ParameterShift {
            name: name.to_string(),
            saved: saved_values[i],
            refit: refit_values[i],
            shift_px,
            saved_std_px,
            refit_std_px,
            shift_std,
            moved,
        });
    }
    // 4. The projection shift.
    let diff = projection_diff(camera, &refit.camera, &DiffOptions::default())?;
    let shift_moved = diff.worst > used.shift_px;
    if shift_moved {
        report.reasons.push(format!(
            "the projection shifted by up to {:.2} px (median {:.2} px; threshold {:.2} px)",
            diff.worst, diff.median, used.shift_px
        ));
    }
    report.projection_shift_px = Some(diff);
    // 5. The pose of a fixed camera.
    if let Some(saved_pose) = &saved.camera_from_target {
        let shift = pose_shift(saved_pose, &refit, &used)?;
        if shift.moved {
            report.reasons.push(format!(
                "the camera moved {:.2} mm and {:.3} deg against the target (thresholds {} mm, {} \
                 deg)",
                shift.translation_mm, shift.rotation_deg, used.pose_mm, used.pose_deg
            ));
        }
        report.pose_shift = Some(shift);
    }
    let drifted = shift_moved
        || !report.moved.is_empty()
        || report.pose_shift.as_ref().is_some_and(|p| p.moved);
    if report.verdict != Verdict::Broken && drifted {
        report.verdict = Verdict::Drifted;
    }
    report.refit = Some(Refit {
        camera: refit.camera,
        rms_px: refit.rms_px,
        projection_std_px: refit_std,
    });
    Ok(report)
}

fn used_thresholds(
    t: &CheckThresholds,
    projection_std_px: Option<f64>,
    broken_rms_px: f64,
) -> UsedThresholds {
    let shift_px = t.shift_px.unwrap_or_else(|| {
        (t.shift_sigma * projection_std_px.unwrap_or(0.0)).max(t.shift_floor_px)
    });
    UsedThresholds {
        shift_px,
        projection_std_px,
        shift_sigma: t.shift_sigma,
        shift_floor_px: t.shift_floor_px,
        param_sigma: t.param_sigma,
        param_floor_px: t.param_floor_px,
        broken_rms_px,
        pose_mm: t.pose_mm,
        pose_deg: t.pose_deg,
    }
}

/// The median change of the refit's view poses from the saved one.
fn pose_shift(
    saved: &Pose,
    refit: &super::CameraCalibration,
    used: &UsedThresholds,
) -> Result<PoseShift> {
    let mut mm = Vec::new();
    let mut deg = Vec::new();
    for v in &refit.views {
        let pose = v.camera_from_target.to_pose()?;
        mm.push((pose.translation.vector - saved.translation.vector).norm() * 1e3);
        deg.push(rotation_angle_between(&pose.rotation, &saved.rotation).to_degrees());
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    };
    let (translation_mm, rotation_deg) = (median(mm), median(deg));
    Ok(PoseShift {
        translation_mm,
        rotation_deg,
        moved: translation_mm > used.pose_mm || rotation_deg > used.pose_deg,
    })
}
