//! Circle grids, dot plates and single circles: blobs grown into a lattice,
//! ordered (right-handed, then id 0 nearest the image's top-left; asymmetric
//! grids with an odd number of rows are unambiguous), ellipse centres
//! refined at full resolution.

use super::blobs::{find_blobs, find_blobs_gray, refine_blob, Blob};
use super::centres::circle_centres;
use super::lattice::{self, PointIndex};
use super::DetectOptions;
use crate::error::{Error, Result};
use crate::image::filter::to_full;
use crate::image::GrayImage;
use crate::target::{DetectedPoint, Polarity, Target};
use nalgebra::{Matrix2, Point2, Vector2};

/// Seeds tried.
const MAX_SEEDS: usize = 60;
/// Blob working level: long side at most this many pixels.
const BLOB_WORKING_SIDE_PX: u32 = 2048;
/// Neighbouring grid blobs differ in area by at most this factor.
const AREA_RATIO: f64 = 3.0;
/// An origin-dot grid's big dot has at least this many times the area of
/// its two grid neighbours (4 on the print; measured on the sub-pixel
/// ellipses), and this many times the ratio of any other corner dot to its
/// neighbours (about 1).
const ORIGIN_DOT_MIN_AREA_RATIO: f64 = 2.0;

/// Working-level blobs and the level they were found at.
pub(crate) fn blobs_at_level(
    img: &GrayImage,
    invert: bool,
    options: &DetectOptions,
) -> (u32, Vec<Blob>) {
    let max_side = options.max_working_side_px.max(BLOB_WORKING_SIDE_PX);
    // At full resolution the 8-bit image itself is thresholded (no float
    // copy of it).
    if super::working_level(img, max_side) == 0 {
        return (0, find_blobs_gray(img, invert));
    }
    let levels = super::pyramid_levels(img, max_side);
    match levels.into_iter().next() {
        Some((level, plane)) => (level, find_blobs(&plane, invert)),
        None => (0, Vec::new()),
    }
}

/// The pyramid level [`blobs_at_level`] works at (without building it).
pub(crate) fn blob_working_level(img: &GrayImage, options: &DetectOptions) -> u32 {
    let max_side = options.max_working_side_px.max(BLOB_WORKING_SIDE_PX);
    super::working_level(img, max_side)
}

fn to_full_blob(b: &Blob, level: u32) -> (Point2<f64>, Matrix2<f64>) {
    let s = (1u64 << level) as f64;
    (
        Point2::new(to_full(b.centre.x, level), to_full(b.centre.y, level)),
        b.cov * (s * s),
    )
}

/// Detect a circle grid or dot plate. `diameter_ratio` (dot plates): dot
/// diameter over pitch, used to reject blobs of the wrong size.
pub(crate) fn detect_grid(
    img: &GrayImage,
    target: &Target,
    polarity: Polarity,
    asymmetric: bool,
    diameter_ratio: Option<f64>,
    options: &DetectOptions,
) -> Result<Vec<DetectedPoint>> {
    let invert = polarity == Polarity::LightOnDark;
    let (level, blobs) = blobs_at_level(img, invert, options);
    let found = find_grid(&blobs, target, asymmetric, diameter_ratio, AREA_RATIO)?;
    measure_grid(
        img, target, asymmetric, invert, level, &blobs, &found, options,
    )
}

