//! The OpenCV polynomial family: Brown-Conrady radial + tangential terms,
//! the rational radial factor and the thin-prism terms, in normalised
//! coordinates (x, y) = (X/Z, Y/Z).
//!
//! ```text
//! r2     = x^2 + y^2
//! radial = (1 + k1 r2 + k2 r2^2 + k3 r2^3) / (1 + k4 r2 + k5 r2^2 + k6 r2^3)
//! x_d    = x radial + 2 p1 x y + p2 (r2 + 2 x^2) + s1 r2 + s2 r2^2
//! y_d    = y radial + p1 (r2 + 2 y^2) + 2 p2 x y + s3 r2 + s4 r2^2
//! ```
//!
//! This is exactly OpenCV's `projectPoints` with 5, 8 or 12 coefficients
//! (no tilt). Brown (`k1 k2 p1 p2 k3`, Halcon's "polynomial") and the
//! seed-000 radial form (`k1 k2 k5`) are special cases with the other
//! coefficients zero, so the math lives here once.

use crate::error::{Error, Result};
use nalgebra::{Matrix2, Vector2};

/// All 12 coefficients of the family, in OpenCV's order
/// `k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Poly {
    pub k: [f64; 6],
    pub p: [f64; 2],
    pub s: [f64; 4],
}

/// Index of each coefficient in [`Poly::jacobian_coeffs`]' 12 columns.
pub(crate) mod col {
    pub const K1: usize = 0;
    pub const K2: usize = 1;
    pub const P1: usize = 2;
    pub const P2: usize = 3;
    pub const K3: usize = 4;
    pub const K4: usize = 5;
    pub const K5: usize = 6;
    pub const K6: usize = 7;
    pub const S1: usize = 8;
    pub const S2: usize = 9;
    pub const S3: usize = 10;
    pub const S4: usize = 11;
}

/// Largest number of Newton steps of the inverse.
const MAX_NEWTON_STEPS: usize = 50;
/// The inverse has converged when the re-distorted point is this close (in
/// normalised units; 1e-12 is ~1e-9 px at a 1000 px focal length).
const NEWTON_TOLERANCE: f64 = 1e-13;

/// Samples of the radial derivative between the centre and a point used to
/// decide whether the point lies before the first fold of the model.
const DOMAIN_SAMPLES: usize = 8;

impl Poly {
    /// Whether normalised radius^2 `r2` lies inside the model's valid
    /// domain: the radial map `r -> r radial(r)` increases and the rational
    /// denominator stays positive on [0, r] (checked at
    /// [`DOMAIN_SAMPLES`] radii). Beyond the first fold a polynomial lens
    /// model maps far-away rays back into the image, which no real lens does.
    /// The tangential and thin-prism terms are assumed small here.
    #[inline]
    pub fn in_domain(&self, r2: f64) -> bool {
        let [k1, k2, k3, k4, k5, k6] = self.k;
        // Fast exact path without a denominator (b = 1): the derivative
        // condition is g(t) = 1 + 3 k1 t + 5 k2 t^2 + 7 k3 t^3 > 0, and this
        // lower bound of g on [0, r2] being positive means every sample
        // passes; otherwise the samples decide.
        if k4 == 0.0 && k5 == 0.0 && k6 == 0.0 && r2 >= 0.0 {
            let bound = 1.0 - r2 * (3.0 * k1.abs() + r2 * (5.0 * k2.abs() + r2 * 7.0 * k3.abs()));
            if bound > 0.0 {
                return true;
            }
        }
        (1..=DOMAIN_SAMPLES).all(|i| {
            let f = i as f64 / DOMAIN_SAMPLES as f64;
            let t = r2 * f * f;
            let a = 1.0 + t * (k1 + t * (k2 + t * k3));
            let b = 1.0 + t * (k4 + t * (k5 + t * k6));
            let da = k1 + t * (2.0 * k2 + t * 3.0 * k3);
            let db = k4 + t * (2.0 * k5 + t * 3.0 * k6);
            // d(r a/b)/dr times b^2.
            b > 0.0 && (a + 2.0 * t * da) * b - 2.0 * t * a * db > 0.0
        })
    }

