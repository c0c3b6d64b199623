//! Marker boards: ChArUco and the ArUco GridBoard (OpenCV), AprilGrid
//! (Kalibr).
//!
//! 1. Candidate quads ([`quads`]: adaptive threshold, 4-connected regions,
//!    convex quadrilaterals, sub-pixel sides) read as markers ([`decode`]:
//!    rectified bit sampling, black-border check, the dictionary's error
//!    correction up to [`MarkerOptions::max_bit_errors`]); the same marker
//!    found at two threshold windows is kept once.
//! 2. Markers are grouped into boards by id: the board of the target's own
//!    ids and, for [`detect_boards`], every other block of as many
//!    consecutive ids (a second board printed with the next ids). Within a
//!    board, markers that the homography of their neighbours places more
//!    than [`OUTLIER_FRACTION`] of their side away are dropped (a
//!    duplicate id, a false decode, the other ChArUco layout). The
//!    board's markers the search missed are then looked for where the
//!    found ones place them and read as the id expected there
//!    ([`recover`], OpenCV's `refineDetectedMarkers`).
//! 3. Points, measured, never interpolated: each is seeded from the
//!    markers around it and refined as a saddle point of the image with the
//!    chessboard detector's sub-pixel fit (`refine.rs`).
//!    - ChArUco: every inner chessboard corner next to at least one
//!      detected marker, seeded from each neighbouring marker's own
//!      homography; a corner whose two neighbouring markers predict it more
//!      than [`DISAGREE_FRACTION`] of the marker margin (or
//!      [`DISAGREE_SIDE_FRACTION`] of the marker side) apart is dropped;
//!      the fit starts from the homography of all of them together.
//!    - AprilGrid: the four corners of every tag (each is an X-junction with
//!      Kalibr's corner squares), seeded at the tag's quad corners.
//!    - ArUco grid: the four corners of every marker, plain L-corners of a
//!      dark square on white with no saddle to refine on: each the meeting
//!      point of two straight edges fitted densely along the marker's sides
//!      ([`grid_corners`]).
//!
//!    Any subset of points may come out (partial views, occlusion).

mod decode;
mod edges;
mod grid_corners;
pub(crate) mod homography;
mod quads;
mod recover;
mod runs;
mod tag_corners;

use super::refine::refine_saddle;
use super::DetectOptions;
use crate::error::{Error, Result};
use crate::image::GrayImage;
use crate::target::marker_board::{self, MarkerLayout};
use crate::target::{DetectedPoint, Detection, Dictionary, Target};
use decode::Marker;
use homography::Homography;
use nalgebra::Point2;
pub(crate) use quads::{decimates, Resolutions};
use std::collections::HashMap;
use tag_corners::{aprilgrid_corners, aruco_grid_corners};

/// A marker is an outlier of its board when the board's homography puts
/// one of its corners further than this fraction of its side away.
pub const OUTLIER_FRACTION: f64 = 0.3;
/// Two neighbouring markers disagree on a ChArUco corner when their
/// predictions differ by more than this fraction of the white margin
/// around a marker (at least [`MIN_DISAGREE_PX`]).
pub const DISAGREE_FRACTION: f64 = 0.5;
/// Radius of a marker's neighbourhood for the consistency check, in
/// marker pitches (1.5 marker sides).
pub const NEIGHBOURHOOD_MARKERS: f64 = 3.0;
/// Floor of the disagreement tolerance, pixels.
pub const MIN_DISAGREE_PX: f64 = 1.5;
/// Floor of the disagreement tolerance as a fraction of the markers' side:
/// a small marker's own homography extrapolates its side's noise to the
/// corner (3-5 px apart on caliscope's 20 px markers, whose joint seed the
/// saddle fit then finds within a pixel); a wrong marker is off by more
/// ([`OUTLIER_FRACTION`] of its side, checked before).
pub const DISAGREE_SIDE_FRACTION: f64 = 0.3;
/// Largest saddle-fit half-window, pixels (the chessboard detector's).
const MAX_WINDOW_PX: f64 = 6.0;
/// Smallest saddle-fit half-window, pixels.
const MIN_WINDOW_PX: f64 = 2.5;
/// A ChArUco corner whose saddle fit fails is fitted again with this
/// fraction of its half-window (at least [`MIN_WINDOW_PX`]): in
/// foreshortened views of caliscope's camera 3, windows of 3.2-3.7 px
/// found no saddle at corners that 0.6-0.75 of them fit within 1 px of
/// OpenCV's corner.
const RETRY_WINDOW_FRACTION: f64 = 0.7;
/// A corner is refined only when it is this many half-windows (plus one
/// pixel) inside the image: the fit's reach (1.5 half-windows) and its
/// smoothing.
const BORDER_WINDOWS: f64 = 2.0;

