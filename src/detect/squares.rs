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
//! lattice steps. Each side is then measured by profiles across it, every
//! half pixel along the side (away from the corners, where the other side's
//! edge would enter the profile): an edge point is the centroid of the
//! profile's derivative (the image gradient along the normal) in a window
//! moved onto it, so the threshold plays no part. A curve is fitted to each
//! side's edge points, a corner is where the curves of its two sides meet,
//! and the profiles are measured again across the refined sides (four
//! passes, the first with a wide search).
//!
//! The curve is a straight line over the whole side, chosen by numbers
//! (test `side_models_compared_on_distorted_renders`: four 1280x960 views
//! through Zhang's lens, k1 = -0.23, one filling the frame, two tilted
//! by 30-35 degrees; mean / max corner error):
//!
//! | side model | noise-free | noise sigma 2 |
//! |---|---|---|
//! | line over the whole side | 0.010 / 0.026 px | **0.017 / 0.054 px** |
//! | parabola over the whole side | 0.0035 / 0.031 px | 0.026 / 0.094 px |
//! | line over the half side next to each corner | 0.0043 / 0.023 px | 0.023 / 0.083 px |
//!
//! The distortion bends a side by up to ~0.1 px, which the line does not
//! follow (its bias, 0.01 px), but the parabola's extrapolation to the
//! corner and the half-side segments double the noise, which dominates
//! at any realistic noise level. On Zhang's photos the line also gives the
//! lowest calibration RMS (0.364 px against 0.407 and 0.385 px; test
//! `zhang1998_square_grid_found_and_calibrated`). Corners come with the
//! covariance propagated from the residuals of their two line fits.

use super::blobs::{bilinear_u8, Blob};
use super::circles::{blobs_at_level, seed_steps};
use super::filter::to_full;
use super::lattice::{self, PointIndex};
use super::DetectOptions;
use crate::error::{Error, Result};
use crate::image::GrayImage;
use crate::target::DetectedPoint;
use nalgebra::{Matrix2, Matrix3, Point2, Vector2, Vector3};

/// Seeds tried.
const MAX_SEEDS: usize = 60;
/// Neighbouring squares differ in area by at most this factor.
const AREA_RATIO: f64 = 3.0;
/// Sample spacing along a profile, pixels.
const PROFILE_STEP_PX: f64 = 0.25;
/// Profile spacing along a side, pixels.
const PROFILE_SPACING_PX: f64 = 0.5;
/// Edge measurement passes (the first with a wide search).
const PASSES: usize = 4;
/// Centroid window half-width in standard deviations of the edge's
/// derivative (plus half a pixel): measured on the distorted renders of the
/// tests, 2.5 gives the least noise without bias (2.0 biases the fixed
/// point by 0.01 px, 3.0 adds 20 % noise). A Gaussian-weighted centroid
/// was worse: its fixed-point iteration converges too slowly.
const WINDOW_SDS: f64 = 2.5;
/// A side needs at least this many edge points.
const MIN_EDGE_POINTS: usize = 6;

