//! Sub-pixel saddle-point refinement at full resolution.
//!
//! Model: around a chessboard corner the Gaussian-smoothed image is
//! point-symmetric, so its saddle point (zero gradient, `det H < 0`) is the
//! corner. A quadratic surface `a u^2 + b u v + c v^2 + d u + e v + f` is
//! fitted by Gaussian-weighted least squares on the smoothed image over a
//! square window, the window is moved to the surface's saddle point and the
//! fit repeated until the step is below 0.002 px. Because the window is
//! symmetric about the final estimate, the odd terms of a point-symmetric
//! pattern vanish there: the estimate has no bias from the quadratic
//! model's misfit. For that the fit points themselves must lie
//! symmetrically about the centre: they are the centre plus whole-pixel
//! offsets, where the smoothed image is the raw pixels weighted by the
//! Gaussian at their fractional distance (the smoothing interpolates).
//! Fitting at the pixels themselves, whose offsets from a centre between
//! pixels are not symmetric, biased the corner with its sub-pixel phase
//! (+-0.007 px on a frontal board, the mean over a board shifted by
//! fractions of a pixel; docs/benchmark-history.md, "Session 14: chessboard
//! corners: the fit points' phase").
//!
//! Cost: the smoothing is never applied to the patch. Weights, basis and
//! smoothing are all separable, so each right-hand side of the normal
//! equations is the raw patch correlated with a separable kernel: 1-D
//! kernels (weighted monomials convolved with the smoothing taps) are built
//! per iteration and the patch is reduced row by row (three dot products
//! per row). The normal matrix is a product of 1-D weight moments.

use crate::image::filter::gaussian_radius;
use crate::image::GrayImage;
use nalgebra::{Matrix2, Matrix6, Point2, Vector2, Vector6};

/// Iterations of the move-and-refit loop.
const MAX_ITERATIONS: usize = 10;
/// Convergence threshold on the step, pixels.
const STEP_TOLERANCE_PX: f64 = 0.002;
/// The weights `exp(-2 t^2 / w^2)` (sigma = half the window) are cut at
/// this multiple of the window, 3 sigma, where they are ~1% (a cut at the
/// window itself biased the fixed point by ~0.07 px on a sheared corner).
const WINDOW_REACH: f64 = 1.5;
/// Monomial exponents (a, b) of `u^a v^b` in the basis order above.
const BASIS: [(usize, usize); 6] = [(2, 0), (1, 1), (0, 2), (1, 0), (0, 1), (0, 0)];

/// A refined corner.
#[derive(Debug, Clone)]
pub(crate) struct SaddleFit {
    pub pos: Point2<f64>,
}

/// Raw pixels around a start point, f32, with the smoothing's sigma and
/// reach (taps at offsets `-rs ..= rs + 1` around a fractional position).
struct Patch {
    size: usize,
    data: Vec<f32>,
    sigma_s: f64,
    rs: usize,
}

/// Refine `start` (full-resolution pixels) with a fit window of half-side
/// `window` pixels. `None` if the fit does not describe a saddle or wanders
/// further than half the window.
pub(crate) fn refine_saddle(img: &GrayImage, start: Point2<f64>, window: f64) -> Option<SaddleFit> {
    let w = window.max(2.0);
    let sigma_s = (w / 3.5).max(1.0);
    let rs = gaussian_radius(sigma_s);
    let travel = 0.5 * w + 1.0;
    let (iw, ih) = (img.width as isize, img.height as isize);
    if iw == 0 || ih == 0 || !start.x.is_finite() || !start.y.is_finite() {
        return None;
    }
    // Everything any admissible window centre can read: fit half-side w,
    // the smoothing taps and the travel, plus one pixel of rounding.
    let margin = (WINDOW_REACH * w + travel).ceil() as isize + rs as isize + 2;
    let (cx, cy) = (start.x.round() as isize, start.y.round() as isize);
    let size = (2 * margin + 1) as usize;
    let mut data = Vec::with_capacity(size * size);
    for y in cy - margin..=cy + margin {
        let row = y.clamp(0, ih - 1) as usize * iw as usize;
        let pixels = &img.pixels[row..row + iw as usize];
        let (x0, x1) = (cx - margin, cx + margin);
        if x0 >= 0 && x1 < iw {
            data.extend(pixels[x0 as usize..=x1 as usize].iter().map(|&v| v as f32));
        } else {
            data.extend((x0..=x1).map(|x| pixels[x.clamp(0, iw - 1) as usize] as f32));
        }
    }
    let patch = Patch {
        size,
        data,
        sigma_s,
        rs,
    };
    let origin = Vector2::new((cx - margin) as f64, (cy - margin) as f64);
    let mut c = start.coords - origin;
    let c0 = c;
    let weights = Weights::new(w, patch.sigma_s);
    for _ in 0..MAX_ITERATIONS {
        let (h, g) = fit_quadratic(&patch, c, &weights)?;
        let det = h.determinant();
        if det >= 0.0 || !det.is_finite() {
            return None;
        }
        let step = -(h.try_inverse()? * g);
        c += step;
        if (c - c0).norm() > travel || !c.x.is_finite() || !c.y.is_finite() {
            return None;
        }
        if step.norm() < STEP_TOLERANCE_PX {
            return Some(SaddleFit {
                pos: Point2::from(c + origin),
            });
        }
    }
    // Not converged to the tolerance: accept only a surface that is still a saddle.
    let (h, _) = fit_quadratic(&patch, c, &weights)?;
    (h.determinant() < 0.0).then(|| SaddleFit {
        pos: Point2::from(c + origin),
    })
}

