//! A chessboard corner as the meeting point of its two edges, each edge
//! located by the centroid of its blur (issue 42: corners under lens blur).
//!
//! Why: the saddle fit ([`super::refine`]) finds the centre of point
//! symmetry of the blurred corner. Under a point-symmetric blur that is the
//! corner; under an asymmetric one (coma, astigmatism off axis, a
//! field-dependent defocus) it is not. With Gaussian fit weights `w` the
//! fit's fixed point solves `sum w(t) t B(c + t) = 0`; for a PSF `k` of
//! centroid 0 the kernel that meets the ideal image is `M(u) = int w(u + s)
//! (u + s) k(s) ds`, whose even part, `~ 1/2 (d^2 w)(u) E[s s s]`, is what
//! biases the fit: it grows with the PSF's third moments (its skew) over
//! the window's curvature, and no window shape removes it (only a uniform,
//! infinite one). On renders with blur growing toward the image corners the
//! saddle landed 0.08 px inside the truth in the outer ring.
//!
//! The rule here: across a straight edge the image is the step convolved
//! with the PSF's projection on the profile's line, so the centroid of the
//! profile's derivative is the projection of the PSF's centroid: the ideal
//! edge, whatever the PSF's shape, as long as the profile reaches the
//! plateaus on both sides. By parts, with plateaus `L` and `R` at `t = -h`
//! and `t = h`, that centroid is `(h (L + R) - int I dt) / (R - L)`: no
//! derivative of noisy pixels, and the weight is uniform across the edge,
//! which is what keeps it unbiased (a weight falling off across the edge
//! brings the skew back).
//!
//! Each edge is sampled on both arms, on profiles parallel to the other
//! edge (so they never cross it), from the blur's reach past the corner to
//! the blur's reach before the next one; a parabola through the edge points
//! of both arms gives the edge through the corner (the lens's curvature of
//! the edge included), and the two parabolas meet at the corner. Effects
//! that are point-symmetric about the corner on a chessboard (the camera's
//! gamma, the marker of a ChArUco square) move the centroid one way on one
//! arm and the other way on the opposite arm, where black and white are
//! swapped: they turn the fitted edge about the corner instead of moving
//! it. A shading (vignetting) does not: it moves every centroid toward the
//! brighter light by about `g h^2 / 2` (`g` its log-slope per pixel, `h`
//! the profile's half-length; 0.01-0.02 px at the outer corners of the
//! renders' vignetting), so its gradient is fitted to the white plateaus
//! and divided out of every profile first.
//!
//! Two passes: the first samples long profiles (a quarter of the grid step,
//! at most [`MAX_REACH_PX`], past the edge) and measures how far the blur
//! reaches on each side of each edge; the second cuts the profiles to that
//! reach plus a margin, as a longer profile only adds noise. The result
//! replaces the saddle only where it is clean: each edge's points within
//! [`MAX_SCATTER_PX`] RMS of their parabola, the second pass within
//! [`MAX_PASS_CHANGE_PX`] of the first, the whole move within
//! [`MAX_SHIFT_PX`]. Ungated, on OpenCV's left JPEGs (real optics, JPEG
//! blocks) it moved 68 of 702 corners by more than 0.3 px and raised the
//! calibration's RMS from 0.163 to 0.253 px; gated at 0.08 px, 670 of them
//! kept the saddle there, and at 0.05 px the detector stays within
//! tests/detect/detect_datasets.rs's bound on agreeing with OpenCV there.
//!
//! Measured with the 0.08 px gate (benches/corner_study.py, 40 views per
//! row, 640x480; mean radial error in the outer ring, saddle fit -> gated
//! edges): ideal
//! renders +0.003 -> +0.001 px (RMS 0.015 -> 0.012 px), "lens blur"
//! -0.075 -> -0.024, "edge blur" -0.118 -> -0.039 (middle ring -0.034 ->
//! -0.009). What is left under the strongest blur grows with the radius
//! and with coma and astigmatism together (each alone leaves under 0.005
//! px); it is not the profiles' length (longer ones change it by under
//! 0.003 px).

