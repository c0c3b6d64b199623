//! Camera calibration from planar targets: normalised-DLT homographies,
//! Zhang's closed-form intrinsics and poses, then one Levenberg-Marquardt
//! over intrinsics, distortion and every view pose ([`calibrate`]), with a
//! report that carries residuals, uncertainties and warnings.

mod closed_form;
mod homography;
mod refine;
mod report;
mod zhang;

pub use closed_form::{intrinsics_from_homographies, pose_from_homography};
pub use homography::homography;
pub use report::{
    CameraCalibration, Correlation, Outlier, PoseReport, ProjectionUncertainty, ViewReport,
};
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
