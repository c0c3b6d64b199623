//! Dark blobs: a locally adaptive threshold, connected components with
//! moments ([`super::runs`]), and sub-pixel ellipse refinement at full
//! resolution.
//!
//! A pixel is "dark" when it lies below the local mean (box window of an
//! eighth of the image) by a quarter of the local mean's distance to the
//! image's 5th-percentile grey level (at least 8 levels): robust to
//! vignetting and gradients, and the exact edges come from the sub-pixel
//! step below, not from the threshold.

use super::ellipse::{fit_ellipse, EllipseFit};
use super::runs;
use crate::image::filter::Plane;
use crate::image::GrayImage;
use nalgebra::{Matrix2, Point2, Vector2};

/// Smallest blob kept, pixels at the working level.
pub(crate) const MIN_BLOB_AREA_PX: f64 = 6.0;
/// Accepted ratio of a blob's area to the area of its moment ellipse.
const FILL_RANGE: (f64, f64) = (0.7, 1.3);
/// Largest major/minor axis ratio (a circle seen at ~80 degrees tilt).
const MAX_ELONGATION: f64 = 6.0;
/// Rays cast from the centre to find edge points.
const RAYS: usize = 64;

/// A connected dark region at the working level.
#[derive(Debug, Clone)]
pub(crate) struct Blob {
    pub centre: Point2<f64>,
    pub area: f64,
    /// Second central moments (pixels^2), including the pixel's own 1/12.
    pub cov: Matrix2<f64>,
}

/// Dark blobs of `plane` (set `invert` for light blobs), larger first.
pub(crate) fn find_blobs(plane: &Plane, invert: bool) -> Vec<Blob> {
    let runs = runs::dark_runs_plane(plane, invert);
    blobs_of(&runs::components(&runs), plane.w, plane.h)
}

/// [`find_blobs`] on the 8-bit image itself (the same blobs as on its
/// float plane, without the plane), for images that fit
/// [`runs::fits_u8`]; the float path otherwise.
pub(crate) fn find_blobs_gray(img: &GrayImage, invert: bool) -> Vec<Blob> {
    if !runs::fits_u8(img) {
        return find_blobs(&Plane::from_gray(img), invert);
    }
    let runs = runs::dark_runs_u8(img, invert);
    blobs_of(
        &runs::components(&runs),
        img.width as usize,
        img.height as usize,
    )
}

/// The components that look like filled ellipses, larger first (equal
/// areas in raster order of their first pixel).
fn blobs_of(components: &[runs::Moments], w: usize, h: usize) -> Vec<Blob> {
    let max_area = (w * h) as f64 / 4.0;
    let mut blobs: Vec<Blob> = components
        .iter()
        .filter_map(|m| {
            let n = m.n as f64;
            if n < MIN_BLOB_AREA_PX || n > max_area || m.border {
                return None;
            }
            let (cx, cy) = (m.sx as f64 / n, m.sy as f64 / n);
            let cov = Matrix2::new(
                m.sxx as f64 / n - cx * cx + 1.0 / 12.0,
                m.sxy as f64 / n - cx * cy,
                m.sxy as f64 / n - cx * cy,
                m.syy as f64 / n - cy * cy + 1.0 / 12.0,
            );
            let det = cov.determinant();
            if det <= 0.0 {
                return None;
            }
            let fill = n / (4.0 * std::f64::consts::PI * det.sqrt());
            let eig = cov.symmetric_eigenvalues();
            let elong = (eig.max() / eig.min().max(1e-9)).sqrt();
            (fill >= FILL_RANGE.0 && fill <= FILL_RANGE.1 && elong <= MAX_ELONGATION).then(|| {
                Blob {
                    centre: Point2::new(cx, cy),
                    area: n,
                    cov,
                }
            })
        })
        .collect();
    blobs.sort_by(|a, b| b.area.total_cmp(&a.area));
    blobs
}

/// A blob's sub-pixel outline: the ellipse fitted to its edge points, and
/// the points themselves (full-resolution pixels), which the
/// perspective-correct centres of [`super::centres`] fit again in board
/// coordinates.
#[derive(Debug, Clone)]
pub(crate) struct Outline {
    pub ellipse: EllipseFit,
    pub edges: Vec<Point2<f64>>,
}

