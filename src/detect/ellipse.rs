//! Ellipse fit to edge points: a least-squares conic
//! `a x^2 + b x y + c y^2 + d x + e y = 1` in coordinates centred and scaled
//! on the points' mean, the centre where the conic's gradient vanishes, and
//! the centre's covariance propagated from the residual scatter.

use nalgebra::{Matrix2, Matrix5, Point2, Vector2, Vector5};

/// A fitted ellipse centre with its 2x2 covariance, pixels and px^2.
#[derive(Debug, Clone)]
pub(crate) struct EllipseFit {
    pub centre: Point2<f64>,
    pub covariance: Matrix2<f64>,
    /// Semi-axes (major, minor), pixels.
    pub semi_axes: (f64, f64),
}

/// Fit an ellipse to at least 6 points; `None` for non-ellipses.
pub(crate) fn fit_ellipse(points: &[Point2<f64>]) -> Option<EllipseFit> {
    let n = points.len();
    if n < 6 {
        return None;
    }
    let mean = points.iter().fold(Vector2::zeros(), |s, p| s + p.coords) / n as f64;
    let scale = (points
        .iter()
        .map(|p| (p.coords - mean).norm_squared())
        .sum::<f64>()
        / n as f64)
        .sqrt();
    if !(scale > 1e-9) {
        return None;
    }
    let rows: Vec<Vector5<f64>> = points
        .iter()
        .map(|p| {
            let q = (p.coords - mean) / scale;
            Vector5::new(q.x * q.x, q.x * q.y, q.y * q.y, q.x, q.y)
        })
        .collect();
    let mut ata = Matrix5::zeros();
    let mut atb = Vector5::zeros();
    for r in &rows {
        ata += r * r.transpose();
        atb += r;
    }
    let ata_inv = ata.try_inverse()?;
    let p = ata_inv * atb;
    let centre_of = |p: &Vector5<f64>| -> Option<Vector2<f64>> {
        let h = Matrix2::new(2.0 * p[0], p[1], p[1], 2.0 * p[2]);
        if h.determinant() <= 0.0 {
            return None;
        }
        Some(-(h.try_inverse()? * Vector2::new(p[3], p[4])))
    };
    let c = centre_of(&p)?;
    // Semi-axes from the conic's quadratic form at the centre.
    let a2 = Matrix2::new(p[0], 0.5 * p[1], 0.5 * p[1], p[2]);
    let k = 1.0 + (c.transpose() * a2 * c)[(0, 0)];
    if k <= 0.0 {
        return None;
    }
    let eig = a2.symmetric_eigenvalues();
    let (l1, l2) = (eig[0].max(eig[1]), eig[0].min(eig[1]));
    if l2 <= 0.0 {
        return None;
    }
    let semi_axes = ((k / l2).sqrt() * scale, (k / l1).sqrt() * scale);
    // Covariance of the conic parameters from the algebraic residuals, then
    // to the centre by a finite-difference Jacobian.
    let sse: f64 = rows.iter().map(|r| (r.dot(&p) - 1.0).powi(2)).sum();
    let dof = (n as f64 - 5.0).max(1.0);
    let cov_p = ata_inv * (sse / dof);
    let mut jac = nalgebra::Matrix2x5::zeros();
    for i in 0..5 {
        let hstep = 1e-6 * p[i].abs().max(1e-3);
        let mut pp = p;
        pp[i] += hstep;
        let cp = centre_of(&pp)?;
        jac.set_column(i, &((cp - c) / hstep));
    }
    let covariance = jac * cov_p * jac.transpose() * (scale * scale);
    Some(EllipseFit {
        centre: Point2::from(c * scale + mean),
        covariance,
        semi_axes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn exact_and_noisy_ellipses() {
        let (cx, cy, a, b, t) = (40.3, -12.7, 9.0, 4.0, 0.6f64);
        let pts = |noise: f64, rng: &mut Rng| -> Vec<Point2<f64>> {
            (0..40)
                .map(|k| {
                    let s = k as f64 / 40.0 * std::f64::consts::TAU;
                    let (u, v) = (a * s.cos(), b * s.sin());
                    Point2::new(
                        cx + u * t.cos() - v * t.sin() + rng.gaussian(noise),
                        cy + u * t.sin() + v * t.cos() + rng.gaussian(noise),
                    )
                })
                .collect()
        };
        let mut rng = Rng::new(3);
        let f = fit_ellipse(&pts(0.0, &mut rng)).unwrap();
        assert!((f.centre.x - cx).abs() < 1e-9 && (f.centre.y - cy).abs() < 1e-9);
        assert!((f.semi_axes.0 - a).abs() < 1e-9 && (f.semi_axes.1 - b).abs() < 1e-9);
        // Noise 0.1 px on 40 points: the centre's sd is about 0.1/sqrt(20) =
        // 0.022 px per axis; the estimated covariance must be of that order.
        let f = fit_ellipse(&pts(0.1, &mut rng)).unwrap();
        let sd = f.covariance[(0, 0)].sqrt();
        assert!(sd > 0.005 && sd < 0.06, "sd {sd}");
        assert!((f.centre.x - cx).abs() < 5.0 * 0.03, "{:?}", f.centre);
        // Collinear points are not an ellipse.
        let line: Vec<Point2<f64>> = (0..10)
            .map(|k| Point2::new(k as f64, 2.0 * k as f64))
            .collect();
        assert!(fit_ellipse(&line).is_none());
    }
}