/// Decoding tunables.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarkerOptions {
    /// Fraction of the dictionary's maximum correction used (OpenCV's
    /// errorCorrectionRate, default 0.6): at most
    /// `floor(rate * max_correction_bits)` wrong bits are corrected.
    pub error_correction_rate: f64,
}

impl Default for MarkerOptions {
    fn default() -> Self {
        MarkerOptions {
            error_correction_rate: 0.6,
        }
    }
}

impl MarkerOptions {
    /// Wrong bits corrected for `dictionary`.
    pub fn max_bit_errors(&self, dictionary: Dictionary) -> u32 {
        (self.error_correction_rate.clamp(0.0, 1.0) * f64::from(dictionary.max_correction_bits()))
            .floor() as u32
    }
}

/// Every marker of `dictionary` in `img` (each once).
pub(crate) fn find_markers(
    img: &GrayImage,
    dictionary: Dictionary,
    border: usize,
    resolutions: Resolutions,
) -> Vec<Marker> {
    let max_errors = MarkerOptions::default().max_bit_errors(dictionary);
    let mut found: Vec<Marker> = Vec::new();
    let cells = dictionary.marker_bits() + 2 * border;
    quads::find_quads(img, resolutions, cells, |q| {
        let Some(m) = decode::read_marker(img, q, dictionary, border, max_errors) else {
            return false;
        };
        let c = centre(&m.corners);
        let side = mean_side(&m.corners);
        match found
            .iter_mut()
            .find(|f| f.id == m.id && (centre(&f.corners) - c).norm() < 0.5 * side)
        {
            Some(f) if m.bit_errors < f.bit_errors => *f = m,
            Some(_) => {}
            None => found.push(m),
        }
        true
    });
    found
}

fn centre(c: &[Point2<f64>; 4]) -> Point2<f64> {
    Point2::from((c[0].coords + c[1].coords + c[2].coords + c[3].coords) / 4.0)
}

fn mean_side(c: &[Point2<f64>; 4]) -> f64 {
    (0..4).map(|k| (c[(k + 1) % 4] - c[k]).norm()).sum::<f64>() / 4.0
}

/// The target's own board in `image` (see the module docs).
pub(crate) fn detect_one(
    image: &GrayImage,
    target: &Target,
    options: &DetectOptions,
) -> Result<Detection> {
    own_board(target, detect_boards(image, target, options))
}

/// The target's own board among `boards` (an error naming the others when
/// it is not there).
pub(crate) fn own_board(target: &Target, boards: Result<Vec<Detection>>) -> Result<Detection> {
    let boards = boards?;
    let others: Vec<String> = boards.iter().map(|d| d.target.to_spec()).collect();
    boards
        .into_iter()
        .find(|d| d.target == *target)
        .ok_or_else(|| Error::NotFound {
            message: format!(
                "found {} with other marker ids ({}), not this board ({}): check the first marker id",
                if others.len() == 1 { "a board" } else { "boards" },
                others.join(", "),
                target.to_spec()
            ),
        })
}

/// Every board of `target`'s layout in `image`: its own ids first, then
/// other id blocks (see the module docs). Errors when there is none.
pub fn detect_boards(
    image: &GrayImage,
    target: &Target,
    _options: &DetectOptions,
) -> Result<Vec<Detection>> {
    boards_at(image, target, Resolutions::HalfThenFull).0
}

