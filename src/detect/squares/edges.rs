//! Sub-pixel corners of one square: edge points from profiles across each
//! side, a curve per side, corners where the curves meet (see the parent
//! module's "Corners" section).

use super::*;

/// A side's curve `v = c0 + c1 u + c2 u^2` in its frame (origin `m`, `t`
/// along the side from its first corner to its second, `n` outward), with
/// the parameters' covariance.
#[derive(Debug, Clone)]
struct Curve {
    m: Point2<f64>,
    t: Vector2<f64>,
    n: Vector2<f64>,
    c: Vector3<f64>,
    cov: Matrix3<f64>,
}

impl Curve {
    fn local(&self, p: &Point2<f64>) -> (f64, f64) {
        let d = p - self.m;
        (d.dot(&self.t), d.dot(&self.n))
    }
    fn basis(u: f64) -> Vector3<f64> {
        Vector3::new(1.0, u, u * u)
    }
    /// Signed distance-like residual `v - poly(u)` and its gradient.
    fn eval(&self, p: &Point2<f64>) -> (f64, Vector2<f64>) {
        let (u, v) = self.local(p);
        let g = v - self.c.dot(&Self::basis(u));
        let slope = self.c[1] + 2.0 * self.c[2] * u;
        (g, self.n - self.t * slope)
    }
    fn point(&self, u: f64) -> Point2<f64> {
        self.m + self.t * u + self.n * self.c.dot(&Self::basis(u))
    }
}

/// Where curves `a` and `b` meet, near `start`, with its covariance.
fn meet(a: &Curve, b: &Curve, start: Point2<f64>) -> Option<(Point2<f64>, Matrix2<f64>)> {
    let mut p = start;
    for _ in 0..8 {
        let (ga, da) = a.eval(&p);
        let (gb, db) = b.eval(&p);
        let j = Matrix2::new(da.x, da.y, db.x, db.y);
        let step = j.try_inverse()? * Vector2::new(ga, gb);
        p -= step;
        if !(p.x.is_finite() && p.y.is_finite()) {
            return None;
        }
        if step.norm() < 1e-9 {
            break;
        }
    }
    let (_, da) = a.eval(&p);
    let (_, db) = b.eval(&p);
    let jinv = Matrix2::new(da.x, da.y, db.x, db.y).try_inverse()?;
    let var = |c: &Curve| {
        let phi = Curve::basis(c.local(&p).0);
        (phi.transpose() * c.cov * phi)[(0, 0)]
    };
    let cov = jinv * Matrix2::new(var(a), 0.0, 0.0, var(b)) * jinv.transpose();
    Some((p, cov))
}

