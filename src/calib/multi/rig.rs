//! Camera-rig calibration (issue 22): N cameras that saw one board in
//! synchronised frames, any camera missing the board in any frame.
//!
//! 1. Each camera alone: its views that fix a homography ([`crate::calib::usable`]),
//!    then Zhang ([`calibrate`]), or, with intrinsics given, only the board
//!    poses under the held camera ([`crate::calib::multi::rig_init::held_camera`]).
//! 2. The co-observation graph ([`crate::calib::multi::rig_graph`]): an error naming the
//!    groups when it is not connected, else a maximum spanning tree from the
//!    rig camera; each edge's child_from_parent is averaged over the shared
//!    frames (rotations by the quaternion mean, as stereo's
//!    [`initial_right_from_left`]) and chained into every camera_from_rig.
//!    Before that, the frame grouping is tested along each edge
//!    ([`super::rig_frame_check`]): the board's motions seen by two cameras
//!    must rotate by the same angles.
//! 3. Each frame's rig_from_target from the camera that saw most of it.
//! 4. One Levenberg-Marquardt ([`crate::calib::multi::rig_problem`]) over every camera's
//!    intrinsics (unless held), every camera_from_rig but the rig camera's
//!    and every frame's board pose; the covariance gives each extrinsic's
//!    standard deviation, widened to the spread of leave-frames-out refits
//!    where that is larger ([`super::rig_jackknife`]).
//! 5. The report ([`RigCalibration`]).

use crate::calib::multi::rig_frame_check::{
    check_pair, message as frame_message, CameraFrames, FrameFinding,
};
use crate::calib::multi::rig_graph::{co_observation_counts, spanning_tree};
use crate::calib::multi::rig_init::{camera_alone, Alone};
use crate::calib::multi::rig_jackknife::{leave_frames_out, WARN_FACTOR};
use crate::calib::multi::rig_problem::{RigProblem, Sighting};
use crate::calib::multi::rig_report::{
    CoObservation, RigCalibration, RigCamera, RigCovariance, RigFrame, RigParameter,
    POSE_PARAMETERS,
};
use crate::calib::multi::same_images::{refuse_identical_views, refuse_zero_baseline};
use crate::calib::multi::stereo::{camera_report_with, initial_right_from_left, TransformStd};
use crate::calib::refine::{block_from_pose, pose_from_block};
use crate::calib::zhang::lm_options;
use crate::calib::{CalibrationOptions, View};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{Pose, PoseJson};
use crate::optim::{solve, BlockParams, BlockProblem, LmOptions};

/// Fewer shared frames than this on a spanning-tree edge draws a warning.
const FEW_SHARED_FRAMES: usize = 3;

/// One camera's input to [`calibrate_rig`].
#[derive(Clone, Debug, PartialEq)]
pub struct RigCameraViews {
    /// Unique name (`--camera NAME ...`).
    pub name: String,
    /// Image width and height, px.
    pub image_size_px: (u32, u32),
    /// Its views, each with the index of its frame (into the frame keys);
    /// at most one view per frame, in any order.
    pub views: Vec<(usize, View)>,
    /// Intrinsics given and held; `None` solves them from its own views.
    pub camera: Option<Camera>,
}

/// What to solve and the provenance the report carries.
#[derive(Clone, Debug, PartialEq)]
pub struct RigOptions {
    /// Options of every solved camera (lens model, held parameters, loss).
    pub calibration: CalibrationOptions,
    /// Name of the camera whose frame is the rig frame; `None`: the first.
    pub rig_frame: Option<String>,
    /// The target spec, carried into the report.
    pub target: String,
    /// How the frames were grouped (`"number"` or `"order"`), carried into
    /// the report.
    pub grouping: String,
}

