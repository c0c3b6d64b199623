//! Planar eye-to-hand calibration *at any height* (seed 001): every parameter
//! of the per-height matrix `robot_from_image` is fitted linearly against the
//! calibration height, optionally after rejecting points of high dispersion;
//! the fitted lines give the matrix, and the mapping of image points with an
//! error estimate, at any height. Also the pixel density (px per mm) against
//! height with its own fit.

use super::linear_fit::{fit_line, fit_line_rejecting, LinearFit};
use super::planar::PlanarMatrix;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Fewest distinct calibration heights for a fit against height.
pub const MIN_HEIGHTS: usize = 2;

/// One value per matrix parameter, keyed by the article's names.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ByParameter<T> {
    /// For `a11`.
    pub a11: T,
    /// For `a12`.
    pub a12: T,
    /// For `tx`.
    pub tx: T,
    /// For `a21`.
    pub a21: T,
    /// For `a22`.
    pub a22: T,
    /// For `ty`.
    pub ty: T,
}

impl<T> ByParameter<T> {
    /// Build by calling `f` with the parameter index 0..6 (order of
    /// [`PlanarMatrix::NAMES`]).
    pub fn try_from_fn(mut f: impl FnMut(usize) -> Result<T>) -> Result<Self> {
        Ok(ByParameter {
            a11: f(0)?,
            a12: f(1)?,
            tx: f(2)?,
            a21: f(3)?,
            a22: f(4)?,
            ty: f(5)?,
        })
    }

    /// References in the order of [`PlanarMatrix::NAMES`].
    pub fn to_array(&self) -> [&T; 6] {
        [
            &self.a11, &self.a12, &self.tx, &self.a21, &self.a22, &self.ty,
        ]
    }
}

/// The linear model of every matrix parameter against height.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HeightModel {
    /// Per parameter: the line `value = intercept + slope * height_mm`.
    pub fit: ByParameter<LinearFit>,
    /// Per parameter: heights (mm) rejected as high-dispersion points before
    /// the final fit (empty without rejection).
    pub rejected_heights_mm: ByParameter<Vec<f64>>,
    /// The calibration heights used, mm, in input order.
    pub heights_mm: Vec<f64>,
}

/// An image point mapped to the robot plane at some height.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MappedPoint {
    /// Height of the plane, mm.
    pub height_mm: f64,
    /// The image point, px.
    pub image_px: [f64; 2],
    /// Robot X, Y, mm.
    pub robot_mm: [f64; 2],
    /// One-sigma error estimate of robot X, Y (mm) from the uncertainty of
    /// the six fitted lines (their scatter about the line at this height).
    /// It does not include errors of the image point itself.
    pub std_mm: [f64; 2],
    /// The interpolated matrix at this height.
    pub robot_from_image: PlanarMatrix,
}

impl HeightModel {
    /// Fit every parameter of `matrices[i]` (at `heights_mm[i]`) against
    /// height. With `reject_threshold = Some(k)`, points whose externally
    /// studentized residual exceeds `k` standard deviations are dropped one
    /// at a time and the line refitted (the article's "eliminate the points
    /// with high dispersion and refit").
    pub fn fit(
        heights_mm: &[f64],
        matrices: &[PlanarMatrix],
        reject_threshold: Option<f64>,
    ) -> Result<HeightModel> {
        if heights_mm.len() != matrices.len() {
            return Err(Error::invalid(
                "matrices",
                format!(
                    "{} heights but {} matrices",
                    heights_mm.len(),
                    matrices.len()
                ),
            ));
        }
        let distinct = count_distinct(heights_mm);
        if distinct < MIN_HEIGHTS {
            return Err(Error::too_few(
                "distinct calibration heights",
                MIN_HEIGHTS,
                distinct,
            ));
        }
        let mut rejected: Vec<Vec<f64>> = Vec::new();
        let fit = ByParameter::try_from_fn(|k| {
            let y: Vec<f64> = matrices.iter().map(|m| m.to_array()[k]).collect();
            match reject_threshold {
                None => {
                    rejected.push(Vec::new());
                    fit_line(heights_mm, &y)
                }
                Some(t) => {
                    let r = fit_line_rejecting(heights_mm, &y, t)?;
                    rejected.push(r.rejected.iter().map(|&i| heights_mm[i]).collect());
                    Ok(r.fit)
                }
            }
        })?;
        let mut it = rejected.into_iter();
        let rejected_heights_mm = ByParameter::try_from_fn(|_| Ok(it.next().unwrap_or_default()))?;
        Ok(HeightModel {
            fit,
            rejected_heights_mm,
            heights_mm: heights_mm.to_vec(),
        })
    }

    /// The matrix at `height_mm` from the fitted lines.
    pub fn matrix_at(&self, height_mm: f64) -> PlanarMatrix {
        let f = self.fit.to_array();
        PlanarMatrix::from_array(std::array::from_fn(|k| f[k].value(height_mm)))
    }