use super::blobs::bilinear_line;
use super::saddle::edge_directions;
use crate::image::GrayImage;
use nalgebra::{Matrix2, Matrix3, Point2, Vector2, Vector3};

/// Spacing of the samples along a profile, pixels.
const SAMPLE_PX: f64 = 0.5;
/// Spacing of the profiles along an arm, pixels.
const ARM_STEP_PX: f64 = 1.0;
/// Length averaged at each end of a profile for its plateau, pixels.
const PLATEAU_PX: f64 = 1.5;
/// Longest reach of the blur looked for, as a fraction of the grid step,
/// clamped to [`MIN_REACH_PX`, `MAX_REACH_PX`]: the first pass's profiles
/// start this far from the other edge and reach this far (plus the
/// plateau) from their own; the second pass trims both to the blur's
/// measured reach (a longer profile only adds noise).
const REACH_FRACTION: f64 = 0.25;
const MIN_REACH_PX: f64 = 3.0;
const MAX_REACH_PX: f64 = 10.0;
/// The blur's reach on one side of an edge: where the mean normalised
/// profile of its edge comes within this of its plateau.
const TAIL_LEVEL: f64 = 0.005;
/// Kept beyond the measured reach, pixels.
const TAIL_MARGIN_PX: f64 = 2.0;
/// Shortest profile half-length, pixels: a blur that reaches past it
/// spoils the plateaus (symmetrically for a symmetric blur, which cancels).
const MIN_HALF_PROFILE_PX: f64 = 4.0;
/// Profiles needed on each arm.
const MIN_PROFILES_PER_ARM: usize = 3;
/// Edges meeting at less than this sine are left to the saddle fit.
const MIN_SINE: f64 = 0.35;
/// Largest RMS of an edge's points about its parabola, pixels.
const MAX_SCATTER_PX: f64 = 0.05;
/// Largest move of the second pass from the first, pixels.
const MAX_PASS_CHANGE_PX: f64 = 0.2;
/// The edge corner replaces the saddle only within this distance, pixels.
const MAX_SHIFT_PX: f64 = 1.0;

/// Where the profiles may go around one corner.
#[derive(Debug, Clone, Copy)]
pub(crate) struct EdgeRoom {
    /// Distance to the nearest neighbouring corner, pixels.
    pub step_px: f64,
    /// How far a profile may reach into a square from its edge, pixels
    /// (a chessboard's square is clear to the next edge; a ChArUco white
    /// square only to its marker).
    pub depth_px: f64,
}

