//! Marker candidates: dark convex quadrilaterals.
//!
//! 1. The search image: the frame itself, or its 2 x 2 mean
//!    ([`runs::decimate`]) when its long side is at least
//!    [`DECIMATE_FROM_PX`] (a quarter of the pixels for every step below;
//!    markers keep at least [`MIN_SIDE_PX`] / 2 pixels a side there).
//! 2. A locally adaptive threshold ([`runs::threshold`]: dark when more
//!    than 7 grey levels below the mean of a square window, two window
//!    sizes as OpenCV's ArUco detector tries several), written as runs of
//!    dark pixels, and the same runs eroded once (breaks the necks where an
//!    AprilGrid tag meets its corner squares under blur).
//! 3. 4-connected regions of runs. Four-connectivity separates regions that
//!    touch only at a corner (a ChArUco board's black squares, an AprilGrid
//!    tag and its corner squares): the X-junction pixel sits at the local
//!    mean, never below it by the offset.
//! 4. Per region: the convex hull of its runs' end points and the
//!    quadrilateral of four hull vertices (farthest-point construction).
//!    Rejected: regions touching the image border, sides below
//!    [`MIN_SIDE_PX`], hulls the quad covers less than [`MIN_QUAD_FILL`] of
//!    (not a quadrilateral), quads larger than the image.
//! 5. A candidate already tried (another window, the eroded runs: the same
//!    corners within [`SAME_QUAD_PX`]) or inside a marker already read is
//!    skipped; the others get sub-pixel corners on the full-resolution
//!    frame ([`edges::refine_quad`]) and go to the reader.
//! 6. When the decimated search reads no marker at all (markers too small
//!    for the decimated image, or a frame without a board), or reads one
//!    whose cells are under [`SMALL_CELL_PX`] frame pixels (its like
//!    nearby are too small for the decimated image: their dark regions
//!    merge with the squares around them or break up there), the frame is
//!    searched again at full resolution. A small ChArUco board (15-22 px
//!    markers, blur 1.4 px) gave 1-19 of its 54 markers at half
//!    resolution and 12-35 at full resolution.

use super::edges::refine_quad;
use super::runs::{self, Region};
use crate::image::GrayImage;
use nalgebra::{Point2, Vector2};
use std::collections::HashMap;

/// Shortest quad side in the frame, pixels: a 4 x 4 marker with its border
/// has cells of at least 1.3 px then.
const MIN_SIDE_PX: f64 = 8.0;
/// The quad must cover this much of the region's hull.
const MIN_QUAD_FILL: f64 = 0.88;
/// Frames whose long side has at least this many pixels are searched at
/// half resolution first.
pub(super) const DECIMATE_FROM_PX: u32 = 1000;
/// A marker read at half resolution whose cells are narrower than this
/// (frame pixels: 2.5 pixels of the decimated image) sends the frame to
/// the full-resolution search as well.
pub(super) const SMALL_CELL_PX: f64 = 5.0;
/// Two candidates whose corners all lie this close (frame pixels) are the
/// same quad.
const SAME_QUAD_PX: f64 = 2.0;

/// A candidate marker outline: corners clockwise on screen (y down),
/// starting anywhere.
#[derive(Debug, Clone)]
pub(crate) struct Quad {
    pub corners: [Point2<f64>; 4],
}

impl Quad {
    fn centre(&self) -> Point2<f64> {
        Point2::from(
            self.corners
                .iter()
                .fold(Vector2::zeros(), |s, p| s + p.coords)
                / 4.0,
        )
    }

    fn mean_side(&self) -> f64 {
        (0..4)
            .map(|k| (self.corners[(k + 1) % 4] - self.corners[k]).norm())
            .sum::<f64>()
            / 4.0
    }

    /// Every corner of `self` within `tol` of one of `other`'s.
    fn same_as(&self, other: &Quad, tol: f64) -> bool {
        self.corners.iter().all(|c| {
            other
                .corners
                .iter()
                .any(|o| (c - o).norm_squared() <= tol * tol)
        })
    }
}

