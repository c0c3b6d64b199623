//! Which circle-centre model the views of a calibration were detected
//! with (circle grids and dot plates; see [`crate::target::CentreModel`]),
//! carried into the calibration output as `centre_model`.

use crate::target::{CentreModel, Detection, Target};
use serde::{Deserialize, Serialize};

/// The views that used one centre model (listed when the views mix models).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CentreModelViews {
    /// The model's name (`perspective_pole`, `local_quadratic`,
    /// `ellipse_centre`).
    pub centre_model: String,
    /// The names of the views detected with it.
    pub views: Vec<String>,
}

/// Name of the `centre_model` of views that use more than one model.
pub const MIXED: &str = "mixed";

/// The model a view's points are: `None` for views that are not circle or
/// dot detections (chessboards, square grids, explicit correspondences);
/// circle detections without the key were written before it existed and
/// are ellipse centres.
fn model_of(detection: Option<&Detection>) -> Option<CentreModel> {
    let d = detection?;
    match d.target {
        Target::CircleGrid { .. } | Target::DotPlate { .. } | Target::OriginDotGrid { .. } => {
            Some(d.centre_model.unwrap_or(CentreModel::EllipseCentre))
        }
        Target::Chessboard { .. }
        | Target::SingleCircle { .. }
        | Target::SquareGrid { .. }
        | Target::Charuco { .. }
        | Target::Aprilgrid { .. }
        | Target::ArucoGrid { .. } => None,
    }
}

/// `(centre_model, centre_models)` of the output: the one model all circle
/// and dot views used, or [`MIXED`] with the views of each model; `(None,
/// None)` when no view is a circle or dot detection.
pub fn centre_models<'a>(
    views: impl IntoIterator<Item = (&'a str, Option<&'a Detection>)>,
) -> (Option<String>, Option<Vec<CentreModelViews>>) {
    let mut groups: Vec<CentreModelViews> = Vec::new();
    for (name, detection) in views {
        let Some(model) = model_of(detection) else {
            continue;
        };
        match groups.iter_mut().find(|g| g.centre_model == model.name()) {
            Some(g) => g.views.push(name.to_string()),
            None => groups.push(CentreModelViews {
                centre_model: model.name().to_string(),
                views: vec![name.to_string()],
            }),
        }
    }
    match groups.len() {
        0 => (None, None),
        1 => (Some(groups[0].centre_model.clone()), None),
        _ => (Some(MIXED.to_string()), Some(groups)),
    }
}
