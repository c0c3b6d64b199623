//! Camera calibration from planar targets: normalised-DLT homographies,
//! Zhang's closed-form intrinsics and poses, then one Levenberg-Marquardt
//! over intrinsics, distortion and every view pose ([`calibrate`]), with a
//! report that carries residuals, uncertainties and warnings.
//!
//! Two cameras with shared views: [`stereo`] (right_from_left, seed 000),
//! with its JSON boundary in [`stereo_json`].
//!
//! From 3-D/2-D point pairs of a non-planar target (seed 002):
//! - [`dlt`]: the 12-parameter projection matrix, decomposed into K, R, t;
//! - [`dlt_kalman`]: the recursive Kalman-filter estimate of the same
//!   12 parameters, with the measurement noise from repeated observations.

pub mod centre_models;
mod closed_form;
pub mod compare;
pub mod dlt;
pub mod dlt_kalman;
pub mod ekf;
mod evaluate;
mod homography;
pub mod json_api;
#[cfg(test)]
mod json_api_tests;
pub mod model_advice;
mod refine;
mod report;
mod residuals;
pub mod stereo;
pub mod stereo_json;
mod stereo_problem;
#[cfg(test)]
mod stereo_tests;
mod tsai;
mod zhang;

pub use closed_form::{intrinsics_from_homographies, pose_from_homography};
pub use homography::homography;
pub use report::{CameraCalibration, Correlation, Outlier, ProjectionUncertainty, ViewReport};
pub use residuals::{distortion_field, view_residuals, DistortionField, PixelVector};
pub use tsai::calibrate_tsai;
pub use zhang::{calibrate, CalibrationOptions};

use nalgebra::{Point2, Point3};
use serde::{Deserialize, Serialize};

/// One image's correspondences: target points (target frame, metres; z = 0
/// for planar targets) and where they were observed (pixels).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct View {
    /// Image name, carried into the report.
    pub name: String,
    /// Target points in the target frame, metres.
    pub object_m: Vec<Point3<f64>>,
    /// Observed pixels, same order and count as `object_m`.
    pub image_px: Vec<Point2<f64>>,
}
