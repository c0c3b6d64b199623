//! Which point of an imaged circle a circle-grid or dot-plate detection
//! reports (the detection JSON's `centre_model`).

use serde::{Deserialize, Serialize};

/// How the centres of imaged circles are estimated (circle grids and dot
/// plates; see `robocal::detect` for the method and the measured errors).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CentreModel {
    /// The image of each circle's centre: the pole of the imaged line at
    /// infinity with respect to the imaged circle, through a homography
    /// fitted to the circle's grid neighbours (the default).
    #[default]
    PerspectivePole,
    /// As `PerspectivePole`, with a quadratic term on top of each local
    /// homography (follows lens distortion across the window).
    LocalQuadratic,
    /// The centre of the ellipse fitted to each circle's edge (no
    /// perspective correction: biased by up to a few tenths of a pixel on
    /// tilted boards; for comparison).
    EllipseCentre,
}

impl CentreModel {
    /// Every model, default first.
    pub const ALL: [CentreModel; 3] = [
        CentreModel::PerspectivePole,
        CentreModel::LocalQuadratic,
        CentreModel::EllipseCentre,
    ];

    /// The name used in JSON and on the command line (`perspective_pole`,
    /// `local_quadratic`, `ellipse_centre`).
    pub fn name(self) -> &'static str {
        match self {
            CentreModel::PerspectivePole => "perspective_pole",
            CentreModel::LocalQuadratic => "local_quadratic",
            CentreModel::EllipseCentre => "ellipse_centre",
        }
    }
}
