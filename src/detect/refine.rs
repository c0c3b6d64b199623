//! Sub-pixel saddle-point refinement at full resolution.
//!
//! Model: around a chessboard corner the Gaussian-smoothed image is
//! point-symmetric, so its saddle point (zero gradient, `det H < 0`) is the
//! corner. A quadratic surface `a u^2 + b u v + c v^2 + d u + e v + f` is
//! fitted by Gaussian-weighted least squares on the smoothed patch, the
//! window is moved to the surface's saddle point and the fit repeated until
//! the step is below 0.002 px. Because the window is symmetric about the
//! final estimate, the odd terms of a point-symmetric pattern vanish there:
//! the estimate has no bias from the quadratic model's misfit.

use super::filter::Plane;
use crate::image::GrayImage;
use nalgebra::{Matrix2, Matrix6, Point2, Vector2, Vector6};

/// Iterations of the move-and-refit loop.
const MAX_ITERATIONS: usize = 10;
/// Convergence threshold on the step, pixels.
const STEP_TOLERANCE_PX: f64 = 0.002;

/// A refined corner.
#[derive(Debug, Clone)]
pub(crate) struct SaddleFit {
    pub pos: Point2<f64>,
}

/// Refine `start` (full-resolution pixels) with a fit window of radius
/// `window` pixels. `None` if the fit does not describe a saddle or wanders
/// further than half the window.
pub(crate) fn refine_saddle(img: &GrayImage, start: Point2<f64>, window: f64) -> Option<SaddleFit> {
    let w = window.max(2.0);
    let sigma_s = (w / 3.5).max(1.0);
    let margin = (w + 3.0 * sigma_s + 0.5 * w).ceil() as isize + 1;
    let (cx, cy) = (start.x.round() as isize, start.y.round() as isize);
    let (iw, ih) = (img.width as isize, img.height as isize);
    if iw == 0 || ih == 0 || !start.x.is_finite() || !start.y.is_finite() {
        return None;
    }
    let size = (2 * margin + 1) as usize;
    let mut data = Vec::with_capacity(size * size);
    for y in cy - margin..=cy + margin {
        let yc = y.clamp(0, ih - 1) as usize * iw as usize;
        for x in cx - margin..=cx + margin {
            data.push(img.pixels[yc + x.clamp(0, iw - 1) as usize] as f32);
        }
    }
    let patch = Plane {
        w: size,
        h: size,
        data,
    }
    .gaussian(sigma_s);
    let origin = Vector2::new((cx - margin) as f64, (cy - margin) as f64);
    let mut c = start.coords - origin;
    let c0 = c;
    let sigma_w2 = 2.0 * (0.5 * w) * (0.5 * w);
    for _ in 0..MAX_ITERATIONS {
        let (h, g) = fit_quadratic(&patch, c, w, sigma_w2)?;
        let det = h.determinant();
        if det >= 0.0 || !det.is_finite() {
            return None;
        }
        let step = -(h.try_inverse()? * g);
        c += step;
        if (c - c0).norm() > 0.5 * w + 1.0 || !c.x.is_finite() {
            return None;
        }
        if step.norm() < STEP_TOLERANCE_PX {
            return Some(SaddleFit {
                pos: Point2::from(c + origin),
            });
        }
    }
    // Not converged to the tolerance: accept only a surface that is still a saddle.
    let (h, _) = fit_quadratic(&patch, c, w, sigma_w2)?;
    (h.determinant() < 0.0).then(|| SaddleFit {
        pos: Point2::from(c + origin),
    })
}

/// Weighted quadratic fit around `c`; returns the surface's Hessian and its
/// gradient at `c`.
fn fit_quadratic(
    patch: &Plane,
    c: Vector2<f64>,
    w: f64,
    sigma_w2: f64,
) -> Option<(Matrix2<f64>, Vector2<f64>)> {
    let mut ata = Matrix6::<f64>::zeros();
    let mut atb = Vector6::<f64>::zeros();
    let x0 = (c.x - w).floor().max(0.0) as usize;
    let x1 = ((c.x + w).ceil() as usize).min(patch.w - 1);
    let y0 = (c.y - w).floor().max(0.0) as usize;
    let y1 = ((c.y + w).ceil() as usize).min(patch.h - 1);
    let w2 = w * w;
    for y in y0..=y1 {
        let v = y as f64 - c.y;
        for x in x0..=x1 {
            let u = x as f64 - c.x;
            let r2 = u * u + v * v;
            if r2 > w2 {
                continue;
            }
            let wt = (-r2 / sigma_w2).exp();
            let basis = Vector6::new(u * u, u * v, v * v, u, v, 1.0);
            let val = patch.data[y * patch.w + x] as f64;
            let wb = basis * wt;
            ata += wb * basis.transpose();
            atb += wb * val;
        }
    }
    let p = ata.cholesky()?.solve(&atb);
    let h = Matrix2::new(2.0 * p[0], p[1], p[1], 2.0 * p[2]);
    Some((h, Vector2::new(p[3], p[4])))
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// A sheared, anti-aliased checker corner at a known sub-pixel position.
    fn corner_image(x0: f64, y0: f64) -> GrayImage {
        let (w, h) = (48u32, 48u32);
        let ss = 8;
        let mut px = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let mut acc = 0.0;
                for sy in 0..ss {
                    for sx in 0..ss {
                        let u = x as f64 - 0.5 + (sx as f64 + 0.5) / ss as f64 - x0;
                        let v = y as f64 - 0.5 + (sy as f64 + 0.5) / ss as f64 - y0;
                        // Edges along (1, 0.3) and (-0.2, 1): not orthogonal.
                        let s1 = v - 0.3 * u;
                        let s2 = u + 0.2 * v;
                        acc += if (s1 > 0.0) == (s2 > 0.0) {
                            220.0
                        } else {
                            30.0
                        };
                    }
                }
                px.push((acc / (ss * ss) as f64).round() as u8);
            }
        }
        GrayImage::new(w, h, px).unwrap()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn recovers_a_sheared_corner_to_a_few_hundredths() {
        for (x0, y0) in [(23.3, 24.71), (22.5, 22.5), (24.05, 23.9)] {
            let img = corner_image(x0, y0);
            let fit = refine_saddle(&img, Point2::new(x0.round() + 1.0, y0.round() - 1.0), 6.0)
                .expect("a saddle");
            // 8x8 supersampling and 8-bit rounding limit the truth to ~0.02 px.
            let err = ((fit.pos.x - x0).powi(2) + (fit.pos.y - y0).powi(2)).sqrt();
            assert!(err < 0.03, "error {err} px at ({x0}, {y0}): {:?}", fit.pos);
        }
        // A flat image has no saddle.
        let flat = GrayImage::new(30, 30, vec![128; 900]).unwrap();
        assert!(refine_saddle(&flat, Point2::new(15.0, 15.0), 5.0).is_none());
    }
}
