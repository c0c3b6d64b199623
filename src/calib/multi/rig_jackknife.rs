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
//!
//! A std estimated from `G` groups has `G - 1` degrees of freedom: the
//! error over it follows Student's t, not the Gaussian, and "within 3
//! std" covers 99.26 % per component at 20 groups instead of 99.73 % (over
//! the 18 components of a four-camera rig, about 88 % of trials instead of
//! 95 % when the spread sets the std). The widening therefore uses the
//! spread times [`coverage_factor`]`(G - 1)` (1.15 at 20 groups, 1.28 at
//! 12; [`FrameSpread::covering`]); the warning compares the plain spread
//! with the model's. With the model right the spread is about the model's
//! std, so the widened std is somewhat above it there (examples/rig_coverage.rs,
//! dev profile, 2026-12-07: mean |error| / std 0.60 for a stereo pair
//! of 12 pairs at one moment, 0.8 for a right std).

use super::rig_graph::{co_observation_counts, spanning_tree};
use super::rig_problem::{RigProblem, Sighting};
use crate::calib::refine::CalibProblem;
use crate::geometry::{rotvec_from_rotation, Pose};
use crate::optim::student_t::coverage_factor;
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
    /// The same times [`coverage_factor`] of its `runs - 1` degrees of
    /// freedom: what the reported std is widened to (module docs).
    pub covering: Vec<[f64; 6]>,
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
    let std: Vec<[f64; 6]> = deltas.iter().map(|d| jackknife_std(d)).collect();
    let covering = std.iter().map(|s| covering_std(s, runs)).collect();
    Some(FrameSpread {
        std,
        covering,
        runs,
    })
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

/// A jackknife std over `runs` refits scaled by [`coverage_factor`] of
/// its `runs - 1` degrees of freedom (module docs).
pub(crate) fn covering_std(std: &[f64; 6], runs: usize) -> [f64; 6] {
    let factor = coverage_factor(runs as f64 - 1.0);
    std.map(|s| s * factor)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_covering_std_is_the_spread_times_the_t_factor_of_its_groups() {
        let spread = [1.0, 2.0, 0.5, 1e-3, 2e-3, 0.0];
        let wide = covering_std(&spread, 20);
        let factor = wide[0];
        // t with 19 degrees of freedom at the Gaussian's 3-std tail.
        assert!((1.10..1.20).contains(&factor), "{factor}");
        for (w, s) in wide.iter().zip(&spread) {
            assert!((w - s * factor).abs() <= 1e-15 * w.abs().max(1.0));
        }
        // Fewer groups, wider; the factor tends to 1 with many.
        assert!(covering_std(&spread, 6)[0] > factor);
        assert!(covering_std(&spread, 10_000)[0] < 1.001);
    }

    #[test]
    fn a_group_left_out_is_every_groups_th_item() {
        assert_eq!(kept_without_group(7, 3, 1), vec![0, 2, 3, 5, 6]);
        assert_eq!(kept_without_group(4, 4, 0), vec![1, 2, 3]);
    }
}
