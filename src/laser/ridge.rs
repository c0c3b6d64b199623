//! Steger's ridge detector, written for one scan line at a time: the
//! image's first and second Gaussian derivatives at the pixels around the
//! first pass's peak, the Hessian's eigenvector of the most negative
//! eigenvalue as the line normal `n`, and the sub-pixel extremum of the
//! second-order Taylor polynomial along it, `t = -(n . grad) / (n^T H n)`.
//! A pixel answers when the extremum falls inside it (|t n| <= 1/2 on both
//! axes); the ridge point is then moved along the line's tangent onto the
//! scan line itself.
//!
//! The Gaussian's sigma is one for the whole image, from the stripe's
//! median width `w` (full width at half maximum): `w / (2 sqrt 3)` (Steger's
//! condition `sigma >= half-width / sqrt 3` for a bar profile, which a
//! saturated stripe is), at least 0.8 px.
//!
//! The centre's std is the noise through the estimator to first order:
//! `noise * |k_n| / |n^T H n|`, with `|k_n|` the L2 norm of the 2-D
//! first-derivative kernel.

use super::stripe::{Peak, Scan};

/// The sampled Gaussian and its derivative kernels (correlation form).
pub(crate) struct Kernels {
    radius: isize,
    /// Smoothing, sums to 1.
    g0: Vec<f64>,
    /// First derivative: a unit ramp answers 1.
    g1: Vec<f64>,
    /// Second derivative: sums to 0, a parabola `j^2 / 2` answers 1.
    g2: Vec<f64>,
    /// L2 norm of the 2-D first-derivative kernel.
    norm1: f64,
}

impl Kernels {
    pub(crate) fn new(sigma: f64) -> Kernels {
        let radius = (3.5 * sigma).ceil().max(2.0) as isize;
        let offsets: Vec<f64> = (-radius..=radius).map(|i| i as f64).collect();
        let g: Vec<f64> = offsets
            .iter()
            .map(|i| (-0.5 * i * i / (sigma * sigma)).exp())
            .collect();
        let sum: f64 = g.iter().sum();
        let g0: Vec<f64> = g.iter().map(|v| v / sum).collect();
        let raw1: Vec<f64> = offsets.iter().zip(&g0).map(|(i, v)| i * v).collect();
        let m1: f64 = offsets.iter().zip(&raw1).map(|(i, v)| i * v).sum();
        let g1: Vec<f64> = raw1.iter().map(|v| v / m1).collect();
        let raw2: Vec<f64> = offsets
            .iter()
            .zip(&g0)
            .map(|(i, v)| (i * i / sigma.powi(4) - 1.0 / (sigma * sigma)) * v)
            .collect();
        let mean2 = raw2.iter().sum::<f64>() / raw2.len() as f64;
        let centred: Vec<f64> = raw2.iter().map(|v| v - mean2).collect();
        let m2: f64 = offsets.iter().zip(&centred).map(|(i, v)| i * i * v).sum();
        let g2: Vec<f64> = centred.iter().map(|v| 2.0 * v / m2).collect();
        let norm1 =
            (g1.iter().map(|v| v * v).sum::<f64>() * g0.iter().map(|v| v * v).sum::<f64>()).sqrt();
        Kernels {
            radius,
            g0,
            g1,
            g2,
            norm1,
        }
    }
}

/// Derivatives at (line i, position j): (r_i, r_j, r_ii, r_ij, r_jj).
fn derivatives(scan: &Scan, i: isize, j: isize, k: &Kernels) -> [f64; 5] {
    let r = k.radius;
    let mut out = [0.0; 5];
    for a in -r..=r {
        let (mut s0, mut s1, mut s2) = (0.0, 0.0, 0.0);
        for b in -r..=r {
            let v = scan.at(i + a, j + b) as f64;
            let kb = (b + r) as usize;
            s0 += v * k.g0[kb];
            s1 += v * k.g1[kb];
            s2 += v * k.g2[kb];
        }
        let ka = (a + r) as usize;
        out[0] += k.g1[ka] * s0;
        out[1] += k.g0[ka] * s1;
        out[2] += k.g2[ka] * s0;
        out[3] += k.g1[ka] * s1;
        out[4] += k.g0[ka] * s2;
    }
    out
}

/// The ridge centre on line `i` near the first pass's peak, with its std;
/// `None` when no pixel near the peak holds the ridge.
pub(crate) fn refine(scan: &Scan, i: usize, p: &Peak, k: &Kernels, noise: f64) -> Option<Peak> {
    let j0 = p.centre.round() as isize;
    let mut best: Option<(f64, f64, f64)> = None;
    for j in (j0 - 2)..=(j0 + 2) {
        if j < 0 || j >= scan.len as isize {
            continue;
        }
        let [ri, rj, rii, rij, rjj] = derivatives(scan, i as isize, j, k);
        let tr = rii + rjj;
        let disc = ((rii - rjj).powi(2) + 4.0 * rij * rij).sqrt();
        let lambda = 0.5 * (tr - disc);
        if lambda >= 0.0 {
            continue;
        }
        // Eigenvector of lambda, from the better-conditioned row.
        let (ni, nj) = if (rii - lambda).abs() > (rjj - lambda).abs() {
            (-rij, rii - lambda)
        } else {
            (rjj - lambda, -rij)
        };
        let norm = (ni * ni + nj * nj).sqrt();
        let (ni, nj) = if norm > 0.0 {
            (ni / norm, nj / norm)
        } else {
            (0.0, 1.0)
        };
        let t = -(ri * ni + rj * nj) / lambda;
        // The scan axis runs within 45 deg of the line's normal.
        if nj.abs() < 0.6 {
            continue;
        }
        let (di, dj) = (t * ni, t * nj);
        if di.abs() > 0.5 || dj.abs() > 0.5 {
            continue;
        }
        // Along the tangent (ti, tj) = (-nj, ni) back onto line i.
        let (ti, tj) = (-nj, ni);
        let along = if ti.abs() > 1e-6 {
            dj - di * tj / ti
        } else {
            dj
        };
        let pos = j as f64 + along;
        let std = (noise * k.norm1 / lambda.abs()).max(0.01);
        if best.map_or(true, |b| t.abs() < b.2) {
            best = Some((pos, std, t.abs()));
        }
    }
    best.map(|(centre, std, _)| Peak { centre, std, ..*p })
}
