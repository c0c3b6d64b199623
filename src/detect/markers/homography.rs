//! Plane-to-image homographies for marker boards: a normalised DLT with
//! `h33 = 1` (board points near the origin map to finite pixels, so `h33`
//! is far from 0) solved by least squares over any number of points >= 4.

use nalgebra::{Matrix3, Point2, SMatrix, SVector, Vector2, Vector3};

/// A homography with its normalisations: `image = T_img^-1 H T_board board`.
#[derive(Debug, Clone)]
pub(crate) struct Homography {
    h: Matrix3<f64>,
}

impl Homography {
    /// Fit to `(board, image)` pairs; `None` with fewer than 4 pairs or a
    /// degenerate configuration.
    pub fn fit(pairs: &[(Point2<f64>, Point2<f64>)]) -> Option<Homography> {
        if pairs.len() < 4 {
            return None;
        }
        let (tb, ti) = (
            normaliser(pairs.iter().map(|p| p.0)),
            normaliser(pairs.iter().map(|p| p.1)),
        );
        let (ata, atb) = dlt_normal_equations(pairs.iter().map(|(b, i)| {
            let b = tb * Vector3::new(b.x, b.y, 1.0);
            let u = ti * Vector3::new(i.x, i.y, 1.0);
            (b.xy(), u.xy())
        }));
        let x = ata.cholesky()?.solve(&atb);
        let h = Matrix3::new(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], 1.0);
        let h = ti.try_inverse()? * h * tb;
        h.iter().all(|v| v.is_finite()).then_some(Homography { h })
    }

    /// The image of board point `b`; `None` at or behind the horizon.
    pub fn map(&self, b: &Point2<f64>) -> Option<Point2<f64>> {
        let w = self.h * Vector3::new(b.x, b.y, 1.0);
        (w.z.abs() > 1e-12).then(|| Point2::new(w.x / w.z, w.y / w.z))
    }
}

/// The normal equations of the DLT rows r1 = (b, 1, 0, 0, 0, -u.x b) and
/// r2 = (0, 0, 0, b, 1, -u.y b) over `(b, u)` pairs (normalised board and
/// image points; also the local homographies of `detect::centres`),
/// summed entry by entry as `ata += r1 r1^T + r2 r2^T` would sum them but
/// without the products of the structural zeros (half the
/// multiplications): an entry never holds -0 (it starts at +0), so adding
/// a zero product changes no bit.
pub(crate) fn dlt_normal_equations(
    pairs: impl Iterator<Item = (Vector2<f64>, Vector2<f64>)>,
) -> (SMatrix<f64, 8, 8>, SVector<f64, 8>) {
    let mut ata = [[0.0f64; 8]; 8];
    let mut atb = [0.0f64; 8];
    for (b, u) in pairs {
        let r1 = [b.x, b.y, 1.0, 0.0, 0.0, 0.0, -u.x * b.x, -u.x * b.y];
        let r2 = [0.0, 0.0, 0.0, b.x, b.y, 1.0, -u.y * b.x, -u.y * b.y];
        for i in 0..3 {
            for j in 0..3 {
                // r2[3..6] == r1[0..3]: the two diagonal blocks agree.
                let v = r1[i] * r1[j];
                ata[i][j] += v;
                ata[i + 3][j + 3] += v;
            }
        }
        for j in 6..8 {
            for i in 0..6 {
                let v = if i < 3 { r1[i] * r1[j] } else { r2[i] * r2[j] };
                ata[i][j] += v;
                ata[j][i] += v;
            }
            for i in 6..8 {
                ata[i][j] += r1[i] * r1[j] + r2[i] * r2[j];
            }
            atb[j] += r1[j] * u.x + r2[j] * u.y;
        }
        for i in 0..3 {
            atb[i] += r1[i] * u.x;
            atb[i + 3] += r2[i + 3] * u.y;
        }
    }
    (
        SMatrix::<f64, 8, 8>::from_fn(|r, c| ata[r][c]),
        SVector::<f64, 8>::from(atb),
    )
}

