//! Targets at the wasm boundary: specs and target JSON read by the core,
//! their canonical spec, board points and printable sheet.

use super::js_error;
use crate::target::Target;
use serde::Serialize;
use wasm_bindgen::prelude::*;

/// A target from a CLI spec (`chessboard:9x6:30mm`,
/// `circles:4x11:20mm:asymmetric`, `dots:7x7:25mm`, `circle:10mm`,
/// `squares:8x8:12.7mm:22.5778mm`) or a target JSON object, validated
/// ([`crate::api::detect::DetectRequest::from_spec_or_json`]).
pub(super) fn target_from(spec_or_json: &str) -> Result<Target, JsError> {
    crate::api::detect::DetectRequest::from_spec_or_json(spec_or_json)
        .map(|request| request.target)
        .map_err(js_error)
}

/// The target of a CLI spec or target JSON, checked by the core: the target
/// JSON (`{"kind": "chessboard", "cols", "rows", "square_m"}`, ...; kinds
/// and metres as in `docs/detection-json.md`), or the core's error.
#[wasm_bindgen]
pub fn parse_target(spec_or_json: &str) -> Result<String, JsError> {
    let target = target_from(spec_or_json)?;
    serde_json::to_string(&target).map_err(|e| JsError::new(&e.to_string()))
}

/// A Kalibr calibration-target YAML (`target_type: aprilgrid` with
/// `tagCols`, `tagRows`, `tagSize`, `tagSpacing`, or `target_type:
/// checkerboard`) as the target JSON ([`parse_target`]'s output), or the
/// reader's error naming the line or key.
#[wasm_bindgen]
pub fn read_kalibr_target(yaml: &str) -> Result<String, JsError> {
    let target = crate::io::parse_kalibr_target(yaml).map_err(js_error)?;
    serde_json::to_string(&target).map_err(|e| JsError::new(&e.to_string()))
}

/// The canonical CLI spec of a target (spec or JSON): what
/// `robocal detect --target` takes, e.g. `chessboard:9x6:30mm`.
#[wasm_bindgen]
pub fn target_spec(spec_or_json: &str) -> Result<String, JsError> {
    Ok(target_from(spec_or_json)?.to_spec())
}

/// The board points of a target (spec or JSON) in id order: a JSON array of
/// `{"id", "x_m", "y_m"}`, metres in the board frame (z = 0 on the board).
#[wasm_bindgen]
pub fn target_points(spec_or_json: &str) -> Result<String, JsError> {
    #[derive(Serialize)]
    struct Point {
        id: usize,
        x_m: f64,
        y_m: f64,
    }
    let points: Vec<Point> = target_from(spec_or_json)?
        .object_points()
        .into_iter()
        .map(|(id, p)| Point {
            id,
            x_m: p.x,
            y_m: p.y,
        })
        .collect();
    serde_json::to_string(&points).map_err(|e| JsError::new(&e.to_string()))
}

/// The printable sheet of a target (spec or JSON) as SVG text, at true
/// scale in millimetres, with a 100 mm check bar and the spec printed on
/// it (`robocal::target::svg::board_svg`).
#[wasm_bindgen]
pub fn target_svg(spec_or_json: &str) -> Result<String, JsError> {
    Ok(crate::target::svg::board_svg(&target_from(spec_or_json)?))
}