/// Windows (odd side, pixels) of the adaptive threshold for an image.
fn windows(w: u32, h: u32) -> [usize; 2] {
    let long = w.max(h) as usize;
    let small = (long / 80).clamp(7, 31) | 1;
    [small, (3 * small).min(91) | 1]
}

/// Candidates tried so far: those `read` accepted (a marker, by centre and
/// side) and the rest (by the cell of their centre, [`SAME_QUAD_PX`]
/// pixels a side: the same quad is in a neighbouring cell).
#[derive(Default)]
struct Tried {
    markers: Vec<(Point2<f64>, f64)>,
    others: HashMap<(i64, i64), Vec<Quad>>,
}

impl Tried {
    fn cell(p: Point2<f64>) -> (i64, i64) {
        (
            (p.x / SAME_QUAD_PX).floor() as i64,
            (p.y / SAME_QUAD_PX).floor() as i64,
        )
    }

    fn covers(&self, q: &Quad) -> bool {
        let c = q.centre();
        if self
            .markers
            .iter()
            .any(|(m, side)| (c - m).norm_squared() < 0.25 * side * side)
        {
            return true;
        }
        let (i, j) = Tried::cell(c);
        (i - 1..=i + 1).any(|a| {
            (j - 1..=j + 1).any(|b| {
                self.others
                    .get(&(a, b))
                    .is_some_and(|v| v.iter().any(|o| q.same_as(o, SAME_QUAD_PX)))
            })
        })
    }

    fn add_other(&mut self, q: Quad) {
        self.others
            .entry(Tried::cell(q.centre()))
            .or_default()
            .push(q);
    }
}

/// Hands every candidate quad of `img` to `read` (corners refined on
/// `img`), which says whether it read a marker there; see the module docs.
/// `cells`: a marker's side in cells, its border included.
pub(crate) fn find_quads(
    img: &GrayImage,
    resolutions: Resolutions,
    cells: usize,
    mut read: impl FnMut(&Quad) -> bool,
) {
    let mut tried = Tried::default();
    let large = decimates(img);
    if large && resolutions != Resolutions::FullOnly {
        let half = runs::decimate(img);
        search(img, &half, 2.0, &mut tried, &mut read);
        let small = tried
            .markers
            .iter()
            .any(|(_, side)| *side < SMALL_CELL_PX * cells as f64);
        if !small && (!tried.markers.is_empty() || resolutions == Resolutions::HalfOnly) {
            return;
        }
    }
    if large || resolutions != Resolutions::FullOnly {
        search(img, img, 1.0, &mut tried, &mut read);
    }
}

/// Which of the searches of steps 1 and 6 (module docs) to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Resolutions {
    /// Half resolution on large frames, then full resolution when that
    /// read no marker or a small one (small frames: full resolution).
    HalfThenFull,
    /// The first search alone: half resolution on large frames, then full
    /// resolution only when that read a small marker (small frames: full
    /// resolution).
    HalfOnly,
    /// The full-resolution retry alone: large frames only (nothing on
    /// small ones, which `HalfOnly` searched at full resolution).
    FullOnly,
}

/// Whether `img` is searched at half resolution first.
pub(crate) fn decimates(img: &GrayImage) -> bool {
    img.width.max(img.height) >= DECIMATE_FROM_PX
}

/// One search on `small` (the frame `img` scaled by 1 / `scale`).
fn search(
    img: &GrayImage,
    small: &GrayImage,
    scale: f64,
    tried: &mut Tried,
    read: &mut impl FnMut(&Quad) -> bool,
) {
    let min_side = MIN_SIDE_PX / scale;
    let integral = runs::integral_image(small);
    // Pixel (i, j) of `small` is centred on scale * (i, j) + (scale - 1) / 2.
    let offset = 0.5 * (scale - 1.0);
    for win in windows(small.width, small.height) {
        let mask = runs::threshold(small, &integral, win);
        let eroded = runs::erode(&mask);
        for (m, inset) in [(&mask, 0.5), (&eroded, 1.5)] {
            for region in runs::regions(m, (0.5 * min_side) as u32) {
                let Some(q) = quad_of(&region, inset, min_side) else {
                    continue;
                };
                let q = Quad {
                    corners: q
                        .corners
                        .map(|p| Point2::new(scale * p.x + offset, scale * p.y + offset)),
                };
                if tried.covers(&q) {
                    continue;
                }
                let refined = refine_quad(img, q.clone(), scale);
                if read(&refined) {
                    tried.markers.push((refined.centre(), refined.mean_side()));
                } else {
                    tried.add_other(q);
                }
            }
        }
    }
}

