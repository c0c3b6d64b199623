//! The board's flex, estimated with the calibration (`board_warp` of
//! [`super::CalibrationOptions`]): mrcal's two-parameter paraboloid
//! ([`super::refine::BoardExtent`]), reported in millimetres.

use super::refine::CalibProblem;
use crate::optim::LmResult;
use serde::{Deserialize, Serialize};

/// Peak bow (mm) above which the report warns.
pub const WARP_WARNING_MM: f64 = 1.0;

/// The estimated flex of the board: the z offset (along the board's
/// normal, the target frame's +z) of a point at board (x, y) is
/// `x_mm (1 - xr^2) + y_mm (1 - yr^2)` with xr, yr running from -1 to 1
/// across the board's points (mrcal's `calobject_warp`, in mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoardWarp {
    /// The paraboloid's x factor, mm.
    pub x_mm: f64,
    /// The paraboloid's y factor, mm.
    pub y_mm: f64,
    /// 1-sigma of `x_mm` (0 when the covariance is not available).
    pub std_x_mm: f64,
    /// 1-sigma of `y_mm`.
    pub std_y_mm: f64,
    /// The bow at the board's centre (`x_mm + y_mm`), mm.
    pub centre_mm: f64,
}

/// The warp of a fit with the warp estimated; `None` without.
pub(crate) fn board_warp(problem: &CalibProblem, result: &LmResult) -> Option<BoardWarp> {
    problem.warp?;
    let w = problem.warp_of(&result.params.global);
    let n = problem.n_camera();
    let std = |i: usize| {
        result
            .covariance_global
            .as_ref()
            .filter(|c| c.nrows() > n + i)
            .map_or(0.0, |c| c[(n + i, n + i)].max(0.0).sqrt() * 1e3)
    };
    Some(BoardWarp {
        x_mm: w[0] * 1e3,
        y_mm: w[1] * 1e3,
        std_x_mm: std(0),
        std_y_mm: std(1),
        centre_mm: (w[0] + w[1]) * 1e3,
    })
}

/// The warning of a large bow.
pub(crate) fn warp_warning(warp: &BoardWarp) -> Option<String> {
    let peak = warp
        .centre_mm
        .abs()
        .max(warp.x_mm.abs())
        .max(warp.y_mm.abs());
    (peak > WARP_WARNING_MM).then(|| {
        format!(
            "the board bows by {:.2} mm at its centre (x {:.2} mm, y {:.2} mm): more than \
             {WARP_WARNING_MM} mm; a calibration that takes the board as flat is biased by \
             it: keep the warp estimated (--board-warp) or stiffen the board",
            warp.centre_mm, warp.x_mm, warp.y_mm
        )
    })
}
