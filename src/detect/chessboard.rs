//! Chessboard detection: saddle candidates on a pyramid level, grid growth
//! from seeds, the ordering rule, then saddle refinement at full resolution.
//!
//! # Order of the corners
//!
//! Corner ids run row by row (`id = i + j * cols`, `i` along the side with
//! `cols` corners). Of the orderings that fit the board:
//! 1. the board's x -> y turns clockwise in the image (board z points away
//!    from the camera: a right-handed board frame seen from the front);
//! 2. the outer square diagonally beyond corner 0 is dark (the print's
//!    top-left square in the usual drawing). When `cols + rows` is odd this
//!    decides the order uniquely in every view; when it is even the board is
//!    symmetric under a 180-degree turn and both ends qualify;
//! 3. remaining ties (symmetric boards, and square boards with `cols ==
//!    rows`): corner 0 is the candidate nearest the image's top-left pixel.
//!    Such orders can flip between views that turn the board by more than
//!    90 degrees: use a board with `cols + rows` odd (e.g. 9x6) for
//!    multi-view work.

use super::lattice::{self, Cells, PointIndex};
use super::refine::refine_saddle;
use super::saddle::{self, Candidate};
use super::DetectOptions;
use crate::error::{Error, Result};
use crate::image::filter::{box_level, max_f32, min_f32, min_f64, to_full, Plane};
use crate::image::GrayImage;
use crate::target::DetectedPoint;
use nalgebra::{Point2, Vector2};

/// Pyramid levels searched after the coarsest one, each twice as fine.
const FINER_LEVELS: u32 = 2;
/// Seeds tried per pyramid level.
const MAX_SEEDS: usize = 40;
/// A seed's first neighbours respond at least this fraction of the seed.
const NEIGHBOUR_RESPONSE_FRACTION: f32 = 0.15;
/// Angle between a seed's edge direction and a neighbour, radians.
const SEED_ANGLE_TOLERANCE: f64 = 0.35;

/// The outcome of one level: a complete board or the best partial grid.
enum LevelResult {
    Complete(Vec<Point2<f64>>, f64),
    Partial { found: usize, message: String },
}

/// Detect a `cols x rows` chessboard; corners in board order, full-resolution
/// pixels, refined.
pub(crate) fn detect_chessboard(
    img: &GrayImage,
    cols: usize,
    rows: usize,
    options: &DetectOptions,
) -> Result<Vec<DetectedPoint>> {
    let board: Vec<(i32, i32)> = (0..rows as i32)
        .flat_map(|j| (0..cols as i32).map(move |i| (i, j)))
        .collect();
    let mut best_partial: Option<(usize, String)> = None;
    // Coarsest level first: most boards are found there at a quarter of
    // the next level's cost; the finer levels catch small boards and give
    // closer starts when a coarse level's corners cannot be refined.
    let coarse = super::working_level(img, options.max_working_side_px);
    for level in (coarse.saturating_sub(FINER_LEVELS)..=coarse).rev() {
        let plane = box_level(img, level);
        match detect_at_level(&plane, level, cols, rows, &board)? {
            LevelResult::Complete(coarse, step) => {
                match refine_all(img, &coarse, level, step, cols) {
                    Ok(points) => return Ok(points),
                    // A finer level starts the refinement closer to the corners.
                    Err(Error::NotFound { message }) => best_partial = Some((cols * rows, message)),
                    Err(e) => return Err(e),
                }
            }
            LevelResult::Partial { found, message } => {
                if best_partial.as_ref().map_or(true, |b| found > b.0) {
                    best_partial = Some((found, message));
                }
            }
        }
    }
    let message = best_partial
        .map(|p| p.1)
        .unwrap_or_else(|| format!("board not found: no {cols}x{rows} chessboard corners"));
    Err(Error::NotFound { message })
}