/// What is fitted to a side's edge points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
// The alternatives are measured against the default in the tests.
#[cfg_attr(not(test), allow(dead_code))]
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
    let (level, blobs) = blobs_at_level(img, false, options);
    let board: Vec<(i32, i32)> = (0..rows as i32)
        .flat_map(|j| (0..cols as i32).map(move |i| (i, j)))
        .collect();
    let n = board.len();
    let name = format!("{cols}x{rows} square grid");
    let pts: Vec<Point2<f64>> = blobs.iter().map(|b| b.centre).collect();
    let index = PointIndex::new(&pts, 16.0);
    let mut in_board = vec![false; pts.len()];
    let mut found: Vec<Vec<usize>> = Vec::new();
    let mut best_partial = 0usize;
    for seed in 0..pts.len().min(MAX_SEEDS) {
        if in_board[seed] {
            continue;
        }
        let Some((step_a, step_b)) = seed_steps(&blobs, seed) else {
            continue;
        };
        // A square's side over the grid step, within a factor 2.
        let q = blobs[seed].area.sqrt() / step_a.norm().max(step_b.norm()) / side_over_pitch;
        if !(0.5..=2.0).contains(&q) {
            continue;
        }
        let accept = |i: usize, _: (i32, i32), _: &lattice::Prediction| {
            let r = blobs[i].area / blobs[seed].area;
            (1.0 / AREA_RATIO..=AREA_RATIO).contains(&r)
        };
        let mut cells = lattice::grow(&index, seed, step_a, step_b, 2 * n + 8, &accept);
        // Dark clutter beside the board (Zhang's image2: the backdrop next
        // to the corner square) may join the lattice: keep the one full
        // board-sized window.
        if let Some(window) = lattice::trim_to_window(&cells, cols, rows) {
            cells = window;
        }
        let maps = lattice::complete_maps(&cells, &board, false);
        match lattice::choose_order(&pts, &cells, &maps, &board, cols, &|_| false) {
            Some(order) => {
                cells.values().for_each(|&i| in_board[i] = true);
                found.push(order);
                if found.len() > 1 {
                    return Err(Error::NotFound {
                        message: format!("two candidate boards: two complete {name}s in the image"),
                    });
                }
            }
            None => best_partial = best_partial.max(cells.len().min(n)),
        }
    }
    let Some(order) = found.pop() else {
        let message = if best_partial > 1 {
            format!(
                "found {best_partial} of {n} squares of the {name}: the grid may be cut off, occluded or the counts wrong"
            )
        } else {
            format!("board not found: no {name} in the image")
        };
        return Err(Error::NotFound { message });
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

/// A side's curve `v = c0 + c1 u + c2 u^2` in its frame (origin `m`, `t`
/// along the side from its first corner to its second, `n` outward), with
/// the parameters' covariance.
#[derive(Debug, Clone)]
struct Curve {
    m: Point2<f64>,
    t: Vector2<f64>,
    n: Vector2<f64>,
    c: Vector3<f64>,
    cov: Matrix3<f64>,
}

impl Curve {
    fn local(&self, p: &Point2<f64>) -> (f64, f64) {
        let d = p - self.m;
        (d.dot(&self.t), d.dot(&self.n))
    }
    fn basis(u: f64) -> Vector3<f64> {
        Vector3::new(1.0, u, u * u)
    }
    /// Signed distance-like residual `v - poly(u)` and its gradient.
    fn eval(&self, p: &Point2<f64>) -> (f64, Vector2<f64>) {
        let (u, v) = self.local(p);
        let g = v - self.c.dot(&Self::basis(u));
        let slope = self.c[1] + 2.0 * self.c[2] * u;
        (g, self.n - self.t * slope)
    }
    fn point(&self, u: f64) -> Point2<f64> {
        self.m + self.t * u + self.n * self.c.dot(&Self::basis(u))
    }
}

/// Where curves `a` and `b` meet, near `start`, with its covariance.
fn meet(a: &Curve, b: &Curve, start: Point2<f64>) -> Option<(Point2<f64>, Matrix2<f64>)> {
    let mut p = start;
    for _ in 0..8 {
        let (ga, da) = a.eval(&p);
        let (gb, db) = b.eval(&p);
        let j = Matrix2::new(da.x, da.y, db.x, db.y);
        let step = j.try_inverse()? * Vector2::new(ga, gb);
        p -= step;
        if !(p.x.is_finite() && p.y.is_finite()) {
            return None;
        }
        if step.norm() < 1e-9 {
            break;
        }
    }
    let (_, da) = a.eval(&p);
    let (_, db) = b.eval(&p);
    let jinv = Matrix2::new(da.x, da.y, db.x, db.y).try_inverse()?;
    let var = |c: &Curve| {
        let phi = Curve::basis(c.local(&p).0);
        (phi.transpose() * c.cov * phi)[(0, 0)]
    };
    let cov = jinv * Matrix2::new(var(a), 0.0, 0.0, var(b)) * jinv.transpose();
    Some((p, cov))
}

/// Sub-pixel corners of one dark square from its coarse corners (clockwise
/// on screen). `gap_px`: roughly the light gap to the next square.
fn refine_square(
    img: &GrayImage,
    coarse: &[Point2<f64>; 4],
    gap_px: f64,
    model: SideModel,
) -> Option<[(Point2<f64>, Matrix2<f64>); 4]> {
    let centre = Point2::from(coarse.iter().fold(Vector2::zeros(), |s, p| s + p.coords) / 4.0);
    let side_px = (0..4)
        .map(|k| (coarse[(k + 1) % 4] - coarse[k]).norm())
        .fold(f64::MAX, f64::min);
    if !(side_px >= 4.0) || !gap_px.is_finite() {
        return None;
    }
    let inside = bilinear_u8(img, centre.x, centre.y);
    let mut corners: Vec<(Point2<f64>, Matrix2<f64>)> =
        coarse.iter().map(|p| (*p, Matrix2::zeros())).collect();
    // Curves from the previous pass (sides k = corner k -> k + 1).
    let mut curves: Option<Vec<Curve>> = None;
    let mut half_window = 3.0f64;
    for pass in 0..PASSES {
        let search = if pass == 0 {
            (0.2 * side_px).min(0.35 * gap_px - half_window).max(1.0)
        } else {
            1.0
        };
        let mut fitted: Vec<[Curve; 2]> = Vec::with_capacity(4);
        let mut widths = Vec::new();
        for k in 0..4 {
            let (p, q) = (corners[k].0, corners[(k + 1) % 4].0);
            let chord = q - p;
            let len = chord.norm();
            if !(len >= 4.0) {
                return None;
            }
            let t = chord / len;
            let mut nrm = Vector2::new(t.y, -t.x);
            let m = Point2::from((p.coords + q.coords) * 0.5);
            if nrm.dot(&(m - centre)) < 0.0 {
                nrm = -nrm;
            }
            // Angles at both ends set how far from each corner profiles are
            // clear of the other side.
            let excl = |corner: usize, other: Point2<f64>| {
                let d = (other - corners[corner].0).normalize();
                let along = if corner == k { t } else { -t };
                let cos = d.dot(&along).clamp(-0.99, 0.99);
                let sin = (1.0 - cos * cos).sqrt();
                let reach = search + half_window + 1.0;
                ((half_window + reach * cos.max(0.0)) / sin + 1.0).clamp(2.0, 0.3 * len)
            };
            let e0 = excl(k, corners[(k + 3) % 4].0);
            let e1 = excl((k + 1) % 4, corners[(k + 2) % 4].0);
            let prev = curves.as_ref().map(|c| &c[k]);
            let mut edge_pts: Vec<(f64, f64)> = Vec::new();
            let mut u = -0.5 * len + e0;
            while u <= 0.5 * len - e1 {
                // Base point on the previous curve (or the chord).
                let base = match prev {
                    Some(c) => {
                        let (uc, _) = c.local(&(m + t * u));
                        c.point(uc)
                    }
                    None => m + t * u,
                };
                if let Some((s, width)) =
                    edge_on_profile(img, base, nrm, search, half_window, inside)
                {
                    let e = base + nrm * s;
                    let d = e - m;
                    edge_pts.push((d.dot(&t), d.dot(&nrm)));
                    widths.push(width);
                }
                u += PROFILE_SPACING_PX;
            }
            let span = (-0.5 * len + e0, 0.5 * len - e1);
            let f = fit_side(m, t, nrm, &edge_pts, span, model)?;
            fitted.push(f);
        }
        // The blur seen on the edges sets the next pass's window.
        if !widths.is_empty() {
            widths.sort_by(f64::total_cmp);
            let sd = widths[widths.len() / 2];
            half_window = (WINDOW_SDS * sd + 0.5).clamp(1.5, (0.3 * gap_px).max(1.5));
        }
        let mut next = Vec::with_capacity(4);
        for k in 0..4 {
            // Corner k joins side k - 1 (its end) and side k (its start).
            let a = &fitted[(k + 3) % 4][1];
            let b = &fitted[k][0];
            let (c, cov) = meet(a, b, corners[k].0)?;
            if (c - coarse[k]).norm() > 0.35 * side_px {
                return None;
            }
            next.push((c, cov));
        }
        corners = next;
        // The next pass's profiles follow each side's first curve (the two
        // half-side segments of a side nearly coincide).
        curves = Some(fitted.iter().map(|f| f[0].clone()).collect());
    }
    convex(&corners.iter().map(|c| c.0).collect::<Vec<_>>())
        .then(|| [corners[0], corners[1], corners[2], corners[3]])
}

/// Curves for a side's two ends (the same curve unless the model fits a
/// segment per corner). `span`: the range of `u` that was measured.
fn fit_side(
    m: Point2<f64>,
    t: Vector2<f64>,
    n: Vector2<f64>,
    pts: &[(f64, f64)],
    span: (f64, f64),
    model: SideModel,
) -> Option<[Curve; 2]> {
    match model {
        SideModel::Line | SideModel::Parabola => {
            let degree = if model == SideModel::Line { 1 } else { 2 };
            let c = fit_poly(m, t, n, pts, degree)?;
            Some([c.clone(), c])
        }
        SideModel::CornerSegments => {
            let mid = 0.5 * (span.0 + span.1);
            let first: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.0 <= mid).collect();
            let second: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.0 >= mid).collect();
            Some([
                fit_poly(m, t, n, &first, 1)?,
                fit_poly(m, t, n, &second, 1)?,
            ])
        }
    }
}

