//! Circle grids, dot plates and single circles: blobs grown into a lattice,
//! ordered (right-handed, then id 0 nearest the image's top-left; asymmetric
//! grids with an odd number of rows are unambiguous), ellipse centres
//! refined at full resolution.

use super::blobs::{find_blobs, refine_blob, Blob};
use super::centres::circle_centres;
use super::filter::to_full;
use super::lattice::{self, PointIndex};
use super::DetectOptions;
use crate::error::{Error, Result};
use crate::image::GrayImage;
use crate::target::{DetectedPoint, Polarity, Target};
use nalgebra::{Matrix2, Point2, Vector2};

/// Seeds tried.
const MAX_SEEDS: usize = 60;
/// Blob working level: long side at most this many pixels.
const BLOB_WORKING_SIDE_PX: u32 = 2048;
/// Neighbouring grid blobs differ in area by at most this factor.
const AREA_RATIO: f64 = 3.0;

/// Working-level blobs and the level they were found at.
pub(crate) fn blobs_at_level(
    img: &GrayImage,
    invert: bool,
    options: &DetectOptions,
) -> (u32, Vec<Blob>) {
    let max_side = options.max_working_side_px.max(BLOB_WORKING_SIDE_PX);
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
    let order = match search_grid(&blobs, &search, &two_boards)? {
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
    pub seed_fits: &'a dyn Fn(&Blob, Vector2<f64>, Vector2<f64>) -> bool,
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
        let accept = |i: usize, _: (i32, i32), _: &lattice::Prediction| {
            let r = blobs[i].area / blobs[seed].area;
            (1.0 / AREA_RATIO..=AREA_RATIO).contains(&r)
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