/// [`detect_boards`] over some of the marker search's resolutions; the
/// flag says whether any marker of the dictionary was read.
pub(crate) fn boards_at(
    image: &GrayImage,
    target: &Target,
    resolutions: Resolutions,
) -> (Result<Vec<Detection>>, bool) {
    let markers = match target.clone().validated().and_then(|t| {
        marker_board::layout(&t).map(|l| (t, l)).ok_or_else(|| {
            Error::invalid(
                "target",
                format!("{} is not a marker board", target.to_spec()),
            )
        })
    }) {
        Ok((t, layout)) => {
            let found = find_markers(image, layout.dictionary, layout.border_bits, resolutions);
            (t, layout, found)
        }
        Err(e) => return (Err(e), false),
    };
    let read = !markers.2.is_empty();
    (boards_from(image, markers), read)
}

/// The boards the found markers make up.
fn boards_from(
    image: &GrayImage,
    (target, layout, markers): (Target, MarkerLayout, Vec<Marker>),
) -> Result<Vec<Detection>> {
    let dictionary = layout.dictionary;
    if markers.is_empty() {
        return Err(Error::NotFound {
            message: format!(
                "no {} markers found: is the board in view, sharp and lit, and the dictionary right?",
                dictionary.name()
            ),
        });
    }
    if let Some(e) = other_layout_fits_better(&target, &markers) {
        return Err(e);
    }
    let mut out = Vec::new();
    for board in candidate_boards(&target, &layout, &markers) {
        if let Some(d) = assemble(image, &board, &markers) {
            out.push(d);
        }
    }
    if out.is_empty() {
        return Err(no_board_error(&target, &markers));
    }
    Ok(out)
}

/// The target and every other block of consecutive ids seen, as targets.
fn candidate_boards(target: &Target, layout: &MarkerLayout, markers: &[Marker]) -> Vec<Target> {
    let count = layout.markers.len() as i64;
    let first = match target {
        Target::Charuco {
            first_id,
            marker_ids: None,
            ..
        }
        | Target::Aprilgrid { first_id, .. }
        | Target::ArucoGrid { first_id, .. } => *first_id as i64,
        _ => return vec![target.clone()],
    };
    let mut blocks: Vec<i64> = markers
        .iter()
        .map(|m| (m.id as i64 - first).div_euclid(count))
        .collect();
    blocks.sort_unstable_by_key(|b| (*b != 0, *b));
    blocks.dedup();
    blocks
        .into_iter()
        .filter_map(|b| {
            let f = first + b * count;
            let mut t = target.clone();
            match &mut t {
                Target::Charuco { first_id, .. }
                | Target::Aprilgrid { first_id, .. }
                | Target::ArucoGrid { first_id, .. } => {
                    *first_id = usize::try_from(f).ok()?;
                }
                _ => {}
            }
            t.validated().ok()
        })
        .collect()
}

/// The found markers that belong to the board of `layout` (each with its
/// index in the layout) and that one homography places consistently.
fn board_markers<'m>(layout: &MarkerLayout, markers: &'m [Marker]) -> Vec<(usize, &'m Marker)> {
    let index: HashMap<usize, usize> = layout
        .markers
        .iter()
        .enumerate()
        .map(|(k, m)| (m.id, k))
        .collect();
    let mut mine: Vec<(usize, &Marker)> = markers
        .iter()
        .filter_map(|m| index.get(&m.id).map(|&k| (k, m)))
        .collect();
    consistent_markers(layout, &mut mine);
    mine
}

/// One board's detection from the markers, `None` when none of its
/// markers is consistent.
fn assemble(image: &GrayImage, board: &Target, markers: &[Marker]) -> Option<Detection> {
    let layout = marker_board::layout(board)?;
    let mut mine = board_markers(&layout, markers);
    if mine.is_empty() {
        return None;
    }
    let recovered = recover::recover_missing(image, &layout, &mine);
    mine.extend(recovered.iter().map(|(k, m)| (*k, m)));
    let points = match board {
        Target::Charuco { .. } => charuco_corners(image, board, &layout, &mine),
        Target::Aprilgrid { .. } => aprilgrid_corners(image, board, &layout, &mine),
        Target::ArucoGrid { .. } => aruco_grid_corners(image, &layout, &mine),
        _ => Vec::new(),
    };
    if points.is_empty() {
        return None;
    }
    Some(Detection {
        image_size_px: [image.width, image.height],
        target: board.clone(),
        points,
        centre_model: None,
        polarity: None,
    })
}

