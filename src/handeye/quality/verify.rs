//! Verification against data the solve did not see.
//!
//! **Held-out poses.** For a robot pose `robot[i]` and the camera's view
//! of the target from it (`camera[i]`, by PnP), the calibration predicts
//! the target pose in the camera frame through the chain
//! (`camera_from_target = x^-1 * robot[i]^-1 * y`, [`crate::handeye::Chain`]);
//! the error is the distance (mm) between the predicted and observed
//! position of a target point (its origin, or the board's centre when the
//! board points are known), and the angle between the two poses. It is set
//! beside the same error of the views that were solved (`in_sample_rms_mm`):
//! with `n` solved views and 12 unknowns (2 views' worth) a held-out view's
//! error is expected about `sqrt(n / (n - 2))` times the in-sample RMS;
//! much more says the calibration does not generalise (a bad pose in the
//! solve, robot error that depends on the pose, wrong intrinsics).
//!
//! **Touch test.** A point touched with the tool centre point (base
//! coordinates, metres, as the robot reports it) and seen in an image
//! taken from robot pose `view`: the error is the distance (mm) from the
//! touched point to the camera's ray through the observed pixel, the ray
//! placed in the base frame by the calibration, and the pixel distance
//! between the observed pixel and the touched point projected.

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::handeye::quality::residuals::pose_difference;
use crate::handeye::{Chain, Pose, Setup};
use nalgebra::{Point2, Point3};
use serde::{Deserialize, Serialize};

/// A held-out view whose error exceeds this multiple of the expected is
/// named in the verdict.
pub const HOLDOUT_WARN_RATIO: f64 = 3.0;

/// One held-out pose.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct HoldoutPose {
    /// Its view index: the solved views are `0..n`, the held-out ones
    /// continue from `n` (the input's last pairs).
    pub view: usize,
    /// Distance between the predicted and observed target point (mm).
    pub translation_mm: f64,
    /// Angle between the predicted and observed target pose (degrees).
    pub rotation_deg: f64,
}

/// The report's `holdout` object.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct HoldoutReport {
    /// The target point compared (metres, target frame).
    pub target_point_m: [f64; 3],
    /// Every held-out pose.
    pub per_pose: Vec<HoldoutPose>,
    /// RMS of their `translation_mm`.
    pub rms_mm: f64,
    /// Largest `translation_mm`.
    pub max_mm: f64,
    /// RMS of their `rotation_deg`.
    pub rotation_rms_deg: f64,
    /// The same error over the views that were solved (mm).
    pub in_sample_rms_mm: f64,
    /// What a held-out view is expected to show: `in_sample_rms_mm *
    /// sqrt(n / (n - 2))` (mm).
    pub expected_rms_mm: f64,
    /// One line: whether the held-out poses agree with the fit.
    pub verdict: String,
}

fn predicted_error(chain: &Chain, i: usize, x: &Pose, y: &Pose, c: &Point3<f64>) -> (f64, f64) {
    let predicted = x.inverse() * chain.robot[i].inverse() * y;
    let observed = chain.camera[i];
    let d = (predicted * c - observed * c).norm() * 1e3;
    (d, pose_difference(&predicted, &observed).1)
}

fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    (v.iter().map(|a| a * a).sum::<f64>() / v.len() as f64).sqrt()
}

