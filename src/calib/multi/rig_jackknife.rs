//! How far a rig's extrinsics move when frames are left out: the check of
//! the joint fit's reported std against the data (issue 35: "uncertainty
//! that covers the truth when the model is not exactly right", here the
//! timing error of free-running cameras).
//!
//! The joint fit's covariance assumes independent pixel noise. When a
//! frame's images were not taken at one moment while the board moved, each
//! camera saw the board at a slightly different pose: an error shared by
//! every point of a view, which the covariance does not know and which
//! moves the extrinsics far beyond it (11 std at 5 ms in
//! `examples/rig_coverage.rs` before this check). The frames are left out
//! group by group (a delete-a-group jackknife over at most [`MAX_GROUPS`]
//! groups of every `groups`-th frame), each refit from the full solution
//! for at most [`ITERATIONS`] steps, and the spread of the extrinsics over
//! the refits, `(G - 1) / G * sum (x_g - mean)^2`, is what the data say
//! the extrinsics' variance is, whatever its cause. The reported std is
//! widened to it axis by axis where it is larger (with the model right the
//! factor stays near 1); a factor beyond [`WARN_FACTOR`] is also said.

use super::rig_graph::{co_observation_counts, spanning_tree};
use super::rig_problem::{RigProblem, Sighting};
use crate::calib::refine::CalibProblem;
use crate::geometry::{rotvec_from_rotation, Pose};
use crate::optim::{solve, BlockParams, BlockProblem, LmOptions, LmResult};

/// Most groups of frames left out (one refit each).
pub const MAX_GROUPS: usize = 20;
/// Fewest groups for a spread worth reporting.
pub const MIN_GROUPS: usize = 6;
/// Solver steps per refit, from the full solution.
pub const ITERATIONS: usize = 10;
/// A spread this many times the model's std is named in a warning.
pub const WARN_FACTOR: f64 = 2.5;

/// The leave-frames-out spread of every camera's camera_from_rig:
/// `[rotation (left perturbation) rad x3, translation m x3]` per camera
/// (zeros for the rig camera), and the refits it rests on.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct FrameSpread {
    /// Per camera, the jackknife std of its camera_from_rig.
    pub std: Vec<[f64; 6]>,
    /// Refits done (groups whose removal kept the cameras connected).
    pub runs: usize,
}

/// The spread of the module docs, or `None` with fewer than
/// [`MIN_GROUPS`] usable refits.
pub(crate) fn leave_frames_out<'a>(
    cameras: &dyn Fn() -> Vec<CalibProblem<'a>>,
    problem: &RigProblem<'a>,
    full: &LmResult,
    lm: &LmOptions,
    names: &[String],
) -> Option<FrameSpread> {
    let n_frames = problem.frames.len();
    let groups = n_frames.min(MAX_GROUPS);
    if groups < MIN_GROUPS {
        return None;
    }
    let n_cameras = names.len();
    let full_poses: Vec<Pose> = (0..n_cameras)
        .map(|k| problem.camera_from_rig(&full.params.global, k))
        .collect();
    let mut deltas: Vec<Vec<[f64; 6]>> = vec![Vec::new(); n_cameras];
    let mut runs = 0;
    for g in 0..groups {
        let keep = kept_without_group(n_frames, groups, g);
        let frames: Vec<Vec<Sighting>> = keep.iter().map(|&f| problem.frames[f].clone()).collect();
        // The refit must still tie every camera to the rig.
        let mut frames_of = vec![Vec::new(); n_cameras];
        for (i, sightings) in frames.iter().enumerate() {
            for s in sightings {
                frames_of[s.camera].push(i);
            }
        }
        if frames_of.iter().any(Vec::is_empty)
            || spanning_tree(
                &co_observation_counts(&frames_of),
                problem.rig_camera,
                names,
            )
            .is_err()
        {
            continue;
        }
        let sub = RigProblem {
            cameras: cameras(),
            rig_camera: problem.rig_camera,
            frames,
        };
        let Some(refit) = refit_from_full(&sub, full, &keep, lm) else {
            continue;
        };
        runs += 1;
        for (k, d) in deltas.iter_mut().enumerate() {
            let pose = sub.camera_from_rig(&refit.params.global, k);
            d.push(pose_delta(&pose, &full_poses[k]));
        }
    }
    if runs < MIN_GROUPS {
        return None;
    }
    let std = deltas.iter().map(|d| jackknife_std(d)).collect();
    Some(FrameSpread { std, runs })
}

/// The indices of `n` items kept when group `g` of `groups` (every
/// `groups`-th item from `g`) is left out.
pub(crate) fn kept_without_group(n: usize, groups: usize, g: usize) -> Vec<usize> {
    (0..n).filter(|i| i % groups != g).collect()
}

/// `sub`, the problem over the items `keep`, refit from the full
/// solution's global parameters and the blocks of `keep`, for at most
/// [`ITERATIONS`] steps; `None` when the solver fails.
pub(crate) fn refit_from_full(
    sub: &dyn BlockProblem,
    full: &LmResult,
    keep: &[usize],
    lm: &LmOptions,
) -> Option<LmResult> {
    let start = BlockParams {
        global: full.params.global.clone(),
        blocks: keep
            .iter()
            .map(|&i| full.params.blocks[i].clone())
            .collect(),
    };
    let options = LmOptions {
        max_iterations: ITERATIONS,
        fixed_blocks: Vec::new(),
        ..lm.clone()
    };
    solve(sub, &start, &options).ok()
}

/// How far `pose` is from `full`: `[rotation (left perturbation) rad x3,
/// translation m x3]`.
pub(crate) fn pose_delta(pose: &Pose, full: &Pose) -> [f64; 6] {
    let r = rotvec_from_rotation(&(pose.rotation * full.rotation.inverse()));
    let t = pose.translation.vector - full.translation.vector;
    [r.x, r.y, r.z, t.x, t.y, t.z]
}

/// The delete-a-group jackknife std of each of six components over the
/// refits' deltas from the full solution: `sqrt((G - 1) / G * sum (x_g -
/// mean)^2)` for `G` refits.
pub(crate) fn jackknife_std(deltas: &[[f64; 6]]) -> [f64; 6] {
    let n = deltas.len() as f64;
    let mut out = [0.0; 6];
    if deltas.is_empty() {
        return out;
    }
    for (i, o) in out.iter_mut().enumerate() {
        let mean = deltas.iter().map(|x| x[i]).sum::<f64>() / n;
        let ss: f64 = deltas.iter().map(|x| (x[i] - mean).powi(2)).sum();
        *o = ((n - 1.0) / n * ss).sqrt();
    }
    out
}
