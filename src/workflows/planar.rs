//! Planar eye-to-hand calibration at one height (seed 001): the 2-D transform
//! `robot_from_image` that maps undistorted image points (px) to robot
//! X, Y (mm) on a plane at a known height, fitted by least squares from
//! point pairs, with per-point residuals.
//!
//! Three models, chosen by the user ([`TransformKind`]):
//! - `rigid`: rotation + translation, unit scale (only meaningful when the
//!   image coordinates are already metric);
//! - `similarity`: rotation + uniform scale + translation;
//! - `affine`: the full 2x3 matrix (six parameters). The article's Table 4
//!   matrices are affine (a12 != a21 and a11 != -a22).
//!
//! Image axes (u right, v down) and robot axes (x, y) often have opposite
//! handedness; rigid and similarity fits then contain a reflection, which
//! the least-squares solution (Umeyama without the determinant correction)
//! finds by itself and reports as `reflected`.

use crate::error::{Error, Result};
use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};

/// Fewest point pairs per height (three non-collinear points fix a plane
/// transform and leave one redundant point with four corners).
pub const MIN_POINTS: usize = 3;

/// Ratio of the smaller to the larger spread of the image points below which
/// they count as collinear.
const COLLINEAR_RATIO: f64 = 1e-6;

/// The 2-D transform model fitted at each height.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TransformKind {
    /// Rotation and translation (and a reflection when the data demands it).
    #[serde(rename = "rigid")]
    Rigid,
    /// Rotation, uniform scale and translation (and reflection).
    #[serde(rename = "similarity")]
    Similarity,
    /// General 2x3 affine matrix.
    #[serde(rename = "affine")]
    Affine,
}

impl TransformKind {
    /// Parse `rigid`, `similarity` or `affine`.
    pub fn parse(name: &str) -> Result<TransformKind> {
        match name {
            "rigid" => Ok(TransformKind::Rigid),
            "similarity" => Ok(TransformKind::Similarity),
            "affine" => Ok(TransformKind::Affine),
            other => Err(Error::invalid(
                "transform",
                format!("expected rigid, similarity or affine, got '{other}'"),
            )),
        }
    }
}

/// A 2x3 matrix `robot_from_image`: `x_mm = a11 u + a12 v + tx`,
/// `y_mm = a21 u + a22 v + ty` with (u, v) in px. Field names follow the
/// article's Table 4.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlanarMatrix {
    /// mm of robot x per px of u.
    pub a11: f64,
    /// mm of robot x per px of v.
    pub a12: f64,
    /// Robot x of the image origin, mm.
    pub tx: f64,
    /// mm of robot y per px of u.
    pub a21: f64,
    /// mm of robot y per px of v.
    pub a22: f64,
    /// Robot y of the image origin, mm.
    pub ty: f64,
}

/// One per-height matrix, as in the article's Table 4. In JSON one flat
/// object `{"height_mm", "a11", "a12", "tx", "a21", "a22", "ty"}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HeightMatrix {
    /// Calibration height, mm.
    pub height_mm: f64,
    /// The matrix `robot_from_image` at that height.
    #[serde(flatten)]
    pub robot_from_image: PlanarMatrix,
}

impl PlanarMatrix {
    /// Parameter names in the order of [`PlanarMatrix::to_array`].
    pub const NAMES: [&'static str; 6] = ["a11", "a12", "tx", "a21", "a22", "ty"];

    /// The six parameters as `[a11, a12, tx, a21, a22, ty]`.
    pub fn to_array(&self) -> [f64; 6] {
        [self.a11, self.a12, self.tx, self.a21, self.a22, self.ty]
    }

    /// Build from `[a11, a12, tx, a21, a22, ty]`.
    pub fn from_array(p: [f64; 6]) -> PlanarMatrix {
        PlanarMatrix {
            a11: p[0],
            a12: p[1],
            tx: p[2],
            a21: p[3],
            a22: p[4],
            ty: p[5],
        }
    }

    /// Map an image point (px) to robot coordinates (mm).
    pub fn apply(&self, image_px: [f64; 2]) -> [f64; 2] {
        let [u, v] = image_px;
        [
            self.a11 * u + self.a12 * v + self.tx,
            self.a21 * u + self.a22 * v + self.ty,
        ]
    }

    /// Map a robot point (mm) back to the image (px); fails when the linear
    /// part is singular.
    pub fn apply_inverse(&self, robot_mm: [f64; 2]) -> Result<[f64; 2]> {
        let a = Matrix2::new(self.a11, self.a12, self.a21, self.a22);
        let inv = a
            .try_inverse()
            .ok_or_else(|| Error::degenerate("the 2x2 part of the planar matrix is singular"))?;
        let p = inv * Vector2::new(robot_mm[0] - self.tx, robot_mm[1] - self.ty);
        Ok([p.x, p.y])
    }
}

/// One image/robot point pair on the calibration plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointPair {
    /// Undistorted image point, px.
    pub image_px: [f64; 2],
    /// Robot X, Y, mm.
    pub robot_mm: [f64; 2],
}