/// Calibrate a rig: `frame_keys` names the synchronised frames (the
/// report keeps their order), `cameras` hold each camera's views keyed by
/// frame index. See the module docs for the steps.
pub fn calibrate_rig(
    cameras: &[RigCameraViews],
    frame_keys: &[String],
    options: &RigOptions,
) -> Result<RigCalibration> {
    let rig_camera = validate(cameras, frame_keys, options)?;
    let names: Vec<String> = cameras.iter().map(|c| c.name.clone()).collect();
    // 1. Each camera alone.
    let alone = cameras
        .iter()
        .map(|c| camera_alone(c, &options.calibration))
        .collect::<Result<Vec<Alone>>>()?;
    let mut warnings: Vec<String> = alone.iter().flat_map(|a| a.warnings.clone()).collect();
    // 2. The graph and the extrinsics along its spanning tree.
    let frames_of: Vec<Vec<usize>> = alone.iter().map(|a| a.frames.clone()).collect();
    let counts = co_observation_counts(&frames_of);
    let tree = spanning_tree(&counts, rig_camera, &names)?;
    // Is each frame's group of images taken at one moment? The board's
    // motions tell, before any joint fit ([`super::rig_frame_check`]): a
    // camera whose images sit shifted in the frames is refused with the
    // shift named; a grouping that no shift explains is warned.
    for &[parent, child] in &tree {
        let frames_of = |k: usize| CameraFrames {
            frames: &alone[k].frames,
            camera_from_target: &alone[k].poses,
        };
        if let Some(finding) = check_pair(&frames_of(parent), &frames_of(child)) {
            let text = frame_message(
                &finding,
                &names[parent],
                &names[child],
                frame_keys,
                &options.grouping,
            );
            match finding {
                FrameFinding::Shifted { .. } => return Err(Error::invalid("rig frames", text)),
                FrameFinding::Disagree { .. } => warnings.push(text),
            }
        }
    }
    let mut camera_from_rig = vec![Pose::identity(); cameras.len()];
    for &[parent, child] in &tree {
        let shared: Vec<(Pose, Pose)> = alone[parent]
            .frames
            .iter()
            .enumerate()
            .filter_map(|(i, f)| {
                let j = alone[child].frames.iter().position(|g| g == f)?;
                Some((alone[parent].poses[i], alone[child].poses[j]))
            })
            .collect();
        let (p, c): (Vec<Pose>, Vec<Pose>) = shared.into_iter().unzip();
        let child_from_parent = initial_right_from_left(&p, &c)?;
        camera_from_rig[child] = child_from_parent * camera_from_rig[parent];
        if counts[parent][child] < FEW_SHARED_FRAMES {
            warnings.push(format!(
                "cameras {} and {} share only {} frame(s): their relative pose rests on few \
                 board views; add frames where both see the board",
                names[parent], names[child], counts[parent][child]
            ));
        }
    }
    // 3. The frames some camera used, each from the camera that saw most of it.
    let mut frames: Vec<Vec<Sighting>> = vec![Vec::new(); frame_keys.len()];
    for (k, a) in alone.iter().enumerate() {
        for (view, &f) in a.frames.iter().enumerate() {
            frames[f].push(Sighting { camera: k, view });
        }
    }
    let used_frames: Vec<usize> = (0..frame_keys.len())
        .filter(|&f| !frames[f].is_empty())
        .collect();
    let blocks: Vec<Vec<f64>> = used_frames
        .iter()
        .map(|&f| {
            let best = frames[f]
                .iter()
                .max_by_key(|s| (alone[s.camera].n_used(s.view), usize::MAX - s.camera))
                .copied()
                .unwrap_or(Sighting { camera: 0, view: 0 });
            let camera_from_target = alone[best.camera].poses[best.view];
            block_from_pose(&(camera_from_rig[best.camera].inverse() * camera_from_target))
        })
        .collect();
    // 4. The joint bundle adjustment.
    let problem = RigProblem {
        cameras: alone.iter().map(Alone::problem).collect(),
        rig_camera,
        frames: used_frames.iter().map(|&f| frames[f].clone()).collect(),
    };
    let mut global: Vec<f64> = alone.iter().flat_map(|a| a.camera.params()).collect();
    let mut fixed_global: Vec<bool> = alone.iter().flat_map(|a| a.fixed.clone()).collect();
    for (k, pose) in camera_from_rig.iter().enumerate() {
        if k != rig_camera {
            global.extend(block_from_pose(pose));
            fixed_global.extend([false; 6]);
        }
    }
    let lm = LmOptions {
        fixed_global,
        ..lm_options(&alone[rig_camera].camera, &options.calibration)?
    };
    let result = solve(&problem, &BlockParams { global, blocks }, &lm)?;
    // 5. The report.
    let residuals = problem.residuals_and_jacobian(&result.params, false)?;
    let owners = problem.residual_cameras();
    let (mut cam_sq, mut cam_n) = (vec![0.0; cameras.len()], vec![0usize; cameras.len()]);
    let (mut frame_sq, mut frame_n) = (
        vec![0.0; used_frames.len()],
        vec![0usize; used_frames.len()],
    );
    for (r, &k) in residuals.iter().zip(&owners) {
        let sq = r.residuals.norm_squared();
        cam_sq[k] += sq;
        cam_n[k] += 1;
        if let Some(b) = r.block {
            frame_sq[b] += sq;
            frame_n[b] += 1;
        }
    }
    let rms = |sq: f64, n: usize| if n == 0 { 0.0 } else { (sq / n as f64).sqrt() };
    // The extrinsics' std checked against the spread of leave-frames-out
    // refits ([`super::rig_jackknife`]) and widened to it axis by axis.
    let mut covariance_global = result.covariance_global.clone();
    let spread = leave_frames_out(
        &|| alone.iter().map(Alone::problem).collect(),
        &problem,
        &result,
        &lm,
        &names,
    );
    if let (Some(c), Some(spread)) = (covariance_global.as_mut(), &spread) {
        for (k, name) in names.iter().enumerate() {
            let Some(o) = problem.pose_offset(k) else {
                continue;
            };
            let mut worst: f64 = 1.0;
            for i in 0..6 {
                let model = c[(o + i, o + i)].max(0.0).sqrt();
                if model > 0.0 {
                    // Widened to the t-scaled spread, warned on the plain one.
                    let factor = (spread.covering[k][i] / model).max(1.0);
                    c.row_mut(o + i).scale_mut(factor);
                    c.column_mut(o + i).scale_mut(factor);
                    worst = worst.max(spread.std[k][i] / model);
                }
            }
            if worst > WARN_FACTOR {
                warnings.push(format!(
                    "camera {}: leaving frames out moves its camera_from_rig {worst:.1}x more \
                     than the joint fit's std says ({} refits): the frames disagree beyond the \
                     pixel noise (images of a frame not taken at one moment while the board \
                     moved, a board that bends, a camera that moved between frames); its std \
                     is widened to that spread. Hold the board still for each frame or trigger \
                     the cameras together",
                    name, spread.runs
                ));
            }
        }
    }
    let std: Option<Vec<f64>> = covariance_global
        .as_ref()
        .map(|c| c.diagonal().iter().map(|v| v.max(0.0).sqrt()).collect());
    let g = &result.params.global;
    let rig_from_target: Vec<Pose> = result
        .params
        .blocks
        .iter()
        .map(|b| pose_from_block(b))
        .collect();
    let mut rig_cameras = Vec::with_capacity(cameras.len());
    for (k, a) in alone.iter().enumerate() {
        let pose = problem.camera_from_rig(g, k);
        let o = problem.params_offset(k);
        let n = a.camera.params().len();
        let view_blocks: Vec<Vec<f64>> = a
            .frames
            .iter()
            .map(|f| {
                let b = used_frames.iter().position(|u| u == f).unwrap_or(0);
                block_from_pose(&(pose * rig_from_target[b]))
            })
            .collect();
        let lm = LmOptions {
            fixed_global: a.fixed.clone(),
            ..lm_options(&a.camera, &options.calibration)?
        };
        let calibration = camera_report_with(
            &problem.cameras[k],
            &g[o..o + n],
            &view_blocks,
            a.outliers.clone(),
            cameras[k].image_size_px,
            &options.calibration,
            lm,
        )?;
        let camera_from_rig_std = match (problem.pose_offset(k), &std) {
            (Some(o), Some(s)) => Some(TransformStd {
                rotation_rad: [s[o], s[o + 1], s[o + 2]],
                translation_m: [s[o + 3], s[o + 4], s[o + 5]],
            }),
            _ => None,
        };
        if k != rig_camera {
            refuse_zero_baseline(
                "camera_from_rig",
                &format!("cameras {} and {}", names[rig_camera], names[k]),
                pose.translation.vector.norm(),
                camera_from_rig_std.as_ref().map(|s| s.translation_m),
            )?;
        }
        rig_cameras.push(RigCamera {
            name: names[k].clone(),
            calibration,
            intrinsics_held: a.held,
            camera_from_rig: PoseJson::from(&pose),
            camera_from_rig_std,
            rms_px: rms(cam_sq[k], cam_n[k]),
            frames_seen: a.frames.clone(),
        });
    }
    // A joint fit that drags a camera's intrinsics far from what its own
    // views say (issue 35): the rig's frames disagree with that camera
    // (timing between free-running cameras, a camera moved between frames),
    // and the intrinsics absorb it. Named, with the fix.
    for (k, a) in alone.iter().enumerate() {
        if let Some(w) = intrinsics_drift(
            &names[k],
            &a.camera,
            &rig_cameras[k].calibration.camera,
            &a.solo_std,
        ) {
            warnings.push(w);
        }
    }
    // Each solved camera's own advice (few views, uncovered image corners,
    // no tilt, correlated parameters), named; a held camera's intrinsics
    // are given, so its coverage advice does not apply.
    for c in rig_cameras.iter().filter(|c| !c.intrinsics_held) {
        let name = &c.name;
        warnings.extend(
            c.calibration
                .warnings
                .iter()
                .map(|w| format!("camera {name}: {w}")),
        );
    }
    let rig_frames = frame_keys
        .iter()
        .enumerate()
        .map(|(f, key)| {
            let b = used_frames.iter().position(|u| *u == f);
            RigFrame {
                key: key.clone(),
                rig_from_target: b.map(|b| PoseJson::from(&rig_from_target[b])),
                cameras: frames[f].iter().map(|s| names[s.camera].clone()).collect(),
                rms_px: b.map_or(0.0, |b| rms(frame_sq[b], frame_n[b])),
            }
        })
        .collect();
    let covariance = covariance_global
        .as_ref()
        .map(|c| rig_covariance(&problem, &alone, &names, c));
    Ok(RigCalibration {
        kind: crate::report_kind::ReportKind::Rig,
        robocal_version: crate::VERSION.to_string(),
        rig_frame: names[rig_camera].clone(),
        target: options.target.clone(),
        grouping: options.grouping.clone(),
        cameras: rig_cameras,
        frames: rig_frames,
        co_observation: CoObservation {
            cameras: names,
            frames: counts,
            spanning_tree: tree,
        },
        rms_px: rms(cam_sq.iter().sum(), cam_n.iter().sum()),
        iterations: result.iterations,
        termination: result.termination,
        warnings,
        covariance,
    })
}