/// Detect ROS-Industrial's modified circle grid ([`crate::target::origin_dot`]):
/// dark dots grown into a lattice that accepts the origin dot (four times
/// the others' area), ordered as every grid (right-handed), then turned so
/// that the largest corner dot is point `(rows - 1) cols`: any turn of the
/// print, 180 degrees included (and 90 on a square grid), reads the same.
/// Corner sizes are compared with their neighbours' by their sub-pixel
/// ellipses.
pub(crate) fn detect_origin_dot_grid(
    img: &GrayImage,
    target: &Target,
    options: &DetectOptions,
) -> Result<Vec<DetectedPoint>> {
    let Target::OriginDotGrid { cols, rows, .. } = target else {
        return Err(Error::invalid(
            "target",
            format!("{} is not an origin-dot grid", target.to_spec()),
        ));
    };
    let (cols, rows) = (*cols, *rows);
    let (level, blobs) = blobs_at_level(img, false, options);
    let s = crate::target::origin_dot::ORIGIN_DOT_SCALE;
    let found = find_grid(
        &blobs,
        target,
        false,
        Some(crate::target::origin_dot::DOT_DIAMETER_RATIO),
        AREA_RATIO * s * s,
    )?;
    // Corners (0, 0), (cols - 1, 0), (0, rows - 1) (the origin's place),
    // (cols - 1, rows - 1) of the found order, each with its neighbours in
    // its row and its column: a corner's size relative to theirs, as
    // ROS-Industrial's finder compares them (the dots' own sizes differ by
    // more than 1.6x between the near and far corners of a tilted board).
    let n = found.len();
    let corners = [
        (0, [1, cols]),
        (cols - 1, [cols - 2, 2 * cols - 1]),
        (n - cols, [n - cols + 1, n - 2 * cols]),
        (n - 1, [n - 2, n - 1 - cols]),
    ];
    let area = |id: usize| {
        let (centre, cov) = to_full_blob(&blobs[found[id]], level);
        refine_blob(img, centre, &cov, false).map_or(0.0, |o| {
            std::f64::consts::PI * o.ellipse.semi_axes.0 * o.ellipse.semi_axes.1
        })
    };
    let relative: Vec<f64> = corners
        .iter()
        .map(|&(c, [a, b])| {
            let around = 0.5 * (area(a) + area(b));
            if around > 0.0 {
                area(c) / around
            } else {
                0.0
            }
        })
        .collect();
    let big = (0..4)
        .max_by(|&a, &b| relative[a].total_cmp(&relative[b]))
        .unwrap_or(2);
    let clear = (0..4)
        .filter(|&k| k != big)
        .all(|k| relative[big] >= ORIGIN_DOT_MIN_AREA_RATIO * relative[k].max(1.0));
    if !clear {
        return Err(Error::NotFound {
            message: format!(
                "found the {} but no corner dot is twice the size of its neighbours: is the origin dot printed and in view?",
                describe(target)
            ),
        });
    }
    let order = turn_to_origin(&found, cols, rows, big).ok_or_else(|| Error::NotFound {
        message: format!(
            "the origin dot of the {} is at the end of a column, not of a row: are the columns and rows swapped (ROS-Industrial's origin dot starts the last row)?",
            describe(target)
        ),
    })?;
    measure_grid(img, target, false, false, level, &blobs, &order, options)
}

/// `order` (right-handed, `cols x rows`) turned in the board's plane so that
/// its corner `big` (0: first of row 0, 1: last of row 0, 2: first of the
/// last row, 3: last of the last row) becomes the first of the last row.
/// A quarter turn swaps columns and rows: only a square grid has one
/// (`None` otherwise).
fn turn_to_origin(order: &[usize], cols: usize, rows: usize, big: usize) -> Option<Vec<usize>> {
    let n = order.len();
    let m = cols;
    match big {
        2 => Some(order.to_vec()),
        // Half a turn: (i, j) -> (cols - 1 - i, rows - 1 - j).
        1 => Some((0..n).map(|id| order[n - 1 - id]).collect()),
        // A quarter turn either way: new (i, j) is old (m - 1 - j, i) or
        // old (j, m - 1 - i); both keep the order right-handed.
        0 if cols == rows => Some(
            (0..n)
                .map(|id| order[(m - 1 - id / m) + (id % m) * m])
                .collect(),
        ),
        3 if cols == rows => Some(
            (0..n)
                .map(|id| order[id / m + (m - 1 - id % m) * m])
                .collect(),
        ),
        _ => None,
    }
}

