//! How far a stereo pair's right_from_left moves when pairs are left out:
//! the stereo form of [`super::rig_jackknife`] (issue 35). The joint fit's
//! covariance assumes independent pixel noise; when the two images of a
//! pair were not taken at one moment while the board moved (free-running
//! cameras, a hand-held board), or the board bends, each pair carries an
//! error shared by all its points that the covariance does not know. On
//! OpenCV's real left/right set the leave-pairs-out spread of the
//! translation is about twice the model's std.
//!
//! The pairs are left out group by group (every `groups`-th pair, at most
//! [`MAX_GROUPS`] groups, at least [`MIN_GROUPS`]), each refit from the
//! full solution for at most [`ITERATIONS`](super::rig_jackknife::ITERATIONS) steps; the jackknife variance
//! of right_from_left over the refits, times the Student-t factor of its
//! `G - 1` degrees of freedom ([`super::rig_jackknife`]'s docs), widens
//! the reported std axis by axis where it is larger, and a plain spread
//! beyond [`WARN_FACTOR`] times the model's is said.

use super::rig_jackknife::{
    covering_std, jackknife_std, kept_without_group, pose_delta, refit_from_full, MAX_GROUPS,
    MIN_GROUPS,
};
use super::stereo_problem::StereoProblem;
use crate::calib::refine::CalibProblem;
use crate::calib::View;
use crate::optim::{LmOptions, LmResult};

pub(crate) use super::rig_jackknife::WARN_FACTOR;

/// The leave-pairs-out spread of right_from_left.
pub(crate) struct PairSpread {
    /// The jackknife std, `[rotation (left perturbation) rad x3,
    /// translation m x3]`.
    pub std: [f64; 6],
    /// The same times the t factor of its `runs - 1` degrees of freedom:
    /// what the reported std is widened to.
    pub covering: [f64; 6],
    /// Refits it rests on.
    pub runs: usize,
}

/// The leave-pairs-out spread of right_from_left; `None` with fewer than
/// [`MIN_GROUPS`] pairs or refits.
pub(crate) fn leave_pairs_out(
    problem: &StereoProblem,
    full: &LmResult,
    lm: &LmOptions,
) -> Option<PairSpread> {
    let n_pairs = problem.left.views.len();
    let groups = n_pairs.min(MAX_GROUPS);
    if groups < MIN_GROUPS {
        return None;
    }
    let full_rfl = problem.right_from_left(&full.params.global);
    let mut deltas = Vec::with_capacity(groups);
    for g in 0..groups {
        let keep = kept_without_group(n_pairs, groups, g);
        let pick_views =
            |views: &[View]| -> Vec<View> { keep.iter().map(|&i| views[i].clone()).collect() };
        let pick_used = |used: &[Vec<bool>]| -> Vec<Vec<bool>> {
            keep.iter().map(|&i| used[i].clone()).collect()
        };
        let (left_views, right_views) = (
            pick_views(problem.left.views),
            pick_views(problem.right.views),
        );
        let (left_used, right_used) = (pick_used(problem.left.used), pick_used(problem.right.used));
        let sub = StereoProblem {
            left: CalibProblem {
                views: &left_views,
                used: &left_used,
                ..problem.left
            },
            right: CalibProblem {
                views: &right_views,
                used: &right_used,
                ..problem.right
            },
            n_left: problem.n_left,
            n_right: problem.n_right,
        };
        let Some(refit) = refit_from_full(&sub, full, &keep, lm) else {
            continue;
        };
        let rfl = sub.right_from_left(&refit.params.global);
        deltas.push(pose_delta(&rfl, &full_rfl));
    }
    let runs = deltas.len();
    (runs >= MIN_GROUPS).then(|| {
        let std = jackknife_std(&deltas);
        PairSpread {
            std,
            covering: covering_std(&std, runs),
            runs,
        }
    })
}
