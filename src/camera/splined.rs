//! The splined stereographic lens model: a stereographic base projection
//! plus a smooth 2-D B-spline correction, for lenses no parametric model
//! fits everywhere (mrcal's `LENSMODEL_SPLINED_STEREOGRAPHIC` is the idea;
//! this parametrisation is robocal's own, see docs/lens-models.md).
//!
//! A ray `p = (x, y, z)` maps to its stereographic normalised point
//!
//! ```text
//! u = 2 tan(theta / 2) (x, y) / |(x, y)| = 2 (x, y) / (|p| + z)
//! ```
//!
//! (theta the angle off the optical axis; defined up to, not including,
//! 180 degrees), then to the distorted normalised point `m = u + delta(u)`
//! (pixel = K m, so fx fy cx cy are the base projection's), with `delta`
//! a uniform tensor-product B-spline of degree `order` (2 or 3) whose
//! `nx x ny` control values (a 2-vector each) sit on a regular grid over
//! `[-u_max[0], u_max[0]] x [-u_max[1], u_max[1]]`. The field is split
//! into `nx - order` by `ny - order` equal cells; outside it the edge
//! cells' polynomials extend (smooth, but unconstrained by the spline's
//! support there). Control value `k = row * nx + col` is the coefficient
//! pair `dx{k}`, `dy{k}` (normalised units), in that order.

use crate::error::{Error, Result};
use nalgebra::{Matrix2, Matrix2x3, Vector2, Vector3};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// A distorted normalised point, d m / d point, d m / d coefficients.
type Projected = (Vector2<f64>, Matrix2x3<f64>, Vec<Vector2<f64>>);

/// Largest number of control points along either axis.
pub const MAX_KNOTS: usize = 40;
/// Default control points along x and y: 12 x 8 (mrcal's typical 30 x 18
/// scaled down: a 4:3 image keeps square cells, and 192 coefficients fit in
/// seconds on 40 views; raise them for a lens with fine structure).
pub const DEFAULT_KNOTS: (usize, usize) = (12, 8);
/// Default spline degree (cubic: continuous curvature, as mrcal's default).
pub const DEFAULT_ORDER: usize = 3;
/// Default weight of the smoothness prior (see [`Spline::smoothness`]):
/// on a noise-free render through a bumpy lens (a few px of bumps per
/// knot), 0.1 biased the fit by 0.28 px, 0.01 by 0.1 px, 0.001 by < 0.05 px;
/// 0.01 keeps cells without data tame on 20-40 views.
pub const DEFAULT_SMOOTHNESS: f64 = 0.01;
/// Largest Newton steps of the inverse.
const MAX_NEWTON_STEPS: usize = 50;
/// Convergence of the inverse, normalised units.
const NEWTON_TOLERANCE: f64 = 1e-14;

/// The spline's layout and control values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spline {
    /// Degree of the B-spline: 2 (quadratic) or 3 (cubic).
    pub order: usize,
    /// Control points along x.
    pub nx: usize,
    /// Control points along y.
    pub ny: usize,
    /// Half extent of the knot field in stereographic units (`2 tan(theta/2)`)
    /// along x and y; `[0, 0]` until a calibration sets it to cover the image.
    pub u_max: [f64; 2],
    /// Weight of the smoothness prior in the calibration: each second
    /// difference of neighbouring control values' change from the
    /// calibration's start (the parametric fit's lens), times the focal
    /// length, is a residual of this weight (in pixels) beside the points'.
    pub smoothness: f64,
    /// Control values `[dx0, dy0, dx1, dy1, ...]`, `2 nx ny` of them.
    pub control: Vec<f64>,
}

impl Spline {
    /// A zero correction of `nx x ny` control points of degree `order`,
    /// field not yet set.
    pub fn new(order: usize, nx: usize, ny: usize) -> Spline {
        Spline {
            order,
            nx,
            ny,
            u_max: [0.0, 0.0],
            smoothness: DEFAULT_SMOOTHNESS,
            control: vec![0.0; 2 * nx * ny],
        }
    }

    /// The layout's refusals: order 2 or 3, more control points than the
    /// order and at most [`MAX_KNOTS`] per axis, a set field, `2 nx ny`
    /// control values.
    pub fn check(&self) -> Result<()> {
        if !(self.order == 2 || self.order == 3) {
            return Err(Error::invalid(
                "order",
                format!("the spline order must be 2 or 3, got {}", self.order),
            ));
        }
        for (name, n) in [("nx", self.nx), ("ny", self.ny)] {
            if n <= self.order || n > MAX_KNOTS {
                return Err(Error::invalid(
                    name,
                    format!(
                        "needs {} to {MAX_KNOTS} control points for order {}, got {n}",
                        self.order + 1,
                        self.order
                    ),
                ));
            }
        }
        if !self.u_max.iter().all(|u| u.is_finite() && *u > 0.0) {
            return Err(Error::invalid(
                "u_max",
                format!(
                    "the spline's field is not set (u_max {:?}): a calibration sets it",
                    self.u_max
                ),
            ));
        }
        if self.control.len() != 2 * self.nx * self.ny {
            return Err(Error::invalid(
                "control",
                format!(
                    "{}x{} control points need {} values, got {}",
                    self.nx,
                    self.ny,
                    2 * self.nx * self.ny,
                    self.control.len()
                ),
            ));
        }
        Ok(())
    }

