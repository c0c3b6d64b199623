//! Seeded board-free clutter: images with many dark and light quadrilaterals,
//! ellipses and strokes on a shaded background, for checking that a marker
//! detector finds no marker where there is none. The quads (and quads
//! painted over quads) are what a marker detector's candidate stage takes
//! for marker outlines, so every one of them reaches the bit decoder.

use super::Rng;
use crate::image::GrayImage;

/// Shapes per megapixel (drawn with the painter's algorithm, later on top).
const SHAPES_PER_MPX: f64 = 150.0;

/// One shape: an inside test in pixel coordinates and its bounding box.
enum Shape {
    /// Convex quad, corners in order.
    Quad([(f64, f64); 4]),
    /// Ellipse: centre, half-axes, angle.
    Ellipse((f64, f64), (f64, f64), f64),
    /// Stroke from a to b with half-width w.
    Stroke((f64, f64), (f64, f64), f64),
}

impl Shape {
    fn inside(&self, x: f64, y: f64) -> bool {
        match self {
            Shape::Quad(c) => (0..4).all(|i| {
                let (a, b) = (c[i], c[(i + 1) % 4]);
                (b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0) >= 0.0
            }),
            Shape::Ellipse((cx, cy), (a, b), t) => {
                let (s, c) = t.sin_cos();
                let (dx, dy) = (x - cx, y - cy);
                let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
                (u / a).powi(2) + (v / b).powi(2) <= 1.0
            }
            Shape::Stroke(a, b, w) => {
                let (dx, dy) = (b.0 - a.0, b.1 - a.1);
                let l2 = dx * dx + dy * dy;
                let t = (((x - a.0) * dx + (y - a.1) * dy) / l2).clamp(0.0, 1.0);
                let (px, py) = (a.0 + t * dx - x, a.1 + t * dy - y);
                px * px + py * py <= w * w
            }
        }
    }

    fn bounds(&self) -> (f64, f64, f64, f64) {
        let pts: Vec<(f64, f64)> = match self {
            Shape::Quad(c) => c.to_vec(),
            Shape::Ellipse((cx, cy), (a, b), _) => {
                let r = a.max(*b);
                vec![(cx - r, cy - r), (cx + r, cy + r)]
            }
            Shape::Stroke(a, b, w) => vec![
                (a.0.min(b.0) - w, a.1.min(b.1) - w),
                (a.0.max(b.0) + w, a.1.max(b.1) + w),
            ],
        };
        pts.iter().fold(
            (f64::MAX, f64::MAX, f64::MIN, f64::MIN),
            |(x0, y0, x1, y1), p| (x0.min(p.0), y0.min(p.1), x1.max(p.0), y1.max(p.1)),
        )
    }
}

fn random_shape(rng: &mut Rng, w: f64, h: f64) -> Shape {
    let (cx, cy) = (rng.range(0.0, w), rng.range(0.0, h));
    let size = rng.range(8.0, 0.15 * w.min(h));
    match rng.below(4) {
        // Quads twice as often: they are the marker-like shapes.
        0 | 1 => {
            let t = rng.range(0.0, std::f64::consts::TAU);
            let aspect = rng.range(0.5, 2.0);
            let (hx, hy) = (size * aspect.sqrt() / 2.0, size / aspect.sqrt() / 2.0);
            let (s, c) = t.sin_cos();
            let mut corner = |u: f64, v: f64| {
                let j = 0.15 * size;
                (
                    cx + c * u - s * v + rng.range(-j, j),
                    cy + s * u + c * v + rng.range(-j, j),
                )
            };
            let mut q = [(0.0, 0.0); 4];
            for (k, (u, v)) in [(-hx, -hy), (-hx, hy), (hx, hy), (hx, -hy)]
                .iter()
                .enumerate()
            {
                q[k] = corner(*u, *v);
            }
            // `inside` wants the order with a positive shoelace sum.
            let area2: f64 = (0..4)
                .map(|i| q[i].0 * q[(i + 1) % 4].1 - q[(i + 1) % 4].0 * q[i].1)
                .sum();
            if area2 < 0.0 {
                q.reverse();
            }
            Shape::Quad(q)
        }
        2 => Shape::Ellipse(
            (cx, cy),
            (size / 2.0, rng.range(0.3, 1.0) * size / 2.0),
            rng.range(0.0, std::f64::consts::PI),
        ),
        _ => {
            let t = rng.range(0.0, std::f64::consts::TAU);
            let l = rng.range(2.0, 4.0) * size;
            Shape::Stroke(
                (cx, cy),
                (cx + l * t.cos(), cy + l * t.sin()),
                rng.range(1.0, 6.0),
            )
        }
    }
}

/// A `width` x `height` clutter image from `seed`: a shaded background,
/// about 150 shapes per megapixel in random grey levels (2 x 2 subsamples
/// per pixel at their edges), then Gaussian noise of `noise_sigma` grey
/// levels. Deterministic for a seed on every platform.
pub fn clutter(width: u32, height: u32, seed: u64, noise_sigma: f64) -> GrayImage {
    let mut rng = Rng::new(seed);
    let (w, h) = (width as f64, height as f64);
    let (g0, gx, gy) = (
        rng.range(80.0, 180.0),
        rng.range(-60.0, 60.0),
        rng.range(-60.0, 60.0),
    );
    let mut plane: Vec<f64> = (0..height)
        .flat_map(|y| (0..width).map(move |x| g0 + gx * x as f64 / w + gy * y as f64 / h))
        .collect();
    let count = (SHAPES_PER_MPX * w * h / 1e6).round() as usize;
    for _ in 0..count {
        let shape = random_shape(&mut rng, w, h);
        let grey = rng.range(0.0, 255.0);
        let (x0, y0, x1, y1) = shape.bounds();
        let xs = x0.floor().max(0.0) as u32..(x1.ceil().min(w - 1.0).max(0.0) as u32 + 1);
        for y in y0.floor().max(0.0) as u32..(y1.ceil().min(h - 1.0).max(0.0) as u32 + 1) {
            for x in xs.clone() {
                let covered = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)]
                    .iter()
                    .filter(|(dx, dy)| shape.inside(x as f64 + dx, y as f64 + dy))
                    .count() as f64
                    / 4.0;
                let p = &mut plane[(y * width + x) as usize];
                *p += covered * (grey - *p);
            }
        }
    }
    let pixels = plane
        .iter()
        .map(|v| (v + noise_sigma * rng.normal()).round().clamp(0.0, 255.0) as u8)
        .collect();
    GrayImage::new(width, height, pixels).expect("width * height pixels")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clutter_is_seeded_and_full_of_contrast() {
        // The size and seed of tests/detect/detect_markers.rs and the comparison.
        let a = clutter(1280, 960, 500, 2.0);
        assert_eq!(a.pixels, clutter(1280, 960, 500, 2.0).pixels);
        assert_ne!(a.pixels, clutter(1280, 960, 501, 2.0).pixels);
        // Shapes in random grey levels: both dark and light areas (about a
        // tenth of the image each for this seed).
        let n = a.pixels.len();
        assert!(a.pixels.iter().filter(|&&p| p < 60).count() > n / 20);
        assert!(a.pixels.iter().filter(|&&p| p > 200).count() > n / 20);
    }
}