/// The report's covariance over the free global parameters, named; a held
/// aspect ratio's `fy` (not a parameter of the solve) follows `fx`.
fn rig_covariance(
    problem: &RigProblem,
    alone: &[Alone],
    names: &[String],
    covariance: &nalgebra::DMatrix<f64>,
) -> RigCovariance {
    let n = problem.n_global();
    // Rows of the full covariance to report, with a row of the solve each
    // maps to and its scale (fy = aspect * fx).
    let mut rows: Vec<(RigParameter, usize, f64)> = Vec::new();
    for (k, a) in alone.iter().enumerate() {
        let o = problem.params_offset(k);
        let aspect = problem.cameras[k].aspect;
        for (i, name) in a.camera.param_names().iter().enumerate() {
            let parameter = RigParameter {
                camera: names[k].clone(),
                parameter: name.to_string(),
            };
            match (i, aspect) {
                (1, Some(r)) if !a.fixed[0] => rows.push((parameter, o, r)),
                _ if a.fixed[i] => {}
                _ => rows.push((parameter, o + i, 1.0)),
            }
        }
        if let Some(p) = problem.pose_offset(k) {
            for (i, name) in POSE_PARAMETERS.iter().enumerate() {
                let parameter = RigParameter {
                    camera: names[k].clone(),
                    parameter: name.to_string(),
                };
                rows.push((parameter, p + i, 1.0));
            }
        }
    }
    debug_assert!(rows.iter().all(|r| r.1 < n));
    RigCovariance {
        matrix: rows
            .iter()
            .map(|(_, i, a)| {
                rows.iter()
                    .map(|(_, j, b)| a * b * covariance[(*i, *j)])
                    .collect()
            })
            .collect(),
        parameters: rows.into_iter().map(|r| r.0).collect(),
    }
}

