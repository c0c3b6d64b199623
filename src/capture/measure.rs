//! Per-frame measures of live capture: how blurred the board is and how far
//! its points moved over the last frames.

use crate::image::GrayImage;
use crate::target::DetectedPoint;

/// Gradient samples taken at most on the board's region (rows and columns
/// are strided beyond it), bounding the cost on large frames.
const MAX_SAMPLES: usize = 250_000;
/// Percentile of the gradient magnitudes taken as the edge strength: the
/// strongest edges, yet above isolated noise.
const EDGE_PERCENTILE: f64 = 0.98;
/// Percentiles of the grey levels taken as the board's dark and light.
const CONTRAST_PERCENTILES: (f64, f64) = (0.05, 0.95);

/// The blur of the board in a frame, as the sigma (px) of the Gaussian blur
/// that would give its strongest edges their slope:
/// `contrast / (sqrt(2 pi) g)`, where `contrast` is the spread of the grey levels on the board's
/// region (95th minus 5th percentile) and `g` the 98th percentile of the
/// gradient magnitude there (central differences). Relative to the board's
/// own contrast, so independent of exposure and lighting. A focused render
/// (blur sigma 0.7 px) measures about 1 px (the central difference smooths
/// too), a blur of sigma 2.5 px about 2.6 px. The region is the bounding
/// box of the detected points. `None` when the region is under 3x3 pixels
/// or flat.
pub fn blur_px(image: &GrayImage, points: &[DetectedPoint]) -> Option<f64> {
    let (w, h) = (image.width as usize, image.height as usize);
    if points.is_empty() || w < 3 || h < 3 {
        return None;
    }
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for p in points {
        (x0, y0) = (x0.min(p.x_px), y0.min(p.y_px));
        (x1, y1) = (x1.max(p.x_px), y1.max(p.y_px));
    }
    let clamp = |v: f64, n: usize| v.round().clamp(1.0, (n - 2) as f64) as usize;
    let (x0, x1, y0, y1) = (clamp(x0, w), clamp(x1, w), clamp(y0, h), clamp(y1, h));
    if x1 < x0 + 2 || y1 < y0 + 2 {
        return None;
    }
    let area = (x1 - x0 + 1) * (y1 - y0 + 1);
    let stride = ((area as f64 / MAX_SAMPLES as f64).sqrt().ceil() as usize).max(1);
    let px = |x: usize, y: usize| image.pixels[y * w + x] as f64;
    let mut grey = Vec::new();
    let mut gradient = Vec::new();
    for y in (y0..=y1).step_by(stride) {
        for x in (x0..=x1).step_by(stride) {
            grey.push(px(x, y));
            let gx = 0.5 * (px(x + 1, y) - px(x - 1, y));
            let gy = 0.5 * (px(x, y + 1) - px(x, y - 1));
            gradient.push(gx.hypot(gy));
        }
    }
    let contrast = percentile(&mut grey, CONTRAST_PERCENTILES.1)
        - percentile(&mut grey, CONTRAST_PERCENTILES.0);
    let edge = percentile(&mut gradient, EDGE_PERCENTILE);
    (contrast > 0.0 && edge > 0.0).then(|| contrast / ((2.0 * std::f64::consts::PI).sqrt() * edge))
}

fn percentile(values: &mut [f64], q: f64) -> f64 {
    let k = ((values.len() - 1) as f64 * q).round() as usize;
    let (_, v, _) = values.select_nth_unstable_by(k, f64::total_cmp);
    *v
}

/// The largest distance (px) any point moved between `a` and `b`, over the
/// ids both hold (points sorted by id, as detections are); `None` when they
/// share no id.
pub fn motion_px(a: &[DetectedPoint], b: &[DetectedPoint]) -> Option<f64> {
    let (mut i, mut j) = (0, 0);
    let mut worst: Option<f64> = None;
    while i < a.len() && j < b.len() {
        match a[i].id.cmp(&b[j].id) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                let d = (a[i].x_px - b[j].x_px).hypot(a[i].y_px - b[j].y_px);
                worst = Some(worst.map_or(d, |w| w.max(d)));
                i += 1;
                j += 1;
            }
        }
    }
    worst
}
