//! The lens-model table at the wasm boundary: what the page's lens list and
//! the npm package's callers choose from (`camera::LENS_MODELS`).

use crate::camera::LENS_MODELS;
use serde::Serialize;
use wasm_bindgen::prelude::*;

/// Another name of a model and what it means.
#[derive(Serialize)]
struct Alias {
    name: &'static str,
    means: &'static str,
}

/// One row of the table as JSON.
#[derive(Serialize)]
struct LensModelJson {
    name: &'static str,
    aliases: Vec<Alias>,
    label: &'static str,
    description: &'static str,
    coefficients: &'static [&'static str],
    start_values: Vec<f64>,
    export_formats: &'static [&'static str],
    wide_angle: bool,
}

/// The lens models, in menu order (the default first), as a JSON array:
/// `[{"name": "brown", "aliases": [{"name": "brown5", "means": ...}],
/// "label", "description", "coefficients", "start_values",
/// "export_formats", "wide_angle"}, ...]`.
#[wasm_bindgen]
pub fn lens_models() -> String {
    let rows: Vec<LensModelJson> = LENS_MODELS
        .iter()
        .map(|m| LensModelJson {
            name: m.name,
            aliases: m
                .aliases
                .iter()
                .map(|&(name, means)| Alias { name, means })
                .collect(),
            label: m.label,
            description: m.description,
            coefficients: m.coefficients,
            start_values: m.start_values(),
            export_formats: m.export_formats,
            wide_angle: m.wide_angle,
        })
        .collect();
    // Strings, numbers and booleans only: serialising cannot fail.
    serde_json::to_string(&rows).unwrap_or_else(|_| "[]".into())
}
