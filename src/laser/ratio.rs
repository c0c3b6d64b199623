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
//! profile and only bound the model from below (censored samples); the
//! others count alike (the noise is additive on the difference). The fit
//! is the project's solver ([`crate::optim::solve`], analytic Jacobian)
//! from one start: the best of a grid of centres and sigmas about the
//! centre of gravity, where the model is linear in `b` and `A`. The
//! centre's std is `s sqrt((J^T J)^-1)`, `s` the larger of the image
//! noise and the fit's residual RMS. When the fit fails (too few
//! unsaturated samples, no convergence, a centre outside the window) the
//! centre of gravity is kept with a std of at least `FALLBACK_STD_PX`, so
//! the plane fit weights it down.
//!
//! Only windows near an edge take this path: elsewhere the centre of
//! gravity is unbiased and unchanged.

use super::stripe::Peak;
use crate::error::{Error, Result};
use crate::optim::{solve, BlockParams, BlockProblem, LmOptions, ResidualBlock, ResidualRun};
use nalgebra::{DMatrix, DVector};

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

/// The standard normal distribution function.
fn phi(x: f64) -> f64 {
    0.5 * (1.0 + libm::erf(x / std::f64::consts::SQRT_2))
}

/// The standard normal density.
fn density(x: f64) -> f64 {
    (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt()
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

/// The model `m(j)` for parameters `(b, A, c, w)` and its derivatives
/// along them.
fn model(step: &Step, p: &[f64], j: f64) -> (f64, [f64; 4]) {
    let (b, amp, c, w) = (p[0], p[1], p[2], p[3]);
    let s = step.blur;
    let (ss, s2) = (w * w + s * s, s * s);
    let root = ss.sqrt();
    let d = j - c;
    let g = (-d * d / (2.0 * ss)).exp();
    let t = w * s / root;
    let u = ((c * s2 + j * w * w) / ss - step.at) / t;
    let rise = step.a2 - step.a1;
    let h = step.a1 + rise * phi(u);
    let dh_du = rise * density(u);
    // d/dc and d/dw of the Gaussian and of u (mu = (c s^2 + j w^2) / S^2).
    let dg_dc = g * d / ss;
    let dg_dw = g * d * d * w / (ss * ss);
    let du_dc = s2 / ss / t;
    let dmu_dw = 2.0 * w * s2 * d / (ss * ss);
    let dt_dw = s2 * s / (ss * root);
    let du_dw = (dmu_dw - u * dt_dw) / t;
    (
        b + amp * g * h,
        [
            1.0,
            g * h,
            amp * (dg_dc * h + g * dh_du * du_dc),
            amp * (dg_dw * h + g * dh_du * du_dw),
        ],
    )
}

/// The step model fitted to one window's samples `(position, on - off,
/// clipped)`: a clipped sample's residual is the model's shortfall below
/// its level only (a censored sample), 0 once the model reaches it.
struct EdgeFit<'a> {
    step: &'a Step,
    samples: &'a [(f64, f64, bool)],
    /// Where the centre may go (the window about the peak) and the widest
    /// sigma, pixels.
    centre: (f64, f64),
    max_sigma: f64,
}

impl EdgeFit<'_> {
    /// Residuals and their Jacobian (transposed, 4 x m) at `p`; `None`
    /// outside the model's domain (a sigma below 0.2 px or beyond the
    /// window, a non-positive amplitude, the centre outside the window).
    fn rows(&self, p: &[f64]) -> Option<(DVector<f64>, DMatrix<f64>)> {
        let (amp, c, w) = (p[1], p[2], p[3]);
        if !(w > 0.2 && w < self.max_sigma && amp > 0.0 && c > self.centre.0 && c < self.centre.1) {
            return None;
        }
        let m = self.samples.len();
        let mut r = DVector::zeros(m);
        let mut jt = DMatrix::zeros(4, m);
        for (k, &(j, v, clipped)) in self.samples.iter().enumerate() {
            let (value, grad) = model(self.step, p, j);
            if clipped && value >= v {
                continue;
            }
            r[k] = value - v;
            for (i, g) in grad.iter().enumerate() {
                jt[(i, k)] = *g;
            }
        }
        Some((r, jt))
    }
}

impl BlockProblem for EdgeFit<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        _jacobians: bool,
    ) -> Result<Vec<ResidualBlock>> {
        let (r, jt) = self.rows(&params.global).ok_or_else(outside)?;
        Ok((0..r.len())
            .map(|k| ResidualBlock {
                block: None,
                residuals: DVector::from_element(1, r[k]),
                jac_global: DMatrix::from_row_slice(1, 4, jt.column(k).as_slice()),
                jac_block: DMatrix::zeros(1, 0),
            })
            .collect())
    }

    fn residual_runs(&self, params: &BlockParams) -> Option<Result<Vec<ResidualRun>>> {
        Some(
            self.rows(&params.global)
                .ok_or_else(outside)
                .map(|(r, jt)| {
                    let m = r.len();
                    vec![ResidualRun {
                        block: None,
                        group: 1,
                        residuals: r,
                        jac_global_t: jt,
                        jac_block_t: DMatrix::zeros(0, m),
                    }]
                }),
        )
    }
}

/// The error that makes the solver reject a step out of the model's domain.
fn outside() -> Error {
    Error::degenerate("the step model's parameters left their domain")
}