    /// Map `image_px` to robot X, Y at `height_mm`, with an error estimate.
    pub fn map(&self, height_mm: f64, image_px: [f64; 2]) -> MappedPoint {
        let m = self.matrix_at(height_mm);
        let s: [f64; 6] = std::array::from_fn(|k| self.fit.to_array()[k].value_std(height_mm));
        let [u, v] = image_px;
        // The six lines are fitted independently: their errors add in variance.
        let sx = ((u * s[0]).powi(2) + (v * s[1]).powi(2) + s[2].powi(2)).sqrt();
        let sy = ((u * s[3]).powi(2) + (v * s[4]).powi(2) + s[5].powi(2)).sqrt();
        MappedPoint {
            height_mm,
            image_px,
            robot_mm: m.apply(image_px),
            std_mm: [sx, sy],
            robot_from_image: m,
        }
    }
}

/// Number of distinct values (exact comparison: heights come from one file).
pub fn count_distinct(values: &[f64]) -> usize {
    let mut v: Vec<f64> = values.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v.len()
}

/// Pixel density of a quadrilateral plate at one height: px per mm along its
/// length (sides AB and DC) and width (sides BC and AD), the article's
/// Eq. (15): `Pr_l = (l1 + l2) / (2 l)`, `Pr_w = (w1 + w2) / (2 w)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PixelDensity {
    /// Height of the plate, mm.
    pub height_mm: f64,
    /// px per mm along the length (A->B, D->C).
    pub length_px_per_mm: f64,
    /// px per mm along the width (B->C, A->D).
    pub width_px_per_mm: f64,
}

/// Pixel density from the image corners A, B, C, D (in order around the
/// plate) and the plate's length |AB| and width |BC| in mm.
pub fn pixel_density(
    height_mm: f64,
    corners_px: &[[f64; 2]; 4],
    length_mm: f64,
    width_mm: f64,
) -> Result<PixelDensity> {
    if !(length_mm > 0.0 && width_mm > 0.0) {
        return Err(Error::invalid(
            "plate_size_mm",
            format!("expected positive length and width, got {length_mm} x {width_mm}"),
        ));
    }
    let d = |a: [f64; 2], b: [f64; 2]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
    let [a, b, c, dd] = *corners_px;
    Ok(PixelDensity {
        height_mm,
        length_px_per_mm: (d(a, b) + d(dd, c)) / (2.0 * length_mm),
        width_px_per_mm: (d(b, c) + d(a, dd)) / (2.0 * width_mm),
    })
}

/// Linear fits of the pixel density against height.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DensityFit {
    /// px/mm along the length against height (mm).
    pub length: LinearFit,
    /// px/mm along the width against height (mm).
    pub width: LinearFit,
}

/// Fit both pixel densities against height.
pub fn fit_density(densities: &[PixelDensity]) -> Result<DensityFit> {
    let h: Vec<f64> = densities.iter().map(|d| d.height_mm).collect();
    let l: Vec<f64> = densities.iter().map(|d| d.length_px_per_mm).collect();
    let w: Vec<f64> = densities.iter().map(|d| d.width_px_per_mm).collect();
    Ok(DensityFit {
        length: fit_line(&h, &l)?,
        width: fit_line(&h, &w)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn linear_family(h: f64) -> PlanarMatrix {
        PlanarMatrix::from_array([
            -0.0056 + 1e-5 * h,
            0.7 - 2e-4 * h,
            -1748.8 + 0.35 * h,
            0.698 - 2e-4 * h,
            0.005 - 1e-5 * h,
            682.2 + 0.55 * h,
        ])
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn exact_family_is_reproduced_between_heights() {
        let h = [15.0, 45.0, 75.0, 105.0];
        let m: Vec<PlanarMatrix> = h.iter().map(|&v| linear_family(v)).collect();
        let model = HeightModel::fit(&h, &m, None).unwrap();
        let p = model.map(60.0, [2000.0, 1500.0]);
        let truth = linear_family(60.0).apply([2000.0, 1500.0]);
        assert!(
            (p.robot_mm[0] - truth[0]).abs() < 1e-9,
            "x {:?}",
            p.robot_mm
        );
        assert!(
            (p.robot_mm[1] - truth[1]).abs() < 1e-9,
            "y {:?}",
            p.robot_mm
        );
        assert!(p.std_mm[0] < 1e-9 && p.std_mm[1] < 1e-9, "{:?}", p.std_mm);
        assert_eq!(model.fit.tx.r2, Some(1.0));
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn one_height_or_mismatched_counts_are_refused() {
        let m = [linear_family(15.0), linear_family(15.0)];
        assert_eq!(
            HeightModel::fit(&[15.0, 15.0], &m, None)
                .unwrap_err()
                .to_string(),
            "requires at least 2 distinct calibration heights, got 1"
        );
        assert_eq!(
            HeightModel::fit(&[15.0, 30.0, 45.0], &m, None)
                .unwrap_err()
                .to_string(),
            "matrices: 3 heights but 2 matrices"
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn density_of_a_rectangle() {
        let c = [[0.0, 0.0], [0.0, 300.0], [150.0, 300.0], [150.0, 0.0]];
        let d = pixel_density(10.0, &c, 200.0, 100.0).unwrap();
        assert_eq!((d.length_px_per_mm, d.width_px_per_mm), (1.5, 1.5));
    }
}