/// Sub-pixel ellipse of a dark blob at full resolution. `centre`/`cov` are
/// the blob's moments scaled to full resolution; edge points are where each
/// ray's profile crosses the mid level between the blob's inside and the
/// background just outside it, moved to the centroid of the gradient there
/// ([`gradient_centroid`]).
pub(crate) fn refine_blob(
    img: &GrayImage,
    centre: Point2<f64>,
    cov: &Matrix2<f64>,
    invert: bool,
) -> Option<Outline> {
    let plane_at = |x: f64, y: f64| -> f64 {
        let v = bilinear_u8(img, x, y);
        if invert {
            255.0 - v
        } else {
            v
        }
    };
    let cov_inv = cov.try_inverse()?;
    // Each ray's direction and its reach: the moment ellipse's boundary
    // (Mahalanobis distance 2), the same for both passes.
    let rays: Vec<(Vector2<f64>, f64)> = (0..RAYS)
        .map(|k| {
            let phi = k as f64 / RAYS as f64 * std::f64::consts::TAU;
            let d = Vector2::new(phi.cos(), phi.sin());
            (d, 2.0 / (d.transpose() * cov_inv * d)[(0, 0)].sqrt())
        })
        .collect();
    let mut c = centre;
    let mut fit = None;
    let mut line = Vec::new();
    for pass in 0..2 {
        // The first pass only re-centres the rays; the gradient centroid
        // (most of the time spent here) is for the edges that are kept.
        let centroid = pass == 1;
        let mut edges = Vec::with_capacity(RAYS);
        for &(d, r) in &rays {
            let ray = Ray { img, invert, c, d };
            if let Some(e) = edge_on_ray(&ray, &plane_at, r, centroid, &mut line) {
                edges.push(e);
            }
        }
        if edges.len() < RAYS / 2 {
            return None;
        }
        let f = fit_ellipse(&edges)?;
        // The fitted ellipse must resemble the moment ellipse (semi-axis 2 sd).
        if (f.centre - centre).norm() > 2.0 * cov.trace().sqrt()
            || f.semi_axes.0 > 4.0 * cov.trace().sqrt()
        {
            return None;
        }
        c = f.centre;
        fit = Some(Outline { ellipse: f, edges });
    }
    fit
}

/// Half-width of the window along a ray over which an edge point is the
/// centroid of the intensity gradient, px (bounded by 0.3 of the blob's
/// radius so a small dot's window stays on its own edge). It covers the
/// edge of the renders' 0.7 px blur and of a lens slightly out of focus;
/// 1.5-3.5 px gave the same centre errors on the renders of
/// tests/detect/detect_circles.rs (docs/benchmark-history.md, issue 20, session 16).
const EDGE_HALF_WINDOW_PX: f64 = 2.5;
/// Sample spacing of that window, px.
const EDGE_SAMPLE_PX: f64 = 0.25;
/// Passes of the centroid (each re-centres the window on the last one).
const EDGE_CENTROID_PASSES: usize = 4;
/// How far the centroid may move from the mid-level crossing, px: the two
/// differ by a fraction of the blur on an edge, so a larger move is the
/// window reaching a neighbouring edge, not this one.
const EDGE_CENTROID_TRAVEL_PX: f64 = 1.0;

/// A ray `c + t d` through the image (its profile inverted for a light
/// blob on a dark ground).
struct Ray<'a> {
    img: &'a GrayImage,
    invert: bool,
    c: Point2<f64>,
    d: Vector2<f64>,
}

impl Ray<'_> {
    /// The profile at `t0 + k step`, `k < count`, into `out`
    /// ([`bilinear_line`]: one pass along the line).
    fn profile(&self, t0: f64, step: f64, count: usize, out: &mut Vec<f64>) {
        bilinear_line(self.img, self.c, self.d, (t0, step), count, out);
        if self.invert {
            out.iter_mut().for_each(|v| *v = 255.0 - *v);
        }
    }
}