/// The corner from its edges' centroids, starting at the saddle fit's
/// `corner` with its Hessian `hessian` (for the edge directions). `None`
/// when the room is too small for the blur's reach, an arm leaves the image
/// or has too few profiles with contrast, or the result strays from the
/// saddle by more than [`MAX_SHIFT_PX`].
pub(crate) fn refine_by_edges(
    img: &GrayImage,
    corner: Point2<f64>,
    hessian: &Matrix2<f64>,
    room: EdgeRoom,
) -> Option<Point2<f64>> {
    let [mut d1, mut d2] = edge_directions(hessian)?;
    let reach = (REACH_FRACTION * room.step_px).clamp(MIN_REACH_PX, MAX_REACH_PX);
    // Half-length of the profiles as sampled: the longest reach plus the
    // plateau, within the room.
    let h = (reach + PLATEAU_PX)
        .min(room.depth_px)
        .min(0.5 * room.step_px);
    let h = (h / SAMPLE_PX).floor() * SAMPLE_PX;
    if h < MIN_HALF_PROFILE_PX {
        return None;
    }
    // The blur's reach on the (-across, +across) sides of each edge.
    let mut tails = [[reach; 2]; 2];
    let mut c = corner;
    // Twice: the second pass samples along the directions the first one
    // measured (the Hessian's are those of the smoothed, blurred image)
    // and trims the profiles to the blur's reach the first one measured.
    for pass in 0..2 {
        let sine = (d1.x * d2.y - d1.y * d2.x).abs();
        if sine < MIN_SINE {
            return None;
        }
        // An edge's profiles start clear of the other edge's blur.
        let arms = |other: [f64; 2]| {
            let clear = (other[0].max(other[1]) + TAIL_MARGIN_PX).min(reach) / sine;
            (clear, room.step_px - clear)
        };
        let p1 = sample_arms(img, c, d1, d2, arms(tails[1]), h)?;
        let p2 = sample_arms(img, c, d2, d1, arms(tails[0]), h)?;
        let shading = shading_gradient(&p1, &p2, d1, d2, h)?;
        let (g1, g2) = (shading.dot(&d2), shading.dot(&d1));
        let limits = |t: [f64; 2]| t.map(|v| (v + TAIL_MARGIN_PX + PLATEAU_PX).min(h));
        let e1 = fit_edge(&p1, g1, h, limits(tails[0]), room.step_px)?;
        let e2 = fit_edge(&p2, g2, h, limits(tails[1]), room.step_px)?;
        if pass == 0 {
            tails = [tail_reach(&p1, &e1, g1, h), tail_reach(&p2, &e2, g2, h)];
        }
        // c + a d1 + b d2 on both curves: b = e1(a), a = e2(b).
        let (mut a, mut b) = (0.0, 0.0);
        for _ in 0..20 {
            let (na, nb) = (eval(&e2, b), eval(&e1, a));
            let done = (na - a).abs() + (nb - b).abs() < 1e-6;
            (a, b) = (na, nb);
            if done {
                break;
            }
        }
        let next = c + d1 * a + d2 * b;
        if !(next.x.is_finite() && next.y.is_finite()) || (next - corner).norm() > MAX_SHIFT_PX {
            return None;
        }
        if pass == 1 && (next - c).norm() > MAX_PASS_CHANGE_PX {
            return None;
        }
        // The edges' directions at the corner, for the next pass.
        let t1 = (d1 + d2 * slope(&e1, a)).normalize();
        let t2 = (d2 + d1 * slope(&e2, b)).normalize();
        (d1, d2, c) = (t1, t2, next);
    }
    Some(c)
}

/// The blur's reach on each side of an edge, pixels from the fitted edge:
/// the farthest offset where the mean of the profiles, normalised to 0 and
/// 1 at their plateaus, is more than [`TAIL_LEVEL`] off its plateau.
fn tail_reach(profiles: &[Profile], edge: &Vector3<f64>, shade: f64, h: f64) -> [f64; 2] {
    let n = profiles.first().map_or(0, |p| p.samples.len());
    // Offsets k - k_edge in -n..=n, index + n.
    let mut sum = vec![0.0; 2 * n + 1];
    let mut count = vec![0usize; 2 * n + 1];
    for p in profiles {
        let flat = unshaded(&p.samples, shade, h);
        let (l, r) = (plateau(&flat, false), plateau(&flat, true));
        if (r - l).abs() < 1.0 {
            continue;
        }
        let k_edge = ((eval(edge, p.s) + h) / SAMPLE_PX).round() as isize;
        for (k, v) in flat.iter().enumerate() {
            let j = k as isize - k_edge;
            let norm = (v - l) / (r - l);
            let dev = if j < 0 { norm } else { 1.0 - norm };
            let i = (j + n as isize).clamp(0, 2 * n as isize) as usize;
            sum[i] += dev;
            count[i] += 1;
        }
    }
    let mut out = [0.0f64; 2];
    for (i, (&s, &c)) in sum.iter().zip(&count).enumerate() {
        let j = i as isize - n as isize;
        if c == 0 || j == 0 || (s / c as f64).abs() <= TAIL_LEVEL {
            continue;
        }
        let side = usize::from(j > 0);
        out[side] = out[side].max(j.unsigned_abs() as f64 * SAMPLE_PX);
    }
    out
}

