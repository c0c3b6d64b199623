//! A candidate quad's corners to sub-pixel: each side's line is fitted to
//! gradient maxima sampled across it; neighbouring lines meet at the
//! corners.

use super::quads::Quad;
use crate::image::GrayImage;
use nalgebra::{Point2, Vector2};

/// Sample points per side for the edge fit.
const EDGE_SAMPLES: usize = 12;
/// Search half-length across a side, pixels.
const EDGE_SEARCH_PX: f64 = 2.5;
/// Step of the profile across a side, pixels.
const STEP_PX: f64 = 0.25;
/// Profile samples: -EDGE_SEARCH_PX..=EDGE_SEARCH_PX in steps of STEP_PX.
const PROFILE: usize = 21;
/// A refined corner further than this from the candidate's is not trusted
/// (the candidate is kept as it was), pixels.
const MAX_CORNER_SHIFT_PX: f64 = 3.0;

/// Sub-pixel corners from lines fitted to each side's gradient maxima.
/// When that fails on a candidate from a `scale` times smaller image, it
/// is fitted with a search (and step) `scale` times wider first, then
/// again as one from the frame.
pub(super) fn refine_quad(img: &GrayImage, q: Quad, scale: f64) -> Quad {
    let fine = fit_quad(img, q.clone(), 1.0);
    if scale <= 1.0 || fine.corners != q.corners {
        return fine;
    }
    fit_quad(img, fit_quad(img, q, scale), 1.0)
}

/// One fit with the search and step scaled by `scale`; the quad unchanged
/// when a side cannot be fitted.
fn fit_quad(img: &GrayImage, q: Quad, scale: f64) -> Quad {
    let mut lines = Vec::with_capacity(4);
    for k in 0..4 {
        let (a, b) = (q.corners[k], q.corners[(k + 1) % 4]);
        match edge_line(img, a, b, scale) {
            Some(l) => lines.push(l),
            None => return q,
        }
    }
    let mut corners = q.corners;
    for k in 0..4 {
        // Corner k is where side k-1 meets side k.
        let (l0, l1) = (&lines[(k + 3) % 4], &lines[k]);
        match intersect(l0, l1) {
            Some(p) if (p - q.corners[k]).norm() < MAX_CORNER_SHIFT_PX * scale => corners[k] = p,
            _ => return q,
        }
    }
    Quad { corners }
}

/// A line through `point` along the unit vector `dir`.
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

/// Bilinear grey level at (x, y), clamped to the image.
fn bilinear(img: &GrayImage, x: f64, y: f64) -> f64 {
    let (w, h) = (img.width as usize, img.height as usize);
    let x = x.clamp(0.0, (w - 1) as f64);
    let y = y.clamp(0.0, (h - 1) as f64);
    // Non-negative after the clamp: truncation is the floor.
    let (x0, y0) = (x as usize, y as usize);
    let (fx, fy) = (x - x0 as f64, y - y0 as f64);
    let dx = usize::from(x0 + 1 < w);
    let dy = if y0 + 1 < h { w } else { 0 };
    let i = y0 * w + x0;
    let p = &img.pixels;
    let top = f64::from(p[i]) + (f64::from(p[i + dx]) - f64::from(p[i])) * fx;
    let bottom = f64::from(p[i + dy]) + (f64::from(p[i + dy + dx]) - f64::from(p[i + dy])) * fx;
    top + (bottom - top) * fy
}