/// Samples of the march in [`edge_on_ray`] taken along the line at once.
const MARCH_CHUNK: usize = 16;

/// Edge point on the ray `c + t d` where the profile rises through the
/// mid level between the blob's inside and the background just outside,
/// then, with `centroid`, moved to the centroid of the gradient around it
/// ([`gradient_centroid`]). `sample` is the point sampler of the level's
/// six samples; the march takes the profile in chunks along the line.
fn edge_on_ray(
    ray: &Ray,
    sample: &impl Fn(f64, f64) -> f64,
    r: f64,
    centroid: bool,
    line: &mut Vec<f64>,
) -> Option<Point2<f64>> {
    let (c, d) = (ray.c, ray.d);
    let at = |t: f64| sample(c.x + d.x * t, c.y + d.y * t);
    let inside = (at(0.35 * r) + at(0.45 * r) + at(0.55 * r)) / 3.0;
    let outside = (at(1.45 * r + 1.0) + at(1.55 * r + 1.0) + at(1.65 * r + 1.0)) / 3.0;
    if outside - inside < 4.0 {
        return None;
    }
    let level = 0.5 * (inside + outside);
    let step = 0.25;
    let start = 0.55 * r;
    let end = 1.45 * r + 1.0;
    // Steps k = 0, 1, ... while start + k step < end, each comparing the
    // sample at k with the one at k + 1.
    let steps = ((end - start) / step).ceil().max(0.0) as usize;
    let mut prev = at(start);
    let mut k0 = 0;
    while k0 < steps {
        let n = MARCH_CHUNK.min(steps - k0);
        ray.profile(start + (k0 + 1) as f64 * step, step, n, line);
        for (i, &v) in line.iter().enumerate() {
            if prev < level && v >= level {
                let f = (level - prev) / (v - prev);
                let te = start + (k0 + i) as f64 * step + f * step;
                let te = if centroid {
                    gradient_centroid(ray, te, EDGE_HALF_WINDOW_PX.min(0.3 * r), line)
                } else {
                    te
                };
                return Some(Point2::new(c.x + d.x * te, c.y + d.y * te));
            }
            prev = v;
        }
        k0 += n;
    }
    None
}

/// The centroid of the rising gradient `at(s + 0.5) - at(s - 0.5)` over
/// the window `[te - hw, te + hw]`, re-centred on itself until it stops
/// moving (at most [`EDGE_CENTROID_PASSES`] times) and kept within
/// [`EDGE_CENTROID_TRAVEL_PX`] of the crossing `t0` it starts from; `t0`
/// when the window has no rising gradient. The profile is sampled once, on
/// a grid of [`EDGE_SAMPLE_PX`] steps from `t0` (the gradient's half-pixel
/// offsets are whole grid steps), and the passes sum over it.
///
/// Why not the mid-level crossing alone: that crossing moves with any error
/// of the level, which is estimated from a few samples inside and outside
/// the blob (pulled by vignetting, a neighbouring circle, the blur of a
/// curved edge). The gradient's centroid needs no level: it is the edge of
/// a blurred step whatever the step's two grey levels are. Measured on the
/// noise-free renders of tests/calib/calib_circles.rs (9x6 grid, 30 mm, one
/// draw): the crossing left a systematic floor of 0.006-0.009 px mean under
/// the centres, the centroid 0.0023-0.0038 px, and the intrinsics error
/// from the twelve views fell from 0.136 to 0.041 px through the strongly
/// distorted camera, from 0.056 to 0.009 px through the 'std' one
/// (docs/benchmark-history.md, issue 20, session 16).
fn gradient_centroid(ray: &Ray, t0: f64, hw: f64, profile: &mut Vec<f64>) -> f64 {
    let ds = EDGE_SAMPLE_PX;
    // Offsets of the gradient's sample points from t0, in grid steps: the
    // window's reach (travel + half-width) and the half pixel either side.
    let half_pixel = (0.5 / ds).round() as i64;
    let reach = ((EDGE_CENTROID_TRAVEL_PX + hw) / ds).ceil() as i64;
    let first = -reach - half_pixel;
    let count = (2 * (reach + half_pixel) + 1) as usize;
    ray.profile(t0 + first as f64 * ds, ds, count, profile);
    let profile = &*profile;
    // Gradient at grid offset j (|j| <= reach), from the profile above.
    let gradient = |j: i64| {
        let k = (j + reach + half_pixel) as usize;
        profile[k + half_pixel as usize] - profile[k - half_pixel as usize]
    };
    let mut te = t0;
    for _ in 0..EDGE_CENTROID_PASSES {
        let (mut sum_w, mut sum_ws) = (0.0, 0.0);
        for j in -reach..=reach {
            let s = t0 + j as f64 * ds;
            // Each grid point stands for the step of width ds around it:
            // the part of that step inside the window weighs (so the sum
            // moves smoothly with te, not by whole steps).
            let inside = ((hw - (s - te).abs()) / ds + 0.5).clamp(0.0, 1.0);
            let g = gradient(j) * inside;
            if g > 0.0 {
                sum_w += g;
                sum_ws += g * s;
            }
        }
        if sum_w <= 0.0 {
            break;
        }
        let next =
            (sum_ws / sum_w).clamp(t0 - EDGE_CENTROID_TRAVEL_PX, t0 + EDGE_CENTROID_TRAVEL_PX);
        let moved = (next - te).abs();
        te = next;
        if moved < 1e-3 {
            break;
        }
    }
    te
}