    /// The coefficient names `dx0 dy0 dx1 ...`, one per control value
    /// (none before the calibration makes them).
    pub fn names(&self) -> &'static [&'static str] {
        let all = all_names();
        &all[..self.control.len().min(all.len())]
    }

    /// The full field of view the knot field spans, degrees (x, y).
    pub fn field_deg(&self) -> [f64; 2] {
        self.u_max.map(|u| 4.0 * (0.5 * u).atan().to_degrees())
    }

    /// Along one axis: the first control index, the weights and their
    /// derivatives with respect to u.
    fn axis(&self, u: f64, n: usize, u_max: f64) -> (usize, [f64; 4], [f64; 4]) {
        let p = self.order;
        let cells = n - p;
        let h = 2.0 * u_max / cells as f64;
        let s_f = (u + u_max) / h;
        let s = (s_f.floor().max(0.0) as usize).min(cells - 1);
        let t = s_f - s as f64;
        let (w, dw) = basis(p, t);
        (s, w, dw.map(|d| d / h))
    }

    /// delta(u), its 2x2 Jacobian with respect to u, and the control
    /// values it touches with their weights (`(index of dx, weight)`).
    fn eval(&self, u: &Vector2<f64>) -> (Vector2<f64>, Matrix2<f64>, Vec<(usize, f64)>) {
        let (sx, wx, dwx) = self.axis(u.x, self.nx, self.u_max[0]);
        let (sy, wy, dwy) = self.axis(u.y, self.ny, self.u_max[1]);
        let mut value = Vector2::zeros();
        let (mut d_ux, mut d_uy) = (Vector2::zeros(), Vector2::zeros());
        let mut touched = Vec::with_capacity((self.order + 1) * (self.order + 1));
        for b in 0..=self.order {
            for a in 0..=self.order {
                let k = (sy + b) * self.nx + sx + a;
                let c = Vector2::new(self.control[2 * k], self.control[2 * k + 1]);
                let w = wx[a] * wy[b];
                value += c * w;
                d_ux += c * (dwx[a] * wy[b]);
                d_uy += c * (wx[a] * dwy[b]);
                touched.push((2 * k, w));
            }
        }
        (value, Matrix2::from_columns(&[d_ux, d_uy]), touched)
    }

    /// The coefficient index of each `dx` the correction at `u` touches,
    /// with its weight.
    pub(crate) fn touched(&self, u: &Vector2<f64>) -> Vec<(usize, f64)> {
        self.eval(u).2
    }

    /// The distorted normalised point of a ray, d m / d point and
    /// d m / d control value (one column per coefficient).
    pub(crate) fn project(&self, p: &Vector3<f64>) -> Result<Projected> {
        let (u, du_dp) = stereographic(p)?;
        self.check()?;
        let (delta, d_delta, touched) = self.eval(&u);
        let m = u + delta;
        let d_point = (Matrix2::identity() + d_delta) * du_dp;
        let mut d_coeffs = vec![Vector2::zeros(); self.control.len()];
        for (i, w) in touched {
            d_coeffs[i].x += w;
            d_coeffs[i + 1].y += w;
        }
        Ok((m, d_point, d_coeffs))
    }

    /// The distorted normalised point `m = u + delta(u)` of the
    /// stereographic point `u` and the determinant of d m / d u: where it
    /// is not positive the correction folds (two rays share a pixel).
    pub(crate) fn map_and_determinant(&self, u: &Vector2<f64>) -> (Vector2<f64>, f64) {
        let (delta, d_delta, _) = self.eval(u);
        (u + delta, (Matrix2::identity() + d_delta).determinant())
    }

    /// [`Spline::project`]'s point alone.
    pub(crate) fn project_point(&self, p: &Vector3<f64>) -> Result<Vector2<f64>> {
        let (u, _) = stereographic(p)?;
        self.check()?;
        Ok(u + self.eval(&u).0)
    }

    /// The unit ray of a distorted normalised point: Newton on
    /// `u + delta(u) = m`, refused where the correction folds.
    pub(crate) fn unproject(&self, m: &Vector2<f64>) -> Result<Vector3<f64>> {
        self.check()?;
        let mut u = *m;
        for _ in 0..MAX_NEWTON_STEPS {
            let (delta, d_delta, _) = self.eval(&u);
            let r = u + delta - m;
            let j = Matrix2::identity() + d_delta;
            if !(j.determinant() > 0.0) {
                break;
            }
            if r.norm() <= NEWTON_TOLERANCE * (1.0 + m.norm()) {
                let s = 0.25 * u.norm_squared();
                return Ok(Vector3::new(u.x, u.y, 1.0 - s) / (1.0 + s));
            }
            let Some(inv) = j.try_inverse() else { break };
            u -= inv * r;
            if !u.iter().all(|v| v.is_finite()) {
                break;
            }
        }
        Err(Error::NoConvergence {
            message: format!(
                "splined unprojection of ({:.6}, {:.6}): the correction folds or does not converge",
                m.x, m.y
            ),
        })
    }

    /// The second differences of neighbouring control points along rows
    /// and columns: the smoothness prior's stencils, each three control
    /// indices (the index of the `dx` coefficient; `dy` follows it).
    pub fn smoothness_stencils(&self) -> Vec<[usize; 3]> {
        let idx = |col: usize, row: usize| 2 * (row * self.nx + col);
        let mut out = Vec::new();
        for row in 0..self.ny {
            for col in 1..self.nx.saturating_sub(1) {
                out.push([idx(col - 1, row), idx(col, row), idx(col + 1, row)]);
            }
        }
        for col in 0..self.nx {
            for row in 1..self.ny.saturating_sub(1) {
                out.push([idx(col, row - 1), idx(col, row), idx(col, row + 1)]);
            }
        }
        out
    }

    /// The control point (col, row) whose support holds the most of the
    /// stereographic point `u`: for the data-support mask.
    pub fn cell_of(&self, u: &Vector2<f64>) -> (usize, usize) {
        let (sx, _, _) = self.axis(u.x, self.nx, self.u_max[0]);
        let (sy, _, _) = self.axis(u.y, self.ny, self.u_max[1]);
        (sx, sy)
    }
}

