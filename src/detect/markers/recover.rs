//! Markers the search missed, recovered from the board geometry (what
//! OpenCV's `refineDetectedMarkers` does).
//!
//! The markers found on a board place every one it lacks: the homography
//! of the found markers near it (within [`NEIGHBOURHOOD_MARKERS`] marker
//! pitches, as the consistency check uses; all of them when fewer than two
//! are near; a single marker places only its direct neighbours) maps its
//! board corners into the image. There its sides are
//! fitted to the image's edges ([`refine_quad`]) and its cells are read
//! with looser contrast and border limits than a search without a place
//! (and, from 6 x 6 bits on, with the expected marker's own threshold
//! too: [`read_expected`]); it is kept only when it reads as the predicted id,
//! in the predicted rotation, with at most [`recover_bit_errors`] wrong
//! bits, and when its fitted corners stay within [`MAX_SHIFT_FRACTION`] of
//! its side of the prediction. Markers recovered in one round help place
//! the rest in the next (up to [`ROUNDS`]).
//!
//! A small, blurred or faint marker fails the search's candidate stage
//! (its dark region merges with its neighbours' or breaks up at the
//! adaptive threshold, or the decimated search never sees it) long before
//! its cells become unreadable: recovered, it gives the ChArUco corners
//! and AprilGrid tag corners around it.

use super::decode::{read_expected, Marker};
use super::edges::refine_quad;
use super::homography::Homography;
use super::quads::Quad;
use super::{centre, mean_side, NEIGHBOURHOOD_MARKERS};
use crate::image::GrayImage;
use crate::target::marker_board::MarkerLayout;
use nalgebra::Point2;

/// Smallest predicted marker side that is read, pixels (a 4 x 4 marker with
/// its border has cells of 1 px then).
const MIN_SIDE_PX: f64 = 6.0;
/// A recovered marker's fitted corners lie within this fraction of its side
/// of the predicted ones.
const MAX_SHIFT_FRACTION: f64 = 0.25;
/// Rounds of recovery (each uses the markers recovered before it).
const ROUNDS: usize = 3;

/// Wrong bits a recovered marker may have: an eighth of its inner bits (at
/// least one) for markers under 6 x 6, 2 for 4 x 4 and 3 for 5 x 5; a
/// sixth from 6 x 6 on, 6 for 6 x 6 and 8 for 7 x 7 (the id and the
/// rotation are known, so a random pattern passes with a chance of 0.2 %
/// for 4 x 4, 0.008 % for 5 x 5, 0.003 % for 6 x 6; an eighth, 4 wrong
/// bits, left AprilGrid tags of 2.2 px cells unread that the board placed
/// and that read within 6 at their place: see [`read_expected`]).
pub(crate) fn recover_bit_errors(marker_bits: usize) -> u32 {
    let inner = marker_bits * marker_bits;
    let share = if marker_bits >= 6 { 6 } else { 8 };
    (inner / share).max(1) as u32
}

/// The markers of `layout` missing from `mine` (board index, marker) that
/// read where the found ones place them; see the module docs.
pub(super) fn recover_missing(
    image: &GrayImage,
    layout: &MarkerLayout,
    mine: &[(usize, &Marker)],
) -> Vec<(usize, Marker)> {
    let mut known: Vec<(usize, [Point2<f64>; 4])> =
        mine.iter().map(|(k, m)| (*k, m.corners)).collect();
    let mut out = Vec::new();
    if known.is_empty() {
        return out;
    }
    let pitch = layout
        .markers
        .first()
        .map_or(1.0, |m| (m.corners[1] - m.corners[0]).norm())
        * 1.5;
    let max_errors = recover_bit_errors(layout.dictionary.marker_bits());
    let (w, h) = (f64::from(image.width), f64::from(image.height));
    for _ in 0..ROUNDS {
        let mut added = Vec::new();
        for (k, board_marker) in layout.markers.iter().enumerate() {
            if known.iter().any(|(j, _)| *j == k) {
                continue;
            }
            let here = centre(&board_marker.corners);
            let near: Vec<&(usize, [Point2<f64>; 4])> = known
                .iter()
                .filter(|(j, _)| {
                    (centre(&layout.markers[*j].corners) - here).norm()
                        <= NEIGHBOURHOOD_MARKERS * pitch
                })
                .collect();
            let refs: Vec<&(usize, [Point2<f64>; 4])> = if near.len() >= 2 || known.len() < 2 {
                near
            } else {
                known.iter().collect()
            };
            // One marker alone places only its neighbours (its homography
            // extrapolates).
            let reach = if refs.len() == 1 { 2.0 } else { f64::INFINITY };
            if refs.is_empty()
                || refs.iter().all(|(j, _)| {
                    (centre(&layout.markers[*j].corners) - here).norm() > reach * pitch
                })
            {
                continue;
            }
            let pairs: Vec<_> = refs
                .iter()
                .flat_map(|(j, c)| layout.markers[*j].corners.into_iter().zip(*c))
                .collect();
            let Some(hom) = Homography::fit(&pairs) else {
                continue;
            };
            let mut predicted = [Point2::origin(); 4];
            let mut ok = true;
            for (p, b) in predicted.iter_mut().zip(&board_marker.corners) {
                match hom.map(b) {
                    Some(q) if q.x >= 1.0 && q.y >= 1.0 && q.x <= w - 2.0 && q.y <= h - 2.0 => {
                        *p = q
                    }
                    _ => ok = false,
                }
            }
            let side = mean_side(&predicted);
            if !ok || side < MIN_SIDE_PX || !clockwise(&predicted) {
                continue;
            }
            let fitted = refine_quad(image, Quad { corners: predicted }, 1.0).corners;
            if fitted
                .iter()
                .zip(&predicted)
                .any(|(f, p)| (f - p).norm() > MAX_SHIFT_FRACTION * side)
            {
                continue;
            }
            let Some(bit_errors) = read_expected(
                image,
                &fitted,
                layout.dictionary,
                layout.border_bits,
                board_marker.id,
                max_errors,
            ) else {
                continue;
            };
            added.push((
                k,
                Marker {
                    id: board_marker.id,
                    corners: fitted,
                    bit_errors,
                },
            ));
        }
        if added.is_empty() {
            break;
        }
        known.extend(added.iter().map(|(k, m)| (*k, m.corners)));
        out.extend(added);
    }
    out
}

/// Whether a quad's corners run clockwise on screen (y down) and it is
/// convex: a prediction that folds over is no marker.
fn clockwise(c: &[Point2<f64>; 4]) -> bool {
    (0..4).all(|k| {
        let (a, b, d) = (c[k], c[(k + 1) % 4], c[(k + 2) % 4]);
        (b.x - a.x) * (d.y - b.y) - (b.y - a.y) * (d.x - b.x) > 0.0
    })
}