/// `v.floor()` without the libm call that x86-64's baseline (no SSE4.1)
/// makes of it: a truncation moved down for negative non-integers. Exact
/// for every |v| < 2^52 (and NaN gives NaN downstream as before); larger
/// values take `floor` itself.
#[inline]
fn floor(v: f64) -> f64 {
    if v.abs() < 4.5e15 {
        let t = v as i64 as f64;
        if t > v {
            t - 1.0
        } else {
            t
        }
    } else {
        v.floor()
    }
}

#[inline(always)]
pub(crate) fn bilinear_u8(img: &GrayImage, x: f64, y: f64) -> f64 {
    let (w, h) = (img.width as isize, img.height as isize);
    let (x0, y0) = (floor(x), floor(y));
    let (fx, fy) = (x - x0, y - y0);
    let get = |xi: isize, yi: isize| -> f64 {
        let xc = xi.clamp(0, w - 1) as usize;
        let yc = yi.clamp(0, h - 1) as usize;
        img.pixels[yc * w as usize + xc] as f64
    };
    let (xi, yi) = (x0 as isize, y0 as isize);
    if xi >= 0 && yi >= 0 && xi + 1 < w && yi + 1 < h {
        // Inside: the four pixels without clamping (the same value).
        let i = yi as usize * w as usize + xi as usize;
        let row = &img.pixels[i..i + 2];
        let next = &img.pixels[i + w as usize..i + w as usize + 2];
        return (row[0] as f64 * (1.0 - fx) + row[1] as f64 * fx) * (1.0 - fy)
            + (next[0] as f64 * (1.0 - fx) + next[1] as f64 * fx) * fy;
    }
    (get(xi, yi) * (1.0 - fx) + get(xi + 1, yi) * fx) * (1.0 - fy)
        + (get(xi, yi + 1) * (1.0 - fx) + get(xi + 1, yi + 1) * fx) * fy
}

/// Fraction bits of [`bilinear_line`]'s fixed-point positions.
const FIXED_BITS: u32 = 20;