/// A profile's samples divided by the illumination's slope `shade` (log
/// per pixel along the profile).
fn unshaded(samples: &[f64], shade: f64, h: f64) -> Vec<f64> {
    samples
        .iter()
        .enumerate()
        .map(|(k, v)| v * (-shade * (-h + k as f64 * SAMPLE_PX)).exp())
        .collect()
}

fn eval(p: &Vector3<f64>, s: f64) -> f64 {
    p[0] + s * (p[1] + s * p[2])
}

fn slope(p: &Vector3<f64>, s: f64) -> f64 {
    p[1] + 2.0 * s * p[2]
}

/// One profile across an edge: its position `s` along the edge (signed:
/// the two arms), its offset from the corner at its middle, and its
/// samples at `-h + k SAMPLE_PX` along `across`.
struct Profile {
    s: f64,
    middle: Vector2<f64>,
    samples: Vec<f64>,
}

/// The profiles of the edge along `along` through (about) `c`: along
/// `across`, at `c + s along` for `s0 <= |s| <= s1`. `None` when one leaves
/// the image or an arm has fewer than [`MIN_PROFILES_PER_ARM`].
fn sample_arms(
    img: &GrayImage,
    c: Point2<f64>,
    along: Vector2<f64>,
    across: Vector2<f64>,
    (s0, s1): (f64, f64),
    h: f64,
) -> Option<Vec<Profile>> {
    let count = (2.0 * h / SAMPLE_PX).round() as usize + 1;
    let (w, hh) = (img.width as f64, img.height as f64);
    let inside = |p: Point2<f64>| p.x >= 0.0 && p.y >= 0.0 && p.x <= w - 1.0 && p.y <= hh - 1.0;
    let per_arm = ((s1 - s0) / ARM_STEP_PX).floor() as usize + 1;
    if s1 < s0 || per_arm < MIN_PROFILES_PER_ARM {
        return None;
    }
    let mut out = Vec::with_capacity(2 * per_arm);
    for sign in [-1.0, 1.0] {
        for k in 0..per_arm {
            let s = sign * (s0 + k as f64 * ARM_STEP_PX);
            let base = c + along * s;
            if !inside(base - across * h) || !inside(base + across * h) {
                return None;
            }
            let mut samples = Vec::with_capacity(count);
            bilinear_line(img, base, across, (-h, SAMPLE_PX), count, &mut samples);
            out.push(Profile {
                s,
                middle: along * s,
                samples,
            });
        }
    }
    Some(out)
}

/// Mean of the first (`last` false) or last plateau of a profile.
fn plateau(samples: &[f64], last: bool) -> f64 {
    let n = (PLATEAU_PX / SAMPLE_PX).round() as usize + 1;
    let part = if last {
        &samples[samples.len().saturating_sub(n)..]
    } else {
        &samples[..n.min(samples.len())]
    };
    part.iter().sum::<f64>() / part.len().max(1) as f64
}

/// The gradient of the log of the illumination (vignetting, shading) per
/// pixel, from the white plateaus of every profile: `ln v = alpha + g . x`.
/// A multiplicative slope `g . u` across a profile moves its centroid by
/// about `g . u h^2 / 2` toward the brighter light, the same way on both
/// arms: it does not cancel, so the profiles are divided by it.
fn shading_gradient(
    p1: &[Profile],
    p2: &[Profile],
    d1: Vector2<f64>,
    d2: Vector2<f64>,
    h: f64,
) -> Option<Vector2<f64>> {
    let reach = h - 0.5 * PLATEAU_PX;
    let mut ata = Matrix3::zeros();
    let mut atb = Vector3::zeros();
    for (profiles, across) in [(p1, d2), (p2, d1)] {
        for p in profiles {
            let (l, r) = (plateau(&p.samples, false), plateau(&p.samples, true));
            let (v, x) = if r > l {
                (r, p.middle + across * reach)
            } else {
                (l, p.middle - across * reach)
            };
            if v < 1.0 {
                continue;
            }
            let phi = Vector3::new(1.0, x.x, x.y);
            ata += phi * phi.transpose();
            atb += phi * v.ln();
        }
    }
    let g = ata.cholesky()?.solve(&atb);
    Some(Vector2::new(g[1], g[2]))
}