/// A fitted transform with its per-point residuals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanarFit {
    /// The model fitted.
    pub kind: TransformKind,
    /// The fitted matrix.
    pub robot_from_image: PlanarMatrix,
    /// Whether the fitted linear part has a negative determinant (image and
    /// robot axes of opposite handedness).
    pub reflected: bool,
    /// Per point: fitted minus given robot X, Y (mm), in input order.
    pub residuals_mm: Vec<[f64; 2]>,
    /// Root mean square of the residual vector lengths, mm.
    pub rms_mm: f64,
}

/// Fit `kind` to `pairs` by least squares.
pub fn fit_transform(pairs: &[PointPair], kind: TransformKind) -> Result<PlanarFit> {
    if pairs.len() < MIN_POINTS {
        return Err(Error::too_few("point pairs", MIN_POINTS, pairs.len()));
    }
    let n = pairs.len() as f64;
    let p: Vec<Vector2<f64>> = pairs.iter().map(|q| Vector2::from(q.image_px)).collect();
    let q: Vec<Vector2<f64>> = pairs.iter().map(|q| Vector2::from(q.robot_mm)).collect();
    let mp = p.iter().sum::<Vector2<f64>>() / n;
    let mq = q.iter().sum::<Vector2<f64>>() / n;
    // Scatter of the image points and cross-covariance robot x image.
    let mut spp = Matrix2::zeros();
    let mut sqp = Matrix2::zeros();
    for (a, b) in p.iter().zip(&q) {
        spp += (a - mp) * (a - mp).transpose();
        sqp += (b - mq) * (a - mp).transpose();
    }
    check_not_collinear(&spp, pairs.len())?;
    let linear = match kind {
        TransformKind::Affine => {
            let inv = spp
                .try_inverse()
                .ok_or_else(|| Error::degenerate("the image points are collinear"))?;
            sqp * inv
        }
        TransformKind::Rigid | TransformKind::Similarity => {
            let svd = sqp.svd(true, true);
            let (u, v_t) = match (svd.u, svd.v_t) {
                (Some(u), Some(v_t)) => (u, v_t),
                _ => return Err(Error::degenerate("SVD of the cross-covariance failed")),
            };
            // Best orthogonal matrix, proper or not: no determinant correction.
            let rotation = u * v_t;
            let scale = match kind {
                TransformKind::Similarity => svd.singular_values.sum() / spp.trace(),
                _ => 1.0,
            };
            rotation * scale
        }
    };
    let t = mq - linear * mp;
    let m = PlanarMatrix {
        a11: linear[(0, 0)],
        a12: linear[(0, 1)],
        tx: t.x,
        a21: linear[(1, 0)],
        a22: linear[(1, 1)],
        ty: t.y,
    };
    let residuals_mm: Vec<[f64; 2]> = pairs
        .iter()
        .map(|pp| {
            let f = m.apply(pp.image_px);
            [f[0] - pp.robot_mm[0], f[1] - pp.robot_mm[1]]
        })
        .collect();
    let rms_mm = (residuals_mm
        .iter()
        .map(|r| r[0] * r[0] + r[1] * r[1])
        .sum::<f64>()
        / n)
        .sqrt();
    Ok(PlanarFit {
        kind,
        robot_from_image: m,
        reflected: linear.determinant() < 0.0,
        residuals_mm,
        rms_mm,
    })
}

