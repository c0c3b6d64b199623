//! What the refinement over pixels runs ([`RefineMode`]) and reports (the
//! report's `refinement` object, [`RefinementSummary`]).

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::handeye::refine::pixel_problem::{RefineOptions, RobotNoise};
use serde::{Deserialize, Serialize};

/// Which refinement to run after the closed forms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RefineMode {
    /// Closed forms only (the reprojection RMS is still reported when image
    /// points are given).
    None,
    /// Reprojection error over `x` and the target pose, robot poses exact.
    Trusted,
    /// As `Trusted`, with a correction per robot pose whose noise is
    /// estimated from the data (Halcon's "stochastic" model).
    Stochastic,
    /// As `Trusted`, plus every camera intrinsic (seed 003's joint LM).
    JointIntrinsics,
}

impl RefineMode {
    /// The snake_case name used in JSON and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RefineMode::None => "none",
            RefineMode::Trusted => "trusted",
            RefineMode::Stochastic => "stochastic",
            RefineMode::JointIntrinsics => "joint_intrinsics",
        }
    }

    /// The refinement options of this mode (`None` for [`RefineMode::None`]).
    pub fn options(self, pixel_sigma_px: f64) -> Option<RefineOptions> {
        let (robot_noise, intrinsics) = match self {
            RefineMode::None => return None,
            RefineMode::Trusted => (RobotNoise::Trusted, false),
            RefineMode::Stochastic => (RobotNoise::Estimate, false),
            RefineMode::JointIntrinsics => (RobotNoise::Trusted, true),
        };
        Some(RefineOptions {
            intrinsics,
            robot_noise,
            pixel_sigma_px,
            points_in_world: false,
            focal_scale: false,
        })
    }
}

impl std::str::FromStr for RefineMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let all = [
            RefineMode::None,
            RefineMode::Trusted,
            RefineMode::Stochastic,
            RefineMode::JointIntrinsics,
        ];
        let wanted = s.to_ascii_lowercase().replace('-', "_");
        all.into_iter().find(|m| m.name() == wanted).ok_or_else(|| {
            Error::invalid(
                "refine",
                format!(
                    "unknown refinement '{s}' (valid: none, trusted, stochastic, joint_intrinsics)"
                ),
            )
        })
    }
}

/// What the refinement did (the report's `refinement` object).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct RefinementSummary {
    /// The mode run.
    pub mode: RefineMode,
    /// The closed form it started from.
    pub started_from: String,
    /// Reprojection RMS of the starting closed form (px).
    pub closed_form_reprojection_rms_px: f64,
    /// Reprojection RMS after refinement (px).
    pub reprojection_rms_px: f64,
    /// Reprojection RMS per view after refinement (px).
    pub per_view_reprojection_rms_px: Vec<f64>,
    /// Estimated robot rotation noise per component (degrees), stochastic mode.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub robot_rotation_noise_deg: Option<f64>,
    /// Estimated robot translation noise per component (mm), stochastic mode.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub robot_translation_noise_mm: Option<f64>,
    /// The refined camera, joint-intrinsics mode.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub camera: Option<Camera>,
}
