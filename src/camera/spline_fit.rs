//! A splined camera that reproduces another camera: the start of a splined
//! calibration (from a parametric fit) and the renderer's non-parametric
//! true lens (a parametric lens plus a bump field).

use super::splined::{stereographic, Spline};
use super::{Camera, Distortion};
use crate::error::{Error, Result};
use nalgebra::{DMatrix, Point2, Vector2};

/// Samples per image side of the least-squares fit.
const FIT_SAMPLES: (usize, usize) = (48, 36);
/// Samples per image side when the field is measured.
const BORDER_SAMPLES: usize = 64;
/// The knot field extends this much beyond the image's farthest ray.
const FIELD_MARGIN: f64 = 1.02;
/// Weight of the smoothness rows in the fit (keeps cells without samples
/// determined).
const FIT_SMOOTHNESS: f64 = 1e-4;

impl Camera {
    /// A splined camera (`spline`'s order and knots, its field set to cover
    /// this camera's image) with this camera's fx fy cx cy skew, whose
    /// projection matches this one's: the control values are the linear
    /// least-squares fit to this camera's `m - u` on a grid of pixels.
    /// The field covers the rays of the border pixels this camera can
    /// unproject; fails when it can unproject none.
    pub fn splined_like(&self, spline: &Spline) -> Result<Camera> {
        let mut spline = Spline {
            control: vec![0.0; 2 * spline.nx * spline.ny],
            u_max: [1.0, 1.0],
            ..spline.clone()
        };
        spline.check()?;
        let (w, h) = (self.width as f64 - 1.0, self.height as f64 - 1.0);
        let u_of = |px: Point2<f64>| -> Option<Vector2<f64>> {
            let ray = self.unproject(&px).ok()?;
            stereographic(&ray).ok().map(|(u, _)| u)
        };
        let mut u_max: [f64; 2] = [0.0, 0.0];
        for i in 0..=BORDER_SAMPLES {
            let t = i as f64 / BORDER_SAMPLES as f64;
            for px in [
                Point2::new(t * w, 0.0),
                Point2::new(t * w, h),
                Point2::new(0.0, t * h),
                Point2::new(w, t * h),
            ] {
                // A border pixel the camera cannot unproject (a fitted
                // fisheye polynomial that folds beyond its data, in the
                // image corners) is left out: the field covers the rays
                // the camera has.
                let Some(u) = u_of(px) else { continue };
                u_max[0] = u_max[0].max(u.x.abs());
                u_max[1] = u_max[1].max(u.y.abs());
            }
        }
        if !(u_max[0] > 0.0 && u_max[1] > 0.0) {
            return Err(Error::invalid(
                "camera",
                format!(
                    "no pixel of the {}x{} image's border unprojects: no spline field to cover",
                    self.width, self.height
                ),
            ));
        }
        spline.u_max = u_max.map(|u| u * FIELD_MARGIN);
        spline.check()?;
        let n = spline.nx * spline.ny;
        let mut normal = DMatrix::<f64>::zeros(n, n);
        let mut rhs = DMatrix::<f64>::zeros(n, 2);
        for iy in 0..FIT_SAMPLES.1 {
            for ix in 0..FIT_SAMPLES.0 {
                let px = Point2::new(
                    ix as f64 * w / (FIT_SAMPLES.0 - 1) as f64,
                    iy as f64 * h / (FIT_SAMPLES.1 - 1) as f64,
                );
                let Some(u) = u_of(px) else { continue };
                let Ok(m) = self.normalized_from_pixel(&px) else {
                    continue;
                };
                let target = m - u;
                let touched = spline.weights(&u);
                for &(a, wa) in &touched {
                    for &(b, wb) in &touched {
                        normal[(a, b)] += wa * wb;
                    }
                    rhs[(a, 0)] += wa * target.x;
                    rhs[(a, 1)] += wa * target.y;
                }
            }
        }
        for [a, b, c] in spline.smoothness_stencils() {
            let idx = [a / 2, b / 2, c / 2];
            let coef = [1.0, -2.0, 1.0];
            for i in 0..3 {
                for j in 0..3 {
                    normal[(idx[i], idx[j])] += FIT_SMOOTHNESS * coef[i] * coef[j];
                }
            }
        }
        let solution = normal.cholesky().map(|c| c.solve(&rhs)).ok_or_else(|| {
            Error::degenerate("the spline fit to the camera's projection is singular")
        })?;
        for k in 0..n {
            spline.control[2 * k] = solution[(k, 0)];
            spline.control[2 * k + 1] = solution[(k, 1)];
        }
        Ok(Camera {
            distortion: Distortion::Splined(spline),
            ..self.clone()
        })
    }
}

impl Spline {
    /// The control points (their index `k`, not the coefficient's) the
    /// correction at `u` touches, with their weights.
    pub(crate) fn weights(&self, u: &Vector2<f64>) -> Vec<(usize, f64)> {
        self.touched(u)
            .into_iter()
            .map(|(i, w)| (i / 2, w))
            .collect()
    }
}

/// Samples per knot cell and axis when a splined camera is searched for a
/// fold (a fold narrower than an eighth of a cell needs a control value
/// jump no smoothness prior leaves).
const FOLD_SAMPLES_PER_CELL: usize = 8;
/// The fold search extends this much beyond the knot field (the bundle
/// adjustment can move border pixels' rays slightly outside it).
const FOLD_FIELD_MARGIN: f64 = 1.1;

impl Camera {
    /// Where a splined camera folds among the pixels `keep` accepts: the
    /// pixel and determinant of d m / d u (negative or zero: rays on both
    /// sides of the fold share pixels) of the sampled stereographic point
    /// with the lowest determinant that is not positive; `None` when there
    /// is no fold there or the camera is not splined.
    pub fn splined_fold(&self, keep: impl Fn(&Point2<f64>) -> bool) -> Option<(Point2<f64>, f64)> {
        let Distortion::Splined(spline) = &self.distortion else {
            return None;
        };
        spline.check().ok()?;
        let (w, h) = (self.width as f64 - 0.5, self.height as f64 - 0.5);
        let samples = |n: usize| (n - spline.order) * FOLD_SAMPLES_PER_CELL + 1;
        let (sx, sy) = (samples(spline.nx), samples(spline.ny));
        let along = |i: usize, n: usize, u_max: f64| {
            FOLD_FIELD_MARGIN * u_max * (2.0 * i as f64 / (n - 1) as f64 - 1.0)
        };
        let mut worst: Option<(Point2<f64>, f64)> = None;
        for iy in 0..sy {
            for ix in 0..sx {
                let u = Vector2::new(
                    along(ix, sx, spline.u_max[0]),
                    along(iy, sy, spline.u_max[1]),
                );
                let (m, det) = spline.map_and_determinant(&u);
                if !(det <= 0.0) || worst.is_some_and(|(_, d)| d <= det) {
                    continue;
                }
                let px = self.pixel_from_normalized(&m);
                let inside = px.x >= -0.5 && px.y >= -0.5 && px.x <= w && px.y <= h;
                if inside && keep(&px) {
                    worst = Some((px, det));
                }
            }
        }
        worst
    }
}