/// The held-out check: `solved` the chain the calibration used, `held` the
/// held-out views (with `first_index`, the input index of the first), `c`
/// the target point compared.
pub fn holdout_report(
    solved: &Chain,
    held: &Chain,
    first_index: usize,
    (x, y): (&Pose, &Pose),
    c: &Point3<f64>,
) -> HoldoutReport {
    let in_sample: Vec<f64> = (0..solved.len())
        .map(|i| predicted_error(solved, i, x, y, c).0)
        .collect();
    let per_pose: Vec<HoldoutPose> = (0..held.len())
        .map(|i| {
            let (t, r) = predicted_error(held, i, x, y, c);
            HoldoutPose {
                view: first_index + i,
                translation_mm: t,
                rotation_deg: r,
            }
        })
        .collect();
    let t: Vec<f64> = per_pose.iter().map(|p| p.translation_mm).collect();
    let r: Vec<f64> = per_pose.iter().map(|p| p.rotation_deg).collect();
    let n = solved.len() as f64;
    let in_sample_rms_mm = rms(&in_sample);
    let expected_rms_mm = if n > 2.0 {
        in_sample_rms_mm * (n / (n - 2.0)).sqrt()
    } else {
        in_sample_rms_mm
    };
    let rms_mm = rms(&t);
    let max_mm = t.iter().copied().fold(0.0, f64::max);
    let bad: Vec<String> = per_pose
        .iter()
        .filter(|p| p.translation_mm > HOLDOUT_WARN_RATIO * expected_rms_mm.max(1e-6))
        .map(|p| p.view.to_string())
        .collect();
    let verdict = if bad.is_empty() {
        format!(
            "the {} held-out poses agree with the fit: target position error RMS {rms_mm:.2} mm \
             against {expected_rms_mm:.2} mm expected",
            per_pose.len()
        )
    } else {
        format!(
            "held-out view(s) {} miss the prediction by more than {HOLDOUT_WARN_RATIO} times the \
             expected {expected_rms_mm:.2} mm (RMS {rms_mm:.2} mm, largest {max_mm:.2} mm): the \
             calibration does not generalise there; check those poses, the robot's accuracy and \
             the camera calibration",
            bad.join(", ")
        )
    };
    HoldoutReport {
        target_point_m: [c.x, c.y, c.z],
        per_pose,
        rms_mm,
        max_mm,
        rotation_rms_deg: rms(&r),
        in_sample_rms_mm,
        expected_rms_mm,
        verdict,
    }
}

/// One touched point.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TouchPoint {
    /// The tool centre point when it touched the point, base frame (m).
    pub base_m: [f64; 3],
    /// Where the point is seen in the image (px).
    pub image_px: [f64; 2],
    /// The robot pose (index into the request's poses) the image was taken
    /// from; unused eye-to-hand (the camera does not move).
    #[serde(default)]
    pub view: usize,
}

/// One touched point's error.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct TouchResult {
    /// Distance from the touched point to the observed pixel's ray (mm).
    pub distance_mm: f64,
    /// Distance between the observed pixel and the touched point projected (px).
    pub pixel_error_px: f64,
    /// Depth of the touched point in the camera frame (m).
    pub depth_m: f64,
}

/// The report's `touch_test` object.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct TouchReport {
    /// Every point, in input order.
    pub points: Vec<TouchResult>,
    /// RMS of `distance_mm`.
    pub rms_mm: f64,
    /// Largest `distance_mm`.
    pub max_mm: f64,
}

