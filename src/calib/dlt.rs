//! The 12-parameter direct linear transform (seed 002, Eq. 2.1-2.4): the 3x4
//! projection matrix `P` with `[u v 1]^T ~ P [X Y Z 1]^T` from at least six
//! non-coplanar 3-D/2-D pairs, by linear least squares on Hartley-normalized
//! data, then decomposed into `K [R | t]` (`t` of `camera_from_world`).
//!
//! Scale convention of the returned `P`: the third row's first three entries
//! have unit norm and `det(P[:, :3]) > 0`, so `P[2] . [X 1]` is the depth of
//! X in the camera frame (in world units) and the sign is the physical one.

use crate::error::{Error, Result};
use crate::geometry::Pose;
use nalgebra::{
    DMatrix, Matrix3, Matrix3x4, Point2, Point3, Rotation3, Translation3, UnitQuaternion, Vector3,
    Vector4,
};

/// Fewest 3-D/2-D pairs for the 11 degrees of freedom of `P`.
pub const MIN_POINTS: usize = 6;

/// Ratio of the smallest to the largest spread of the 3-D points below which
/// they count as coplanar (the DLT then has a family of solutions).
const COPLANAR_RATIO: f64 = 1e-6;

/// Ratio of the second-smallest to the largest singular value of the
/// normalized design matrix below which the solution is not unique.
const RANK_RATIO: f64 = 1e-9;

/// A projection matrix with its decomposition and residuals.
#[derive(Debug, Clone, PartialEq)]
pub struct DltSolution {
    /// `P` in the scale convention of the module docs.
    pub projection: Matrix3x4<f64>,
    /// Intrinsics: upper triangular, positive diagonal, `K[2][2] = 1`.
    pub camera_matrix: Matrix3<f64>,
    /// Rotation (det +1) and translation of the world in the camera frame.
    pub camera_from_world: Pose,
    /// Per point: projected minus measured pixel, in input order.
    pub residuals_px: Vec<[f64; 2]>,
    /// Root mean square of the residual vector lengths, px.
    pub rms_px: f64,
}

/// Solve the DLT from `points_world` (any length unit; `camera_from_world`'s
/// translation comes out in that unit) and their pixels.
pub fn solve_dlt(points_world: &[Point3<f64>], pixels: &[Point2<f64>]) -> Result<DltSolution> {
    let p = projection_dlt(points_world, pixels)?;
    solution_from_projection(&p, points_world, pixels)
}

/// The linear DLT estimate of `P` (normalized data), in the module's scale convention.
pub fn projection_dlt(
    points_world: &[Point3<f64>],
    pixels: &[Point2<f64>],
) -> Result<Matrix3x4<f64>> {
    if points_world.len() != pixels.len() {
        return Err(Error::invalid(
            "pixels",
            format!(
                "{} 3-D points but {} pixels",
                points_world.len(),
                pixels.len()
            ),
        ));
    }
    let n = points_world.len();
    if n < MIN_POINTS {
        return Err(Error::too_few("3-D/2-D point pairs", MIN_POINTS, n));
    }
    check_not_coplanar(points_world)?;
    let (t3, xs) = normalize_3d(points_world);
    let (t2, us) = normalize_2d(pixels);
    let mut a = DMatrix::<f64>::zeros(2 * n, 12);
    for (i, (x, u)) in xs.iter().zip(&us).enumerate() {
        let xh = [x.x, x.y, x.z, 1.0];
        for j in 0..4 {
            a[(2 * i, j)] = xh[j];
            a[(2 * i, 8 + j)] = -u.x * xh[j];
            a[(2 * i + 1, 4 + j)] = xh[j];
            a[(2 * i + 1, 8 + j)] = -u.y * xh[j];
        }
    }
    // Null vector of A: the eigenvector of A^T A with the smallest eigenvalue.
    let eig = (a.transpose() * &a).symmetric_eigen();
    let mut order: Vec<usize> = (0..12).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let (smallest2, largest) = (
        eig.eigenvalues[order[1]].max(0.0),
        eig.eigenvalues[order[11]],
    );
    if largest <= 0.0 || (smallest2 / largest).sqrt() < RANK_RATIO {
        return Err(Error::degenerate(
            "the 3-D/2-D pairs do not determine a unique projection matrix \
             (critical configuration): spread the points over more of the volume",
        ));
    }
    let v = eig.eigenvectors.column(order[0]);
    let pn = Matrix3x4::from_row_slice(v.as_slice());
    let inv2 = t2
        .try_inverse()
        .ok_or_else(|| Error::degenerate("all pixels coincide"))?;
    Ok(normalize_scale(&(inv2 * pn * t3)))
}

