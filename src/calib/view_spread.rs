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
//! (`N - P` the residuals' degrees of freedom). Two levels, on the ratio
//! of fx, fy, cx, cy or skew against its F quantile:
//! - past the one-sided tail of 2 Gaussian std ([`WIDEN_TAIL`]), every
//!   std is widened to the cluster-robust one where that is larger, the
//!   correlations kept (so the projection uncertainty map widens with it),
//!   without a word: weak evidence, and on data that agree it only puts a
//!   std at an unbiased estimate of itself;
//! - past 3.5 std ([`TAIL`], 0.023 %: under one calibration in 1,000 by
//!   chance), the views disagree: the widened std is also multiplied by
//!   the Student-t coverage factor of its `nu` (a std from few degrees of
//!   freedom, [`crate::optim::student_t::coverage_factor`]), and a warning
//!   names the parameter that disagrees most.
//!
//! Measured (`examples/view_spread_coverage.rs`, 400 seeded trials of the
//! example camera, 9x6 board, 0.2 px noise): views stretched by 0.1 % per
//! image, 15 views: all of fx, fy, cx, cy within 3 std in 96.8 % of the
//! trials (69.2 % with the residuals' std alone), warned in 71 %; 8 views:
//! 93.2 % (69.9 %); views that agree: unchanged coverage (99.0-99.2 %),
//! mean abs(error) / std 0.70-0.85, warned in 0-0.25 %. (s25's first rule
//! used the leave-one-view-out spread itself; views of uneven leverage
//! inflate it, and an exact 20-view render read 1.6-2.5x.)

use super::refine::CalibProblem;
use crate::optim::student_t::{coverage_factor, f_upper_quantile};
use crate::optim::{
    cluster_robust_covariance, cluster_robust_from_final, BlockProblem, LmResult, Loss, ResidualRun,
};
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
    // The views' stacked rows, as the solver took them at its last
    // evaluation; evaluated again only when the solver kept none.
    let rows = |runs: &[ResidualRun]| runs.iter().map(|r| r.residuals.len()).sum::<usize>();
    let reused = result.final_normal.as_deref().and_then(|last| {
        cluster_robust_from_final(last, &result.params, loss, &free)
            .map(|robust| (robust, rows(&last.normal.weighted_runs)))
    });
    let (robust, n_residuals) = match reused {
        Some(found) => found,
        None => {
            let Some(Ok(residuals)) = problem.residual_runs(&result.params) else {
                return unchanged;
            };
            (
                cluster_robust_covariance(&result.params, &residuals, loss, &free),
                rows(&residuals),
            )
        }
    };
    let Some(robust) = robust else {
        return unchanged;
    };
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
    let t = coverage_factor(nu(worst));
    let factor = if t > 1.1 {
        format!(
            ", times {t:.2} (Student's t: a std from {:.0} degrees of freedom is itself \
             uncertain; more views narrow it)",
            nu(worst)
        )
    } else {
        String::new()
    };
    let warning = format!(
        "the views disagree more than their residuals say: {}'s std from the views' disagreement \
         is {} ({:.1}x its std from the residuals, {}; up to {:.2}x is chance with {} views, \
         {:.0} effective degrees of freedom){also}. Every std, and the projection uncertainty, \
         is widened to the views' disagreement where that is larger{factor}. Errors shared by the \
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calib::{calibrate, CalibrationOptions, View};
    use crate::camera::Camera;
    use crate::synth::{Rng, Scene};
    use nalgebra::Point2;
    use wasm_bindgen_test::wasm_bindgen_test;

    const DISAGREE: &str = "the views disagree more than their residuals say: ";

    /// 15 views of the example camera (0.2 px noise); each view's pixels
    /// also stretched about the image centre by its own factors of std
    /// `stretch` across and down (an error shared by an image's corners).
    fn views(seed: u64, stretch: f64) -> (Camera, Vec<View>) {
        let camera = Camera::example_brown();
        let scene = Scene::calibration(seed, &camera, (9, 6), 0.03, 15, 0.2).unwrap();
        let (cx, cy) = (camera.width as f64 / 2.0, camera.height as f64 / 2.0);
        let mut rng = Rng::new(seed ^ 0x5eed);
        let views = scene
            .views
            .into_iter()
            .map(|mut v| {
                let (mx, my) = (1.0 + rng.gaussian(stretch), 1.0 + rng.gaussian(stretch));
                for p in &mut v.image_px {
                    *p = Point2::new(cx + mx * (p.x - cx), cy + my * (p.y - cy));
                }
                v
            })
            .collect();
        (camera, views)
    }

    fn pinhole(camera: &Camera) -> [f64; 4] {
        let k = camera.camera_matrix();
        [k[(0, 0)], k[(1, 1)], k[(0, 2)], k[(1, 2)]]
    }

    /// Views stretched by 0.2 % each (two seeds): a warning names the
    /// disagreement and every one of fx, fy, cx, cy is within 3 reported
    /// std of the truth; the same views unstretched: no warning.
    #[wasm_bindgen_test(unsupported = test)]
    fn views_that_disagree_are_named_and_their_std_covers_the_truth() {
        let names = ["fx", "fy", "cx", "cy"];
        for seed in [20_003, 20_011] {
            let (camera, views) = views(seed, 2e-3);
            let size = (camera.width, camera.height);
            let report = calibrate(&views, size, &CalibrationOptions::default()).unwrap();
            let warning = report
                .warnings
                .iter()
                .find(|w| w.starts_with(DISAGREE))
                .unwrap_or_else(|| panic!("seed {seed}: no warning: {:?}", report.warnings));
            assert!(warning.contains("is widened to the views' disagreement"));
            let truth = pinhole(&camera);
            let got = pinhole(&report.camera);
            for i in 0..4 {
                let std = report.std[names[i]];
                let z = (got[i] - truth[i]) / std;
                println!("seed {seed} {}: error / std {z:.2}", names[i]);
                assert!(z.abs() <= 3.0, "seed {seed} {}: {z}", names[i]);
            }
        }
        let (camera, clean) = views(20_003, 0.0);
        let size = (camera.width, camera.height);
        let report = calibrate(&clean, size, &CalibrationOptions::default()).unwrap();
        assert!(
            !report.warnings.iter().any(|w| w.starts_with(DISAGREE)),
            "{:?}",
            report.warnings
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn thresholds_are_the_f_quantiles() {
        // Many residual degrees of freedom: F(nu, inf) = chi^2_nu / nu;
        // chi^2_10's upper 2.275 % point is 20.77, its 0.0233 % point 33.41 (scipy).
        assert!((threshold(10.0, 1e6, WIDEN_TAIL) - 2.077).abs() < 0.01);
        assert!((threshold(10.0, 1e6, TAIL) - 3.341).abs() < 0.01);
        // Fewer degrees of freedom, a higher bar.
        assert!(threshold(4.0, 1000.0, TAIL) > threshold(10.0, 1000.0, TAIL));
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn numbers_keep_three_significant_digits() {
        assert_eq!(significant(1.53642), "1.54");
        assert_eq!(significant(0.38642), "0.386");
        assert_eq!(significant(0.000_213), "2.13e-4");
        assert_eq!(significant(0.0), "0");
    }
}