fn detect_at_level(
    plane: &Plane,
    level: u32,
    cols: usize,
    rows: usize,
    board: &[(i32, i32)],
) -> Result<LevelResult> {
    let n = cols * rows;
    let cands = saddle::candidates(plane, 6 * n + 300);
    let pts: Vec<Point2<f64>> = cands.iter().map(|c| c.pos).collect();
    let index = PointIndex::new(&pts, 16.0);
    let mut in_board = vec![false; pts.len()];
    let mut complete: Vec<(Vec<Point2<f64>>, f64)> = Vec::new();
    let mut best: Option<Cells> = None;
    for seed in 0..cands.len().min(MAX_SEEDS) {
        if in_board[seed] {
            continue;
        }
        let Some(cells) = grow_from(plane, &cands, &index, seed, 4 * n + 16) else {
            continue;
        };
        let maps = lattice::complete_maps(&cells, board, false);
        if !maps.is_empty() {
            let prefer = |order: &[usize]| origin_is_dark(&cands, order, cols);
            if let Some(order) = lattice::choose_order(&pts, &cells, &maps, board, cols, &prefer) {
                cells.values().for_each(|&i| in_board[i] = true);
                let step = mean_step(&pts, &order, cols);
                complete.push((order.iter().map(|&i| pts[i]).collect(), step));
                if complete.len() > 1 {
                    return Err(Error::NotFound {
                        message: format!(
                            "two candidate boards: two complete {cols}x{rows} chessboards in the image"
                        ),
                    });
                }
                continue;
            }
        }
        if best.as_ref().map_or(true, |b| cells.len() > b.len()) {
            best = Some(cells);
        }
    }
    if let Some((coarse, step)) = complete.pop() {
        return Ok(LevelResult::Complete(coarse, step * (1u64 << level) as f64));
    }
    let Some(cells) = best else {
        return Ok(LevelResult::Partial {
            found: 0,
            message: format!("board not found: no {cols}x{rows} chessboard corners"),
        });
    };
    Ok(LevelResult::Partial {
        found: cells.len(),
        message: partial_message(plane, &pts, &cells, cols, rows),
    })
}

/// Grow a grid from candidate `seed`; `None` when the seed has no grid
/// neighbours along both of its edge directions.
fn grow_from(
    plane: &Plane,
    cands: &[Candidate],
    index: &PointIndex,
    seed: usize,
    max_cells: usize,
) -> Option<Cells> {
    let s = &cands[seed];
    let dirs = saddle::edge_directions(&s.hessian)?;
    let mut steps = [None, None];
    for (k, d) in dirs.iter().enumerate() {
        let mut best: Option<(f64, Vector2<f64>)> = None;
        for sign in [1.0, -1.0] {
            let dir = d * sign;
            for (i, c) in cands.iter().enumerate() {
                let v = c.pos - s.pos;
                let dist = v.norm();
                // Weak saddles along an edge (JPEG blocks, noise) are not
                // grid neighbours: they respond far less than the seed.
                if i == seed
                    || dist < 4.0
                    || c.response < NEIGHBOUR_RESPONSE_FRACTION * s.response
                    || v.dot(&dir) / dist < SEED_ANGLE_TOLERANCE.cos()
                {
                    continue;
                }
                if best.map_or(true, |b| dist < b.0) {
                    best = Some((dist, v * sign));
                }
            }
        }
        steps[k] = best.map(|b| b.1);
    }
    let (step_a, step_b) = (steps[0]?, steps[1]?);
    let ratio = step_a.norm() / step_b.norm();
    if !(0.25..=4.0).contains(&ratio) {
        return None;
    }
    let unit = ring_unit();
    let ring = |p: Point2<f64>, a: &Vector2<f64>, b: &Vector2<f64>| {
        is_x_junction(plane, p, RING_FRACTION * a.norm().min(b.norm()), &unit)
    };
    if !ring(s.pos, &step_a, &step_b) {
        return None;
    }
    let seed_pol = polarity(&s.hessian, &step_a, &step_b);
    let accept = |i: usize, cell: (i32, i32), pred: &lattice::Prediction| {
        let expected = if (cell.0 + cell.1) % 2 == 0 {
            seed_pol
        } else {
            -seed_pol
        };
        polarity(&cands[i].hessian, &pred.step_a, &pred.step_b) == expected
            && ring(cands[i].pos, &pred.step_a, &pred.step_b)
    };
    let cells = lattice::grow(index, seed, step_a, step_b, max_cells, &accept);
    (cells.len() >= 4).then_some(cells)
}

/// Refinement window (half-side) as a fraction 1 / this of the local grid
/// step, capped at [`MAX_WINDOW_PX`]. Measured on the bench sets
/// (benches/compare_opencv.py): step / 6 capped at 6 px gives 0.015 px mean
/// error at noise sigma 2 where step / 3 capped at 12 px gave 0.025 px:
/// larger windows take in more of the pattern the quadratic model does not
/// describe and more clutter (the board's frame, thin outer squares).
const WINDOW_FRACTION_INV: f64 = 6.0;
/// Largest refinement window half-side, pixels.
const MAX_WINDOW_PX: f64 = 6.0;

