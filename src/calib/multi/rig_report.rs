//! The result of a camera-rig calibration (issue 22): N cameras that saw
//! one board in synchronised frames, not every camera in every frame.
//!
//! This file is the JSON contract of `robocal rig -o rig.json`, read back by
//! `robocal export rig.json --format ...`, the page and the npm package. Its
//! field names are kept; new fields get `#[serde(default)]`.
//!
//! Conventions: the rig frame is one camera's frame (`rig_frame`, camera 0
//! unless chosen); `camera_from_rig` maps rig coordinates into that camera
//! (`p_cam = camera_from_rig * p_rig`), so the rig camera's is the identity;
//! each frame's board pose is `rig_from_target`, and camera k saw the board
//! at `camera_from_rig[k] * rig_from_target`.

use crate::calib::multi::stereo::TransformStd;
use crate::calib::CameraCalibration;
use crate::geometry::PoseJson;
use crate::optim::Termination;
use crate::report_kind::ReportKind;
use serde::{Deserialize, Serialize};

/// One camera of the rig.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigCamera {
    /// The name given on input (`--camera NAME ...`), unique in the rig.
    pub name: String,
    /// Its intrinsics and distortion at the joint optimum (its `views` are
    /// the frames it saw, in frame order, with the board pose it saw).
    pub calibration: CameraCalibration,
    /// Whether the intrinsics were given and held (`true`) or solved.
    pub intrinsics_held: bool,
    /// Rig frame -> this camera (identity for the rig camera).
    pub camera_from_rig: PoseJson,
    /// Standard deviations of `camera_from_rig` from the joint covariance
    /// (`None` for the rig camera, or when singular).
    pub camera_from_rig_std: Option<TransformStd>,
    /// RMS reprojection error over this camera's points, px.
    pub rms_px: f64,
    /// Frames in which this camera saw the board (indices into `frames`).
    pub frames_seen: Vec<usize>,
}

/// One synchronised frame (a board pose).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigFrame {
    /// The key the images were grouped by (the number in the file names, or
    /// the position when grouped by order).
    pub key: String,
    /// The board in the rig frame; `None` when no camera used it.
    pub rig_from_target: Option<PoseJson>,
    /// Names of the cameras whose view of this frame was used.
    pub cameras: Vec<String>,
    /// RMS reprojection error over the frame's points in all cameras, px.
    pub rms_px: f64,
}

/// Which cameras saw the board together, and how often.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CoObservation {
    /// Camera names, in the order of the matrix rows and columns.
    pub cameras: Vec<String>,
    /// `frames[i][j]`: frames seen by both camera i and camera j (the
    /// diagonal: frames seen by camera i).
    pub frames: Vec<Vec<usize>>,
    /// The pairs the initialisation chained (the spanning tree), as indices
    /// into `cameras`, parent first.
    pub spanning_tree: Vec<[usize; 2]>,
}

/// The result of a rig calibration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigCalibration {
    /// What the report is: `rig`, or `rig_handeye` when a `handeye` object
    /// was added beside the keys (absent from reports written before the
    /// key existed).
    #[serde(default = "ReportKind::rig")]
    pub kind: ReportKind,
    /// robocal version that produced the report (`crate_version` in reports
    /// written before every report said `robocal_version`).
    #[serde(alias = "crate_version")]
    pub robocal_version: String,
    /// Name of the camera whose frame is the rig frame.
    pub rig_frame: String,
    /// The target spec (`robocal detect --target` spelling).
    pub target: String,
    /// How the images were grouped into frames: `"number"` (the number in
    /// the file names) or `"order"`.
    pub grouping: String,
    /// The cameras, in input order.
    pub cameras: Vec<RigCamera>,
    /// The frames, in key order.
    pub frames: Vec<RigFrame>,
    /// The co-observation graph.
    pub co_observation: CoObservation,
    /// RMS reprojection error over every point of every camera, px.
    pub rms_px: f64,
    /// Joint solver iterations.
    pub iterations: usize,
    /// Why the joint solver stopped.
    pub termination: Termination,
    /// Views left out and why, weak links, and the like.
    #[serde(default)]
    pub warnings: Vec<String>,
    /// The joint covariance of every solved rig parameter (absent in files
    /// of older versions, or when the solver's information was singular).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub covariance: Option<RigCovariance>,
}

/// One solved parameter of the rig: a camera's intrinsic (`fx`, `fy`, `cx`,
/// `cy`, `skew` or a distortion coefficient, as [`crate::camera::Camera::param_names`])
/// or a component of its `camera_from_rig`: `rotation_x`, `rotation_y`,
/// `rotation_z` (rad, the left perturbation `R = exp(d) R_est`),
/// `translation_x`, `translation_y`, `translation_z` (m).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigParameter {
    /// The camera's name.
    pub camera: String,
    /// The parameter's name.
    pub parameter: String,
}

/// The covariance of the rig's solved parameters from the joint bundle
/// adjustment (scaled by the residual variance): held intrinsics and the
/// rig camera's identity are not parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigCovariance {
    /// The parameters, in the order of the matrix rows and columns.
    pub parameters: Vec<RigParameter>,
    /// The symmetric covariance matrix, row by row.
    pub matrix: Vec<Vec<f64>>,
}

/// The names of the `camera_from_rig` components in [`RigParameter`].
pub const POSE_PARAMETERS: [&str; 6] = [
    "rotation_x",
    "rotation_y",
    "rotation_z",
    "translation_x",
    "translation_y",
    "translation_z",
];
