//! The hand-eye report's answers for the field: the error at the tool
//! centre point, held-out poses and the touch test
//! ([`crate::handeye::quality::work_point`], [`crate::handeye::quality::verify`]),
//! around the one orchestration [`solve_handeye`].
//!
//! Request keys (JSON, beside those of [`crate::api::handeye`]):
//! `"tcp_m": [x, y, z]` (the tool centre point in the flange frame,
//! metres), `"holdout": N` (the last N pose pairs are left out of the solve
//! and checked against it) and `"touch": [{"base_m": [x, y, z],
//! "image_px": [u, v], "view": i}]` (points touched with the tool centre
//! point; needs the camera).

use crate::api::handeye::{board_centre, solve_handeye, ImagePoints};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::handeye::quality::verify::{holdout_report, touch_test, TouchPoint};
use crate::handeye::quality::work_point::{work_point_error, Placement};
use crate::handeye::report::HandEyeReport;
use crate::handeye::solve::{HandEyeInput, HandEyeOptions};
use crate::handeye::{Chain, Pose, Setup};
use nalgebra::{Point3, Vector3};

/// Fewest pose pairs the solve keeps when some are held out.
pub const MIN_SOLVED_POSES: usize = 3;

/// What to measure beyond the solve (all optional).
#[derive(Debug, Clone, Default)]
pub struct FieldRequest {
    /// The tool centre point in the flange (gripper) frame (m).
    pub tcp_m: Option<[f64; 3]>,
    /// Hold the last `holdout` pose pairs out of the solve.
    pub holdout: usize,
    /// Points touched with the tool centre point.
    pub touch: Vec<TouchPoint>,
    /// The camera, for the touch test (with images: the images' camera).
    pub camera: Option<Camera>,
}

/// The tool centre point in the camera transform's left frame: the gripper
/// frame eye-in-hand; eye-to-hand, the base frame with the flange at the
/// calibration pose nearest the poses' mean position (the middle of the
/// workspace the calibration saw).
pub fn tcp_point(setup: Setup, tcp: &[f64; 3], base_from_gripper: &[Pose]) -> Option<Vector3<f64>> {
    let p = Point3::from(*tcp);
    match setup {
        Setup::EyeInHand => Some(p.coords),
        Setup::EyeToHand => {
            let n = base_from_gripper.len() as f64;
            let mean = base_from_gripper
                .iter()
                .map(|b| b.translation.vector)
                .sum::<Vector3<f64>>()
                / n;
            let nearest = base_from_gripper.iter().min_by(|a, b| {
                let da = (a.translation.vector - mean).norm();
                let db = (b.translation.vector - mean).norm();
                da.total_cmp(&db).then_with(|| {
                    // Equal distances: the same pick whatever the order.
                    let ka = a.translation.vector.as_slice().to_vec();
                    let kb = b.translation.vector.as_slice().to_vec();
                    ka.partial_cmp(&kb).unwrap_or(std::cmp::Ordering::Equal)
                })
            })?;
            Some((nearest * p).coords)
        }
    }
}

fn transforms(report: &HandEyeReport) -> Result<(Pose, Pose)> {
    let (x, y) = match report.setup {
        Setup::EyeInHand => (&report.gripper_from_camera, &report.base_from_target),
        Setup::EyeToHand => (&report.base_from_camera, &report.gripper_from_target),
    };
    match (x, y) {
        (Some(x), Some(y)) => Ok((x.to_pose()?, y.to_pose()?)),
        _ => Err(Error::degenerate("the report holds no solved transforms")),
    }
}

/// The centre of the board points of every view (target frame), or the
/// target origin without image points.
fn target_centre(images: Option<&ImagePoints>) -> Point3<f64> {
    images
        .and_then(|p| board_centre(p.views))
        .unwrap_or_else(Point3::origin)
}

/// [`solve_handeye`] with the [`FieldRequest`]: the last `holdout` pairs
/// (and their image points) left out of the solve and checked against it,
/// the error at the tool centre point, and the touch test.
pub fn solve_handeye_field(
    input: &HandEyeInput,
    options: &HandEyeOptions,
    images: Option<&ImagePoints>,
    warnings_first: Vec<String>,
    field: &FieldRequest,
) -> Result<HandEyeReport> {
    let n = input.base_from_gripper.len();
    let h = field.holdout;
    if h > 0 && n < h + MIN_SOLVED_POSES {
        return Err(Error::invalid(
            "holdout",
            format!(
                "{h} pose pairs held out of {n}: the solve needs at least {MIN_SOLVED_POSES} \
                 (12 or more recommended)"
            ),
        ));
    }
    let keep = n - h;
    let solved_input = HandEyeInput {
        setup: input.setup,
        base_from_gripper: input.base_from_gripper[..keep.min(n)].to_vec(),
        camera_from_target: input.camera_from_target[..keep.min(input.camera_from_target.len())]
            .to_vec(),
    };
    let solved_images = images.map(|p| ImagePoints {
        views: &p.views[..keep.min(p.views.len())],
        ..*p
    });
    let mut report = solve_handeye(
        &solved_input,
        options,
        solved_images.as_ref(),
        warnings_first,
    )?;
    let (x, y) = transforms(&report)?;
    if let (Some(tcp), Some(summary)) = (field.tcp_m, &report.pose_refinement) {
        if let Some(q) = tcp_point(input.setup, &tcp, &solved_input.base_from_gripper) {
            report.tcp_error = work_point_error(
                &summary.covariance,
                input.setup,
                &x,
                &q,
                Placement::ToolCentrePoint,
            );
        }
    }
    if h > 0 {
        let all = Chain::new(
            input.setup,
            &input.base_from_gripper,
            &input.camera_from_target,
        )?;
        let solved: Vec<usize> = (0..keep).collect();
        let held: Vec<usize> = (keep..n).collect();
        report.holdout = Some(holdout_report(
            &all.subset(&solved),
            &all.subset(&held),
            keep,
            (&x, &y),
            &target_centre(solved_images.as_ref()),
        ));
    }
    if !field.touch.is_empty() {
        let camera = field
            .camera
            .as_ref()
            .or(images.map(|p| p.camera))
            .ok_or_else(|| Error::invalid("touch", "the touch test needs the camera ('camera')"))?;
        report.touch_test = Some(touch_test(
            input.setup,
            &x,
            &input.base_from_gripper,
            camera,
            &field.touch,
        )?);
    }
    crate::finite::check_finite("report", &report)?;
    Ok(report)
}
