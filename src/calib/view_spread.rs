//! Do the views agree as well as their residuals say? (issue 35: "check
//! internal consistency (leave-one-out) against the reported std and widen
//! it, or warn, when they disagree beyond it".)
//!
//! The camera's covariance `s^2 (J^T J)^-1` takes every corner's error as
//! independent. On real photos part of the error is shared by the corners
//! of one image (blur or lighting that differs between images, a board
//! that bends differently as it is moved), the views disagree more than
//! the residual scatter says, and that std is too small: leave-one-view-out
//! refits of OpenCV's 13 left sample photos spread 4.0x the reported std
//! in cx and 2.4x in cy (s25, `benches/view_spread.sh`).
//!
//! The check compares the reported covariance with the views' own
//! disagreement, the cluster-robust covariance with Bell and McCaffrey's
//! leverage correction ([`crate::optim::cluster_robust_covariance`], one
//! cluster a view). When the errors are independent, as the model says,
//! that estimate has the reported variance as its expectation and scatters
//! about it as `chi^2_nu / nu`, `nu` its effective degrees of freedom; so
//! the ratio of the two variances is `F(nu, N - P)` distributed
//! (`N - P` the residuals' degrees of freedom). The views disagree when
//! the ratio of fx, fy, cx, cy or skew passes its F quantile at the
//! one-sided tail of 3.5 Gaussian std ([`TAIL`], 0.023 %: under one
//! calibration in 1,000 with four parameters by chance). (s25's first rule used the
//! leave-one-view-out spread itself; views of uneven leverage inflate it,
//! and an exact 20-view render read 1.6-2.5x.)
//!
//! Then every std is widened to the cluster-robust one where that is
//! larger, times the Student-t coverage factor of its `nu` (a std from few
//! degrees of freedom, [`crate::optim::student_t::coverage_factor`]); the
//! correlations are kept, so the projection uncertainty map widens with
//! it; and a warning names the parameter that disagrees most.

use super::refine::CalibProblem;
use crate::optim::student_t::{coverage_factor, f_upper_quantile};
use crate::optim::{cluster_robust_covariance, BlockProblem, LmResult, Loss};
use nalgebra::DMatrix;

/// The parameters whose disagreement decides (the distortion coefficients
/// are widened with them, never on their own: high-order coefficients are
/// set by the few views at the image's edge).
const PINHOLE: [&str; 5] = ["fx", "fy", "cx", "cy", "skew"];

/// The views' disagreement with the reported covariance.
#[derive(Clone, Debug)]
pub(crate) struct ViewSpread {
    /// The camera covariance (the report's layout), widened when the views
    /// disagree.
    pub covariance: DMatrix<f64>,
    /// The warning that says so; `None` when they agree.
    pub warning: Option<String>,
}

/// The variance ratio beyond which the views disagree, for a cluster-robust
/// variance of `nu` effective degrees of freedom against one from `dof`
/// residual degrees of freedom.
pub fn threshold(nu: f64, dof: f64, tail: f64) -> f64 {
    f_upper_quantile(tail, nu.max(0.5), dof.max(1.0))
}

/// The one-sided tail of the Gaussian beyond 2 std, `P(Z > 2)`: past it
/// the std is widened without a word (the views' disagreement is then
/// the better estimate, and a false alarm only widens a std to an
/// unbiased estimate of itself).
const WIDEN_TAIL: f64 = 2.275_013_194_817_92e-2;

/// The one-sided tail of the Gaussian beyond 3.5 std, `P(Z > 3.5)`: the
/// chance of a false alarm per parameter. (At 3 std, 0.135 %, 400 exact
/// renders of 8-20 views warned in 0.5-1.2 %: the chi-square law of the
/// cluster-robust variance is a little light in its tail.)
const TAIL: f64 = 2.326_290_790_355_25e-4;