/// Drop the markers that their neighbours misplace, worst first, until
/// every one fits: each marker is checked against the homography of the
/// detected markers within [`NEIGHBOURHOOD_MARKERS`] marker pitches of it on
/// the board (local, so lens distortion does not count against it); a
/// marker with fewer than two such neighbours is checked against all the
/// others.
fn consistent_markers(layout: &MarkerLayout, mine: &mut Vec<(usize, &Marker)>) {
    let board_centre = |k: usize| centre(&layout.markers[k].corners);
    let pitch = layout
        .markers
        .first()
        .map_or(1.0, |m| (m.corners[1] - m.corners[0]).norm())
        * 1.5;
    loop {
        if mine.len() < 2 {
            return;
        }
        let mut worst: Option<(usize, f64)> = None;
        for (i, (k, m)) in mine.iter().enumerate() {
            let near: Vec<&(usize, &Marker)> = mine
                .iter()
                .filter(|(j, _)| {
                    *j != *k
                        && (board_centre(*j) - board_centre(*k)).norm()
                            <= NEIGHBOURHOOD_MARKERS * pitch
                })
                .collect();
            let others: Vec<&(usize, &Marker)> = if near.len() >= 2 {
                near
            } else {
                mine.iter().filter(|(j, _)| *j != *k).collect()
            };
            let pairs: Vec<_> = others
                .iter()
                .flat_map(|(j, o)| layout.markers[*j].corners.into_iter().zip(o.corners))
                .collect();
            let Some(h) = Homography::fit(&pairs) else {
                continue;
            };
            let err = layout.markers[*k]
                .corners
                .iter()
                .zip(&m.corners)
                .map(|(b, p)| h.map(b).map_or(f64::INFINITY, |q| (q - p).norm()))
                .fold(0.0, f64::max)
                / mean_side(&m.corners);
            if worst.map_or(true, |(_, e)| err > e) {
                worst = Some((i, err));
            }
        }
        match worst {
            Some((i, e)) if e > OUTLIER_FRACTION => {
                mine.remove(i);
            }
            _ => return,
        }
    }
}

/// The saddle fit of a seed with half-window `window`, or `None`.
fn refine(image: &GrayImage, seed: Point2<f64>, window: f64) -> Option<Point2<f64>> {
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
    ((fit.pos - seed).norm() <= 0.5 * window + 1.0 && inside(fit.pos)).then_some(fit.pos)
}