    /// The distorted normalised point alone: the value of [`Poly::distort`]
    /// (the same expressions, so the same bits) without its Jacobians, for
    /// projections that need no derivatives.
    pub fn distort_value(&self, n: &Vector2<f64>) -> Vector2<f64> {
        let (x, y) = (n.x, n.y);
        let [k1, k2, k3, k4, k5, k6] = self.k;
        let [p1, p2] = self.p;
        let [s1, s2, s3, s4] = self.s;
        let r2 = x * x + y * y;
        let r4 = r2 * r2;
        let r6 = r4 * r2;
        let a = 1.0 + k1 * r2 + k2 * r4 + k3 * r6;
        let b = 1.0 + k4 * r2 + k5 * r4 + k6 * r6;
        let radial = a / b;
        let xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) + s1 * r2 + s2 * r4;
        let yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y + s3 * r2 + s4 * r4;
        Vector2::new(xd, yd)
    }

    /// Distorted normalised point, its 2x2 Jacobian with respect to (x, y),
    /// and the 2x12 Jacobian with respect to the coefficients (columns in
    /// the order of [`col`]).
    pub fn distort(&self, n: &Vector2<f64>) -> (Vector2<f64>, Matrix2<f64>, [Vector2<f64>; 12]) {
        let (m, d_n, columns) = self.distort_lazy(n);
        let mut d_c = [Vector2::zeros(); 12];
        for (c, d) in d_c.iter_mut().enumerate() {
            *d = columns.column(c);
        }
        (m, d_n, d_c)
    }

    /// [`Poly::distort`] with the coefficient columns left to compute one
    /// at a time ([`CoefficientColumns::column`], the same expressions, so
    /// the same bits): a model that uses 5 of the 12 columns skips the
    /// others' divisions.
    pub fn distort_lazy(
        &self,
        n: &Vector2<f64>,
    ) -> (Vector2<f64>, Matrix2<f64>, CoefficientColumns) {
        let (x, y) = (n.x, n.y);
        let [k1, k2, k3, k4, k5, k6] = self.k;
        let [p1, p2] = self.p;
        let [s1, s2, s3, s4] = self.s;
        let r2 = x * x + y * y;
        let r4 = r2 * r2;
        let r6 = r4 * r2;
        let a = 1.0 + k1 * r2 + k2 * r4 + k3 * r6;
        let b = 1.0 + k4 * r2 + k5 * r4 + k6 * r6;
        // Without a denominator (b is 1 exactly) a division by it or its
        // square changes no bit, and is skipped.
        let radial = if b == 1.0 { a } else { a / b };
        let da = k1 + 2.0 * k2 * r2 + 3.0 * k3 * r4;
        let db = k4 + 2.0 * k5 * r2 + 3.0 * k6 * r4;
        // d radial / d r2
        let dr = if b == 1.0 {
            da * b - a * db
        } else {
            (da * b - a * db) / (b * b)
        };
        let xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) + s1 * r2 + s2 * r4;
        let yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y + s3 * r2 + s4 * r4;
        let d_n = Matrix2::new(
            radial
                + 2.0 * x * x * dr
                + 2.0 * p1 * y
                + 6.0 * p2 * x
                + 2.0 * s1 * x
                + 4.0 * s2 * r2 * x,
            2.0 * x * y * dr + 2.0 * p1 * x + 2.0 * p2 * y + 2.0 * s1 * y + 4.0 * s2 * r2 * y,
            2.0 * x * y * dr + 2.0 * p1 * x + 2.0 * p2 * y + 2.0 * s3 * x + 4.0 * s4 * r2 * x,
            radial
                + 2.0 * y * y * dr
                + 6.0 * p1 * y
                + 2.0 * p2 * x
                + 2.0 * s3 * y
                + 4.0 * s4 * r2 * y,
        );
        let columns = CoefficientColumns {
            x,
            y,
            r2,
            r4,
            r6,
            a,
            b,
        };
        (Vector2::new(xd, yd), d_n, columns)
    }

    /// The undistorted normalised point whose distortion is `m`, by Newton's
    /// method from `m`. Fails rather than return a point on the far side of
    /// a fold of the distortion (where its Jacobian determinant is <= 0) or
    /// a point that does not re-distort onto `m`.
    pub fn undistort(&self, m: &Vector2<f64>) -> Result<Vector2<f64>> {
        let mut n = *m;
        let scale = 1.0 + m.norm();
        for _ in 0..MAX_NEWTON_STEPS {
            let (d, j, _) = self.distort(&n);
            let residual = d - m;
            if !residual.iter().all(|v| v.is_finite()) {
                break;
            }
            if residual.norm() <= NEWTON_TOLERANCE * scale {
                if j.determinant() <= 0.0 || !self.in_domain(n.norm_squared()) {
                    return Err(Error::NoConvergence {
                        message: format!(
                            "undistorting ({:.6}, {:.6}): the solution lies beyond the fold of the distortion model",
                            m.x, m.y
                        ),
                    });
                }
                return Ok(n);
            }
            let Some(j_inv) = j.try_inverse() else { break };
            let mut step = j_inv * residual;
            // Damp steps that would jump far outside the current radius: the
            // polynomial is only trustworthy near the image.
            let limit = 0.5 * (1.0 + n.norm());
            if step.norm() > limit {
                step *= limit / step.norm();
            }
            n -= step;
        }
        Err(Error::NoConvergence {
            message: format!(
                "undistorting ({:.6}, {:.6}): Newton's method did not converge in {MAX_NEWTON_STEPS} steps",
                m.x, m.y
            ),
        })
    }
}

/// What the coefficient columns of [`Poly::distort`] need at one point.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CoefficientColumns {
    x: f64,
    y: f64,
    r2: f64,
    r4: f64,
    r6: f64,
    a: f64,
    b: f64,
}

impl CoefficientColumns {
    /// d distorted point / d coefficient `c` (an index of [`col`]).
    #[inline]
    pub fn column(&self, c: usize) -> Vector2<f64> {
        let Self {
            x,
            y,
            r2,
            r4,
            r6,
            a,
            b,
        } = *self;
        let v = |a: f64, b: f64| Vector2::new(a, b);
        // Without a denominator (b is 1 exactly) as in `distort_lazy`.
        let num = |rp: f64| {
            if b == 1.0 {
                v(x * rp, y * rp)
            } else {
                v(x * rp / b, y * rp / b)
            }
        };
        let den = |rp: f64| v(-x * a * rp / (b * b), -y * a * rp / (b * b));
        match c {
            col::K1 => num(r2),
            col::K2 => num(r4),
            col::K3 => num(r6),
            col::K4 => den(r2),
            col::K5 => den(r4),
            col::K6 => den(r6),
            col::P1 => v(2.0 * x * y, r2 + 2.0 * y * y),
            col::P2 => v(r2 + 2.0 * x * x, 2.0 * x * y),
            col::S1 => v(r2, 0.0),
            col::S2 => v(r4, 0.0),
            col::S3 => v(0.0, r2),
            _ => v(0.0, r4),
        }
    }
}
