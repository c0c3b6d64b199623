//! Grids of separate dark squares (Zhang's 1998 target): dark blobs grown
//! into a lattice of squares, ordered, then each square's four corners from
//! sub-pixel edges.
//!
//! # Order
//!
//! Squares are ordered like circle grids (see [`crate::target`] for the
//! ids): of the lattice orderings that fit the board, (1) the board's
//! x -> y turns clockwise in the image (a right-handed board frame seen from
//! the front), (2) square 0 is the candidate nearest the image's top-left
//! pixel. A square grid has no marker, so it is always symmetric under a
//! 180-degree turn (and under 90 degrees when `cols == rows`): rule 2
//! decides, and the order can flip between views that turn the board by
//! more than 90 (square boards: 45) degrees in the image, as for symmetric
//! chessboards.
//!
//! # Corners
//!
//! Each square's first corners come from its blob centre and the local
//! lattice steps. Each side is then measured by profiles across it (away
//! from the corners, where the other side's edge would enter the
//! profile): an edge point is the centroid of the profile's derivative
//! (the image gradient along the normal) in a window moved onto it, so the
//! threshold plays no part. The samples at the window's two ends count by
//! the part of their cell inside it, so the centroid moves continuously
//! with the window instead of jumping by a sample whenever an end crosses
//! one (that jump left the corners to jitter with the sampling phase from
//! pass to pass). A curve is fitted to each side's edge points,
//! a corner is where the curves of its two sides meet, and the profiles
//! are measured again across the refined sides: one coarse pass
//! (samples every 0.5 px, a profile every 2 px, at least 16 per side, a
//! wide search), then fine passes (samples every 0.25 px, a
//! profile per pixel) until one moves no corner by more than 0.05 px
//! (usually the first: fine passes agree to ~0.005 px), at most four
//! passes in all. Only the fine passes decide the corners; the coarse one
//! brings the sides within the fine search (docs/benchmark-history.md,
//! "Square grids: speed" and sessions 9-14).

//! The curve is a straight line over the whole side, chosen by numbers
//! (test `side_models_compared_on_distorted_renders`: four 1280x960 views
//! through Zhang's lens, k1 = -0.23, one filling the frame, two tilted
//! by 30-35 degrees; mean / max corner error):
//!
//! | side model | noise-free | noise sigma 2 |
//! |---|---|---|
//! | line over the whole side | 0.010 / 0.026 px | **0.017 / 0.051 px** |
//! | parabola over the whole side | 0.0036 / 0.028 px | 0.026 / 0.097 px |
//! | line over the half side next to each corner | 0.0049 / 0.022 px | 0.022 / 0.077 px |
//!
//! (The model is fitted in the fine passes; the coarse pass always fits a
//! line, its few profiles only place the sides.)
//!
//! The distortion bends a side by up to ~0.1 px, which the line does not
//! follow (its bias, 0.01 px), but the parabola's extrapolation to the
//! corner and the half-side segments double the noise, which dominates
//! at any realistic noise level. On Zhang's photos the line also gives the
//! lowest calibration RMS (0.362 px; 0.407 and 0.385 px for the others
//! when they were measured, session 8; test
//! `zhang1998_square_grid_found_and_calibrated`). Corners come with the
//! covariance propagated from the residuals of their two line fits.

use super::blobs::{bilinear_line, bilinear_u8, find_blobs, Blob};
use super::circles::{blob_working_level, blobs_at_level, search_grid, GridSearch};
use super::DetectOptions;
use crate::error::{Error, Result};
use crate::image::filter::{box_level, to_full};
use crate::image::GrayImage;
use crate::target::DetectedPoint;
use nalgebra::{Matrix2, Matrix3, Point2, Vector2, Vector3};