/// Sub-pixel corners of one dark square from its coarse corners (clockwise
/// on screen). `gap_px`: roughly the light gap to the next square.
pub(super) fn refine_square(
    img: &GrayImage,
    coarse: &[Point2<f64>; 4],
    gap_px: f64,
    model: SideModel,
) -> Option<[(Point2<f64>, Matrix2<f64>); 4]> {
    let centre = Point2::from(coarse.iter().fold(Vector2::zeros(), |s, p| s + p.coords) / 4.0);
    let side_px = (0..4)
        .map(|k| (coarse[(k + 1) % 4] - coarse[k]).norm())
        .fold(f64::MAX, f64::min);
    if !(side_px >= 4.0) || !gap_px.is_finite() {
        return None;
    }
    let inside = bilinear_u8(img, centre.x, centre.y);
    let mut corners: Vec<(Point2<f64>, Matrix2<f64>)> =
        coarse.iter().map(|p| (*p, Matrix2::zeros())).collect();
    // Curves from the previous pass (sides k = corner k -> k + 1).
    let mut curves: Option<Vec<Curve>> = None;
    let mut half_window = 3.0f64;
    let mut scratch = Profile::default();
    for pass in 0..PASSES {
        let search = if pass == 0 {
            (0.2 * side_px).min(0.35 * gap_px - half_window).max(1.0)
        } else {
            1.0
        };
        // Coarse passes only bring the sides near; the fine ones measure.
        let fine = pass >= COARSE_PASSES;
        let sample_step = if fine {
            PROFILE_STEP_PX
        } else {
            COARSE_PROFILE_STEP_PX
        };
        let mut fitted: Vec<[Curve; 2]> = Vec::with_capacity(4);
        let mut widths = Vec::new();
        for k in 0..4 {
            let (p, q) = (corners[k].0, corners[(k + 1) % 4].0);
            let chord = q - p;
            let len = chord.norm();
            if !(len >= 4.0) {
                return None;
            }
            let t = chord / len;
            let mut nrm = Vector2::new(t.y, -t.x);
            let m = Point2::from((p.coords + q.coords) * 0.5);
            if nrm.dot(&(m - centre)) < 0.0 {
                nrm = -nrm;
            }
            // Angles at both ends set how far from each corner profiles are
            // clear of the other side.
            let excl = |corner: usize, other: Point2<f64>| {
                let d = (other - corners[corner].0).normalize();
                let along = if corner == k { t } else { -t };
                let cos = d.dot(&along).clamp(-0.99, 0.99);
                let sin = (1.0 - cos * cos).sqrt();
                let reach = search + half_window + 1.0;
                // At least 2 px, at most 0.3 of the side (which wins on
                // sides under 6.7 px: `clamp` would panic there).
                ((half_window + reach * cos.max(0.0)) / sin + 1.0)
                    .max(2.0)
                    .min(0.3 * len)
            };
            let e0 = excl(k, corners[(k + 3) % 4].0);
            let e1 = excl((k + 1) % 4, corners[(k + 2) % 4].0);
            let prev = curves.as_ref().map(|c| &c[k]);
            let mut edge_pts: Vec<(f64, f64)> = Vec::new();
            let mut u = -0.5 * len + e0;
            while u <= 0.5 * len - e1 {
                // Base point on the previous curve (or the chord).
                let base = match prev {
                    Some(c) => {
                        let (uc, _) = c.local(&(m + t * u));
                        c.point(uc)
                    }
                    None => m + t * u,
                };
                let window = (search, half_window, sample_step);
                if let Some((s, width)) =
                    edge_on_profile(img, base, nrm, window, inside, &mut scratch)
                {
                    let e = base + nrm * s;
                    let d = e - m;
                    edge_pts.push((d.dot(&t), d.dot(&nrm)));
                    widths.push(width);
                }
                u += if fine {
                    PROFILE_SPACING_PX
                } else {
                    // At least MIN_FIRST_PASS_PROFILES profiles per side.
                    (len / MIN_FIRST_PASS_PROFILES).clamp(PROFILE_SPACING_PX, FIRST_PASS_SPACING_PX)
                };
            }
            let span = (-0.5 * len + e0, 0.5 * len - e1);
            // The coarse pass's few profiles only place the sides: a line
            // (half-side segments would get too few points there).
            let f = fit_side(
                m,
                t,
                nrm,
                &edge_pts,
                span,
                if fine { model } else { SideModel::Line },
            )?;
            fitted.push(f);
        }
        // The blur seen on the edges sets the next pass's window.
        if !widths.is_empty() {
            widths.sort_by(f64::total_cmp);
            let sd = widths[widths.len() / 2];
            half_window = (WINDOW_SDS * sd + 0.5).clamp(1.5, (0.3 * gap_px).max(1.5));
        }
        let mut next = Vec::with_capacity(4);
        for k in 0..4 {
            // Corner k joins side k - 1 (its end) and side k (its start).
            let a = &fitted[(k + 3) % 4][1];
            let b = &fitted[k][0];
            let (c, cov) = meet(a, b, corners[k].0)?;
            if (c - coarse[k]).norm() > 0.35 * side_px {
                return None;
            }
            next.push((c, cov));
        }
        let moved = next
            .iter()
            .zip(&corners)
            .map(|(a, b)| (a.0 - b.0).norm())
            .fold(0.0, f64::max);
        corners = next;
        if fine && moved <= CONVERGED_PX {
            break;
        }
        // The next pass's profiles follow each side's first curve (the two
        // half-side segments of a side nearly coincide).
        curves = Some(fitted.iter().map(|f| f[0].clone()).collect());
    }
    convex(&corners.iter().map(|c| c.0).collect::<Vec<_>>())
        .then(|| [corners[0], corners[1], corners[2], corners[3]])
}