/// Check the input; returns the rig camera's index.
fn validate(
    cameras: &[RigCameraViews],
    frame_keys: &[String],
    options: &RigOptions,
) -> Result<usize> {
    if cameras.len() < 2 {
        return Err(Error::too_few("cameras in a rig", 2, cameras.len()));
    }
    for (k, c) in cameras.iter().enumerate() {
        if c.name.is_empty() {
            return Err(Error::invalid(
                format!("cameras[{k}].name"),
                "must not be empty",
            ));
        }
        if cameras[..k].iter().any(|o| o.name == c.name) {
            return Err(Error::invalid(
                format!("cameras[{k}].name"),
                format!("'{}' is used twice: camera names must be unique", c.name),
            ));
        }
        let mut seen: Vec<Option<&str>> = vec![None; frame_keys.len()];
        for (f, v) in &c.views {
            let Some(slot) = seen.get_mut(*f) else {
                return Err(Error::invalid(
                    format!("camera {}", c.name),
                    format!(
                        "view {} has frame index {f}, but there are {} frames",
                        v.name,
                        frame_keys.len()
                    ),
                ));
            };
            if let Some(first) = slot {
                return Err(Error::invalid(
                    format!("camera {}", c.name),
                    format!(
                        "two views of frame {}: {first} and {}; keep one",
                        frame_keys[*f], v.name
                    ),
                ));
            }
            *slot = Some(&v.name);
        }
    }
    refuse_identical_cameras(cameras, frame_keys.len())?;
    match &options.rig_frame {
        None => Ok(0),
        Some(name) => cameras.iter().position(|c| &c.name == name).ok_or_else(|| {
            let all: Vec<&str> = cameras.iter().map(|c| c.name.as_str()).collect();
            Error::invalid(
                "rig_frame",
                format!(
                    "no camera is named '{name}' (the cameras are {})",
                    all.join(", ")
                ),
            )
        }),
    }
}