fn check_not_collinear(spp: &Matrix2<f64>, count: usize) -> Result<()> {
    let eig = spp.symmetric_eigenvalues();
    let (lo, hi) = (eig.min().max(0.0), eig.max());
    let ratio = if hi > 0.0 { (lo / hi).sqrt() } else { 0.0 };
    if ratio < COLLINEAR_RATIO {
        return Err(Error::degenerate(format!(
            "the {count} image points are collinear (spread ratio {ratio:.1e}): \
             a planar transform needs points that span both image directions"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn pairs_from(m: &PlanarMatrix, image: &[[f64; 2]]) -> Vec<PointPair> {
        image
            .iter()
            .map(|&p| PointPair {
                image_px: p,
                robot_mm: m.apply(p),
            })
            .collect()
    }

    const CORNERS: [[f64; 2]; 4] = [
        [1284.8, 432.0],
        [1290.7, 3296.7],
        [3015.6, 3293.2],
        [3009.8, 428.5],
    ];

    #[wasm_bindgen_test(unsupported = test)]
    fn every_kind_recovers_its_own_model_exactly() {
        // A mirrored similarity (image v -> robot x), as in the article.
        let (s, th) = (0.7_f64, 0.008_f64);
        let sim = PlanarMatrix::from_array([
            -s * th.sin(),
            s * th.cos(),
            -1743.9,
            s * th.cos(),
            s * th.sin(),
            689.5,
        ]);
        let rigid = PlanarMatrix::from_array([th.cos(), -th.sin(), 10.0, th.sin(), th.cos(), -4.0]);
        let affine = PlanarMatrix::from_array([-0.0057, 0.6978, -1743.9, 0.6959, 0.0051, 689.5]);
        for (kind, m, mirrored) in [
            (TransformKind::Similarity, sim, true),
            (TransformKind::Rigid, rigid, false),
            (TransformKind::Affine, affine, true),
        ] {
            let fit = fit_transform(&pairs_from(&m, &CORNERS), kind).unwrap();
            for (a, b) in fit.robot_from_image.to_array().iter().zip(m.to_array()) {
                assert!((a - b).abs() < 1e-9, "{kind:?}: {a} vs {b}");
            }
            assert_eq!(fit.reflected, mirrored, "{kind:?}");
            assert!(fit.rms_mm < 1e-9, "{kind:?}: rms {} mm", fit.rms_mm);
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn residuals_are_per_point_and_inverse_maps_back() {
        let m = PlanarMatrix::from_array([0.0, 0.7, -1700.0, 0.7, 0.0, 700.0]);
        let mut pairs = pairs_from(&m, &CORNERS);
        pairs[2].robot_mm[0] += 0.4;
        let fit = fit_transform(&pairs, TransformKind::Similarity).unwrap();
        // A least-squares fit spreads a single 0.4 mm error over the corners.
        assert!(fit.residuals_mm[2][0] < -0.1, "{:?}", fit.residuals_mm);
        let back = m.apply_inverse(m.apply([100.0, 200.0])).unwrap();
        assert!((back[0] - 100.0).abs() < 1e-9 && (back[1] - 200.0).abs() < 1e-9);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn bad_input_is_refused_clearly() {
        let m = PlanarMatrix::from_array([0.0, 0.7, -1700.0, 0.7, 0.0, 700.0]);
        let two = pairs_from(&m, &CORNERS[..2]);
        assert_eq!(
            fit_transform(&two, TransformKind::Affine)
                .unwrap_err()
                .to_string(),
            "requires at least 3 point pairs, got 2"
        );
        let line = pairs_from(&m, &[[0.0, 0.0], [10.0, 10.0], [20.0, 20.0]]);
        assert_eq!(
            fit_transform(&line, TransformKind::Similarity)
                .unwrap_err()
                .to_string(),
            "the 3 image points are collinear (spread ratio 0.0e0): \
             a planar transform needs points that span both image directions"
        );
        assert_eq!(
            TransformKind::parse("projective").unwrap_err().to_string(),
            "transform: expected rigid, similarity or affine, got 'projective'"
        );
    }
}