/// Convex hull of a region's pixel centres (monotone chain over the runs'
/// end points, which come in (y, x) order already: the hull of a run is
/// its two ends). Collinear points are dropped.
fn hull(region: &[(u32, runs::Run)]) -> Vec<Point2<f64>> {
    let mut points = Vec::with_capacity(2 * region.len());
    for &(y, r) in region {
        points.push(Point2::new(f64::from(r.x0), f64::from(y)));
        if r.x1 > r.x0 + 1 {
            points.push(Point2::new(f64::from(r.x1 - 1), f64::from(y)));
        }
    }
    let cross = |o: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>| {
        (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
    };
    let mut lower: Vec<Point2<f64>> = Vec::new();
    for p in &points {
        while lower.len() >= 2 && cross(&lower[lower.len() - 2], &lower[lower.len() - 1], p) <= 0.0
        {
            lower.pop();
        }
        lower.push(*p);
    }
    let mut upper: Vec<Point2<f64>> = Vec::new();
    for p in points.iter().rev() {
        while upper.len() >= 2 && cross(&upper[upper.len() - 2], &upper[upper.len() - 1], p) <= 0.0
        {
            upper.pop();
        }
        upper.push(*p);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

fn polygon_area(p: &[Point2<f64>]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % n]);
            a.x * b.y - b.x * a.y
        })
        .sum::<f64>()
        * 0.5
}

/// The region's quadrilateral, corners clockwise on screen, or `None`;
/// `inset` is how far (pixels, along x and y) the region's boundary pixel
/// centres lie inside the dark area's edge.
fn quad_of(region: &Region, inset: f64, min_side: f64) -> Option<Quad> {
    let hull = hull(&region.runs);
    if hull.len() < 4 {
        return None;
    }
    let hull_area = polygon_area(&hull).abs();
    // Farthest-point quad: a far vertex, the vertex farthest from it, then
    // the farthest on each side of that diagonal.
    let c = hull.iter().fold(Vector2::zeros(), |a, p| a + p.coords) / hull.len() as f64;
    let far = |from: Vector2<f64>| {
        (0..hull.len()).max_by(|&a, &b| {
            (hull[a].coords - from)
                .norm_squared()
                .total_cmp(&(hull[b].coords - from).norm_squared())
        })
    };
    let a = far(c)?;
    let b = far(hull[a].coords)?;
    let (pa, pb) = (hull[a], hull[b]);
    let side = |p: &Point2<f64>| (pb.x - pa.x) * (p.y - pa.y) - (pb.y - pa.y) * (p.x - pa.x);
    let left = (0..hull.len()).max_by(|&i, &j| side(&hull[i]).total_cmp(&side(&hull[j])))?;
    let right = (0..hull.len()).min_by(|&i, &j| side(&hull[i]).total_cmp(&side(&hull[j])))?;
    if side(&hull[left]) <= 0.0 || side(&hull[right]) >= 0.0 {
        return None;
    }
    let mut corners = [pa, hull[left], pb, hull[right]];
    if polygon_area(&corners) < 0.0 {
        corners.swap(1, 3);
    }
    let area = polygon_area(&corners);
    if !(area > 0.0) || area < MIN_QUAD_FILL * hull_area {
        return None;
    }
    // Screen-clockwise (y down) means positive shoelace area here.
    for k in 0..4 {
        if (corners[(k + 1) % 4] - corners[k]).norm() < min_side {
            return None;
        }
    }
    // Boundary pixel centres lie `inset` inside the dark region's edge:
    // push the corners out by that much along the diagonals.
    let centre = corners.iter().fold(Vector2::zeros(), |s, p| s + p.coords) / 4.0;
    let corners = corners.map(|p| {
        let d = p.coords - centre;
        Point2::from(p.coords + d.normalize() * inset * std::f64::consts::SQRT_2)
    });
    Some(Quad { corners })
}