/// Refuse two cameras with identical detections in every frame they share.
fn refuse_identical_cameras(cameras: &[RigCameraViews], n_frames: usize) -> Result<()> {
    let frames: Vec<Vec<Option<&View>>> = cameras
        .iter()
        .map(|c| {
            let mut out: Vec<Option<&View>> = vec![None; n_frames];
            for (f, v) in &c.views {
                if let Some(slot) = out.get_mut(*f) {
                    *slot = Some(v);
                }
            }
            out
        })
        .collect();
    for (j, a) in cameras.iter().enumerate() {
        for (k, b) in cameras.iter().enumerate().skip(j + 1) {
            let pairs: Vec<(&View, &View)> = frames[j]
                .iter()
                .zip(&frames[k])
                .filter_map(|(x, y)| Some(((*x)?, (*y)?)))
                .collect();
            refuse_identical_views(
                "cameras",
                &format!("cameras {} and {}", a.name, b.name),
                "shared frames",
                &pairs,
            )?;
        }
    }
    Ok(())
}

/// Frame keys in report order: integer keys numerically, then the others
/// as text.
pub fn sort_frame_keys(keys: &mut [String]) {
    keys.sort_by(|a, b| match (a.parse::<u64>(), b.parse::<u64>()) {
        (Ok(x), Ok(y)) => x.cmp(&y).then_with(|| a.cmp(b)),
        (Ok(_), Err(_)) => std::cmp::Ordering::Less,
        (Err(_), Ok(_)) => std::cmp::Ordering::Greater,
        (Err(_), Err(_)) => a.cmp(b),
    });
}