/// Bilinear samples of `img` at `base + n * (s0 + k * step)`, `k < count`,
/// into `out` (cleared first): the values of [`bilinear_u8`] at each point
/// (to 1e-4 px in position), without its per-sample floor and clamping
/// when the whole line lies inside the image (the points are monotone in
/// `k`, so the two ends decide).
pub(crate) fn bilinear_line(
    img: &GrayImage,
    base: Point2<f64>,
    n: Vector2<f64>,
    (s0, step): (f64, f64),
    count: usize,
    out: &mut Vec<f64>,
) {
    out.clear();
    if count == 0 {
        return;
    }
    let at = |k: usize| base + n * (s0 + k as f64 * step);
    let (w, h) = (img.width as f64, img.height as f64);
    // floor(x) >= 0 and floor(x) + 1 < w, as in `bilinear_u8`'s inside test.
    let inside = |p: Point2<f64>| p.x >= 0.0 && p.y >= 0.0 && p.x < w - 1.0 && p.y < h - 1.0;
    if !(inside(at(0)) && inside(at(count - 1))) {
        out.extend((0..count).map(|k| {
            let p = at(k);
            bilinear_u8(img, p.x, p.y)
        }));
        return;
    }
    // Fixed point (1/2^20 px) stepping: the positions drift by at most
    // count * 2^-21 px (1e-4 px over 200 samples), far below the noise.
    const ONE: f64 = (1u64 << FIXED_BITS) as f64;
    let p0 = at(0);
    let (mut fx_x, mut fx_y) = ((p0.x * ONE) as i64, (p0.y * ONE) as i64);
    let (dx, dy) = (
        (n.x * step * ONE).round() as i64,
        (n.y * step * ONE).round() as i64,
    );
    let stride = img.width as usize;
    let px = &img.pixels[..];
    let last = (img.width as usize) * (img.height as usize) - 1;
    let mask = (1i64 << FIXED_BITS) - 1;
    out.reserve(count);
    for _ in 0..count {
        // Never below 0 (the drift can carry an end at 0 just under it).
        let (qx, qy) = (fx_x.max(0), fx_y.max(0));
        let (xi, yi) = ((qx >> FIXED_BITS) as usize, (qy >> FIXED_BITS) as usize);
        let fx = (qx & mask) as f64 * (1.0 / ONE);
        let fy = (qy & mask) as f64 * (1.0 / ONE);
        // The rounding of the step can carry the last sample just past
        // the last column or row: clamp the index instead of panicking.
        let i = (yi * stride + xi).min(last.saturating_sub(stride + 1));
        // One bounds check per row pair.
        let (top, bottom) = (&px[i..i + 2], &px[i + stride..i + stride + 2]);
        let (a, b) = (top[0] as f64, top[1] as f64);
        let (c, d) = (bottom[0] as f64, bottom[1] as f64);
        out.push((a * (1.0 - fx) + b * fx) * (1.0 - fy) + (c * (1.0 - fx) + d * fx) * fy);
        fx_x += dx;
        fx_y += dy;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn fast_floor_is_floor() {
        for v in [
            0.0,
            0.5,
            1.0,
            -0.5,
            -1.0,
            -1.5,
            2.9999999999999996,
            -1e-300,
            1e15 + 0.5,
            -7.0,
            1e300,
            -1e300,
        ] {
            assert_eq!(floor(v), v.floor(), "{v}");
        }
        assert!(floor(f64::NAN).is_nan());
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn finds_and_refines_an_anti_aliased_disc() {
        let (w, h, cx, cy, rad) = (64usize, 48usize, 30.37, 22.81, 9.0);
        let ss = 8;
        let px: Vec<u8> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                let mut inside = 0;
                for sy in 0..ss {
                    for sx in 0..ss {
                        let u = x - 0.5 + (sx as f64 + 0.5) / ss as f64 - cx;
                        let v = y - 0.5 + (sy as f64 + 0.5) / ss as f64 - cy;
                        inside += (u * u + v * v < rad * rad) as i32;
                    }
                }
                (210.0 - 170.0 * inside as f64 / (ss * ss) as f64).round() as u8
            })
            .collect();
        let img = GrayImage::new(w as u32, h as u32, px).unwrap();
        let blobs = find_blobs(&Plane::from_gray(&img), false);
        assert_eq!(blobs.len(), 1);
        let f = refine_blob(&img, blobs[0].centre, &blobs[0].cov, false)
            .unwrap()
            .ellipse;
        // Supersampling and 8-bit rounding: truth within ~0.02 px.
        assert!(
            (f.centre.x - cx).abs() < 0.02 && (f.centre.y - cy).abs() < 0.02,
            "{:?}",
            f.centre
        );
        assert!((f.semi_axes.0 - rad).abs() < 0.1, "{:?}", f.semi_axes);
    }
}
