//! Marker candidates: dark convex quadrilaterals.
//!
//! 1. A locally adaptive threshold: a pixel is dark when it is more than
//!    [`THRESHOLD_OFFSET`] grey levels below the mean of a square window
//!    around it (means from one integral image; two window sizes, as
//!    OpenCV's ArUco detector tries several).
//! 2. 4-connected components of dark pixels. Four-connectivity separates
//!    regions that touch only at a corner (a ChArUco board's black squares,
//!    an AprilGrid tag and its corner squares): the X-junction pixel sits
//!    at the local mean, never below it by the offset.
//! 3. Per component: its boundary pixels' convex hull and the quadrilateral
//!    of four hull vertices (farthest-point construction). Rejected: regions
//!    touching the image border, sides below [`MIN_SIDE_PX`], hulls the quad
//!    covers less than [`MIN_QUAD_FILL`] of (not a quadrilateral), quads
//!    larger than the image.
//! 4. Corners to sub-pixel: each side's line is fitted to gradient maxima
//!    sampled across it; neighbouring lines meet at the corners.

use crate::image::GrayImage;
use nalgebra::{Point2, Vector2};

/// Grey levels below the local mean for a dark pixel (OpenCV's
/// adaptiveThreshConstant is 7).
const THRESHOLD_OFFSET: i64 = 7;
/// Shortest quad side, pixels: a 4 x 4 marker with its border has cells of
/// at least 1.3 px then.
pub(crate) const MIN_SIDE_PX: f64 = 8.0;
/// The quad must cover this much of the region's hull.
const MIN_QUAD_FILL: f64 = 0.88;
/// Sample points per side for the edge fit.
const EDGE_SAMPLES: usize = 12;
/// Search half-length across a side, pixels.
const EDGE_SEARCH_PX: f64 = 2.5;

/// A candidate marker outline: corners clockwise on screen (y down),
/// starting anywhere.
#[derive(Debug, Clone)]
pub(crate) struct Quad {
    pub corners: [Point2<f64>; 4],
}

/// Windows (odd side, pixels) of the adaptive threshold for an image.
fn windows(w: u32, h: u32) -> [usize; 2] {
    let long = w.max(h) as usize;
    let small = (long / 80).clamp(7, 31) | 1;
    [small, (3 * small).min(91) | 1]
}

/// Every candidate quad of `img` (duplicates across the threshold windows
/// included; the decoder's duplicates are merged by the caller).
pub(crate) fn find_quads(img: &GrayImage) -> Vec<Quad> {
    let (w, h) = (img.width as usize, img.height as usize);
    let integral = integral_image(img);
    let mut out = Vec::new();
    for win in windows(img.width, img.height) {
        let mask = threshold(img, &integral, win);
        let eroded = erode(&mask, w, h);
        for (m, inset) in [(&mask, 0.5), (&eroded, 1.5)] {
            for region in components(m, w, h) {
                if let Some(q) = quad_of(&region, inset) {
                    out.push(refine_quad(img, q));
                }
            }
        }
    }
    out
}

/// Dark pixels whose four neighbours are dark too: breaks the one- or
/// two-pixel necks where dark regions meet at a corner under blur and tilt
/// (an AprilGrid tag and its corner squares), at the price of a pixel all
/// round (the quad is pushed back out by it).
fn erode(mask: &[bool], w: usize, h: usize) -> Vec<bool> {
    let mut out = vec![false; w * h];
    for y in 1..h.saturating_sub(1) {
        for x in 1..w - 1 {
            let i = y * w + x;
            out[i] = mask[i] && mask[i - 1] && mask[i + 1] && mask[i - w] && mask[i + w];
        }
    }
    out
}

fn integral_image(img: &GrayImage) -> Vec<u64> {
    let (w, h) = (img.width as usize, img.height as usize);
    let mut s = vec![0u64; (w + 1) * (h + 1)];
    for y in 0..h {
        let mut row = 0u64;
        for x in 0..w {
            row += u64::from(img.pixels[y * w + x]);
            s[(y + 1) * (w + 1) + x + 1] = s[y * (w + 1) + x + 1] + row;
        }
    }
    s
}

fn threshold(img: &GrayImage, s: &[u64], win: usize) -> Vec<bool> {
    let (w, h) = (img.width as usize, img.height as usize);
    let r = win / 2;
    let mut mask = vec![false; w * h];
    for y in 0..h {
        let (y0, y1) = (y.saturating_sub(r), (y + r + 1).min(h));
        for x in 0..w {
            let (x0, x1) = (x.saturating_sub(r), (x + r + 1).min(w));
            let sum = s[y1 * (w + 1) + x1] + s[y0 * (w + 1) + x0]
                - s[y0 * (w + 1) + x1]
                - s[y1 * (w + 1) + x0];
            let area = ((x1 - x0) * (y1 - y0)) as i64;
            let v = i64::from(img.pixels[y * w + x]);
            mask[y * w + x] = (v + THRESHOLD_OFFSET) * area < sum as i64;
        }
    }
    mask
}

/// Boundary pixels of one 4-connected dark region not touching the image
/// border.
struct Region {
    boundary: Vec<Point2<f64>>,
}

