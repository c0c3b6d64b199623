//! Camera calibration from planar targets: normalised-DLT homographies,
//! Zhang's closed-form intrinsics and poses, then one Levenberg-Marquardt
//! over intrinsics, distortion and every view pose ([`calibrate`]), with a
//! report that carries residuals, uncertainties and warnings.
//!
//! Several cameras ([`multi`]): two with shared views,
//! [`multi::stereo`] (right_from_left, seed 000), with its JSON boundary in
//! [`crate::api::stereo`]; N cameras in synchronised frames: [`multi::rig`]
//! (every camera_from_rig), its result in [`multi::rig_report`], its JSON
//! boundary in [`crate::api::rig`]. The camera pose of one view from its
//! points: [`pnp`].
//!
//! From 3-D/2-D point pairs of a non-planar target (seed 002):
//! - [`dlt`]: the 12-parameter projection matrix, decomposed into K, R, t;
//! - [`dlt_kalman`]: the recursive Kalman-filter estimate of the same
//!   12 parameters, with the measurement noise from repeated observations.

mod board_warp;
pub mod centre_models;
pub mod check;
#[cfg(test)]
mod check_tests;
mod closed_form;
pub mod compare;
pub mod cross_validation;
pub mod dlt;
pub mod dlt_kalman;
pub mod ekf;
mod evaluate;
mod homography;
pub mod model_advice;
mod model_advice_screen;
pub mod multi;
pub mod plausibility;
pub mod pnp;
pub mod projection_diff;
mod refine;
mod rejected;
mod report;
mod residuals;
mod splined;
#[cfg(test)]
mod splined_tests;
pub mod starts;
mod tsai;
pub mod usable;
mod view_spread;
mod zhang;

pub use board_warp::{BoardWarp, WARP_WARNING_MM};
pub use closed_form::{intrinsics_from_homographies, pose_from_homography};
pub use homography::homography;
pub use plausibility::Severity;
pub use rejected::{RejectedInView, RejectedPoints};
pub use report::{
    projection_uncertainty, CameraCalibration, Correlation, Outlier, ProjectionUncertainty,
    ViewReport,
};
pub use residuals::{distortion_field, view_residuals, DistortionField, PixelVector};
pub use splined::SplineSupport;
pub use tsai::calibrate_tsai;
pub use usable::{homography_problem, usable_views, LeftOut};
pub use zhang::{calibrate, CalibrationOptions};

use crate::target::Detection;
use nalgebra::{Point2, Point3};
use serde::{Deserialize, Serialize};

/// One image's correspondences: target points (target frame, metres; z = 0
/// for planar targets) and where they were observed (pixels). A view may
/// hold any subset of the target's points; `point_ids` says which.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct View {
    /// Image name, carried into the report.
    pub name: String,
    /// Target points in the target frame, metres.
    pub object_m: Vec<Point3<f64>>,
    /// Observed pixels, same order and count as `object_m`.
    pub image_px: Vec<Point2<f64>>,
    /// The target's id of each point (a detection's ids), same order as
    /// `object_m`; empty means the points are numbered by their position.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub point_ids: Vec<usize>,
}

impl View {
    /// A view of explicit correspondences, points numbered by position.
    pub fn new(
        name: impl Into<String>,
        object_m: Vec<Point3<f64>>,
        image_px: Vec<Point2<f64>>,
    ) -> View {
        View {
            name: name.into(),
            object_m,
            image_px,
            point_ids: Vec::new(),
        }
    }

    /// The view of a detection: its points (any subset of the target's)
    /// with their board positions and ids.
    pub fn from_detection(name: impl Into<String>, detection: &Detection) -> View {
        // Board points looked up by id (not by position: a board's ids
        // need not be 0..n); points whose id the target lacks are skipped,
        // as in `Detection::correspondences`.
        let mut board = std::collections::BTreeMap::new();
        for (id, p) in detection.target.object_points() {
            board.insert(id, p);
        }
        let mut view = View::new(name, Vec::new(), Vec::new());
        for p in &detection.points {
            if let Some(o) = board.get(&p.id) {
                view.object_m.push(*o);
                view.image_px.push(Point2::new(p.x_px, p.y_px));
                view.point_ids.push(p.id);
            }
        }
        view
    }

    /// The target's id of the view's `index`-th point.
    pub fn point_id(&self, index: usize) -> usize {
        self.point_ids.get(index).copied().unwrap_or(index)
    }
}