/// 1-D pieces of the fit along one axis for window centre `c`: the fit
/// points are `c + t` for the integers `|t| <= n`, so they lie
/// symmetrically about `c` wherever `c` falls between pixels. The
/// smoothed image there is the raw pixels weighted by the Gaussian at
/// their fractional offsets, `S(c + t) = sum_j raw(floor(c) + t + j)
/// G(frac(c) - j)`. `first`: the raw pixel of `t = -n, j = 0`; the weight
/// moments `sum g(t) t^k` (k = 0..4: the odd ones vanish); the kernels
/// `h_a = (g t^a) * taps` (a = 0..2) over `count + 2 rs + 1` raw pixels
/// starting `rs` before `first`.
struct Axis {
    first: isize,
    moments: [f64; 5],
    kernels: [Vec<f32>; 3],
}

/// What [`axis`] needs that does not depend on the window centre, built
/// once per corner: the fit weights `g(t) = exp(-t^2 / s)` at the integers
/// `|t| <= n`, the monomials they weight and their moments, and the
/// smoothing's constants.
struct Weights {
    n: isize,
    /// `[g, g t, g t^2]` at `t = -n ..= n`.
    phi: Vec<[f64; 3]>,
    /// `sum g(t) t^k`, k = 0..4.
    moments: [f64; 5],
    /// The smoothing's reach and `2 sigma^2`.
    rs: usize,
    s: f64,
    /// `exp(-2 / s)`: how the smoothing taps' ratio falls per tap.
    fall: f64,
}

impl Weights {
    fn new(w: f64, sigma_s: f64) -> Weights {
        let sigma_w2 = 2.0 * (0.5 * w) * (0.5 * w);
        let n = (WINDOW_REACH * w).floor() as isize;
        let count = (2 * n + 1) as usize;
        let mut moments = [0.0f64; 5];
        let mut phi = Vec::with_capacity(count);
        // g(t) by recurrence over the unit steps of t: the ratio
        // g(t + 1) / g(t) = exp(-(2 t + 1) / s) itself shrinks by exp(-2 / s).
        let t0 = -n as f64;
        let mut g = (-t0 * t0 / sigma_w2).exp();
        let mut ratio = (-(2.0 * t0 + 1.0) / sigma_w2).exp();
        let shrink = (-2.0 / sigma_w2).exp();
        for k in 0..count {
            let t = t0 + k as f64;
            let mut p = g;
            for m in moments.iter_mut() {
                *m += p;
                p *= t;
            }
            phi.push([g, g * t, g * t * t]);
            g *= ratio;
            ratio *= shrink;
        }
        let rs = gaussian_radius(sigma_s);
        let s = 2.0 * sigma_s * sigma_s;
        Weights {
            n,
            phi,
            moments,
            rs,
            s,
            fall: (-2.0 / s).exp(),
        }
    }
}