/// Rescale `p` so that `||P[2, :3]|| = 1` and `det(P[:, :3]) > 0`.
pub fn normalize_scale(p: &Matrix3x4<f64>) -> Matrix3x4<f64> {
    let m = p.fixed_view::<3, 3>(0, 0);
    let s = m.row(2).norm() * m.determinant().signum();
    if s == 0.0 || !s.is_finite() {
        return *p;
    }
    p / s
}

/// Decompose `p` and compute the residuals of the given pairs.
pub fn solution_from_projection(
    p: &Matrix3x4<f64>,
    points_world: &[Point3<f64>],
    pixels: &[Point2<f64>],
) -> Result<DltSolution> {
    let p = normalize_scale(p);
    let (camera_matrix, rotation, translation) = decompose(&p)?;
    let residuals_px: Vec<[f64; 2]> = points_world
        .iter()
        .zip(pixels)
        .map(|(x, u)| {
            let q = project(&p, x);
            [q.x - u.x, q.y - u.y]
        })
        .collect();
    let n = residuals_px.len().max(1) as f64;
    let rms_px = (residuals_px
        .iter()
        .map(|r| r[0] * r[0] + r[1] * r[1])
        .sum::<f64>()
        / n)
        .sqrt();
    Ok(DltSolution {
        projection: p,
        camera_matrix,
        camera_from_world: Pose::from_parts(
            Translation3::from(translation),
            UnitQuaternion::from_rotation_matrix(&rotation),
        ),
        residuals_px,
        rms_px,
    })
}

/// Project a world point with `p` (homogeneous division).
pub fn project(p: &Matrix3x4<f64>, x: &Point3<f64>) -> Point2<f64> {
    let h = p * Vector4::new(x.x, x.y, x.z, 1.0);
    Point2::new(h.x / h.z, h.y / h.z)
}

/// RQ decomposition `P[:, :3] = s K R`: K upper triangular with positive
/// diagonal and `K[2][2] = 1`, R a rotation; `t = (sK)^-1 P[:, 3]`.
pub fn decompose(p: &Matrix3x4<f64>) -> Result<(Matrix3<f64>, Rotation3<f64>, Vector3<f64>)> {
    let m: Matrix3<f64> = p.fixed_view::<3, 3>(0, 0).into();
    if m.determinant().abs() < f64::EPSILON * m.norm().powi(3) {
        return Err(Error::degenerate(
            "the left 3x3 block of P is singular: not a finite camera",
        ));
    }
    // RQ from QR of the flipped transpose: with J the exchange matrix,
    // (J M)^T = Q U  =>  M = (J U^T J) (J Q^T).
    let j = Matrix3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0);
    let qr = (j * m).transpose().qr();
    let mut k = j * qr.r().transpose() * j;
    let mut r = j * qr.q().transpose();
    // Make the diagonal of K positive: K D, D R with D = diag(+-1).
    for i in 0..3 {
        if k[(i, i)] < 0.0 {
            k.column_mut(i).neg_mut();
            r.row_mut(i).neg_mut();
        }
    }
    if r.determinant() < 0.0 {
        // det(M) > 0 after normalize_scale; a negative det(R) means P was
        // given with the opposite sign.
        k = -k;
        r = -r;
    }
    let t = k
        .try_inverse()
        .ok_or_else(|| Error::degenerate("K is singular"))?
        * p.column(3);
    let k = k / k[(2, 2)];
    Ok((k, Rotation3::from_matrix_unchecked(r), t))
}

fn check_not_coplanar(points: &[Point3<f64>]) -> Result<()> {
    let n = points.len() as f64;
    let c = points.iter().map(|p| p.coords).sum::<Vector3<f64>>() / n;
    let mut s = Matrix3::zeros();
    for p in points {
        let d = p.coords - c;
        s += d * d.transpose();
    }
    let eig = s.symmetric_eigenvalues();
    let (lo, hi) = (eig.min().max(0.0), eig.max());
    let ratio = if hi > 0.0 { (lo / hi).sqrt() } else { 0.0 };
    if ratio < COPLANAR_RATIO {
        return Err(Error::degenerate(format!(
            "the {} 3-D points are coplanar (spread ratio {ratio:.1e}): the 12-parameter DLT \
             needs non-coplanar points; move the target along z too",
            points.len()
        )));
    }
    Ok(())
}