/// Curves for a side's two ends (the same curve unless the model fits a
/// segment per corner). `span`: the range of `u` that was measured.
fn fit_side(
    m: Point2<f64>,
    t: Vector2<f64>,
    n: Vector2<f64>,
    pts: &[(f64, f64)],
    span: (f64, f64),
    model: SideModel,
) -> Option<[Curve; 2]> {
    match model {
        SideModel::Line | SideModel::Parabola => {
            let degree = if model == SideModel::Line { 1 } else { 2 };
            let c = fit_poly(m, t, n, pts, degree)?;
            Some([c.clone(), c])
        }
        SideModel::CornerSegments => {
            let mid = 0.5 * (span.0 + span.1);
            let first: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.0 <= mid).collect();
            let second: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.0 >= mid).collect();
            Some([
                fit_poly(m, t, n, &first, 1)?,
                fit_poly(m, t, n, &second, 1)?,
            ])
        }
    }
}

/// Least-squares polynomial `v(u)` of degree 1 or 2, with one pass of
/// outlier rejection (residuals beyond 3 robust sigmas, at least 0.15 px).
fn fit_poly(
    m: Point2<f64>,
    t: Vector2<f64>,
    n: Vector2<f64>,
    pts: &[(f64, f64)],
    degree: usize,
) -> Option<Curve> {
    let solve =
        |use_pt: &dyn Fn(usize) -> bool| -> Option<(Vector3<f64>, Matrix3<f64>, f64, usize)> {
            let mut ata = Matrix3::zeros();
            let mut atb = Vector3::zeros();
            let mut count = 0;
            for (i, &(u, v)) in pts.iter().enumerate() {
                if !use_pt(i) {
                    continue;
                }
                let phi = Curve::basis(u);
                ata += phi * phi.transpose();
                atb += phi * v;
                count += 1;
            }
            if count < MIN_EDGE_POINTS {
                return None;
            }
            if degree < 2 {
                // Pin c2 = 0 with a unit row that does not touch the others.
                for k in 0..3 {
                    ata[(2, k)] = 0.0;
                    ata[(k, 2)] = 0.0;
                }
                ata[(2, 2)] = 1.0;
                atb[2] = 0.0;
            }
            let inv = ata.try_inverse()?;
            let c = inv * atb;
            let sse: f64 = pts
                .iter()
                .enumerate()
                .filter(|(i, _)| use_pt(*i))
                .map(|(_, &(u, v))| (v - c.dot(&Curve::basis(u))).powi(2))
                .sum();
            let dof = (count as f64 - (degree + 1) as f64).max(1.0);
            let mut cov = inv * (sse / dof);
            if degree < 2 {
                cov[(2, 2)] = 0.0;
            }
            Some((c, cov, (sse / dof).sqrt(), count))
        };
    let (c, _, _, _) = solve(&|_| true)?;
    let mut res: Vec<f64> = pts
        .iter()
        .map(|&(u, v)| (v - c.dot(&Curve::basis(u))).abs())
        .collect();
    let resid = res.clone();
    res.sort_by(f64::total_cmp);
    let robust = (1.4826 * res[res.len() / 2]).max(0.05);
    let limit = (3.0 * robust).max(0.15);
    let (c, cov, _, _) = solve(&|i| resid[i] <= limit)?;
    Some(Curve { m, t, n, c, cov })
}

/// A profile's samples, reused from profile to profile (no allocation per
/// profile).
#[derive(Default)]
pub(super) struct Profile {
    vals: Vec<f64>,
    /// Running sums of the derivative `d`, `d s` and `d s^2` over the
    /// samples before k (k + 1 entries): a window's centroid in O(1).
    sums: Vec<[f64; 3]>,
}