fn charuco_corners(
    image: &GrayImage,
    board: &Target,
    layout: &MarkerLayout,
    mine: &[(usize, &Marker)],
) -> Vec<DetectedPoint> {
    let Target::Charuco {
        squares_x,
        squares_y,
        square_m,
        marker_m,
        ..
    } = board
    else {
        return Vec::new();
    };
    // Marker index by its square.
    let square_of = |k: usize| {
        let c = centre(&layout.markers[k].corners);
        (
            (c.x / square_m).floor() as usize,
            (c.y / square_m).floor() as usize,
        )
    };
    let detected: HashMap<(usize, usize), (usize, &Marker)> =
        mine.iter().map(|&(k, m)| (square_of(k), (k, m))).collect();
    let margin_m = 0.5 * (square_m - marker_m);
    let mut out = Vec::new();
    for j in 0..squares_y - 1 {
        for i in 0..squares_x - 1 {
            let corner = Point2::new((i + 1) as f64 * square_m, (j + 1) as f64 * square_m);
            let around = [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)];
            let mut predictions = Vec::new();
            let mut all_pairs = Vec::new();
            let mut px_per_m = 0.0;
            let mut side_px = 0.0;
            for sq in around {
                let Some(&(k, m)) = detected.get(&sq) else {
                    continue;
                };
                let pairs: Vec<_> = layout.markers[k]
                    .corners
                    .into_iter()
                    .zip(m.corners)
                    .collect();
                if let Some(p) = Homography::fit(&pairs).and_then(|h| h.map(&corner)) {
                    predictions.push(p);
                    px_per_m += mean_side(&m.corners) / marker_m;
                    side_px += mean_side(&m.corners);
                    all_pairs.extend(pairs);
                }
            }
            if predictions.is_empty() {
                continue;
            }
            px_per_m /= predictions.len() as f64;
            side_px /= predictions.len() as f64;
            let margin_px = margin_m * px_per_m;
            let tol = (DISAGREE_FRACTION * margin_px)
                .max(MIN_DISAGREE_PX)
                .max(DISAGREE_SIDE_FRACTION * side_px);
            if predictions.len() == 2 && (predictions[0] - predictions[1]).norm() > tol {
                continue;
            }
            // Seeded from both markers' corners at once: the corner lies
            // between them, where their joint homography interpolates
            // (each marker's own extrapolates past its side).
            let Some(seed) = Homography::fit(&all_pairs).and_then(|h| h.map(&corner)) else {
                continue;
            };
            // The fit's weights reach 1.5 windows: stay within the white
            // margin plus the marker's black border.
            let border_px = marker_m / (layout.dictionary.marker_bits() + 2) as f64 * px_per_m;
            // A foreshortened view brings the marker closer to the corner
            // along the short axis than the mean side says: a window that
            // finds no saddle there is tried again smaller.
            let window = ((margin_px + border_px) / 2.0).clamp(MIN_WINDOW_PX, MAX_WINDOW_PX);
            let smaller = (RETRY_WINDOW_FRACTION * window).max(MIN_WINDOW_PX);
            let fit = refine(image, seed, window).or_else(|| {
                (smaller < window)
                    .then(|| refine(image, seed, smaller))
                    .flatten()
            });
            if let Some(p) = fit {
                out.push(DetectedPoint {
                    id: i + j * (squares_x - 1),
                    x_px: p.x,
                    y_px: p.y,
                    covariance_px2: None,
                });
            }
        }
    }
    out
}

/// Markers of `board`'s ids that one homography places consistently.
fn inliers(board: &Target, markers: &[Marker]) -> usize {
    let Some(layout) = marker_board::layout(board) else {
        return 0;
    };
    let mine = board_markers(&layout, markers);
    mine.len()
}

/// A ChArUco board with an even number of rows whose markers sit where the
/// other layout (pre-4.6 or 4.6+) puts them: the error that says so.
fn other_layout_fits_better(target: &Target, markers: &[Marker]) -> Option<Error> {
    let Target::Charuco {
        legacy, squares_y, ..
    } = target
    else {
        return None;
    };
    if squares_y % 2 != 0 {
        return None;
    }
    let mut other = target.clone();
    if let Target::Charuco { legacy: l, .. } = &mut other {
        *l = !*legacy;
    }
    if inliers(&other, markers) <= inliers(target, markers) {
        return None;
    }
    let hint = if *legacy {
        "the layout of OpenCV 4.6 and later: remove ':legacy' from the spec"
    } else {
        "the layout of boards made before OpenCV 4.6: add ':legacy' to the spec"
    };
    Some(Error::NotFound {
        message: format!("the markers do not fit this ChArUco board but fit {hint}"),
    })
}

/// Why no board came out: no marker of this board's ids.
fn no_board_error(target: &Target, markers: &[Marker]) -> Error {
    let mut ids: Vec<usize> = markers.iter().map(|m| m.id).collect();
    ids.sort_unstable();
    ids.dedup();
    let shown: Vec<String> = ids.iter().take(12).map(|i| i.to_string()).collect();
    let more = if ids.len() > 12 { ", ..." } else { "" };
    Error::NotFound {
        message: format!(
            "found {} markers (ids {}{more}) but no consistent {} board: check the board size, the first marker id and the marker layout",
            markers.len(),
            shown.join(", "),
            target.to_spec()
        ),
    }
}
