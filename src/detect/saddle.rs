//! Saddle-point (X-junction) candidates from the Hessian of a smoothed image.
//!
//! At a chessboard corner the smoothed intensity is locally `k u v` along the
//! two edge directions, so the Hessian has eigenvalues of opposite sign and
//! `det H < 0`; straight edges give `det H ~ 0` and blobs `det H > 0`. The
//! response is `-det H` (positive at saddles); local maxima above a threshold
//! relative to the strongest response become candidates. The Hessian also
//! gives each candidate's polarity for the grid growth.

use crate::image::filter::{max_f32, Plane};
use nalgebra::{Matrix2, Point2};

/// Smoothing of the working pyramid level before differentiation, pixels.
pub(crate) const HESSIAN_SIGMA_PX: f64 = 1.5;
/// Candidates keep at least this fraction of the strongest response
/// (a corner at 1/7 of the best contrast still passes).
const RELATIVE_THRESHOLD: f32 = 0.02;
/// Absolute floor on the response, grey levels squared per pixel^4: about a
/// 12-grey-level corner after smoothing; below it everything is noise.
const ABSOLUTE_THRESHOLD: f32 = 0.2;

/// One saddle candidate at the working level.
#[derive(Debug, Clone)]
pub(crate) struct Candidate {
    pub pos: Point2<f64>,
    pub response: f32,
    /// Hessian of the smoothed image at the candidate.
    pub hessian: Matrix2<f64>,
}

/// Hessian entries (xx, xy, yy) at pixel (x, y) of a smoothed plane.
#[inline]
fn hessian_at(s: &Plane, x: usize, y: usize) -> (f32, f32, f32) {
    let w = s.w;
    let i = y * w + x;
    let d = &s.data;
    let c = d[i];
    let xx = d[i + 1] - 2.0 * c + d[i - 1];
    let yy = d[i + w] - 2.0 * c + d[i - w];
    let xy = 0.25 * (d[i + w + 1] - d[i + w - 1] - d[i - w + 1] + d[i - w - 1]);
    (xx, xy, yy)
}

/// Saddle candidates of `level`, strongest first, at most `max_count`.
pub(crate) fn candidates(level: &Plane, max_count: usize) -> Vec<Candidate> {
    let (w, h) = (level.w, level.h);
    if w < 8 || h < 8 {
        return Vec::new();
    }
    let s = level.gaussian(HESSIAN_SIGMA_PX);
    let mut resp = vec![0.0f32; w * h];
    // Row by row over equal-length slices (vectorisable, no bounds checks);
    // the maximum is kept per lane so that it vectorises too.
    let n = w - 2;
    let mut lanes = [0.0f32; 8];
    for y in 1..h - 1 {
        let up = &s.data[(y - 1) * w..y * w];
        let mid = &s.data[y * w..(y + 1) * w];
        let down = &s.data[(y + 1) * w..(y + 2) * w];
        let out = &mut resp[y * w + 1..y * w + 1 + n];
        let (l, c, r) = (&mid[..n], &mid[1..n + 1], &mid[2..]);
        let (u, d) = (&up[1..n + 1], &down[1..n + 1]);
        let (ul, ur, dl, dr) = (&up[..n], &up[2..], &down[..n], &down[2..]);
        for i in 0..n {
            let xx = r[i] - 2.0 * c[i] + l[i];
            let yy = d[i] - 2.0 * c[i] + u[i];
            let xy = 0.25 * (dr[i] - dl[i] - ur[i] + ul[i]);
            out[i] = max_f32(xy * xy - xx * yy, 0.0);
        }
        for chunk in out.chunks_exact(8) {
            for (m, &v) in lanes.iter_mut().zip(chunk) {
                *m = max_f32(*m, v);
            }
        }
        for &v in out.chunks_exact(8).remainder() {
            lanes[0] = max_f32(lanes[0], v);
        }
    }
    let max_r = lanes.iter().fold(0.0f32, |m, &v| max_f32(m, v));
    let threshold = (max_r * RELATIVE_THRESHOLD).max(ABSOLUTE_THRESHOLD);
    let mut out = Vec::new();
    // Stay 3 px from the border: the fit and the 3x3 maximum need the ring.
    // Runs of 8 pixels below the threshold are skipped with one test.
    let (x_lo, x_hi) = (3, w.saturating_sub(3));
    for y in 3..h.saturating_sub(3) {
        let row = &resp[y * w..(y + 1) * w];
        let mut x = x_lo;
        while x < x_hi {
            let end = (x + 8).min(x_hi);
            if !row[x..end].iter().fold(false, |a, &v| a | (v >= threshold)) {
                x = end;
                continue;
            }
            for x in x..end {
                let r = row[x];
                if r < threshold || !is_local_max(&resp, w, x, y) {
                    continue;
                }
                // Parabolic sub-pixel peak of the response for a better start.
                let dx = peak_offset(row[x - 1], r, row[x + 1]);
                let dy = peak_offset(resp[(y - 1) * w + x], r, resp[(y + 1) * w + x]);
                let (xx, xy, yy) = hessian_at(&s, x, y);
                out.push(Candidate {
                    pos: Point2::new(x as f64 + dx, y as f64 + dy),
                    response: r,
                    hessian: Matrix2::new(xx as f64, xy as f64, xy as f64, yy as f64),
                });
            }
            x = end;
        }
    }
    // Strongest first, ties in raster order. Noise images give tens of
    // thousands of weak maxima: select the kept ones before sorting.
    let order = |a: &Candidate, b: &Candidate| {
        b.response
            .total_cmp(&a.response)
            .then(a.pos.y.total_cmp(&b.pos.y))
            .then(a.pos.x.total_cmp(&b.pos.x))
    };
    if out.len() > max_count && max_count > 0 {
        let mut responses: Vec<f32> = out.iter().map(|c| c.response).collect();
        let (_, &mut threshold, _) =
            responses.select_nth_unstable_by(max_count - 1, |a, b| b.total_cmp(a));
        let mut room = max_count - out.iter().filter(|c| c.response > threshold).count();
        out.retain(|c| {
            let keep = c.response > threshold || (c.response == threshold && room > 0);
            if keep && c.response == threshold {
                room -= 1;
            }
            keep
        });
    }
    out.truncate(max_count);
    out.sort_by(order);
    out
}