/// Ring radius for the X-junction test, as a fraction of the grid step.
const RING_FRACTION: f64 = 0.35;
/// Samples on the ring.
const RING_SAMPLES: usize = 24;

/// An inner chessboard corner shows four alternating sectors on a ring
/// around it; the board's outer corners (L- and T-shaped, which also give a
/// saddle response) show two, or four that are not point-symmetric. Samples within 20% of the ring's range from
/// its mid level are ignored so that noise does not add transitions.
fn is_x_junction(
    plane: &Plane,
    p: Point2<f64>,
    radius: f64,
    unit: &[(f64, f64); RING_SAMPLES],
) -> bool {
    // Near the image border the ring shrinks to stay inside it: clamped
    // samples beyond the border repeat its last row or column and break
    // the point symmetry of a corner a few pixels from the edge.
    let inside = min_f64(
        min_f64(p.x, p.y),
        min_f64(plane.w as f64 - 1.0 - p.x, plane.h as f64 - 1.0 - p.y),
    );
    let r = radius.min(inside - 1.0).max(2.0);
    let vals: [f32; RING_SAMPLES] =
        std::array::from_fn(|k| plane.bilinear(p.x + r * unit[k].0, p.y + r * unit[k].1));
    let (lo, hi) = vals.iter().fold((f32::MAX, f32::MIN), |(l, h), &v| {
        (min_f32(l, v), max_f32(h, v))
    });
    let mid = 0.5 * (lo + hi);
    let band = 0.2 * (hi - lo);
    let mut classes = [false; RING_SAMPLES];
    let mut count = 0;
    for v in vals.iter().filter(|v| (**v - mid).abs() > band) {
        classes[count] = *v > mid;
        count += 1;
    }
    let classes = &classes[..count];
    if classes.len() < RING_SAMPLES / 2 {
        return false;
    }
    let changes = (0..classes.len())
        .filter(|&k| classes[k] != classes[(k + 1) % classes.len()])
        .count();
    if changes != 4 {
        return false;
    }
    // Point symmetry: opposite samples of an X-junction agree; a T-junction
    // next to a dark frame (four sectors, but not opposite) does not.
    let half = RING_SAMPLES / 2;
    let (mut pairs, mut agree) = (0, 0);
    for k in 0..half {
        let (a, b) = (vals[k] - mid, vals[k + half] - mid);
        if a.abs() > band && b.abs() > band {
            pairs += 1;
            agree += ((a > 0.0) == (b > 0.0)) as usize;
        }
    }
    pairs >= half / 2 && agree * 10 >= pairs * 9
}

/// Unit vectors at the ring's sample angles.
fn ring_unit() -> [(f64, f64); RING_SAMPLES] {
    std::array::from_fn(|k| {
        let t = k as f64 / RING_SAMPLES as f64 * std::f64::consts::TAU;
        (t.cos(), t.sin())
    })
}

/// Sign of the mixed second derivative along the local grid axes.
fn polarity(h: &nalgebra::Matrix2<f64>, a: &Vector2<f64>, b: &Vector2<f64>) -> i8 {
    if (a.transpose() * h * b)[(0, 0)] >= 0.0 {
        1
    } else {
        -1
    }
}

/// Rule 2 of the module docs: the square beyond corner 0 is dark iff the
/// mixed derivative along the board's x and y is negative there.
fn origin_is_dark(cands: &[Candidate], order: &[usize], cols: usize) -> bool {
    let p0 = cands[order[0]].pos;
    let ex = cands[order[1]].pos - p0;
    let ey = cands[order[cols]].pos - p0;
    polarity(&cands[order[0]].hessian, &ex, &ey) < 0
}

fn mean_step(pts: &[Point2<f64>], order: &[usize], cols: usize) -> f64 {
    let mut sum = 0.0;
    let mut n = 0.0;
    for (k, &i) in order.iter().enumerate() {
        if (k + 1) % cols != 0 {
            sum += (pts[order[k + 1]] - pts[i]).norm();
            n += 1.0;
        }
    }
    if n > 0.0 {
        sum / n
    } else {
        1.0
    }
}