/// The touch test of `points` against the calibration `x` with the robot
/// poses `base_from_gripper` (eye-in-hand: the image of point `k` was taken
/// from `base_from_gripper[points[k].view]`).
pub fn touch_test(
    setup: Setup,
    x: &Pose,
    base_from_gripper: &[Pose],
    camera: &Camera,
    points: &[TouchPoint],
) -> Result<TouchReport> {
    let results = points
        .iter()
        .enumerate()
        .map(|(k, t)| {
            let field = format!("touch[{k}]");
            let camera_from_base = match setup {
                Setup::EyeToHand => x.inverse(),
                Setup::EyeInHand => {
                    let robot = base_from_gripper.get(t.view).ok_or_else(|| {
                        Error::invalid(
                            &field,
                            format!(
                                "view {} but there are {} robot poses",
                                t.view,
                                base_from_gripper.len()
                            ),
                        )
                    })?;
                    x.inverse() * robot.inverse()
                }
            };
            let p = camera_from_base * Point3::from(t.base_m);
            let observed = Point2::from(t.image_px);
            let ray = camera
                .unproject(&observed)
                .map_err(|e| Error::invalid(&field, e.to_string()))?;
            let along = p.coords.dot(&ray);
            let distance = if along > 0.0 {
                (p.coords - ray * along).norm()
            } else {
                p.coords.norm()
            };
            let pixel = camera
                .project(&p)
                .map(|q| (q - observed).norm())
                .map_err(|e| Error::invalid(&field, format!("the touched point: {e}")))?;
            Ok(TouchResult {
                distance_mm: distance * 1e3,
                pixel_error_px: pixel,
                depth_m: p.z,
            })
        })
        .collect::<Result<Vec<TouchResult>>>()?;
    let d: Vec<f64> = results.iter().map(|r| r.distance_mm).collect();
    Ok(TouchReport {
        rms_mm: rms(&d),
        max_mm: d.iter().copied().fold(0.0, f64::max),
        points: results,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::handeye::{handeye_scene, HandEyeSceneConfig};
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn the_true_transforms_predict_noise_free_held_out_views_exactly() {
        let s = handeye_scene(&HandEyeSceneConfig::noise_free(Setup::EyeInHand, 8), 3);
        let chain = Chain::new(s.setup, &s.base_from_gripper, &s.camera_from_target).unwrap();
        let solved = chain.subset(&[0, 1, 2, 3, 4, 5]);
        let held = chain.subset(&[6, 7]);
        let r = holdout_report(&solved, &held, 6, (&s.x_true, &s.y_true), &Point3::origin());
        assert_eq!(r.per_pose.len(), 2);
        assert_eq!(r.per_pose[1].view, 7);
        assert!(r.rms_mm < 1e-9 && r.in_sample_rms_mm < 1e-9, "{r:?}");
        // A transform 2 mm off along x misses every view by 2 mm.
        let off = Pose::translation(0.002, 0.0, 0.0) * s.x_true;
        let r = holdout_report(&solved, &held, 6, (&off, &s.y_true), &Point3::origin());
        assert!((r.max_mm - 2.0).abs() < 1e-6, "{r:?}");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn a_touched_point_on_the_ray_has_no_error() {
        let camera = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
        let x = Pose::translation(0.05, 0.0, 0.1);
        let robot = vec![Pose::translation(0.3, 0.2, 0.5)];
        // A point 0.4 m in front of the camera, 20 mm right of the axis.
        let p_cam = Point3::new(0.02, 0.0, 0.4);
        let base = robot[0] * x * p_cam;
        let seen = camera.project(&p_cam).unwrap();
        let touch = TouchPoint {
            base_m: [base.x, base.y, base.z],
            image_px: [seen.x, seen.y],
            view: 0,
        };
        let r = touch_test(
            Setup::EyeInHand,
            &x,
            &robot,
            &camera,
            std::slice::from_ref(&touch),
        )
        .unwrap();
        assert!(r.rms_mm < 1e-9, "{r:?}");
        assert!((r.points[0].depth_m - 0.4).abs() < 1e-12);
        // Seen 8 px to the right: 8 / 800 * 0.4 m = 4 mm off the ray.
        let moved = TouchPoint {
            image_px: [seen.x + 8.0, seen.y],
            ..touch
        };
        let r = touch_test(
            Setup::EyeInHand,
            &x,
            &robot,
            &camera,
            std::slice::from_ref(&moved),
        )
        .unwrap();
        assert!((r.max_mm - 4.0).abs() < 0.01, "{r:?}");
        assert!((r.points[0].pixel_error_px - 8.0).abs() < 1e-9);
        let bad = TouchPoint { view: 3, ..moved };
        let err = touch_test(Setup::EyeInHand, &x, &robot, &camera, &[bad]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "touch[0]: view 3 but there are 1 robot poses"
        );
    }
}