/// The blob indices of the one complete grid in board order (see
/// [`detect_grid`]); `max_area_ratio`: the largest area over the seed's a
/// grid blob may have ([`AREA_RATIO`], more for the origin-dot grid).
fn find_grid(
    blobs: &[Blob],
    target: &Target,
    asymmetric: bool,
    diameter_ratio: Option<f64>,
    max_area_ratio: f64,
) -> Result<Vec<usize>> {
    let board = target.grid_coords();
    let n = board.len();
    let cols = board.iter().filter(|c| c.1 == 0).count();
    let seed_fits = |seed: &Blob, step_a: Vector2<f64>, step_b: Vector2<f64>| match diameter_ratio {
        // Equivalent diameter over the grid step within a factor 2.
        Some(rho) => {
            let d = (4.0 * seed.area / std::f64::consts::PI).sqrt();
            (0.5..=2.0).contains(&(d / step_a.norm().max(step_b.norm()) / rho))
        }
        None => true,
    };
    let search = GridSearch {
        board: &board,
        cols,
        rows: n / cols.max(1),
        diagonal: asymmetric,
        trim: false,
        seed_fits: &seed_fits,
    };
    let two_boards = || {
        format!(
            "two candidate boards: two complete {} in the image",
            describe(target)
        )
    };
    // An origin-dot grid's big dot has four times the others' area: the
    // lattice takes blobs up to that much larger than the seed (a seed is an
    // ordinary dot: the big one has no neighbour of its size to seed from).
    let order = match search_grid_with(blobs, &search, &two_boards, max_area_ratio)? {
        Ok(order) => order,
        Err(best_partial) => {
            let message = if best_partial > 1 {
                format!(
                    "found {best_partial} of {n} circles of the {}: the grid may be cut off, occluded or the counts wrong",
                    describe(target)
                )
            } else {
                format!("board not found: no {} in the image", describe(target))
            };
            return Err(Error::NotFound { message });
        }
    };
    Ok(order)
}

