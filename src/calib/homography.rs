//! Plane-to-image homographies by the normalised direct linear transform
//! (Hartley): both point sets are moved to their centroid and scaled to a
//! mean distance of sqrt(2) before the SVD, which makes the 9x9 system well
//! conditioned in pixel units.

use crate::error::{Error, Result};
use nalgebra::{DMatrix, Matrix3, Point2};

/// The homography `H` with `image ~ H [x, y, 1]^T` from at least 4 point
/// pairs (plane coordinates in metres, image in pixels), normalised to
/// `H[2][2] = 1` when possible.
pub fn homography(plane: &[Point2<f64>], image: &[Point2<f64>]) -> Result<Matrix3<f64>> {
    if plane.len() != image.len() {
        return Err(Error::invalid(
            "points",
            format!(
                "{} plane points but {} image points",
                plane.len(),
                image.len()
            ),
        ));
    }
    if plane.len() < 4 {
        return Err(Error::too_few(
            "point pairs for a homography",
            4,
            plane.len(),
        ));
    }
    let tp = normalising_transform(plane)?;
    let ti = normalising_transform(image)?;
    // At least 9 rows so that the SVD yields the full 9x9 V.
    let rows = (2 * plane.len()).max(9);
    let mut a = DMatrix::zeros(rows, 9);
    for (k, (p, q)) in plane.iter().zip(image).enumerate() {
        let p = tp * p.to_homogeneous();
        let q = ti * q.to_homogeneous();
        let (x, y, u, v) = (p.x, p.y, q.x, q.y);
        let r = 2 * k;
        a.row_mut(r)
            .copy_from_slice(&[x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y, -u]);
        a.row_mut(r + 1)
            .copy_from_slice(&[0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y, -v]);
    }
    let svd = a.svd(false, true);
    let v_t = svd
        .v_t
        .ok_or_else(|| Error::degenerate("homography SVD failed"))?;
    let (mut min_i, mut min_s) = (0, f64::INFINITY);
    let mut second = f64::INFINITY;
    for (i, &s) in svd.singular_values.iter().enumerate() {
        if s < min_s {
            second = min_s;
            min_i = i;
            min_s = s;
        } else if s < second {
            second = s;
        }
    }
    // A second (near) null vector means the points do not fix H: collinear
    // plane or image points.
    if second <= 1e-9 * svd.singular_values.max() {
        return Err(Error::degenerate(
            "the points do not determine a homography (collinear or repeated points)",
        ));
    }
    let h = v_t.row(min_i);
    let hn = Matrix3::new(h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7], h[8]);
    let ti_inv = ti
        .try_inverse()
        .ok_or_else(|| Error::degenerate("image points are all equal"))?;
    let mut out = ti_inv * hn * tp;
    if out[(2, 2)].abs() > f64::EPSILON * out.amax() {
        out /= out[(2, 2)];
    }
    Ok(out)
}

/// Similarity moving the points' centroid to 0 and their mean distance to
/// sqrt(2).
fn normalising_transform(points: &[Point2<f64>]) -> Result<Matrix3<f64>> {
    let n = points.len() as f64;
    let cx = points.iter().map(|p| p.x).sum::<f64>() / n;
    let cy = points.iter().map(|p| p.y).sum::<f64>() / n;
    let mean = points
        .iter()
        .map(|p| ((p.x - cx).powi(2) + (p.y - cy).powi(2)).sqrt())
        .sum::<f64>()
        / n;
    if !(mean > 0.0) || !mean.is_finite() {
        return Err(Error::degenerate("all points coincide (or are not finite)"));
    }
    let s = std::f64::consts::SQRT_2 / mean;
    Ok(Matrix3::new(
        s,
        0.0,
        -s * cx,
        0.0,
        s,
        -s * cy,
        0.0,
        0.0,
        1.0,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn recovers_an_exact_homography_and_rejects_collinear_points() {
        let h = Matrix3::new(820.0, 12.0, 310.0, -8.0, 805.0, 220.0, 0.05, -0.03, 1.0);
        let plane: Vec<Point2<f64>> = (0..20)
            .map(|i| Point2::new((i % 5) as f64 * 0.03, (i / 5) as f64 * 0.03))
            .collect();
        let image: Vec<Point2<f64>> = plane
            .iter()
            .map(|p| Point2::from_homogeneous(h * p.to_homogeneous()).unwrap_or(Point2::origin()))
            .collect();
        let est = homography(&plane, &image).unwrap_or_else(|e| panic!("{e}"));
        assert!((est - h).amax() < 1e-9 * h.amax(), "{est}");
        let line: Vec<Point2<f64>> = (0..6)
            .map(|i| Point2::new(i as f64, 2.0 * i as f64))
            .collect();
        assert_eq!(
            homography(&line, &line).map_err(|e| e.to_string()),
            Err(
                "the points do not determine a homography (collinear or repeated points)"
                    .to_string()
            )
        );
        assert_eq!(
            homography(&plane[..3], &image[..3]).map_err(|e| e.to_string()),
            Err("requires at least 4 point pairs for a homography, got 3".to_string())
        );
    }
}