/// Hartley normalization of 3-D points: centroid to the origin, mean
/// distance sqrt(3). Returns the 4x4 transform and the normalized points.
fn normalize_3d(points: &[Point3<f64>]) -> (nalgebra::Matrix4<f64>, Vec<Point3<f64>>) {
    let n = points.len() as f64;
    let c = points.iter().map(|p| p.coords).sum::<Vector3<f64>>() / n;
    let mean = points.iter().map(|p| (p.coords - c).norm()).sum::<f64>() / n;
    let s = if mean > 0.0 { 3f64.sqrt() / mean } else { 1.0 };
    let mut t = nalgebra::Matrix4::identity() * s;
    t[(3, 3)] = 1.0;
    t.fixed_view_mut::<3, 1>(0, 3).copy_from(&(-s * c));
    (
        t,
        points
            .iter()
            .map(|p| Point3::from((p.coords - c) * s))
            .collect(),
    )
}

/// Hartley normalization of pixels: centroid to the origin, mean distance sqrt(2).
fn normalize_2d(pixels: &[Point2<f64>]) -> (Matrix3<f64>, Vec<Point2<f64>>) {
    let n = pixels.len() as f64;
    let c = pixels
        .iter()
        .map(|p| p.coords)
        .sum::<nalgebra::Vector2<f64>>()
        / n;
    let mean = pixels.iter().map(|p| (p.coords - c).norm()).sum::<f64>() / n;
    let s = if mean > 0.0 { 2f64.sqrt() / mean } else { 1.0 };
    let t = Matrix3::new(s, 0.0, -s * c.x, 0.0, s, -s * c.y, 0.0, 0.0, 1.0);
    (
        t,
        pixels
            .iter()
            .map(|p| Point2::from((p.coords - c) * s))
            .collect(),
    )
}

/// A seeded synthetic XY-table scene for tests: a camera looking down at
/// stage positions on a 3 x 3 grid at two heights (metres).
#[cfg(test)]
pub(crate) mod scene {
    use super::*;

    pub fn camera() -> (Matrix3<f64>, Pose) {
        let k = Matrix3::new(1000.0, 0.5, 320.0, 0.0, 1010.0, 240.0, 0.0, 0.0, 1.0);
        let rotation = UnitQuaternion::from_euler_angles(3.0, 0.1, -0.2);
        (
            k,
            Pose::from_parts(Translation3::new(0.02, -0.01, 0.6), rotation),
        )
    }

    pub fn projection() -> Matrix3x4<f64> {
        let (k, pose) = camera();
        k * pose.to_homogeneous().fixed_view::<3, 4>(0, 0)
    }

    pub fn stage_points() -> Vec<Point3<f64>> {
        let mut v = Vec::new();
        for z in [0.0, 0.05] {
            for i in 0..3 {
                for j in 0..3 {
                    v.push(Point3::new(
                        -0.1 + 0.1 * i as f64,
                        -0.08 + 0.08 * j as f64,
                        z,
                    ));
                }
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn noise_free_points_give_the_exact_camera() {
        let (k, pose) = scene::camera();
        let pts = scene::stage_points();
        let px: Vec<Point2<f64>> = pts
            .iter()
            .map(|x| project(&scene::projection(), x))
            .collect();
        let s = solve_dlt(&pts, &px).unwrap();
        assert!(
            (s.camera_matrix - k).abs().max() < 1e-6,
            "K {}",
            s.camera_matrix
        );
        let d = s.camera_from_world.inverse() * pose;
        assert!(
            d.translation.vector.norm() < 1e-9,
            "translation error {} m",
            d.translation.vector.norm()
        );
        assert!(
            d.rotation.angle() < 1e-9,
            "rotation error {} rad",
            d.rotation.angle()
        );
        assert!(s.rms_px < 1e-9, "rms {} px", s.rms_px);
        // Depth convention: P[2] . [X 1] is the depth of X.
        let depth = (pose * pts[0]).z;
        let h = s.projection * Vector4::new(pts[0].x, pts[0].y, pts[0].z, 1.0);
        assert!((h.z - depth).abs() < 1e-9, "{} vs {depth} m", h.z);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn bad_input_is_refused_clearly() {
        let pts = scene::stage_points();
        let px: Vec<Point2<f64>> = pts
            .iter()
            .map(|x| project(&scene::projection(), x))
            .collect();
        assert_eq!(
            solve_dlt(&pts[..5], &px[..5]).unwrap_err().to_string(),
            "requires at least 6 3-D/2-D point pairs, got 5"
        );
        assert_eq!(
            solve_dlt(&pts[..9], &px[..9]).unwrap_err().to_string(),
            "the 9 3-D points are coplanar (spread ratio 0.0e0): the 12-parameter DLT \
             needs non-coplanar points; move the target along z too"
        );
        assert_eq!(
            solve_dlt(&pts, &px[..9]).unwrap_err().to_string(),
            "pixels: 18 3-D points but 9 pixels"
        );
    }
}