/// Centres of the grid's circles in board order: each blob's outline at
/// full resolution, then the centre model.
#[allow(clippy::too_many_arguments)]
fn measure_grid(
    img: &GrayImage,
    target: &Target,
    asymmetric: bool,
    invert: bool,
    level: u32,
    blobs: &[Blob],
    order: &[usize],
    options: &DetectOptions,
) -> Result<Vec<DetectedPoint>> {
    let board = target.grid_coords();
    let outlines = order
        .iter()
        .enumerate()
        .map(|(id, &i)| {
            let (c, cov) = to_full_blob(&blobs[i], level);
            refine_blob(img, c, &cov, invert).ok_or_else(|| Error::NotFound {
                message: format!(
                    "circle {id} at ({:.1}, {:.1}) px has no clean edge",
                    c.x, c.y
                ),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let centres = circle_centres(
        &board,
        asymmetric,
        &outlines,
        options.circle_centres,
        (img.width, img.height),
    );
    Ok(outlines
        .iter()
        .zip(centres)
        .enumerate()
        .map(|(id, (o, c))| point(id, c, &o.ellipse))
        .collect())
}

fn describe(target: &Target) -> String {
    match target {
        Target::CircleGrid {
            cols,
            rows,
            asymmetric,
            ..
        } => format!(
            "{cols}x{rows} {} circle grid",
            if *asymmetric {
                "asymmetric"
            } else {
                "symmetric"
            }
        ),
        Target::DotPlate { cols, rows, .. } => format!("{cols}x{rows} dot plate"),
        Target::OriginDotGrid { cols, rows, .. } => format!("{cols}x{rows} origin-dot grid"),
        Target::Chessboard { cols, rows, .. } => format!("{cols}x{rows} chessboard"),
        Target::SingleCircle { .. } => "circle".to_string(),
        Target::SquareGrid { cols, rows, .. } => format!("{cols}x{rows} square grid"),
        Target::Charuco {
            squares_x,
            squares_y,
            ..
        } => format!("{squares_x}x{squares_y} ChArUco board"),
        Target::Aprilgrid {
            tag_cols, tag_rows, ..
        } => format!("{tag_cols}x{tag_rows} AprilGrid"),
        Target::ArucoGrid {
            markers_x,
            markers_y,
            ..
        } => format!("{markers_x}x{markers_y} ArUco grid"),
    }
}

/// A point at `centre` with the covariance of the ellipse fit's centre (the
/// perspective correction moves the centre by a smooth function of the same
/// edge points, which leaves the covariance to first order).
fn point(id: usize, centre: Point2<f64>, fit: &super::ellipse::EllipseFit) -> DetectedPoint {
    DetectedPoint {
        id,
        x_px: centre.x,
        y_px: centre.y,
        covariance_px2: Some([
            fit.covariance[(0, 0)],
            fit.covariance[(0, 1)],
            fit.covariance[(1, 1)],
        ]),
    }
}

/// Whether a seed blob's size fits the grid steps found around it.
pub(crate) type SeedFits<'a> = dyn Fn(&Blob, Vector2<f64>, Vector2<f64>) -> bool + 'a;

/// What the blob-lattice search of [`search_grid`] needs to know of a grid
/// kind (circle grids and dot plates, square grids).
pub(crate) struct GridSearch<'a> {
    /// Board cells `(i, j)` in board order.
    pub board: &'a [(i32, i32)],
    /// Board width in cells (the row length of `board`).
    pub cols: usize,
    /// Board height in cells.
    pub rows: usize,
    /// Cells also meet diagonally (asymmetric circle grids).
    pub diagonal: bool,
    /// Keep only the one full board-sized window of a grown lattice
    /// (clutter of the same kind beside the board may join it).
    pub trim: bool,
    /// Whether a seed blob's size fits the grid steps found around it.
    pub seed_fits: &'a SeedFits<'a>,
}

/// Grows a lattice from each of the first seeds among `blobs` (neighbours
/// of similar area) and returns the blob indices of the one complete board
/// in board order, or `Err(n)` with the largest partial lattice (`n` board
/// cells) when none is complete. Two complete boards are an error with the
/// message of `two_boards`.
pub(crate) fn search_grid(
    blobs: &[Blob],
    search: &GridSearch,
    two_boards: &dyn Fn() -> String,
) -> Result<std::result::Result<Vec<usize>, usize>> {
    search_grid_with(blobs, search, two_boards, AREA_RATIO)
}

/// [`search_grid`] with the largest accepted area over the seed's
/// (`max_area_ratio`, [`AREA_RATIO`] there).
fn search_grid_with(
    blobs: &[Blob],
    search: &GridSearch,
    two_boards: &dyn Fn() -> String,
    max_area_ratio: f64,
) -> Result<std::result::Result<Vec<usize>, usize>> {
    let n = search.board.len();
    let pts: Vec<Point2<f64>> = blobs.iter().map(|b| b.centre).collect();
    let index = PointIndex::new(&pts, 16.0);
    let mut in_board = vec![false; pts.len()];
    let mut found: Vec<Vec<usize>> = Vec::new();
    let mut best_partial = 0usize;
    for seed in 0..pts.len().min(MAX_SEEDS) {
        if in_board[seed] {
            continue;
        }
        let Some((step_a, step_b)) = seed_steps(blobs, seed) else {
            continue;
        };
        if !(search.seed_fits)(&blobs[seed], step_a, step_b) {
            continue;
        }
        // A blob's area is compared with the seed's scaled by the local
        // lattice cell's area over the seed's: perspective shrinks a circle
        // and its cell alike, so a grid tilted 60 degrees, whose near
        // circles have 20 times the area of its far ones, keeps one rule.
        let seed_cell = cell_area(step_a, step_b);
        let accept = |i: usize, _: (i32, i32), pred: &lattice::Prediction| {
            let expected = blobs[seed].area * cell_area(pred.step_a, pred.step_b) / seed_cell;
            let r = blobs[i].area / expected;
            (1.0 / AREA_RATIO..=max_area_ratio).contains(&r)
        };
        let mut cells = lattice::grow(&index, seed, step_a, step_b, 2 * n + 8, &accept);
        if search.trim {
            if let Some(window) = lattice::trim_to_window(&cells, search.cols, search.rows) {
                cells = window;
            }
        }
        let maps = lattice::complete_maps(&cells, search.board, search.diagonal);
        match lattice::choose_order(&pts, &cells, &maps, search.board, search.cols, &|_| false) {
            Some(order) => {
                cells.values().for_each(|&i| in_board[i] = true);
                found.push(order);
                if found.len() > 1 {
                    return Err(Error::NotFound {
                        message: two_boards(),
                    });
                }
            }
            None => best_partial = best_partial.max(cells.len().min(n)),
        }
    }
    Ok(found.pop().ok_or(best_partial))
}

/// The area of the lattice cell spanned by two steps, px^2.
fn cell_area(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    (a.x * b.y - a.y * b.x).abs()
}

/// The seed's two lattice steps: its nearest similar blob, and the nearest
/// one not collinear with it.
fn seed_steps(blobs: &[Blob], seed: usize) -> Option<(Vector2<f64>, Vector2<f64>)> {
    let s = &blobs[seed];
    let similar = |b: &Blob| (1.0 / AREA_RATIO..=AREA_RATIO).contains(&(b.area / s.area));
    let mut near: Vec<(f64, Vector2<f64>)> = blobs
        .iter()
        .enumerate()
        .filter(|(i, b)| *i != seed && similar(b))
        .map(|(_, b)| {
            let v = b.centre - s.centre;
            (v.norm(), v)
        })
        .collect();
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (d1, v1) = *near.first()?;
    let (_, v2) = *near
        .iter()
        .skip(1)
        .find(|(d, v)| *d < 2.5 * d1 && (v.dot(&v1) / (d * d1)).abs() < 0.8)?;
    Some((v1, v2))
}

/// Whether blob `b` (found at pyramid `level`) is darker at its centre
/// than around it, 1.5 equivalent radii out: true of a dark disc, false of
/// a dark ring around a light one.
fn is_filled(img: &GrayImage, b: &Blob, level: u32) -> bool {
    let (c, _) = to_full_blob(b, level);
    let s = (1u64 << level) as f64;
    let radius = 1.5 * s * (b.area / std::f64::consts::PI).sqrt();
    let grey = |x: f64, y: f64| {
        let (x, y) = (x.round(), y.round());
        (x >= 0.0 && y >= 0.0 && x < img.width as f64 && y < img.height as f64)
            .then(|| img.get(x as u32, y as u32).map(f64::from))
            .flatten()
    };
    let Some(centre) = grey(c.x, c.y) else {
        return false;
    };
    let around: Vec<f64> = (0..16)
        .filter_map(|k| {
            let a = k as f64 * std::f64::consts::PI / 8.0;
            grey(c.x + radius * a.cos(), c.y + radius * a.sin())
        })
        .collect();
    around.is_empty() || centre < around.iter().sum::<f64>() / around.len() as f64
}

/// Detect one circle: the largest elliptical dark blob, with the covariance
/// of its fitted centre. Two blobs of similar size are reported, not guessed.
pub(crate) fn detect_single(img: &GrayImage, options: &DetectOptions) -> Result<DetectedPoint> {
    let (level, mut blobs) = blobs_at_level(img, false, options);
    // A dark ring (a light circle's dark surround, the other print) is a
    // blob too; a filled circle is dark at its centre.
    blobs.retain(|b| is_filled(img, b, level));
    let Some(first) = blobs.first() else {
        return Err(Error::NotFound {
            message: "board not found: no dark circle in the image".to_string(),
        });
    };
    if let Some(second) = blobs.get(1) {
        if second.area > 0.5 * first.area {
            let s = (1u64 << level) as f64;
            return Err(Error::NotFound {
                message: format!(
                    "two candidate circles: blobs of {:.0} and {:.0} px^2 near ({:.0}, {:.0}) and ({:.0}, {:.0}) px",
                    first.area * s * s,
                    second.area * s * s,
                    to_full(first.centre.x, level),
                    to_full(first.centre.y, level),
                    to_full(second.centre.x, level),
                    to_full(second.centre.y, level)
                ),
            });
        }
    }
    let (c, cov) = to_full_blob(first, level);
    let fit = refine_blob(img, c, &cov, false).ok_or_else(|| Error::NotFound {
        message: format!(
            "the circle at ({:.1}, {:.1}) px has no clean edge",
            c.x, c.y
        ),
    })?;
    Ok(point(0, fit.ellipse.centre, &fit.ellipse))
}