/// Similarity moving the points' centroid to 0 and their RMS distance to
/// sqrt(2).
fn normaliser(points: impl Iterator<Item = Point2<f64>> + Clone) -> Matrix3<f64> {
    let n = points.clone().count().max(1) as f64;
    let c = points
        .clone()
        .fold(Vector3::zeros(), |a, p| a + Vector3::new(p.x, p.y, 0.0))
        / n;
    let rms = (points
        .map(|p| (p.x - c.x).powi(2) + (p.y - c.y).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    let s = if rms > 1e-12 {
        std::f64::consts::SQRT_2 / rms
    } else {
        1.0
    };
    Matrix3::new(s, 0.0, -s * c.x, 0.0, s, -s * c.y, 0.0, 0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_perspective_map_exactly() {
        let truth = Matrix3::new(60.0, 8.0, 400.0, -5.0, 45.0, 300.0, 0.04, -0.03, 1.0);
        let map = |b: Point2<f64>| {
            let w = truth * Vector3::new(b.x, b.y, 1.0);
            Point2::new(w.x / w.z, w.y / w.z)
        };
        let pairs: Vec<_> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.5, 0.3)]
            .iter()
            .map(|&(x, y)| (Point2::new(x, y), map(Point2::new(x, y))))
            .collect();
        let h = Homography::fit(&pairs).unwrap();
        let b = Point2::new(2.0, -1.5);
        assert!((h.map(&b).unwrap() - map(b)).norm() < 1e-9, "px");
    }

    /// The normal equations as dense outer products (the fit before the
    /// structural zeros were skipped, issue 38).
    fn dense_normal_equations(
        pairs: &[(Point2<f64>, Point2<f64>)],
    ) -> (SMatrix<f64, 8, 8>, SVector<f64, 8>) {
        let tb = normaliser(pairs.iter().map(|p| p.0));
        let ti = normaliser(pairs.iter().map(|p| p.1));
        let mut ata = SMatrix::<f64, 8, 8>::zeros();
        let mut atb = SVector::<f64, 8>::zeros();
        for (b, i) in pairs {
            let b = tb * Vector3::new(b.x, b.y, 1.0);
            let u = ti * Vector3::new(i.x, i.y, 1.0);
            let r1 =
                SVector::<f64, 8>::from([b.x, b.y, 1.0, 0.0, 0.0, 0.0, -u.x * b.x, -u.x * b.y]);
            let r2 =
                SVector::<f64, 8>::from([0.0, 0.0, 0.0, b.x, b.y, 1.0, -u.y * b.x, -u.y * b.y]);
            ata += r1 * r1.transpose() + r2 * r2.transpose();
            atb += r1 * u.x + r2 * u.y;
        }
        (ata, atb)
    }

    #[test]
    fn the_sparse_sums_equal_the_dense_ones_bit_for_bit() {
        let mut rng = crate::rng::Rng::new(38);
        for n in [4usize, 5, 9, 40] {
            let pairs: Vec<_> = (0..n)
                .map(|_| {
                    let b = Point2::new(rng.uniform() * 200.0 - 20.0, rng.uniform() * 150.0);
                    let i = Point2::new(rng.uniform() * 1280.0, rng.uniform() * 960.0);
                    (b, i)
                })
                .collect();
            let (ata, atb) = dense_normal_equations(&pairs);
            let tb = normaliser(pairs.iter().map(|p| p.0));
            let ti = normaliser(pairs.iter().map(|p| p.1));
            let (sparse_ata, sparse_atb) = dlt_normal_equations(pairs.iter().map(|(b, i)| {
                let b = tb * Vector3::new(b.x, b.y, 1.0);
                let u = ti * Vector3::new(i.x, i.y, 1.0);
                (b.xy(), u.xy())
            }));
            let bits = |m: &[f64]| m.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(sparse_ata.as_slice()), bits(ata.as_slice()), "n = {n}");
            assert_eq!(bits(sparse_atb.as_slice()), bits(atb.as_slice()), "n = {n}");
        }
    }
}