fn axis(c: f64, weights: &Weights) -> Axis {
    let Weights { n, rs, s, .. } = *weights;
    let base = c.floor();
    let frac = c - base;
    let count = weights.phi.len();
    // Taps G(frac - j), j = -rs ..= rs + 1, normalised to sum 1: the
    // offset d = frac - j falls by 1 from tap to tap, so G by the same
    // recurrence as g (two exponentials a call instead of one a tap: the
    // wasm build's `exp` is a software one, 5 % of its chessboard
    // detection when taken per tap).
    let d0 = frac + rs as f64;
    let mut tap = (-d0 * d0 / s).exp();
    let mut step = ((2.0 * d0 - 1.0) / s).exp();
    let mut taps: Vec<f64> = (0..2 * rs + 2)
        .map(|_| {
            let t = tap;
            tap *= step;
            step *= weights.fall;
            t
        })
        .collect();
    let sum: f64 = taps.iter().sum();
    taps.iter_mut().for_each(|v| *v /= sum);
    let len = count + 2 * rs + 1;
    let mut kernels = [vec![0.0f32; len], vec![0.0f32; len], vec![0.0f32; len]];
    for (k, phi) in weights.phi.iter().enumerate() {
        // Fit point k reads raw pixels k .. k + 2 rs + 1 (kernel offsets).
        for (kernel, &f) in kernels.iter_mut().zip(phi) {
            for (dst, &tap) in kernel[k..k + 2 * rs + 2].iter_mut().zip(&taps) {
                *dst += (f * tap) as f32;
            }
        }
    }
    Axis {
        first: base as isize - n,
        moments: weights.moments,
        kernels,
    }
}

/// The three dot products of a patch row with the kernels, each summed in
/// four interleaved lanes (one 4-wide vector sum, natively and in wasm
/// simd128) and the lanes added pairwise at the end.
fn row_dots(row: &[f32], kernels: &[Vec<f32>; 3]) -> [f64; 3] {
    let n = row
        .len()
        .min(kernels.iter().map(Vec::len).min().unwrap_or(0));
    let whole = n - n % LANES;
    let mut lanes = [[0.0f32; LANES]; 3];
    for (k, lane) in kernels.iter().zip(lanes.iter_mut()) {
        for (p, q) in row[..whole]
            .chunks_exact(LANES)
            .zip(k[..whole].chunks_exact(LANES))
        {
            for i in 0..LANES {
                lane[i] += p[i] * q[i];
            }
        }
    }
    let mut t = [0.0f64; 3];
    for ((k, lane), out) in kernels.iter().zip(&lanes).zip(t.iter_mut()) {
        let mut sum = (lane[0] + lane[1]) + (lane[2] + lane[3]);
        for i in whole..n {
            sum += row[i] * k[i];
        }
        *out = sum as f64;
    }
    t
}

/// Lanes of [`row_dots`]'s sums.
const LANES: usize = 4;

/// Weighted quadratic fit around `c`; returns the surface's Hessian and its
/// gradient at `c`. `None` when the raw pixels it needs leave the patch.
fn fit_quadratic(
    patch: &Patch,
    c: Vector2<f64>,
    weights: &Weights,
) -> Option<(Matrix2<f64>, Vector2<f64>)> {
    let rs = patch.rs as isize;
    let ax = axis(c.x, weights);
    let ay = axis(c.y, weights);
    let (x0, y0) = (ax.first - rs, ay.first - rs);
    let (nx, ny) = (ax.kernels[0].len(), ay.kernels[0].len());
    if x0 < 0 || y0 < 0 || x0 as usize + nx > patch.size || y0 as usize + ny > patch.size {
        return None;
    }
    // rhs[a][b] = sum over raw pixels of P * hx_a * hy_b.
    let mut rhs = [[0.0f64; 3]; 3];
    for (j, row) in patch
        .data
        .chunks_exact(patch.size)
        .skip(y0 as usize)
        .take(ny)
        .enumerate()
    {
        let row = &row[x0 as usize..x0 as usize + nx];
        let t = row_dots(row, &ax.kernels);
        let hy = [
            ay.kernels[0][j] as f64,
            ay.kernels[1][j] as f64,
            ay.kernels[2][j] as f64,
        ];
        for (a, ta) in t.iter().enumerate() {
            for (b, hb) in hy.iter().enumerate() {
                rhs[a][b] += ta * hb;
            }
        }
    }
    let ata = Matrix6::from_fn(|r, s| {
        let (a1, b1) = BASIS[r];
        let (a2, b2) = BASIS[s];
        ax.moments[a1 + a2] * ay.moments[b1 + b2]
    });
    let atb = Vector6::from_fn(|r, _| {
        let (a, b) = BASIS[r];
        rhs[a][b]
    });
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