/// A joint intrinsic further than this many of the camera's own std from
/// its own calibration is named.
pub const DRIFT_STD: f64 = 5.0;

/// The warning for a camera whose intrinsics the joint fit moved by more
/// than [`DRIFT_STD`] of their own std (`solo_std`, from the camera alone),
/// naming the parameters that moved most (at most three).
pub(crate) fn intrinsics_drift(
    name: &str,
    solo: &Camera,
    joint: &Camera,
    solo_std: &std::collections::BTreeMap<String, f64>,
) -> Option<String> {
    let names = solo.param_names();
    let (a, b) = (solo.params(), joint.params());
    let mut moved: Vec<(f64, String)> = names
        .iter()
        .zip(a.iter().zip(&b))
        .filter_map(|(n, (x, y))| {
            let s = *solo_std.get(*n)?;
            let d = (y - x).abs();
            (s > 0.0 && s.is_finite() && d > DRIFT_STD * s)
                .then(|| (d / s, format!("{n} {x:.4} -> {y:.4} ({:.0} std)", d / s)))
        })
        .collect();
    if moved.is_empty() {
        return None;
    }
    moved.sort_by(|p, q| q.0.total_cmp(&p.0));
    let list: Vec<String> = moved.into_iter().take(3).map(|m| m.1).collect();
    Some(format!(
        "camera {name}: the joint rig fit moved its intrinsics beyond their own uncertainty \
         ({}): the rig's frames disagree with this camera (frames not taken at the same \
         moment by free-running cameras, a camera moved, a board that bends); hold its \
         intrinsics from its own calibration (CLI: --camera-file {name}=camera.json) or check \
         the synchronisation",
        list.join(", ")
    ))
}

#[cfg(test)]
mod drift_tests {
    use super::*;
    use std::collections::BTreeMap;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn intrinsics_moved_beyond_their_own_std_are_named() {
        let solo = Camera::pinhole(907.0, 912.0, 622.0, 360.0, 1280, 720);
        let std: BTreeMap<String, f64> = [("fx", 1.5), ("fy", 1.5), ("cx", 2.0), ("cy", 2.0)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        // Within 5 std: nothing to say.
        let near = Camera::pinhole(910.0, 915.0, 630.0, 362.0, 1280, 720);
        assert_eq!(intrinsics_drift("cam2", &solo, &near, &std), None);
        // cx dragged 108 px (54 std), fx 15 px (10 std): named, largest first.
        let far = Camera::pinhole(922.0, 913.0, 514.0, 361.0, 1280, 720);
        assert_eq!(
            intrinsics_drift("cam2", &solo, &far, &std).unwrap(),
            "camera cam2: the joint rig fit moved its intrinsics beyond their own uncertainty \
             (cx 622.0000 -> 514.0000 (54 std), fx 907.0000 -> 922.0000 (10 std)): the rig's \
             frames disagree with this camera (frames not taken at the same moment by \
             free-running cameras, a camera moved, a board that bends); hold its intrinsics from \
             its own calibration (CLI: --camera-file cam2=camera.json) or check the \
             synchronisation"
        );
        // A held camera (no std of its own) is never named.
        assert_eq!(
            intrinsics_drift("cam2", &solo, &far, &BTreeMap::new()),
            None
        );
    }
}