/// The stereographic normalised point of a ray and d u / d p.
pub(crate) fn stereographic(p: &Vector3<f64>) -> Result<(Vector2<f64>, Matrix2x3<f64>)> {
    let n = p.norm();
    let d = n + p.z;
    if !p.iter().all(|v| v.is_finite()) || !(n > 0.0) || !(d > 1e-9 * n) {
        return Err(Error::invalid(
            "point",
            format!(
                "point ({:.4}, {:.4}, {:.4}) has no stereographic projection (at the centre or straight behind)",
                p.x, p.y, p.z
            ),
        ));
    }
    let u = Vector2::new(2.0 * p.x / d, 2.0 * p.y / d);
    let dd = Vector3::new(p.x / n, p.y / n, p.z / n + 1.0);
    let du = Matrix2x3::new(
        2.0 / d - 2.0 * p.x / (d * d) * dd.x,
        -2.0 * p.x / (d * d) * dd.y,
        -2.0 * p.x / (d * d) * dd.z,
        -2.0 * p.y / (d * d) * dd.x,
        2.0 / d - 2.0 * p.y / (d * d) * dd.y,
        -2.0 * p.y / (d * d) * dd.z,
    );
    Ok((u, du))
}

/// The uniform B-spline weights of degree `p` at local parameter `t` and
/// their derivatives with respect to `t` (unused entries 0).
fn basis(p: usize, t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    if p == 2 {
        (
            [
                0.5 * s * s,
                0.5 * (-2.0 * t * t + 2.0 * t + 1.0),
                0.5 * t * t,
                0.0,
            ],
            [-s, 1.0 - 2.0 * t, t, 0.0],
        )
    } else {
        let t2 = t * t;
        let t3 = t2 * t;
        (
            [
                s * s * s / 6.0,
                (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
                (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
                t3 / 6.0,
            ],
            [
                -0.5 * s * s,
                0.5 * (3.0 * t2 - 4.0 * t),
                0.5 * (-3.0 * t2 + 2.0 * t + 1.0),
                0.5 * t2,
            ],
        )
    }
}

/// `dx0 dy0 dx1 dy1 ...` for the largest layout, made once.
fn all_names() -> &'static [&'static str] {
    static NAMES: OnceLock<Vec<&'static str>> = OnceLock::new();
    NAMES.get_or_init(|| {
        (0..MAX_KNOTS * MAX_KNOTS)
            .flat_map(|k| [format!("dx{k}"), format!("dy{k}")])
            .map(|s| &*Box::leak(s.into_boxed_str()))
            .collect()
    })
}