/// Sample spacing along a profile, pixels (0.5 px would halve the time but
/// moved Zhang's calibration by 0.1-0.3 std: his photos' edges are sharp).
const PROFILE_STEP_PX: f64 = 0.25;
/// Profile spacing along a side in the refining passes, pixels (one
/// profile per pixel column: closer profiles share their pixels through
/// the bilinear interpolation and add time, not information).
const PROFILE_SPACING_PX: f64 = 1.0;
/// Profile spacing in the first, wide pass, pixels (it only has to find
/// the sides for the next pass).
const FIRST_PASS_SPACING_PX: f64 = 2.0;
/// Profiles a side gets in the first pass at least (closer than
/// `FIRST_PASS_SPACING_PX` on short sides).
const MIN_FIRST_PASS_PROFILES: f64 = 16.0;
/// Sample spacing along a profile in the coarse passes, pixels.
const COARSE_PROFILE_STEP_PX: f64 = 0.5;
/// The first passes, coarse: samples every `COARSE_PROFILE_STEP_PX`,
/// profiles every `FIRST_PASS_SPACING_PX` (the first with a wide search).
/// One is enough: a second coarse pass (session 9-12) moved the result of
/// the fine pass after it by ~0.001 px on the renders and took 15 % of a
/// VGA detection (docs/benchmark-history.md, "Session 13").
const COARSE_PASSES: usize = 1;
/// Most edge measurement passes (coarse and fine).
const PASSES: usize = 4;
/// A fine pass that moves no corner by more than this ends the
/// refinement, pixels (the fine passes agree to ~0.005 px, their
/// sampling's jitter: a tighter bound only repeats the fine pass).
const CONVERGED_PX: f64 = 0.05;
/// Centroid window half-width in standard deviations of the edge's
/// derivative (plus half a pixel): measured on the distorted renders of the
/// tests, 2.5 gives the least noise without bias (2.0 biases the fixed
/// point by 0.01 px, 3.0 adds 20 % noise). A Gaussian-weighted centroid
/// was worse: its fixed-point iteration converges too slowly.
const WINDOW_SDS: f64 = 2.5;
/// Most iterations of the centroid window moved onto an edge (it stops
/// once the centroid moves by less than 0.001 px; with the window's ends
/// counted by part, see `edges::window_sums`, it settles in a few).
const CENTROID_ITERATIONS: usize = 8;
/// Blobs are first found one pyramid level above the working level; a
/// board found there is kept when its squares are at least this many
/// pixels across at that level (the median blob's square root of area),
/// else the working level decides.
const MIN_COARSE_SQUARE_PX: f64 = 6.0;
/// A side needs at least this many edge points.
const MIN_EDGE_POINTS: usize = 6;

/// What is fitted to a side's edge points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
// The alternatives are measured against the default in the tests.
#[cfg_attr(any(not(test), target_arch = "wasm32"), allow(dead_code))]
pub(crate) enum SideModel {
    /// A straight line over the whole side: the default.
    Line,
    /// A parabola over the whole side (follows lens distortion).
    Parabola,
    /// A straight line over the half of the side next to each corner.
    CornerSegments,
}

/// Detect a `cols x rows` grid of dark squares: corners in board order.
pub(crate) fn detect_square_grid(
    img: &GrayImage,
    cols: usize,
    rows: usize,
    side_over_pitch: f64,
    options: &DetectOptions,
) -> Result<Vec<DetectedPoint>> {
    detect_with_model(img, cols, rows, side_over_pitch, options, SideModel::Line)
}