/// The camera covariance `c` (layout of `names`, as the report holds it)
/// checked against the views' disagreement and widened when they disagree.
/// `to_camera` maps the solver's global covariance to the report's layout
/// (the camera block, fy from fx when the aspect ratio is held); `aspect`
/// says fy is fx times a held ratio.
pub(crate) fn check_view_spread(
    problem: &CalibProblem,
    result: &LmResult,
    loss: &Loss,
    c: &DMatrix<f64>,
    names: &[String],
    aspect: bool,
    to_camera: impl Fn(&DMatrix<f64>) -> DMatrix<f64>,
) -> ViewSpread {
    let unchanged = ViewSpread {
        covariance: c.clone(),
        warning: None,
    };
    let Some(global) = result.covariance_global.as_ref() else {
        return unchanged;
    };
    let free: Vec<bool> = global.diagonal().iter().map(|v| *v > 0.0).collect();
    let Ok(residuals) = problem.residuals_and_jacobian(&result.params, true) else {
        return unchanged;
    };
    let Some(robust) = cluster_robust_covariance(&result.params, &residuals, loss, &free) else {
        return unchanged;
    };
    let n_residuals: usize = residuals.iter().map(|r| r.residuals.len()).sum();
    let n_free = free.iter().filter(|f| **f).count()
        + result.params.blocks.iter().map(|b| b.len()).sum::<usize>();
    let dof = n_residuals.saturating_sub(n_free) as f64;
    let spread = to_camera(&robust.covariance);
    let n = c.nrows().min(spread.nrows()).min(names.len());
    // fy's degrees of freedom are fx's when it follows fx.
    let nu = |k: usize| {
        let g = if aspect && k == 1 { 0 } else { k };
        robust.dof.get(g).copied().unwrap_or(0.0)
    };
    let ratio = |k: usize| {
        let (s, v) = (spread[(k, k)], c[(k, k)]);
        if v > 0.0 && s >= 0.0 {
            s / v
        } else {
            0.0
        }
    };
    let decides = |k: &usize| PINHOLE.contains(&names[*k].as_str()) && nu(*k) > 0.0;
    let beyond = |tail: f64| -> Vec<(usize, f64, f64)> {
        let mut over: Vec<(usize, f64, f64)> = (0..n)
            .filter(decides)
            .map(|k| (k, ratio(k), threshold(nu(k), dof, tail)))
            .filter(|(_, r, limit)| r > limit)
            .collect();
        over.sort_by(|a, b| (b.1 / b.2).total_cmp(&(a.1 / a.2)));
        over
    };
    if beyond(WIDEN_TAIL).is_empty() {
        return unchanged;
    }
    // Widened to the views' disagreement; when they disagree beyond chance,
    // times the coverage factor of a std from `nu` degrees of freedom.
    let over = beyond(TAIL);
    let widen = |t: bool| {
        let scale: Vec<f64> = (0..c.nrows())
            .map(|k| match (k < n, t) {
                (false, _) => 1.0,
                (true, false) => ratio(k).sqrt().max(1.0),
                (true, true) => (ratio(k).sqrt() * coverage_factor(nu(k))).max(1.0),
            })
            .collect();
        DMatrix::from_fn(c.nrows(), c.ncols(), |i, j| c[(i, j)] * scale[i] * scale[j])
    };
    if over.is_empty() {
        return ViewSpread {
            covariance: widen(false),
            warning: None,
        };
    }
    let covariance = widen(true);
    let (worst, r, limit) = over[0];
    let also: Vec<String> = over
        .iter()
        .skip(1)
        .map(|&(k, r, _)| format!("{} {:.1}x", names[k], r.sqrt()))
        .collect();
    let also = if also.is_empty() {
        String::new()
    } else {
        format!("; also {}", also.join(", "))
    };
    let warning = format!(
        "the views disagree more than their residuals say: {}'s std from the views' disagreement \
         is {} ({:.1}x its std from the residuals, {}; up to {:.2}x is chance with {} views, \
         {:.0} effective degrees of freedom){also}. Every std, and the projection uncertainty, \
         is widened to the views' disagreement where that is larger. Errors shared by the \
         corners of an image do this: blur or lighting that differs between images, a board \
         that is not flat, or a lens the model does not fit; look for a view whose RMS stands \
         out, or try another lens model",
        names[worst],
        significant(spread[(worst, worst)].sqrt()),
        r.sqrt(),
        significant(c[(worst, worst)].sqrt()),
        limit.sqrt(),
        result.params.blocks.len(),
        nu(worst),
    );
    ViewSpread {
        covariance,
        warning: Some(warning),
    }
}

/// `v` to 3 significant digits, in plain notation down to 1e-3.
fn significant(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        format!("{v}")
    } else if v.abs() < 1e-3 {
        format!("{v:.2e}")
    } else {
        let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{v:.digits$}")
    }
}