/// The edge between `a` and `b`: gradient maxima across the side at
/// [`EDGE_SAMPLES`] points in its middle 70 %, then a total-least-squares
/// line.
fn edge_line(img: &GrayImage, a: Point2<f64>, b: Point2<f64>, scale: f64) -> Option<Line> {
    let (search, step_px) = (EDGE_SEARCH_PX * scale, STEP_PX * scale);
    let along = (b - a).try_normalize(1e-12)?;
    let normal = Vector2::new(-along.y, along.x);
    let mut pts = [Point2::origin(); EDGE_SAMPLES];
    let mut n = 0;
    let mut profile = [0.0; PROFILE];
    for s in 0..EDGE_SAMPLES {
        let t = 0.15 + 0.7 * (s as f64 + 0.5) / EDGE_SAMPLES as f64;
        let base = a + (b - a) * t;
        // Profile across the edge; its derivative's peak magnitude.
        let start = base - normal * search;
        let step = normal * step_px;
        for (i, v) in profile.iter_mut().enumerate() {
            let p = start + step * i as f64;
            *v = bilinear(img, p.x, p.y);
        }
        let grad = |i: usize| (profile[i + 2] - profile[i]).abs();
        let (mut imax, mut gmax) = (0, grad(0));
        for i in 1..PROFILE - 2 {
            let g = grad(i);
            if g >= gmax {
                (imax, gmax) = (i, g);
            }
        }
        if gmax < 4.0 || imax == 0 || imax + 1 >= PROFILE - 2 {
            continue;
        }
        let (l, c, r) = (grad(imax - 1), gmax, grad(imax + 1));
        let den = l - 2.0 * c + r;
        let off = if den.abs() > 1e-12 {
            0.5 * (l - r) / den
        } else {
            0.0
        };
        let o = -search + (imax as f64 + 1.0 + off) * step_px;
        pts[n] = base + normal * o;
        n += 1;
    }
    if n < EDGE_SAMPLES / 2 {
        return None;
    }
    let pts = &pts[..n];
    let c = pts.iter().fold(Vector2::zeros(), |s, p| s + p.coords) / n as f64;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in pts {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A dark square (grey 40 on 200) from (x0, y0) to (x0 + s, y0 + s),
    /// its edges smooth steps (logistic, scale 0.6 px: about the renders'
    /// blur), sampled at the pixel centres.
    fn square(w: u32, h: u32, x0: f64, y0: f64, s: f64) -> GrayImage {
        let step = |t: f64| 1.0 / (1.0 + (-t / 0.6).exp());
        let inside = |v: f64, lo: f64| step(v - lo) - step(v - lo - s);
        let mut pixels = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let f = inside(x as f64, x0) * inside(y as f64, y0);
                pixels.push((200.0 - 160.0 * f).round() as u8);
            }
        }
        GrayImage {
            width: w,
            height: h,
            pixels,
        }
    }

    #[test]
    fn refined_corners_come_within_half_a_pixel_from_1_2_px_off() {
        // Edges at x = 20.3 and 50.3, y = 15.7 and 45.7; the candidate is
        // off by up to 1.2 px. The profile is bilinear between pixel
        // centres, so its gradient is flat between the two centres around
        // a steep edge and the peak may land anywhere on that pixel: up to
        // 0.5 px (measured 0.17-0.32 px here). These corners only seed
        // decoding and the saddle fits, which give the reported points.
        let img = square(80, 60, 20.3, 15.7, 30.0);
        let truth = [(20.3, 15.7), (50.3, 15.7), (50.3, 45.7), (20.3, 45.7)];
        let q = Quad {
            corners: [
                Point2::new(21.0, 16.5),
                Point2::new(49.4, 15.0),
                Point2::new(51.5, 45.0),
                Point2::new(20.0, 46.5),
            ],
        };
        let r = refine_quad(&img, q, 1.0);
        for (c, t) in r.corners.iter().zip(truth) {
            assert!((c - Point2::new(t.0, t.1)).norm() < 0.5, "{c} vs {t:?}");
        }
    }

    #[test]
    fn a_flat_image_leaves_the_quad_unchanged() {
        let img = GrayImage {
            width: 40,
            height: 40,
            pixels: vec![128; 1600],
        };
        let c = [(10.0, 10.0), (30.0, 10.0), (30.0, 30.0), (10.0, 30.0)]
            .map(|(x, y)| Point2::new(x, y));
        let r = refine_quad(&img, Quad { corners: c }, 2.0);
        assert_eq!(r.corners, c);
    }
}