/// Edge on the profile `base + s n`, `|s| <= search`: the strongest rise of
/// the grey level (dark inside to light outside), then the centroid of the
/// derivative in a window of half-width `half_window` moved onto it.
/// Returns the offset `s` and the edge's blur (the derivative's sd).
pub(super) fn edge_on_profile(
    img: &GrayImage,
    base: Point2<f64>,
    n: Vector2<f64>,
    (search, half_window, step): (f64, f64, f64),
    inside: f64,
    scratch: &mut Profile,
) -> Option<(f64, f64)> {
    let reach = search + half_window + 0.5;
    let count = (2.0 * reach / step).ceil() as usize + 1;
    let s0 = -reach;
    let at = |k: usize| s0 + k as f64 * step;
    // Samples half a pixel either side of the derivative's sample.
    let half = (0.5 / step).round() as usize;
    bilinear_line(img, base, n, (s0, step), count, &mut scratch.vals);
    let vals = &scratch.vals[..];
    // Derivative over one pixel (the samples half a pixel either side),
    // at sample k; zero where a side is missing.
    let deriv = |k: usize| {
        if k < half || k + half >= count {
            0.0
        } else {
            vals[k + half] - vals[k - half]
        }
    };
    // The samples with |s| <= search: a run around s = 0 (tested exactly,
    // from one sample before the run's estimated start).
    let first_in = (((-search - s0) / step).floor() - 1.0).max(0.0) as usize;
    let mut best: Option<(usize, f64)> = None;
    for k in first_in..count {
        let s = at(k);
        if s > search {
            break;
        }
        let d = deriv(k);
        if s.abs() <= search && best.map_or(true, |b| d > b.1) {
            best = Some((k, d));
        }
    }
    let (kb, peak) = best?;
    // The rise must be a real edge: at least a fifth of the contrast
    // between the square's inside and the light just outside this edge.
    let outside = vals[count - 1].max(vals[(kb + 4 * half).min(count - 1)]);
    let contrast = outside - inside;
    if !(contrast > 10.0) || peak < 0.2 * contrast {
        return None;
    }
    let sums = &mut scratch.sums;
    sums.clear();
    sums.push([0.0; 3]);
    let mut acc = [0.0f64; 3];
    for k in 0..count {
        let (d, s) = (deriv(k), at(k));
        acc = [acc[0] + d, acc[1] + d * s, acc[2] + d * s * s];
        sums.push(acc);
    }
    let mut centre = at(kb);
    let mut width = 0.0;
    for _ in 0..CENTROID_ITERATIONS {
        let [sw, sws, swss] = window_sums(sums, deriv, (s0, step), centre, half_window)?;
        if !(sw > 0.0) {
            return None;
        }
        let c = sws / sw;
        width = (swss / sw - c * c).max(0.0).sqrt();
        let moved = (c - centre).abs();
        centre = c;
        if moved < 1e-3 {
            break;
        }
    }
    (centre.abs() <= search + 0.5).then_some((centre, width))
}

/// Sums of `d`, `d s` and `d s^2` over the window `|s - c| <= h` of a
/// profile sampled every `step` from `s0`: each sample stands for the cell
/// of one step around it and counts by the part of its cell inside the
/// window. So the sums, and the centroid, move continuously with the
/// window; counting whole samples made them jump by a sample's weight
/// whenever the window's end crossed one, which left the fixed point of
/// the centroid iteration (and the corner) to jitter with the sampling
/// phase from pass to pass (docs/benchmark-history.md, "Session 14:
/// square grids, the window's ends"). `sums[k]` holds the sums over the samples before
/// `k`; the window is cut to the profile's cells.
fn window_sums(
    sums: &[[f64; 3]],
    deriv: impl Fn(usize) -> f64,
    (s0, step): (f64, f64),
    c: f64,
    h: f64,
) -> Option<[f64; 3]> {
    let count = sums.len() - 1;
    let at = |k: usize| s0 + k as f64 * step;
    let a = (c - h).max(s0 - 0.5 * step);
    let b = (c + h).min(at(count - 1) + 0.5 * step);
    // The samples whose cells hold the window's ends (a - s0 >= -step / 2,
    // so the cast rounds a non-negative number; no call to `round`).
    let inv = 1.0 / step;
    let lo = (((a - s0) * inv + 0.5) as usize).min(count - 1);
    let hi = (((b - s0) * inv + 0.5) as usize).min(count - 1);
    if hi <= lo {
        return None;
    }
    // Whole cells strictly between, then the two end cells' parts.
    let (x, y) = (sums[lo + 1], sums[hi]);
    let mut acc = [y[0] - x[0], y[1] - x[1], y[2] - x[2]];
    let part_lo = (at(lo) + 0.5 * step - a) * inv;
    let part_hi = (b - (at(hi) - 0.5 * step)) * inv;
    for (k, part) in [(lo, part_lo), (hi, part_hi)] {
        let (d, s) = (deriv(k) * part.clamp(0.0, 1.0), at(k));
        acc = [acc[0] + d, acc[1] + d * s, acc[2] + d * s * s];
    }
    Some(acc)
}

/// The four corners form a convex quadrilateral, clockwise on screen.
fn convex(p: &[Point2<f64>]) -> bool {
    (0..4).all(|k| {
        let a = p[(k + 1) % 4] - p[k];
        let b = p[(k + 2) % 4] - p[(k + 1) % 4];
        a.x * b.y - a.y * b.x > 0.0
    })
}
