//! Plain-data requests and reports of the planar workflow, shared by the CLI
//! (`robocal planar ...`) and the wasm boundary (`planar_fit`,
//! `planar_solve`): JSON in, JSON out.

use crate::error::Result;
use crate::workflows::linear_fit::LinearFit;
pub use crate::workflows::planar::HeightMatrix;
use crate::workflows::planar::PlanarMatrix;
use crate::workflows::planar_height::{ByParameter, HeightModel, MappedPoint};
use crate::workflows::planar_solve::{
    solve_planar, HeightPoint, PlanarSolveOptions, PlanarSolveReport,
};
use serde::{Deserialize, Serialize};

/// A pixel to map at some height.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PredictRequest {
    /// Height of the plane, mm.
    pub height_mm: f64,
    /// Image point, px.
    pub image_px: [f64; 2],
}

/// Input of [`planar_fit`]: matrices per height.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanarFitRequest {
    /// One matrix per calibration height.
    pub matrices: Vec<HeightMatrix>,
    /// Optional rejection threshold (standard deviations), see
    /// [`HeightModel::fit`].
    #[serde(default)]
    pub reject_threshold: Option<f64>,
    /// Pixels to map with the fitted model.
    #[serde(default)]
    pub predict: Vec<PredictRequest>,
}

/// Output of [`planar_fit`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanarFitReport {
    /// Per parameter: its line against height (`intercept`, `slope`, `r2`,
    /// `pearson_r`, `adj_r2`, `rss`, plus `n` and standard errors).
    pub fit: ByParameter<LinearFit>,
    /// Per parameter: heights rejected before the final fit.
    pub rejected_heights_mm: ByParameter<Vec<f64>>,
    /// The mapped pixels, in request order.
    pub predictions: Vec<MappedPoint>,
    /// The request, for re-solving.
    pub input: PlanarFitRequest,
}

/// Fit every matrix parameter against height and map the requested pixels.
pub fn planar_fit(request: &PlanarFitRequest) -> Result<PlanarFitReport> {
    let h: Vec<f64> = request.matrices.iter().map(|m| m.height_mm).collect();
    let m: Vec<PlanarMatrix> = request
        .matrices
        .iter()
        .map(|m| m.robot_from_image)
        .collect();
    let model = HeightModel::fit(&h, &m, request.reject_threshold)?;
    let predictions = request
        .predict
        .iter()
        .map(|p| model.map(p.height_mm, p.image_px))
        .collect();
    Ok(PlanarFitReport {
        fit: model.fit,
        rejected_heights_mm: model.rejected_heights_mm,
        predictions,
        input: request.clone(),
    })
}

/// Input of [`planar_solve`]: point pairs at several heights.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanarSolveRequest {
    /// The observed points; equal `height_mm` values form one height.
    pub points: Vec<HeightPoint>,
    /// Options (transform model, rejection, plate size).
    #[serde(default)]
    pub options: PlanarSolveOptions,
    /// Pixels to map with the fitted model.
    #[serde(default)]
    pub predict: Vec<PredictRequest>,
}

/// Output of [`planar_solve`]: the workflow report plus the mapped pixels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanarSolveResponse {
    /// Per-height matrices with residuals, the fit against height, pixel density.
    #[serde(flatten)]
    pub report: PlanarSolveReport,
    /// The mapped pixels, in request order.
    pub predictions: Vec<MappedPoint>,
    /// The same pixels mapped by the exact homography family (robot X, Y
    /// in mm), when it was fitted.
    pub exact_predictions_mm: Option<Vec<[f64; 2]>>,
}

/// Solve the planar workflow from point pairs and map the requested pixels.
pub fn planar_solve(request: &PlanarSolveRequest) -> Result<PlanarSolveResponse> {
    let report = solve_planar(&request.points, &request.options)?;
    let model = report.model();
    let predictions = request
        .predict
        .iter()
        .map(|p| model.map(p.height_mm, p.image_px))
        .collect();
    let exact_predictions_mm = report
        .exact_family
        .as_ref()
        .map(|f| {
            request
                .predict
                .iter()
                .map(|p| f.map(p.height_mm, p.image_px))
                .collect::<Result<Vec<_>>>()
        })
        .transpose()?;
    Ok(PlanarSolveResponse {
        report,
        predictions,
        exact_predictions_mm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn minimal_json_requests_work() {
        let fit: PlanarFitRequest = serde_json::from_str(
            r#"{"matrices": [
                {"height_mm": 10, "a11": 0, "a12": 0.7, "tx": -1700, "a21": 0.7, "a22": 0, "ty": 700},
                {"height_mm": 20, "a11": 0, "a12": 0.6, "tx": -1600, "a21": 0.6, "a22": 0, "ty": 710}],
              "predict": [{"height_mm": 15, "image_px": [100, 200]}]}"#,
        )
        .unwrap();
        let r = planar_fit(&fit).unwrap();
        // Halfway: a12 = 0.65, tx = -1650: x = 0.65 * 200 - 1650.
        assert!((r.predictions[0].robot_mm[0] - (0.65 * 200.0 - 1650.0)).abs() < 1e-9);
        let solve: PlanarSolveRequest =
            serde_json::from_str(r#"{"points": [], "options": {"transform": "similarity"}}"#)
                .unwrap();
        assert_eq!(
            solve.options.transform,
            crate::workflows::planar::TransformKind::Similarity
        );
        assert_eq!(solve.options.reject_threshold, None);
        assert_eq!(
            planar_solve(&solve).unwrap_err().to_string(),
            "requires at least 2 distinct calibration heights, got 0"
        );
    }
}