/// Least-squares polynomial `v(u)` of degree 1 or 2, with one pass of
/// outlier rejection (residuals beyond 3 robust sigmas, at least 0.15 px).
fn fit_poly(
    m: Point2<f64>,
    t: Vector2<f64>,
    n: Vector2<f64>,
    pts: &[(f64, f64)],
    degree: usize,
) -> Option<Curve> {
    let solve =
        |use_pt: &dyn Fn(usize) -> bool| -> Option<(Vector3<f64>, Matrix3<f64>, f64, usize)> {
            let mut ata = Matrix3::zeros();
            let mut atb = Vector3::zeros();
            let mut count = 0;
            for (i, &(u, v)) in pts.iter().enumerate() {
                if !use_pt(i) {
                    continue;
                }
                let phi = Curve::basis(u);
                ata += phi * phi.transpose();
                atb += phi * v;
                count += 1;
            }
            if count < MIN_EDGE_POINTS {
                return None;
            }
            if degree < 2 {
                // Pin c2 = 0 with a unit row that does not touch the others.
                for k in 0..3 {
                    ata[(2, k)] = 0.0;
                    ata[(k, 2)] = 0.0;
                }
                ata[(2, 2)] = 1.0;
                atb[2] = 0.0;
            }
            let inv = ata.try_inverse()?;
            let c = inv * atb;
            let sse: f64 = pts
                .iter()
                .enumerate()
                .filter(|(i, _)| use_pt(*i))
                .map(|(_, &(u, v))| (v - c.dot(&Curve::basis(u))).powi(2))
                .sum();
            let dof = (count as f64 - (degree + 1) as f64).max(1.0);
            let mut cov = inv * (sse / dof);
            if degree < 2 {
                cov[(2, 2)] = 0.0;
            }
            Some((c, cov, (sse / dof).sqrt(), count))
        };
    let (c, _, _, _) = solve(&|_| true)?;
    let mut res: Vec<f64> = pts
        .iter()
        .map(|&(u, v)| (v - c.dot(&Curve::basis(u))).abs())
        .collect();
    let resid = res.clone();
    res.sort_by(f64::total_cmp);
    let robust = (1.4826 * res[res.len() / 2]).max(0.05);
    let limit = (3.0 * robust).max(0.15);
    let (c, cov, _, _) = solve(&|i| resid[i] <= limit)?;
    Some(Curve { m, t, n, c, cov })
}

