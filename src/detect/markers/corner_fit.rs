//! The sub-pixel fit of a marker board's corner: the saddle fit, then for
//! ChArUco corners the edges' centroids ([`crate::detect::edge_corner`]).

use crate::detect::edge_corner::{refine_by_edges, EdgeRoom};
use crate::detect::refine::refine_saddle;
use crate::image::GrayImage;
use nalgebra::Point2;

/// Largest saddle-fit half-window, pixels (the chessboard detector's).
const MAX_WINDOW_PX: f64 = 6.0;
/// Smallest saddle-fit half-window, pixels.
pub(super) const MIN_WINDOW_PX: f64 = 2.5;
/// A corner is refined only when it is this many half-windows (plus one
/// pixel) inside the image: the fit's reach (1.5 half-windows) and its
/// smoothing.
const BORDER_WINDOWS: f64 = 2.0;
/// Clearance kept between a ChArUco corner's edge profiles and the marker
/// inside the white square, pixels.
pub(super) const EDGE_CLEARANCE_PX: f64 = 1.0;

/// The saddle fit of a seed with half-window `window`, moved to where its
/// edges meet when `room` is given and the edges fit there, or `None`.
pub(super) fn refine(
    image: &GrayImage,
    seed: Point2<f64>,
    window: f64,
    room: Option<EdgeRoom>,
) -> Option<Point2<f64>> {
    let window = window.clamp(MIN_WINDOW_PX, MAX_WINDOW_PX);
    // The fit reads 1.5 half-windows around the corner plus its smoothing:
    // where that reaches past the image edge it sees replicated border
    // pixels and the corner comes out biased (2.6 px on a partial-view
    // render, once outside the image). Such a corner is left out, as one
    // beyond the edge is.
    let margin = BORDER_WINDOWS * window + 1.0;
    let inside = |p: Point2<f64>| {
        p.x >= margin
            && p.y >= margin
            && p.x <= image.width as f64 - 1.0 - margin
            && p.y <= image.height as f64 - 1.0 - margin
    };
    if !inside(seed) {
        return None;
    }
    let fit = refine_saddle(image, seed, window)?;
    let pos = room
        .and_then(|room| refine_by_edges(image, fit.pos, &fit.hessian, room))
        .unwrap_or(fit.pos);
    ((pos - seed).norm() <= 0.5 * window + 1.0 && inside(pos)).then_some(pos)
}