fn components(mask: &[bool], w: usize, h: usize) -> Vec<Region> {
    let mut label = vec![false; w * h];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    let max_pixels = w * h / 2;
    for start in 0..w * h {
        if !mask[start] || label[start] {
            continue;
        }
        label[start] = true;
        stack.push(start);
        let mut boundary = Vec::new();
        let mut touches_border = false;
        let mut count = 0usize;
        while let Some(i) = stack.pop() {
            count += 1;
            let (x, y) = (i % w, i / w);
            if x == 0 || y == 0 || x + 1 == w || y + 1 == h {
                touches_border = true;
                continue;
            }
            let mut edge = false;
            for n in [i - 1, i + 1, i - w, i + w] {
                if mask[n] {
                    if !label[n] {
                        label[n] = true;
                        stack.push(n);
                    }
                } else {
                    edge = true;
                }
            }
            if edge {
                boundary.push(Point2::new(x as f64, y as f64));
            }
        }
        let min_boundary = (4.0 * MIN_SIDE_PX) as usize - 4;
        if !touches_border && boundary.len() >= min_boundary && count <= max_pixels {
            out.push(Region { boundary });
        }
    }
    out
}

/// Convex hull (monotone chain), counter-clockwise in x-right/y-up terms,
/// i.e. clockwise on screen... orientation fixed by the caller.
fn hull(points: &mut [Point2<f64>]) -> Vec<Point2<f64>> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let cross = |o: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>| {
        (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
    };
    let mut lower: Vec<Point2<f64>> = Vec::new();
    for p in points.iter() {
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
fn quad_of(region: &Region, inset: f64) -> Option<Quad> {
    let mut pts = region.boundary.clone();
    let hull = hull(&mut pts);
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
        if (corners[(k + 1) % 4] - corners[k]).norm() < MIN_SIDE_PX {
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

/// Sub-pixel corners from lines fitted to each side's gradient maxima;
/// the quad unchanged when a side cannot be fitted.
fn refine_quad(img: &GrayImage, q: Quad) -> Quad {
    let mut lines = Vec::with_capacity(4);
    for k in 0..4 {
        let (a, b) = (q.corners[k], q.corners[(k + 1) % 4]);
        match edge_line(img, a, b) {
            Some(l) => lines.push(l),
            None => return q,
        }
    }
    let mut corners = q.corners;
    for k in 0..4 {
        // Corner k is where side k-1 meets side k.
        let (l0, l1) = (&lines[(k + 3) % 4], &lines[k]);
        match intersect(l0, l1) {
            Some(p) if (p - q.corners[k]).norm() < 3.0 => corners[k] = p,
            _ => return q,
        }
    }
    Quad { corners }
}

/// A line through `point` with unit `normal`.
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

fn bilinear(img: &GrayImage, x: f64, y: f64) -> f64 {
    let (w, h) = (img.width as usize, img.height as usize);
    let x = x.clamp(0.0, (w - 1) as f64);
    let y = y.clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f64, y - y0 as f64);
    let p = |xx: usize, yy: usize| f64::from(img.pixels[yy * w + xx]);
    (p(x0, y0) * (1.0 - fx) + p(x1, y0) * fx) * (1.0 - fy)
        + (p(x0, y1) * (1.0 - fx) + p(x1, y1) * fx) * fy
}

/// The edge between `a` and `b`: gradient maxima across the side at
/// [`EDGE_SAMPLES`] points in its middle 70 %, then a total-least-squares
/// line.
fn edge_line(img: &GrayImage, a: Point2<f64>, b: Point2<f64>) -> Option<Line> {
    let along = (b - a).normalize();
    let normal = Vector2::new(-along.y, along.x);
    let step = 0.25;
    let n_steps = (2.0 * EDGE_SEARCH_PX / step) as usize;
    let mut pts = Vec::with_capacity(EDGE_SAMPLES);
    for s in 0..EDGE_SAMPLES {
        let t = 0.15 + 0.7 * (s as f64 + 0.5) / EDGE_SAMPLES as f64;
        let base = a + (b - a) * t;
        // Profile across the edge; its derivative's peak magnitude.
        let profile: Vec<f64> = (0..=n_steps)
            .map(|i| {
                let o = -EDGE_SEARCH_PX + i as f64 * step;
                let p = base + normal * o;
                bilinear(img, p.x, p.y)
            })
            .collect();
        let grad: Vec<f64> = profile.windows(3).map(|w| (w[2] - w[0]).abs()).collect();
        let (imax, &gmax) = grad.iter().enumerate().max_by(|x, y| x.1.total_cmp(y.1))?;
        if gmax < 4.0 || imax == 0 || imax + 1 >= grad.len() {
            continue;
        }
        let (l, c, r) = (grad[imax - 1], gmax, grad[imax + 1]);
        let den = l - 2.0 * c + r;
        let off = if den.abs() > 1e-12 {
            0.5 * (l - r) / den
        } else {
            0.0
        };
        let o = -EDGE_SEARCH_PX + (imax as f64 + 1.0 + off) * step;
        pts.push(base + normal * o);
    }
    if pts.len() < EDGE_SAMPLES / 2 {
        return None;
    }
    let c = pts.iter().fold(Vector2::zeros(), |s, p| s + p.coords) / pts.len() as f64;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in &pts {
        let d = p.coords - c;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    // Principal direction of the scatter.
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let dir = Vector2::new(theta.cos(), theta.sin());
    (dir.dot(&along).abs() > 0.9).then_some(Line {
        point: Point2::from(c),
        dir,
    })
}
