//! Points of the boards whose markers carry them: an AprilGrid's tag
//! corners (X-junctions with Kalibr's corner squares, saddle-refined) and
//! an ArUco grid's marker corners (L-corners, [`grid_corners`]).

use super::decode::Marker;
use super::{grid_corners, mean_side, refine, MIN_WINDOW_PX};
use crate::image::GrayImage;
use crate::target::marker_board::MarkerLayout;
use crate::target::{DetectedPoint, Target};
use nalgebra::Point2;

pub(super) fn aprilgrid_corners(
    image: &GrayImage,
    board: &Target,
    layout: &MarkerLayout,
    mine: &[(usize, &Marker)],
) -> Vec<DetectedPoint> {
    let Target::Aprilgrid {
        tag_cols,
        spacing_ratio,
        ..
    } = board
    else {
        return Vec::new();
    };
    let corner_cols = 2 * tag_cols;
    let n = layout.dictionary.marker_bits() + 2 * layout.border_bits;
    let mut out = Vec::new();
    for &(k, m) in mine {
        // The tag's OpenCV corners are printed bottom-right, bottom-left,
        // top-left, top-right: Kalibr's base + 1, base, base + 2 cols,
        // base + 2 cols + 1.
        let base = (k / tag_cols) * corner_cols * 2 + (k % tag_cols) * 2;
        let ids = [base + 1, base, base + corner_cols, base + corner_cols + 1];
        let side = mean_side(&m.corners);
        let gap_px = spacing_ratio * side;
        let border_px = layout.border_bits as f64 * side / n as f64;
        let window = 0.5 * gap_px.min(border_px);
        for (id, seed) in ids.into_iter().zip(m.corners) {
            if let Some(p) = refine(image, seed, window) {
                out.push(DetectedPoint {
                    id,
                    x_px: p.x,
                    y_px: p.y,
                    covariance_px2: None,
                });
            }
        }
    }
    out.sort_by_key(|p| p.id);
    out
}

/// An ArUco grid's points: every consistent marker's four corners
/// ([`grid_corners`]), point `4 k + c` for corner `c` of the board's marker
/// `k` ([`marker_board`]), in id order. Corners within [`MIN_WINDOW_PX`] of
/// the image border are left out (their edge fits reach past it).
pub(super) fn aruco_grid_corners(
    image: &GrayImage,
    layout: &MarkerLayout,
    mine: &[(usize, &Marker)],
) -> Vec<DetectedPoint> {
    let cells = layout.dictionary.marker_bits() + 2 * layout.border_bits;
    let margin = MIN_WINDOW_PX;
    let inside = |p: &Point2<f64>| {
        p.x >= margin
            && p.y >= margin
            && p.x <= image.width as f64 - 1.0 - margin
            && p.y <= image.height as f64 - 1.0 - margin
    };
    let mut out: Vec<DetectedPoint> = mine
        .iter()
        .flat_map(|&(k, m)| {
            grid_corners::refine_corners(image, m.corners, cells)
                .into_iter()
                .enumerate()
                .filter(|(_, p)| inside(p))
                .map(move |(c, p)| DetectedPoint {
                    id: 4 * k + c,
                    x_px: p.x,
                    y_px: p.y,
                    covariance_px2: None,
                })
        })
        .collect();
    out.sort_by_key(|p| p.id);
    out
}
