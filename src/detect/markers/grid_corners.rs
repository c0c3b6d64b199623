//! An ArUco grid's points: each marker's four corners measured again from
//! the marker's found outline (the quad finder's corners come within a
//! pixel or so; its twelve gradient peaks per side leave 0.1-0.3 px): every
//! side's edge located across the side at one sample per pixel of its
//! middle [`SIDE_SPAN`], each at the centroid of the grey-level gradient
//! around its peak, a total-least-squares line through them, neighbouring
//! lines intersected. The profile reaches [`SEARCH_PX`] to either side and
//! the centroid [`CENTROID_HALF_PX`] around the peak, both shrunk to half a
//! cell (bit) on smaller markers, so that the marker's one-bit black border
//! keeps the inner bits out of reach; markers of less than
//! [`MIN_CELL_PX`] per cell keep the finder's corners.
//!
//! The centroid's window must hold the whole blurred edge: on renders
//! (tests/detect/detect_grid_boards.rs, eight views) half-windows of 1.25, 1.75
//! and 2.25 px (searches 2, 2.5, 3 px) gave 0.057 / 0.44, 0.031 / 0.23 and
//! 0.019 / 0.135 px mean / max (a narrow window is pulled towards the pixel
//! grid where the sides run near the pixel axes).

use crate::image::GrayImage;
use nalgebra::{Point2, Vector2};

/// Fraction of a side sampled, centred (away from the corners, where the
/// neighbouring side's edge enters the profile).
const SIDE_SPAN: f64 = 0.8;
/// Half-length of the profile across a side, pixels (at most half a cell).
const SEARCH_PX: f64 = 3.0;
/// Smallest cell (bit) of a marker whose corners are refined, pixels.
const MIN_CELL_PX: f64 = 2.0;
/// Step along the profile, pixels.
const STEP_PX: f64 = 0.125;
/// Half-width of the gradient centroid's window around the peak, pixels
/// (scaled with the search).
const CENTROID_HALF_PX: f64 = 2.25;
/// Fewest edge samples for a side's line.
const MIN_SAMPLES: usize = 6;
/// Smallest gradient peak taken as an edge, grey levels per pixel.
const MIN_GRADIENT: f64 = 6.0;
/// A corner that moves further than this from the finder's is not trusted
/// (the finder's is kept), pixels.
const MAX_SHIFT_PX: f64 = 1.5;

/// The corners of a marker with `cells` cells a side (bits and border),
/// refined; `corners` unchanged when a side cannot be measured.
pub(super) fn refine_corners(
    img: &GrayImage,
    corners: [Point2<f64>; 4],
    cells: usize,
) -> [Point2<f64>; 4] {
    let side = (0..4)
        .map(|k| (corners[(k + 1) % 4] - corners[k]).norm())
        .fold(f64::INFINITY, f64::min);
    let cell_px = side / (cells.max(1) as f64);
    if !(cell_px >= MIN_CELL_PX) {
        return corners;
    }
    let search = SEARCH_PX.min(0.5 * cell_px);
    let mut lines = Vec::with_capacity(4);
    for k in 0..4 {
        match side_line(img, corners[k], corners[(k + 1) % 4], search) {
            Some(l) => lines.push(l),
            None => return corners,
        }
    }
    let mut out = corners;
    for k in 0..4 {
        // Corner k is where side k - 1 meets side k.
        match intersect(&lines[(k + 3) % 4], &lines[k]) {
            Some(p) if (p - corners[k]).norm() <= MAX_SHIFT_PX => out[k] = p,
            _ => return corners,
        }
    }
    out
}

/// A line: a point on it and its unit direction.
struct Line {
    point: Point2<f64>,
    dir: Vector2<f64>,
}

fn intersect(a: &Line, b: &Line) -> Option<Point2<f64>> {
    let den = a.dir.x * b.dir.y - a.dir.y * b.dir.x;
    if den.abs() < 1e-9 {
        return None;
    }
    let d = b.point - a.point;
    let t = (d.x * b.dir.y - d.y * b.dir.x) / den;
    Some(a.point + a.dir * t)
}

/// The edge from `a` to `b` as a line, profiles `search` px to either side
/// (see the module docs).
fn side_line(img: &GrayImage, a: Point2<f64>, b: Point2<f64>, search: f64) -> Option<Line> {
    let length = (b - a).norm();
    let along = (b - a).try_normalize(1e-12)?;
    let normal = Vector2::new(-along.y, along.x);
    let samples = ((SIDE_SPAN * length).floor() as usize).max(MIN_SAMPLES);
    let steps = (2.0 * search / STEP_PX).round() as usize;
    let half = (CENTROID_HALF_PX * search / SEARCH_PX / STEP_PX).round() as usize;
    let mut profile = vec![0.0; steps + 1];
    let mut pts: Vec<Point2<f64>> = Vec::with_capacity(samples);
    for s in 0..samples {
        let t = 0.5 * (1.0 - SIDE_SPAN) + SIDE_SPAN * (s as f64 + 0.5) / samples as f64;
        let base = a + (b - a) * t;
        let start = base - normal * search;
        for (i, v) in profile.iter_mut().enumerate() {
            let p = start + normal * (i as f64 * STEP_PX);
            *v = crate::detect::blobs::bilinear_u8(img, p.x, p.y);
        }
        // Central differences, grey levels per pixel, at samples 1..steps.
        let grad = |i: usize| (profile[i + 1] - profile[i - 1]).abs() / (2.0 * STEP_PX);
        let Some((peak, g)) = (1..steps)
            .map(|i| (i, grad(i)))
            .max_by(|x, y| x.1.total_cmp(&y.1))
        else {
            continue;
        };
        if g < MIN_GRADIENT || peak <= half || peak + half >= steps {
            continue;
        }
        let (mut sw, mut swi) = (0.0, 0.0);
        for i in peak - half..=peak + half {
            let w = grad(i);
            sw += w;
            swi += w * i as f64;
        }
        if sw <= 0.0 {
            continue;
        }
        pts.push(start + normal * (swi / sw * STEP_PX));
    }
    if pts.len() < MIN_SAMPLES {
        return None;
    }
    let n = pts.len() as f64;
    let c = pts.iter().fold(Vector2::zeros(), |s, p| s + p.coords) / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in &pts {
        let d = p.coords - c;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let dir = Vector2::new(theta.cos(), theta.sin());
    (dir.dot(&along).abs() > 0.9).then_some(Line {
        point: Point2::from(c),
        dir,
    })
}