/// The start: on a grid of centres about the centre of gravity (a quarter
/// sigma apart, two sigmas either side) the step model with sigma `w0` is
/// linear in the offset and amplitude; the centre whose least-squares fit
/// over the unclipped samples leaves the least is the start.
fn start(step: &Step, samples: &[(f64, f64, bool)], centre: f64, w0: f64) -> Option<[f64; 4]> {
    let mut best: Option<(f64, [f64; 4])> = None;
    for (k, scale) in (-8..=8).flat_map(|k| [0.7, 1.0, 1.4].map(|s| (k, s))) {
        let c = centre + 0.25 * k as f64 * w0;
        let w = scale * w0;
        let p = [0.0, 1.0, c, w];
        // Normal equations of v = b + A f over the unclipped samples.
        let (mut n, mut sf, mut sff, mut sv, mut sfv, mut svv) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for &(j, v, clipped) in samples {
            if clipped {
                continue;
            }
            let f = model(step, &p, j).0;
            n += 1.0;
            sf += f;
            sff += f * f;
            sv += v;
            sfv += f * v;
            svv += v * v;
        }
        let det = n * sff - sf * sf;
        if det <= 1e-12 * n * sff {
            continue;
        }
        let amp = (n * sfv - sf * sv) / det;
        let b = (sv - amp * sf) / n;
        if amp <= 0.0 {
            continue;
        }
        let rest = svv - b * sv - amp * sfv;
        if best.map_or(true, |(r, _)| rest < r) {
            best = Some((rest, [b, amp, c, w]));
        }
    }
    best.map(|(_, p)| p)
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
    let w0 = (p.width / 2.3548).clamp(0.6, reach as f64 - 0.5);
    let problem = EdgeFit {
        step: &step,
        samples: &samples,
        centre: (jp as f64 - reach as f64, jp as f64 + reach as f64),
        max_sigma: reach as f64,
    };
    let Some(initial) = start(&step, &samples, p.centre, w0) else {
        return fallback;
    };
    let options = LmOptions {
        max_iterations: 50,
        cost_tolerance: 1e-10,
        ..LmOptions::default()
    };
    let initial = BlockParams {
        global: initial.to_vec(),
        blocks: vec![],
    };
    let Ok(fit) = solve(&problem, &initial, &options) else {
        return fallback;
    };
    let q = &fit.params.global;
    // The centre's std: the noise through (J^T J)^-1 at the solution.
    let Some((_, jt)) = problem.rows(q) else {
        return fallback;
    };
    let Some(cov) = (&jt * jt.transpose()).try_inverse() else {
        return fallback;
    };
    // The samples' scatter about the fit: the image noise, or more where
    // the profile is not the model's (speckle, a misjudged step); the
    // image noise alone made these centres' std 0.04 px where they erred
    // 0.3 px (BENCHMARKS.md section 18, s28).
    let scatter = noise.max(fit.residual_variance.max(0.0).sqrt());
    let std = scatter * cov[(2, 2)].max(0.0).sqrt();
    if !std.is_finite() || std > FALLBACK_STD_PX {
        return fallback;
    }
    Peak {
        centre: q[2],
        std: std.max(p.std),
        width: 2.3548 * (q[3] * q[3] + step.blur * step.blur).sqrt(),
        ..p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example_step() -> Step {
        Step {
            a1: 30.0,
            a2: 220.0,
            at: 10.3,
            blur: 0.8,
        }
    }

    #[test]
    fn the_step_models_derivatives_match_finite_differences() {
        let step = example_step();
        for p in [
            [2.0, 1.5, 10.0, 2.1],
            [0.0, 0.7, 12.4, 1.2],
            [-1.0, 2.0, 7.9, 0.5],
        ] {
            for j in [6.0, 9.0, 10.0, 11.0, 14.0] {
                let (_, grad) = model(&step, &p, j);
                for (i, g) in grad.iter().enumerate() {
                    let h = 1e-6;
                    let (mut up, mut down) = (p, p);
                    up[i] += h;
                    down[i] -= h;
                    let fd = (model(&step, &up, j).0 - model(&step, &down, j).0) / (2.0 * h);
                    assert!(
                        (g - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                        "p {p:?}, j {j}, parameter {i}: analytic {g}, numeric {fd}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_noise_free_clipped_profile_gives_its_centre_back() {
        // The model itself sampled (centre 10.37 px, sigma 2, the light side
        // clipped at 255): the fit returns the centre to 1e-6 px from the
        // grid start, the clipped core only bounding it from below.
        let step = example_step();
        let truth = [1.0, 2.5, 10.37, 2.0];
        let samples: Vec<(f64, f64, bool)> = (0..21)
            .map(|j| {
                let v = model(&step, &truth, j as f64).0;
                (j as f64, v.min(255.0), v >= 255.0)
            })
            .collect();
        assert!(samples.iter().filter(|s| s.2).count() >= 3);
        let problem = EdgeFit {
            step: &step,
            samples: &samples,
            centre: (0.0, 20.0),
            max_sigma: 10.0,
        };
        let start = start(&step, &samples, 10.2, 2.6).unwrap();
        let initial = BlockParams {
            global: start.to_vec(),
            blocks: vec![],
        };
        let fit = solve(&problem, &initial, &LmOptions::default()).unwrap();
        let q = &fit.params.global;
        assert!((q[2] - 10.37).abs() < 1e-6, "{q:?}");
        assert!((q[3] - 2.0).abs() < 1e-6, "{q:?}");
    }
}