/// "found 48 of 54 corners: the board may be cut off at the right edge".
fn partial_message(
    plane: &Plane,
    pts: &[Point2<f64>],
    cells: &Cells,
    cols: usize,
    rows: usize,
) -> String {
    let n = cols * rows;
    let found = cells.len();
    let (amin, amax) = range(cells.keys().map(|c| c.0));
    let (bmin, bmax) = range(cells.keys().map(|c| c.1));
    let (span_a, span_b) = ((amax - amin + 1) as usize, (bmax - bmin + 1) as usize);
    let fits = |x: usize, y: usize| (x <= cols && y <= rows) || (x <= rows && y <= cols);
    if !fits(span_a, span_b) {
        return format!(
            "found a {span_a}x{span_b} chessboard grid, larger than the {cols}x{rows} target: check the inner-corner counts"
        );
    }
    let mut sides: Vec<&str> = Vec::new();
    let beyond = [
        (amax + 1, true),
        (amin - 1, true),
        (bmax + 1, false),
        (bmin - 1, false),
    ];
    for (k, along_a) in beyond {
        let (lo, hi) = if along_a { (bmin, bmax) } else { (amin, amax) };
        for m in lo..=hi {
            let cell = if along_a { (k, m) } else { (m, k) };
            let Some(p) = lattice::predict(pts, cells, cell, Vector2::zeros(), Vector2::zeros())
            else {
                continue;
            };
            let side = if p.pos.x < 0.0 {
                "left"
            } else if p.pos.x > plane.w as f64 - 1.0 {
                "right"
            } else if p.pos.y < 0.0 {
                "top"
            } else if p.pos.y > plane.h as f64 - 1.0 {
                "bottom"
            } else {
                continue;
            };
            if !sides.contains(&side) {
                sides.push(side);
            }
        }
    }
    // A whole grid one corner short each way: the spec counted squares.
    let (c, r) = (cols.saturating_sub(1), rows.saturating_sub(1));
    let whole = found == span_a * span_b;
    if sides.is_empty() && whole && ((span_a, span_b) == (c, r) || (span_a, span_b) == (r, c)) {
        return format!(
            "found {c}x{r} inner corners, not the {cols}x{rows} of the target: the spec counts \
             inner corners (a board of {cols}x{rows} squares has {c}x{r}): use chessboard:{c}x{r}:SIZE"
        );
    }
    if sides.is_empty() {
        format!("found {found} of {n} corners: the board may be partly occluded, blurred or unevenly lit")
    } else {
        let edges = if sides.len() == 1 { "edge" } else { "edges" };
        format!(
            "found {found} of {n} corners: the board may be cut off at the {} {edges}",
            sides.join(" and ")
        )
    }
}

fn range(it: impl Iterator<Item = i32>) -> (i32, i32) {
    it.fold((i32::MAX, i32::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

/// Refine every corner at full resolution; the window is a sixth of the
/// local grid step (at most 6 px, at least 2.5 px), one fit per corner.
fn refine_all(
    img: &GrayImage,
    coarse: &[Point2<f64>],
    level: u32,
    step_full: f64,
    cols: usize,
) -> Result<Vec<DetectedPoint>> {
    let full: Vec<Point2<f64>> = coarse
        .iter()
        .map(|p| Point2::new(to_full(p.x, level), to_full(p.y, level)))
        .collect();
    let rows = full.len() / cols.max(1);
    let mut out = Vec::with_capacity(full.len());
    for (id, p) in full.iter().enumerate() {
        let (i, j) = (id % cols, id / cols);
        let mut local = step_full;
        for (di, dj) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
            let (ni, nj) = (i as i64 + di, j as i64 + dj);
            if ni >= 0 && nj >= 0 && (ni as usize) < cols && (nj as usize) < rows {
                local = local.min((full[nj as usize * cols + ni as usize] - p).norm());
            }
        }
        let window = (local / WINDOW_FRACTION_INV).clamp(2.5, MAX_WINDOW_PX);
        // A start from a coarse level can be a few pixels off, beyond the
        // small window's reach: pull it in with a window twice as wide
        // first (rarely needed; the final fit is the small window's).
        let fit = refine_saddle(img, *p, window).or_else(|| {
            let wide = (local / (0.5 * WINDOW_FRACTION_INV)).clamp(2.5, 2.0 * MAX_WINDOW_PX);
            refine_saddle(img, *p, wide).and_then(|f| refine_saddle(img, f.pos, window))
        });
        let Some(fit) = fit else {
            return Err(Error::NotFound {
                message: format!(
                    "corner {id} at ({:.1}, {:.1}) px could not be refined: blurred or occluded?",
                    p.x, p.y
                ),
            });
        };
        out.push(DetectedPoint {
            id,
            x_px: fit.pos.x,
            y_px: fit.pos.y,
            covariance_px2: None,
        });
    }
    Ok(out)
}