/// Edge on the profile `base + s n`, `|s| <= search`: the strongest rise of
/// the grey level (dark inside to light outside), then the centroid of the
/// derivative in a window of half-width `half_window` moved onto it.
/// Returns the offset `s` and the edge's blur (the derivative's sd).
fn edge_on_profile(
    img: &GrayImage,
    base: Point2<f64>,
    n: Vector2<f64>,
    search: f64,
    half_window: f64,
    inside: f64,
) -> Option<(f64, f64)> {
    let reach = search + half_window + 0.5;
    let count = (2.0 * reach / PROFILE_STEP_PX).ceil() as usize + 1;
    let s0 = -reach;
    let at = |k: usize| s0 + k as f64 * PROFILE_STEP_PX;
    let vals: Vec<f64> = (0..count)
        .map(|k| {
            let p = base + n * at(k);
            bilinear_u8(img, p.x, p.y)
        })
        .collect();
    // Derivative over one pixel (two samples either side), at sample k.
    let half = (0.5 / PROFILE_STEP_PX).round() as usize;
    let deriv: Vec<f64> = (0..count)
        .map(|k| {
            if k < half || k + half >= count {
                0.0
            } else {
                vals[k + half] - vals[k - half]
            }
        })
        .collect();
    let mut best: Option<(usize, f64)> = None;
    for (k, d) in deriv.iter().enumerate() {
        if at(k).abs() <= search && best.map_or(true, |b| *d > b.1) {
            best = Some((k, *d));
        }
    }
    let (kb, peak) = best?;
    // The rise must be a real edge: at least a fifth of the contrast
    // between the square's inside and the light just outside this edge.
    let outside =
        vals[count - 1].max(vals[(kb + (1.0 / PROFILE_STEP_PX) as usize * 2).min(count - 1)]);
    let contrast = outside - inside;
    if !(contrast > 10.0) || peak < 0.2 * contrast {
        return None;
    }
    let mut centre = at(kb);
    let mut width = 0.0;
    for _ in 0..4 {
        let (mut sw, mut sws, mut swss) = (0.0, 0.0, 0.0);
        for (k, d) in deriv.iter().enumerate() {
            let s = at(k);
            if (s - centre).abs() <= half_window {
                sw += d;
                sws += d * s;
                swss += d * s * s;
            }
        }
        if !(sw > 0.0) {
            return None;
        }
        let c = sws / sw;
        width = (swss / sw - c * c).max(0.0).sqrt();
        let moved = (c - centre).abs();
        centre = c;
        if moved < 1e-3 {
            break;
        }
    }
    (centre.abs() <= search + 0.5).then_some((centre, width))
}