fn is_local_max(resp: &[f32], w: usize, x: usize, y: usize) -> bool {
    let r = resp[y * w + x];
    for dy in -2isize..=2 {
        for dx in -2isize..=2 {
            if dx == 0 && dy == 0 {
                continue;
            }
            let j = ((y as isize + dy) as usize) * w + (x as isize + dx) as usize;
            let v = resp[j];
            // Ties broken towards the earlier pixel so plateaus give one peak.
            if v > r || (v == r && (dy < 0 || (dy == 0 && dx < 0))) {
                return false;
            }
        }
    }
    true
}

fn peak_offset(l: f32, c: f32, r: f32) -> f64 {
    let den = l - 2.0 * c + r;
    if den.abs() < 1e-12 {
        0.0
    } else {
        (0.5 * (l - r) / den).clamp(-0.5, 0.5) as f64
    }
}

/// The two edge directions (unit vectors, angles in [0, pi)) of a saddle:
/// the zero lines of the quadratic form `d^T H d`.
pub(crate) fn edge_directions(h: &Matrix2<f64>) -> Option<[nalgebra::Vector2<f64>; 2]> {
    let a = 0.5 * (h[(0, 0)] + h[(1, 1)]);
    let b = 0.5 * (h[(0, 0)] - h[(1, 1)]);
    let c = h[(0, 1)];
    let r = (b * b + c * c).sqrt();
    if r <= a.abs() || r == 0.0 {
        return None;
    }
    let phi = c.atan2(b);
    let delta = (-a / r).acos();
    let t1 = 0.5 * (phi + delta);
    let t2 = 0.5 * (phi - delta);
    Some([
        nalgebra::Vector2::new(t1.cos(), t1.sin()),
        nalgebra::Vector2::new(t2.cos(), t2.sin()),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn finds_the_x_junction_of_four_quadrants() {
        let (w, h) = (41usize, 41usize);
        let data = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 - 20.0, (i / w) as f64 - 20.0);
                if (x >= 0.0) == (y >= 0.0) {
                    200.0
                } else {
                    40.0
                }
            })
            .collect();
        let c = candidates(&Plane { w, h, data }, 10);
        assert_eq!(c.len(), 1, "{c:?}");
        // The junction lies between pixels 19 and 20 (edges at x = -0.5).
        assert!((c[0].pos.x - 19.5).abs() <= 0.5 && (c[0].pos.y - 19.5).abs() <= 0.5);
        let d = edge_directions(&c[0].hessian).unwrap();
        // Edges are the axes: one direction ~(1,0), the other ~(0,1).
        let along_x = d.iter().filter(|v| v.x.abs() > 0.95).count();
        let along_y = d.iter().filter(|v| v.y.abs() > 0.95).count();
        assert_eq!((along_x, along_y), (1, 1), "{d:?}");
    }
}
