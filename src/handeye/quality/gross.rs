//! One pose pair whose residual is orders of magnitude above the others'
//! (a row typed in mm in a metre file, a digit too many) is refused by
//! name before the solve (issue 35): a robust refinement would only
//! down-weight it and report a transform far off.

use crate::error::{Error, Result};
use crate::handeye::closed_form::{solve_method, solve_with_motions};
use crate::handeye::quality::residuals::{lever_arm_m, view_residuals, ViewResidual};
use crate::handeye::{Chain, HandEyeMethod, Motion, MotionPairs, Pose, MIN_POSES};

/// A pose pair is a gross error when, with it left out, its residual (the
/// displacement at the target, mm) is this many times the median of the
/// others ...
pub const GROSS_RATIO: f64 = 100.0;
/// ... and at least this large (mm): noise-free data has medians of 1e-9 mm,
/// and a few centimetres are the robust refinement's to down-weight.
pub const GROSS_MIN_MM: f64 = 100.0;
/// Pose pairs with the largest residuals under the full solution that are
/// each tried left out.
const GROSS_CANDIDATES: usize = 3;

/// Refuse a pose pair whose residual is orders of magnitude above the
/// others' (a row typed in mm in a metre file, a digit too many): with the
/// candidate left out (each of the [`GROSS_CANDIDATES`] largest residuals
/// under the full Park-Martin solution; the one whose removal fits the
/// others best), its residual is above [`GROSS_RATIO`] times the median of
/// the others and above [`GROSS_MIN_MM`]. The error names the pair.
pub fn refuse_gross_pose(chain: &Chain, pairs: MotionPairs) -> Result<()> {
    refuse_gross_pose_with(chain, pairs, None)
}

/// [`refuse_gross_pose`] with the chain's motions for `pairs` already built
/// (`kept` of [`crate::handeye::closed_form::motion::build_motions`]): with
/// every pair, a chain with one pose left out has exactly the motions that
/// do not touch it, in the same order, so they are filtered instead of
/// rebuilt (half a million motions at 1,000 poses, four times).
pub(crate) fn refuse_gross_pose_with(
    chain: &Chain,
    pairs: MotionPairs,
    motions: Option<&[Motion]>,
) -> Result<()> {
    let n = chain.len();
    if n <= MIN_POSES {
        return Ok(());
    }
    let lever = lever_arm_m(chain);
    let displacement = |r: &ViewResidual| {
        let rot_mm = r.rotation_deg.to_radians() * lever * 1e3;
        r.translation_mm.hypot(rot_mm)
    };
    let motions = motions.filter(|_| pairs == MotionPairs::All);
    // The Park-Martin solution of `c`, the chain with `left_out` removed.
    let solve = |c: &Chain, left_out: Option<usize>| -> Option<(Pose, Pose)> {
        let (x, y, _) = match (motions, left_out) {
            (Some(all), None) => solve_with_motions(HandEyeMethod::ParkMartin, c, all),
            (Some(all), Some(k)) => {
                let rest: Vec<Motion> = all
                    .iter()
                    .filter(|m| m.from != k && m.to != k)
                    .cloned()
                    .collect();
                solve_with_motions(HandEyeMethod::ParkMartin, c, &rest)
            }
            (None, _) => solve_method(HandEyeMethod::ParkMartin, c, pairs),
        }
        .ok()?;
        Some((x, y))
    };
    let Some((x, y)) = solve(chain, None) else {
        return Ok(());
    };
    let full: Vec<f64> = view_residuals(chain, &x, &y)
        .iter()
        .map(displacement)
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| full[b].total_cmp(&full[a]));
    // (median of the others, the candidate, its residual and rotation).
    let mut best: Option<(f64, usize, ViewResidual, f64)> = None;
    for &c in order.iter().take(GROSS_CANDIDATES) {
        let keep: Vec<usize> = (0..n).filter(|&i| i != c).collect();
        let rest = Chain {
            robot: keep.iter().map(|&i| chain.robot[i]).collect(),
            camera: keep.iter().map(|&i| chain.camera[i]).collect(),
        };
        let Some((x, y)) = solve(&rest, Some(c)) else {
            continue;
        };
        let residuals = view_residuals(chain, &x, &y);
        let mut others: Vec<f64> = keep.iter().map(|&i| displacement(&residuals[i])).collect();
        others.sort_by(f64::total_cmp);
        let median = others[others.len() / 2];
        if best.as_ref().map_or(true, |b| median < b.0) {
            let own = residuals[c].clone();
            let d = displacement(&own);
            best = Some((median, c, own, d));
        }
    }
    let Some((median, c, own, d)) = best else {
        return Ok(());
    };
    if d > GROSS_RATIO * median && d > GROSS_MIN_MM {
        return Err(Error::invalid(
            "poses",
            format!(
                "pose pair {c} (robot pose and camera pose {c}, counting from 0) is a gross \
                 error: with it left out the other {} fit one hand-eye transform with a median \
                 residual of {median:.3} mm, and it is off by {:.1} mm and {:.2} deg: that row \
                 holds a typo or another unit (millimetres in a metre file?): fix or remove it",
                n - 1,
                own.translation_mm,
                own.rotation_deg
            ),
        ));
    }
    Ok(())
}