/// The four corners form a convex quadrilateral, clockwise on screen.
fn convex(p: &[Point2<f64>]) -> bool {
    (0..4).all(|k| {
        let a = p[(k + 1) % 4] - p[k];
        let b = p[(k + 2) % 4] - p[(k + 1) % 4];
        a.x * b.y - a.y * b.x > 0.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Camera, Distortion};
    use crate::synth::{render, RenderOptions};
    use crate::target::Target;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

    /// Zhang's lens scaled to 1280x960: f 1665 px, k1 -0.2286, k2 0.1904.
    fn zhang_camera() -> Camera {
        Camera {
            distortion: Distortion::Brown {
                k1: -0.228601,
                k2: 0.190353,
                k3: 0.0,
                p1: 0.0,
                p2: 0.0,
            },
            ..Camera::pinhole(1665.0, 1665.1, 607.9, 413.2, 1280, 960)
        }
    }

    fn pose(target: &Target, rpy: (f64, f64, f64), at: (f64, f64, f64)) -> Isometry3<f64> {
        let pts = target.object_points();
        let mx = pts.iter().map(|p| p.1.x).fold(0.0, f64::max) / 2.0;
        let my = pts.iter().map(|p| p.1.y).fold(0.0, f64::max) / 2.0;
        let r = UnitQuaternion::from_euler_angles(rpy.0, rpy.1, rpy.2);
        let t = Vector3::new(at.0, at.1, at.2) - r * Vector3::new(mx, my, 0.0);
        Isometry3::from_parts(Translation3::from(t), r)
    }

    /// Mean and max corner error of `model` over `views` (rpy, distance).
    fn errors(model: SideModel, noise: f64, views: &[((f64, f64, f64), f64)]) -> (f64, f64) {
        let target = Target::parse_spec("squares:8x8:12.7mm:22.5778mm").unwrap();
        let cam = zhang_camera();
        let (mut sum, mut max, mut n) = (0.0, 0.0f64, 0.0);
        for (k, (rpy, z)) in views.iter().enumerate() {
            let o = RenderOptions {
                noise_sigma: noise,
                // 8x8 supersampling quantises a near-axis-aligned edge in
                // 1/8 px steps (0.12 px jumps along the side): 32 keeps the
                // truth below the errors measured.
                supersample: 32,
                seed: 10 + k as u64,
                ..RenderOptions::default()
            };
            let r = render(&cam, &target, &pose(&target, *rpy, (0.004, 0.012, *z)), &o).unwrap();
            assert_eq!(r.points.len(), 256, "view {k}");
            let pts = detect_with_model(
                &r.image,
                8,
                8,
                12.7 / 22.5778,
                &DetectOptions::default(),
                model,
            )
            .unwrap_or_else(|e| panic!("view {k}: {e}"));
            // Views turned by more than 45 degrees may start from another
            // corner of the square board (the documented rule): compare
            // with the nearest truth point, and the ids where the turn is small.
            for d in &pts {
                let (e, id) = r
                    .points
                    .iter()
                    .map(|t| {
                        (
                            ((d.x_px - t.x_px).powi(2) + (d.y_px - t.y_px).powi(2)).sqrt(),
                            t.id,
                        )
                    })
                    .fold((f64::MAX, 0), |a, b| if b.0 < a.0 { b } else { a });
                if rpy.2.abs() < 0.3 {
                    assert_eq!(id, d.id, "view {k}");
                }
                sum += e;
                max = max.max(e);
                n += 1.0;
            }
        }
        (sum / n, max)
    }

    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn finds_a_small_square_grid_with_exact_corners() {
        // 4x3 squares, pinhole, 640x480, noise-free: the ids follow the
        // documented order and every corner is within 0.03 px of the truth
        // (measured mean 0.0025 px).
        let target = Target::parse_spec("squares:4x3:20mm:32mm").unwrap();
        let cam = Camera::pinhole(700.0, 700.0, 321.3, 238.9, 640, 480);
        let o = RenderOptions {
            noise_sigma: 0.0,
            supersample: 16,
            ..RenderOptions::default()
        };
        let r = render(
            &cam,
            &target,
            &pose(&target, (0.2, -0.3, 0.1), (0.0, 0.0, 0.4)),
            &o,
        )
        .unwrap();
        assert_eq!(r.points.len(), 48);
        let d = crate::detect::detect(&r.image, &target, &DetectOptions::default()).unwrap();
        assert_eq!(d.points.len(), 48);
        let mut sum = 0.0;
        for (p, t) in d.points.iter().zip(&r.points) {
            assert_eq!(p.id, t.id);
            let e = ((p.x_px - t.x_px).powi(2) + (p.y_px - t.y_px).powi(2)).sqrt();
            assert!(e < 0.03, "id {}: {e} px", p.id);
            sum += e;
            let c = p.covariance_px2.unwrap();
            assert!(c[0] >= 0.0 && c[2] >= 0.0 && c[0] < 0.01, "{c:?}");
        }
        eprintln!("mean {} px", sum / 48.0);
        // Cut off: the count is reported.
        let half = crate::image::GrayImage::new(
            320,
            480,
            (0..480)
                .flat_map(|y| r.image.pixels[y * 640..y * 640 + 320].to_vec())
                .collect(),
        )
        .unwrap();
        let e = crate::detect::detect(&half, &target, &DetectOptions::default()).unwrap_err();
        assert!(
            e.to_string()
                .contains("of 12 squares of the 4x3 square grid"),
            "{e}"
        );
    }

    /// The numbers behind the default side model (module docs); about 30 s,
    /// run with `cargo test --lib side_models -- --ignored --nocapture`.
    #[cfg(not(target_arch = "wasm32"))]
    #[test]
    #[ignore]
    fn side_models_compared_on_distorted_renders() {
        let views = [
            ((0.05, -0.08, 0.03), 0.38),
            // Filling the frame like Zhang's images: the most bent sides.
            ((0.02, 0.06, -0.04), 0.355),
            ((0.5, 0.2, -0.2), 0.47),
            ((-0.3, 0.55, 0.5), 0.47),
        ];
        for noise in [0.0, 2.0] {
            for model in [
                SideModel::Line,
                SideModel::Parabola,
                SideModel::CornerSegments,
            ] {
                let (mean, max) = errors(model, noise, &views);
                eprintln!("noise {noise}: {model:?}: mean {mean:.4} px, max {max:.4} px");
            }
        }
    }
}