/// The parabola `t(s)` of an edge's points `c + s along + t across` from
/// its profiles, each first divided by the illumination's slope `shade`
/// (log per pixel along `across`) and cut to `limits` (pixels on the
/// `-across` and `+across` sides).
fn fit_edge(
    profiles: &[Profile],
    shade: f64,
    h: f64,
    limits: [f64; 2],
    scale: f64,
) -> Option<Vector3<f64>> {
    let first = ((h - limits[0]) / SAMPLE_PX).round().max(0.0) as usize;
    let last = ((h + limits[1]) / SAMPLE_PX).round() as usize;
    let (ta, tb) = (-h + first as f64 * SAMPLE_PX, -h + last as f64 * SAMPLE_PX);
    let mut points = Vec::with_capacity(profiles.len());
    for p in profiles {
        let flat = unshaded(&p.samples, shade, h);
        let Some(cut) = flat.get(first..=last) else {
            continue;
        };
        if let Some((t, contrast)) = centroid(cut, ta, tb) {
            points.push((p.s, t, contrast * contrast));
        }
    }
    for arm in [-1.0, 1.0] {
        if points.iter().filter(|p| p.0 * arm > 0.0).count() < MIN_PROFILES_PER_ARM {
            return None;
        }
    }
    // Profiles whose contrast is far below the typical one cross something
    // else (a marker, the board's rim, an occluder).
    let mut weights: Vec<f64> = points.iter().map(|p| p.2).collect();
    weights.sort_by(f64::total_cmp);
    let typical = weights[weights.len() / 2];
    points.retain(|p| p.2 >= 0.25 * typical);
    let scale = scale.max(1.0);
    let fit = |pts: &[(f64, f64, f64)]| -> Option<Vector3<f64>> {
        let mut ata = Matrix3::zeros();
        let mut atb = Vector3::zeros();
        for &(s, t, wt) in pts {
            let u = s / scale;
            let phi = Vector3::new(1.0, u, u * u);
            ata += phi * phi.transpose() * wt;
            atb += phi * (t * wt);
        }
        let p = ata.cholesky()?.solve(&atb);
        Some(Vector3::new(p[0], p[1] / scale, p[2] / (scale * scale)))
    };
    let first = fit(&points)?;
    // One pass without the outliers (beyond 4 robust sigmas).
    let mut res: Vec<f64> = points
        .iter()
        .map(|p| (p.1 - eval(&first, p.0)).abs())
        .collect();
    res.sort_by(f64::total_cmp);
    let cut = (4.0 * 1.4826 * res[res.len() / 2]).max(0.05);
    let kept: Vec<_> = points
        .into_iter()
        .filter(|p| (p.1 - eval(&first, p.0)).abs() <= cut)
        .collect();
    if kept.len() < 2 * MIN_PROFILES_PER_ARM {
        return None;
    }
    let edge = fit(&kept)?;
    // An edge whose points scatter about the parabola is not one straight
    // (or gently bent) edge under a blur: leave the corner to the saddle.
    let rms = (kept
        .iter()
        .map(|p| (p.1 - eval(&edge, p.0)).powi(2))
        .sum::<f64>()
        / kept.len() as f64)
        .sqrt();
    (rms <= MAX_SCATTER_PX).then_some(edge)
}

