//! The stripe's centre where the board's albedo changes under it.
//!
//! The stripe image is `on = B * (albedo * (ambient + L))` and the laser-off
//! image `off = B * (albedo * ambient)`, `B` the lens blur and the pixel's
//! area, so `on - off = B * (albedo * L)`: across a black/white edge of the
//! print the difference is the laser profile `L` times a step, and its
//! centre of gravity is pulled towards the light side (0.4-0.9 px on renders
//! where the edge is within 3 px of the centre, more where the light side
//! saturates and is clipped).
//!
//! Where the laser-off image shows an edge within two pixels of the centre
//! of gravity's window, the edge is measured in the laser-off image itself
//! (the two albedo levels `a1`, `a2` either side, the sub-pixel position
//! `x_e` where it crosses their mean, and its blur `s` from the spread of
//! its derivative), and the difference is fitted with the model that step
//! implies for a Gaussian profile (centre `c`, sigma `w`, amplitude `A`,
//! offset `b`), blurred by a Gaussian of sigma `s`:
//!
//! `m(j) = b + A exp(-(j - c)^2 / (2 S^2)) (a1 + (a2 - a1) Phi((mu_j - x_e) / t))`
//!
//! with `S^2 = w^2 + s^2`, `mu_j = (c s^2 + j w^2) / S^2`, `t = w s / S` (the
//! product of the profile and the blur kernel integrated over the light
//! side). Saturated pixels (`on` at or above `255 - 1.5 noise`) hold no
//! profile and are left out; the others count alike (the noise is additive
//! on the difference), Levenberg-Marquardt from five starts about the
//! centre of gravity. The
//! centre's std is `noise sqrt((J^T J)^-1)`. When the fit fails (too few
//! unsaturated samples, no convergence, a centre outside the window) the
//! centre of gravity is kept with a std of at least `FALLBACK_STD_PX`, so
//! the plane fit weights it down.
//!
//! Only windows near an edge take this path: elsewhere the centre of
//! gravity is unbiased and unchanged.

use super::stripe::Peak;
use nalgebra::{Matrix4, Vector4};

/// Relative change of `off` (beyond the noise) that marks an albedo edge.
const EDGE_STEP: f64 = 0.1;
/// The std given to a centre of gravity near an edge that the model fit
/// could not replace, pixels.
const FALLBACK_STD_PX: f64 = 0.5;

/// Whether `off[lo..=hi]` changes by more than its noise and `EDGE_STEP`.
fn uneven(off: &[f32], lo: usize, hi: usize, noise: f64) -> bool {
    let (mut mn, mut mx) = (f64::MAX, f64::MIN);
    for &v in &off[lo..=hi] {
        mn = mn.min(v as f64);
        mx = mx.max(v as f64);
    }
    mx - mn > EDGE_STEP * mx + 4.0 * noise
}

/// The standard normal distribution function (Abramowitz and Stegun
/// 7.1.26, error below 1.5e-7).
fn phi(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erf = 1.0 - poly * (-z * z).exp();
    if x >= 0.0 {
        0.5 * (1.0 + erf)
    } else {
        0.5 * (1.0 - erf)
    }
}

/// An albedo step in the laser-off image: levels before and after, the
/// position of their mean and the blur's sigma, pixels.
struct Step {
    a1: f64,
    a2: f64,
    at: f64,
    blur: f64,
}

/// The strongest step of `off` within `[lo, hi]`, with 3 px either side
/// of it flat (one edge only).
fn step_in(off: &[f32], lo: usize, hi: usize) -> Option<Step> {
    let n = off.len();
    let k = (lo..hi.min(n - 1)).max_by(|&a, &b| {
        let da = (off[a + 1] - off[a]).abs();
        let db = (off[b + 1] - off[b]).abs();
        da.total_cmp(&db)
    })?;
    // Levels 3-5 px either side of the step between k and k + 1.
    if k < 4 || k + 6 > n {
        return None;
    }
    let mean =
        |a: usize, b: usize| off[a..=b].iter().map(|&v| v as f64).sum::<f64>() / (b - a + 1) as f64;
    let a1 = mean(k - 4, k - 2);
    let a2 = mean(k + 3, k + 5);
    let mid = 0.5 * (a1 + a2);
    // The crossing of the mean between the two samples that bracket it.
    let mut at = None;
    for j in k - 1..=k + 1 {
        let (u, v) = (off[j] as f64 - mid, off[j + 1] as f64 - mid);
        if u * v <= 0.0 && u != v {
            at = Some(j as f64 + u / (u - v));
            break;
        }
    }
    let at = at?;
    // The blur: the derivative's spread about the crossing (its samples
    // at half pixels carry 1/12 px^2 of their own).
    let (mut sw, mut s2) = (0.0, 0.0);
    for j in k - 2..=k + 2 {
        let d = (off[j + 1] - off[j]) as f64 * (a2 - a1).signum();
        if d > 0.0 {
            let x = j as f64 + 0.5 - at;
            sw += d;
            s2 += d * x * x;
        }
    }
    if sw <= 0.0 {
        return None;
    }
    let blur = (s2 / sw - 1.0 / 12.0).max(0.09).sqrt();
    Some(Step { a1, a2, at, blur })
}