pub(crate) fn detect_with_model(
    img: &GrayImage,
    cols: usize,
    rows: usize,
    side_over_pitch: f64,
    options: &DetectOptions,
    model: SideModel,
) -> Result<Vec<DetectedPoint>> {
    let board: Vec<(i32, i32)> = (0..rows as i32)
        .flat_map(|j| (0..cols as i32).map(move |i| (i, j)))
        .collect();
    let n = board.len();
    let name = format!("{cols}x{rows} square grid");
    // A square's side over the grid step, within a factor 2.
    let seed_fits = |seed: &Blob, step_a: Vector2<f64>, step_b: Vector2<f64>| {
        (0.5..=2.0)
            .contains(&(seed.area.sqrt() / step_a.norm().max(step_b.norm()) / side_over_pitch))
    };
    let search = GridSearch {
        board: &board,
        cols,
        rows,
        diagonal: false,
        // Dark clutter beside the board (Zhang's image2: the backdrop next
        // to the corner square) may join the lattice.
        trim: true,
        seed_fits: &seed_fits,
    };
    let two_boards = || format!("two candidate boards: two complete {name}s in the image");
    // First one level coarser than the working level (a quarter of the
    // pixels: blob finding was 40 % of the time at VGA), kept only when its
    // squares are at least `MIN_COARSE_SQUARE_PX` across there; otherwise,
    // or when no board is found, the working level decides (small squares
    // in a large image are not lost).
    let coarse_level = blob_working_level(img, options) + 1;
    let coarse_blobs = find_blobs(&box_level(img, coarse_level), false);
    let coarse = match search_grid(&coarse_blobs, &search, &two_boards) {
        Ok(Ok(order)) => {
            let mut areas: Vec<f64> = order.iter().map(|&i| coarse_blobs[i].area).collect();
            areas.sort_by(f64::total_cmp);
            (areas[areas.len() / 2].sqrt() >= MIN_COARSE_SQUARE_PX).then_some(order)
        }
        _ => None,
    };
    let (level, blobs, order) = match coarse {
        Some(order) => (coarse_level, coarse_blobs, order),
        None => {
            let (level, blobs) = blobs_at_level(img, false, options);
            match search_grid(&blobs, &search, &two_boards)? {
                Ok(order) => (level, blobs, order),
                Err(best_partial) => {
                    let message = if best_partial > 1 {
                        format!(
                            "found {best_partial} of {n} squares of the {name}: the grid may be cut off, occluded or the counts wrong"
                        )
                    } else {
                        format!("board not found: no {name} in the image")
                    };
                    return Err(Error::NotFound { message });
                }
            }
        }
    };
    let centres: Vec<Point2<f64>> = order.iter().map(|&i| full(&blobs[i], level)).collect();
    let mut out = Vec::with_capacity(4 * n);
    for (sq, &(i, j)) in board.iter().enumerate() {
        let at = |di: i32, dj: i32| -> Option<Point2<f64>> {
            let (a, b) = (i + di, j + dj);
            (a >= 0 && b >= 0 && a < cols as i32 && b < rows as i32)
                .then(|| centres[(a + b * cols as i32) as usize])
        };
        let c = centres[sq];
        let step = |d: (i32, i32)| -> Vector2<f64> {
            match (at(d.0, d.1), at(-d.0, -d.1)) {
                (Some(p), Some(m)) => (p - m) * 0.5,
                (Some(p), None) => p - c,
                (None, Some(m)) => c - m,
                (None, None) => Vector2::zeros(),
            }
        };
        let (ex, ey) = (step((1, 0)), step((0, 1)));
        let h = 0.5 * side_over_pitch;
        let coarse = [
            c - ex * h - ey * h,
            c + ex * h - ey * h,
            c + ex * h + ey * h,
            c - ex * h + ey * h,
        ];
        let gap = (1.0 / side_over_pitch - 1.0) * 2.0 * h * ex.norm().min(ey.norm());
        let corners = refine_square(img, &coarse, gap, model).ok_or_else(|| Error::NotFound {
            message: format!(
                "square {sq} of the {name} at ({:.1}, {:.1}) px has no clean edges",
                c.x, c.y
            ),
        })?;
        for (k, (p, cov)) in corners.iter().enumerate() {
            out.push(DetectedPoint {
                id: 4 * sq + k,
                x_px: p.x,
                y_px: p.y,
                covariance_px2: Some([cov[(0, 0)], cov[(0, 1)], cov[(1, 1)]]),
            });
        }
    }
    Ok(out)
}

fn full(b: &Blob, level: u32) -> Point2<f64> {
    Point2::new(to_full(b.centre.x, level), to_full(b.centre.y, level))
}

mod edges;
#[cfg(test)]
mod tests;

use edges::refine_square;