/// Centroid of a profile's derivative, `t` in pixels, and the contrast
/// `R - L`. Samples at `ta + k SAMPLE_PX` up to `tb`; the first and last
/// [`PLATEAU_PX`] give the plateaus. By parts, for plateaus `L` at `ta`
/// and `R` at `tb`: `(tb R - ta L - int I dt) / (R - L)`.
fn centroid(samples: &[f64], ta: f64, tb: f64) -> Option<(f64, f64)> {
    let n = samples.len();
    if n < 2 {
        return None;
    }
    let (left, right) = (plateau(samples, false), plateau(samples, true));
    let contrast = right - left;
    if contrast.abs() < 1.0 {
        return None;
    }
    // Trapezoid over [ta, tb].
    let integral = SAMPLE_PX * (samples.iter().sum::<f64>() - 0.5 * (samples[0] + samples[n - 1]));
    let t = (tb * right - ta * left - integral) / contrast;
    (t > ta + PLATEAU_PX && t < tb - PLATEAU_PX).then_some((t, contrast))
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// A sharp, anti-aliased checker corner at (x0, y0) with edges along
    /// (1, 0.3) and (-0.2, 1): not orthogonal.
    fn corner_image(x0: f64, y0: f64) -> GrayImage {
        let (w, h) = (64u32, 64u32);
        let ss = 8;
        let mut px = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let mut acc = 0.0;
                for sy in 0..ss {
                    for sx in 0..ss {
                        let u = x as f64 - 0.5 + (sx as f64 + 0.5) / ss as f64 - x0;
                        let v = y as f64 - 0.5 + (sy as f64 + 0.5) / ss as f64 - y0;
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
    fn meets_the_edges_of_a_sheared_corner() {
        for (x0, y0) in [(31.3, 32.71), (30.5, 30.5), (32.05, 31.9)] {
            let img = corner_image(x0, y0);
            // The Hessian of `k (n1 . u)(n2 . u)` for the two edge normals.
            let (n1, n2) = (Vector2::new(-0.3, 1.0), Vector2::new(1.0, 0.2));
            let hessian = n1 * n2.transpose() + n2 * n1.transpose();
            let start = Point2::new(x0 + 0.3, y0 - 0.2);
            // Arms and profiles stay inside the 64 px image.
            let room = EdgeRoom {
                step_px: 24.0,
                depth_px: 12.0,
            };
            let p = refine_by_edges(&img, start, &hessian, room).expect("a corner");
            let err = ((p.x - x0).powi(2) + (p.y - y0).powi(2)).sqrt();
            assert!(err < 0.02, "error {err} px at ({x0}, {y0}): {p:?}");
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn the_centroid_of_a_skewed_edge_is_its_centroid() {
        // A step at t = 0.3 blurred by a skewed kernel (a gamma density of
        // shape 2, scale 0.4) shifted to centroid 0: the derivative's
        // centroid stays at 0.3 where the mid-level crossing does not. The
        // kernel starts on a sample (t = -0.5), so the trapezoid is exact
        // to the plateaus' tails.
        let h = 6.0;
        let n = (2.0 * h / SAMPLE_PX) as usize + 1;
        let scale = 0.4;
        let level = |t: f64| {
            let x = t - 0.3 + 2.0 * scale;
            let cdf = if x > 0.0 {
                1.0 - (1.0 + x / scale) * (-x / scale).exp()
            } else {
                0.0
            };
            30.0 + 190.0 * cdf
        };
        let samples: Vec<f64> = (0..n).map(|k| level(-h + k as f64 * SAMPLE_PX)).collect();
        // The mid-level (125) is crossed well before 0.3.
        assert!(level(0.3) > 140.0, "{}", level(0.3));
        let (t, contrast) = centroid(&samples, -h, h).unwrap();
        assert!((t - 0.3).abs() < 0.01, "{t}");
        assert!((contrast - 190.0).abs() < 1.0, "{contrast}");
    }
}