/// The model `m(j)` for parameters `(b, A, c, w)` and its gradient.
fn model(step: &Step, p: &Vector4<f64>, j: f64) -> f64 {
    let (b, amp, c, w) = (p[0], p[1], p[2], p[3]);
    let s = step.blur;
    let ss = w * w + s * s;
    let mu = (c * s * s + j * w * w) / ss;
    let t = w * s / ss.sqrt();
    let g = (-(j - c) * (j - c) / (2.0 * ss)).exp();
    b + amp * g * (step.a1 + (step.a2 - step.a1) * phi((mu - step.at) / t))
}

/// A sample's residual: a clipped one only when the model stays below
/// its level (`v` is then the clipped difference).
fn residual(m: f64, v: f64, clipped: bool) -> f64 {
    if clipped {
        (m - v).min(0.0)
    } else {
        m - v
    }
}

/// The centre of `p` (found by the centre of gravity over `[a, b]`) redone
/// by the step model when the laser-off image shows an albedo edge within
/// two pixels of that window. `line` is `on - off`, `raw` the stripe image,
/// `reach` how far from the peak `jp` samples are taken.
pub(crate) fn across_edge(
    line: &[f32],
    raw: &[u8],
    off: &[f32],
    p: Peak,
    (a, b, jp): (usize, usize, usize),
    reach: usize,
    noise: f64,
) -> Peak {
    let n = line.len();
    if !uneven(off, a.saturating_sub(2), (b + 2).min(n - 1), noise) {
        return p;
    }
    let fallback = Peak {
        std: p.std.max(FALLBACK_STD_PX),
        ..p
    };
    let noise = noise.max(0.5);
    let Some(step) = step_in(off, a.saturating_sub(2), (b + 2).min(n - 1)) else {
        return fallback;
    };
    let lo = jp.saturating_sub(reach);
    let hi = (jp + reach).min(n - 1);
    let clip = 255.0 - 1.5 * noise;
    // (position, on - off, clipped): a clipped sample only says the model
    // reaches its level.
    let samples: Vec<(f64, f64, bool)> = (lo..=hi)
        .map(|j| (j as f64, line[j] as f64, (raw[j] as f64) >= clip))
        .collect();
    if samples.iter().filter(|s| !s.2).count() < 6 {
        return fallback;
    }
    let level: f64 = step.a1.max(step.a2).max(1.0);
    let w0 = (p.width / 2.3548).clamp(0.6, reach as f64);
    let cost = |q: &Vector4<f64>| -> f64 {
        samples
            .iter()
            .map(|&(j, v, clipped)| residual(model(&step, q, j), v, clipped).powi(2))
            .sum()
    };
    let jacobian = |q: &Vector4<f64>| -> (Matrix4<f64>, Vector4<f64>) {
        let mut jtj = Matrix4::zeros();
        let mut jtr = Vector4::zeros();
        for &(j, v, clipped) in &samples {
            let m = model(&step, q, j);
            let r = residual(m, v, clipped);
            if r == 0.0 && clipped {
                continue;
            }
            let mut g = Vector4::zeros();
            for k in 0..4 {
                let h = 1e-6 * q[k].abs().max(1e-3);
                let mut d = *q;
                d[k] += h;
                g[k] = (model(&step, &d, j) - m) / h;
            }
            jtj += g * g.transpose();
            jtr += g * r;
        }
        (jtj, jtr)
    };
    // Gauss-Newton (Levenberg-Marquardt) from a start; the clipped core
    // and the step leave more than one minimum: five starts, the centre of
    // gravity and 1 or 2 sigmas either side.
    let solve = |start: f64| -> (Vector4<f64>, f64) {
        let mut q = Vector4::new(0.0, p.contrast.max(1.0) / level, start, w0);
        let mut current = cost(&q);
        let mut lambda = 1e-3;
        for _ in 0..30 {
            let (jtj, jtr) = jacobian(&q);
            let damped = jtj + Matrix4::from_diagonal(&jtj.diagonal()) * lambda;
            let Some(inv) = damped.try_inverse() else {
                break;
            };
            let next = q - inv * jtr;
            let c = if next[3] > 0.2
                && next[3] < reach as f64
                && next[1] > 0.0
                && (next[2] - jp as f64).abs() < reach as f64
            {
                cost(&next)
            } else {
                f64::INFINITY
            };
            if c < current {
                let done = (next[2] - q[2]).abs() < 1e-5;
                q = next;
                current = c;
                lambda = (lambda * 0.3).max(1e-9);
                if done {
                    break;
                }
            } else {
                lambda *= 10.0;
                if lambda > 1e6 {
                    break;
                }
            }
        }
        (q, current)
    };
    let (q, _) = [0.0, -1.0, 1.0, -2.0, 2.0]
        .map(|k| p.centre + k * w0)
        .into_iter()
        .map(solve)
        .fold((Vector4::zeros(), f64::INFINITY), |a, b| {
            if b.1 < a.1 {
                b
            } else {
                a
            }
        });
    let (jtj, _) = jacobian(&q);
    let Some(cov) = jtj.try_inverse() else {
        return fallback;
    };
    let std = noise * cov[(2, 2)].max(0.0).sqrt();
    let inside = (q[2] - jp as f64).abs() <= reach as f64;
    if !inside || !std.is_finite() || std > FALLBACK_STD_PX {
        return fallback;
    }
    Peak {
        centre: q[2],
        std: std.max(p.std),
        width: 2.3548 * (q[3] * q[3] + step.blur * step.blur).sqrt(),
        ..p
    }
}
