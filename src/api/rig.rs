//! The request and report of rig calibration: the wasm function
//! `calibrate_rig`, the npm call and `robocal rig` (which builds a
//! [`RigInput`] from its flags and detections) all call
//! [`calibrate_rig_input`].
//!
//! Input:
//!
//! ```json
//! {"model": "brown",
//!  "options": {"fix_principal_point": false, "fix_aspect_ratio": false,
//!              "zero_skew": true, "robust": false, "fixed_coefficients": []},
//!  "target": "chessboard:9x6:30mm",
//!  "rig_frame": "front",
//!  "grouping": "number",
//!  "cameras": [
//!    {"name": "front", "image_size_px": [1280, 960],
//!     "views": [{"key": "1", "name": "front01.png", "detection": {...}},
//!               {"key": "2", "name": "front02.png", "object_m": [...], "image_px": [...]}]},
//!    {"name": "side", "camera": {...},
//!     "views": [{"key": "2", "name": "side02.png", "detection": {...}}]}]}
//! ```
//!
//! Views with the same `key` were taken at the same time (one board pose);
//! a camera has at most one view per key and may miss any key. Frames are
//! ordered by key (integer keys numerically, before any other key, which
//! sort as text). A view is a detection or explicit correspondences, as in
//! [`super::camera`]. `camera` (a calibration report's `camera` object)
//! gives a camera's intrinsics and holds them; `image_size_px` may be left
//! out when the views are detections (which must then agree) or a camera
//! is given. `rig_frame` (default: the first camera) names the camera whose
//! frame is the rig frame; `target` and `grouping` (default `"number"`) are
//! carried into the report. The options apply to every solved camera.
//!
//! Output: the [`RigCalibration`] JSON (`cameras` with `camera_from_rig`
//! and `camera_from_rig_std`, `frames`, `co_observation`, `rms_px`, ...),
//! the report `robocal rig` writes.

use super::camera::{
    agreed_image_size, calibration_options, check_size, detection_sizes, views_of, JsonOptions,
    JsonView, LensModel,
};
use crate::calib::multi::rig::{calibrate_rig, sort_frame_keys, RigCameraViews, RigOptions};
use crate::calib::multi::rig_report::RigCalibration;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::target::Detection;
use serde::{Deserialize, Serialize};

/// One view of one camera, with the key of its frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigJsonView {
    /// The frame key (views with one key saw one board pose).
    pub key: String,
    /// Image name, carried into the report.
    pub name: String,
    /// A target detection.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detection: Option<Detection>,
    /// Target points, metres (with `image_px`, instead of `detection`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object_m: Option<Vec<[f64; 3]>>,
    /// Observed pixels, same order as `object_m`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image_px: Option<Vec<[f64; 2]>>,
}

/// One camera of the input.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigJsonCamera {
    /// Unique name.
    pub name: String,
    /// Its views.
    pub views: Vec<RigJsonView>,
    /// Image width and height, px; optional for detections or a given camera.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image_size_px: Option<[u32; 2]>,
    /// Intrinsics given and held.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<Camera>,
}

/// The whole input of [`calibrate_rig_json`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigInput {
    /// Lens model of the solved cameras (default `brown`).
    #[serde(default)]
    pub model: LensModel,
    /// Options of the solved cameras.
    #[serde(default)]
    pub options: JsonOptions,
    /// The cameras.
    pub cameras: Vec<RigJsonCamera>,
    /// The target spec, carried into the report.
    #[serde(default)]
    pub target: String,
    /// The camera whose frame is the rig frame (default: the first).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rig_frame: Option<String>,
    /// How the caller grouped the images into frames (default `number`).
    #[serde(default = "default_grouping")]
    pub grouping: String,
    /// Keys of frames in which no camera found the board, beside those of
    /// the views (`robocal rig` gives every image's key: a rig on a robot
    /// pairs one robot pose with each frame, found or not).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame_keys: Option<Vec<String>>,
}

fn default_grouping() -> String {
    "number".into()
}

/// Calibrate a rig from the JSON input described in the module docs;
/// returns the [`RigCalibration`] JSON.
pub fn calibrate_rig_json(input_json: &str) -> Result<String> {
    let input: RigInput =
        serde_json::from_str(input_json).map_err(|e| super::request_error("rig input", e))?;
    let report = calibrate_rig_input(&input)?;
    serde_json::to_string(&report)
        .map_err(|e| Error::invalid("report", format!("cannot serialise: {e}")))
}

/// [`calibrate_rig_json`] on the parsed input.
pub fn calibrate_rig_input(input: &RigInput) -> Result<RigCalibration> {
    let (cameras, keys) = rig_views(input)?;
    let options = RigOptions {
        calibration: calibration_options(&input.model, &input.options)?,
        rig_frame: input.rig_frame.clone(),
        target: input.target.clone(),
        grouping: input.grouping.clone(),
    };
    calibrate_rig(&cameras, &keys, &options)
}

/// The input's cameras with their views keyed by frame index, and the
/// frame keys in report order.
pub fn rig_views(input: &RigInput) -> Result<(Vec<RigCameraViews>, Vec<String>)> {
    let mut keys: Vec<String> = Vec::new();
    let given = input.frame_keys.iter().flatten();
    let of_views = input
        .cameras
        .iter()
        .flat_map(|c| c.views.iter().map(|v| &v.key));
    for key in given.chain(of_views) {
        if !keys.contains(key) {
            keys.push(key.clone());
        }
    }
    sort_frame_keys(&mut keys);
    let mut cameras = Vec::with_capacity(input.cameras.len());
    for (k, c) in input.cameras.iter().enumerate() {
        let plain: Vec<JsonView> = c
            .views
            .iter()
            .map(|v| JsonView {
                name: v.name.clone(),
                detection: v.detection.clone(),
                object_m: v.object_m.clone(),
                image_px: v.image_px.clone(),
            })
            .collect();
        check_size("views", &plain).map_err(|e| within(k, e))?;
        let views = views_of(&plain).map_err(|e| within(k, e))?;
        let frames = c
            .views
            .iter()
            .map(|v| keys.iter().position(|key| *key == v.key).unwrap_or(0));
        cameras.push(RigCameraViews {
            name: c.name.clone(),
            image_size_px: camera_size(k, c)?,
            views: frames.zip(views).collect(),
            camera: c.camera.clone(),
        });
    }
    Ok((cameras, keys))
}

/// Field names of a view error point into its camera (`views[2].image_px`
/// becomes `cameras[1].views[2].image_px`).
fn within(camera: usize, e: Error) -> Error {
    match e {
        Error::Invalid { field, message } => Error::Invalid {
            field: format!("cameras[{camera}].{field}"),
            message,
        },
        other => other,
    }
}

/// One camera's image size: given, the given camera's, or the one all its
/// detections agree on.
fn camera_size(k: usize, c: &RigJsonCamera) -> Result<(u32, u32)> {
    agreed_image_size(
        &format!("cameras[{k}].image_size_px"),
        c.image_size_px
            .or(c.camera.as_ref().map(|cam| [cam.width, cam.height])),
        detection_sizes(
            c.views
                .iter()
                .map(|v| (v.name.as_str(), v.detection.as_ref())),
        ),
        "required when the views are not detections and no camera is given",
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Pose;
    use crate::synth::rig::{rig_scene, RigSceneConfig};
    use wasm_bindgen_test::wasm_bindgen_test;

    /// The seeded noise-free rig as JSON input (explicit correspondences),
    /// cam3's intrinsics given; and the true camera_from_rig.
    fn rig_input() -> (RigInput, Vec<Pose>) {
        let scene = rig_scene(&RigSceneConfig::default(), 5);
        let cameras = (0..4)
            .map(|k| RigJsonCamera {
                name: scene.names[k].clone(),
                views: scene.views[k]
                    .iter()
                    .map(|(f, v)| RigJsonView {
                        key: scene.frame_keys[*f].clone(),
                        name: v.name.clone(),
                        detection: None,
                        object_m: Some(v.object_m.iter().map(|p| [p.x, p.y, p.z]).collect()),
                        image_px: Some(v.image_px.iter().map(|p| [p.x, p.y]).collect()),
                    })
                    .collect(),
                image_size_px: (k != 3).then_some([1280, 960]),
                camera: (k == 3).then(|| scene.cameras[3].clone()),
            })
            .collect();
        let input = RigInput {
            model: LensModel::default(),
            options: JsonOptions::default(),
            cameras,
            target: "chessboard:11x8:60mm".into(),
            rig_frame: None,
            grouping: "number".into(),
            frame_keys: None,
        };
        (input, scene.camera_from_rig)
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn json_round_trip_recovers_the_true_rig() {
        let (input, truth) = rig_input();
        let text = serde_json::to_string(&input).expect("serialise");
        let out: RigCalibration =
            serde_json::from_str(&calibrate_rig_json(&text).expect("solve")).expect("parse");
        // Noise-free correspondences: the optimum is the truth to solver precision.
        for (k, camera) in out.cameras.iter().enumerate() {
            let got = camera.camera_from_rig.to_pose().expect("pose");
            let t = (got.translation.vector - truth[k].translation.vector).norm();
            assert!(t < 1e-9, "cam{k}: {t} m");
            assert!(got.rotation.angle_to(&truth[k].rotation) < 1e-9, "cam{k}");
        }
        assert!(out.cameras[3].intrinsics_held && !out.cameras[2].intrinsics_held);
        assert_eq!(out.frames[10].key, "10");
        assert_eq!(out.target, "chessboard:11x8:60mm");
        assert!(out.rms_px < 1e-6, "rms {} px", out.rms_px);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn bad_inputs_get_plain_messages() {
        let err = |input: &RigInput| calibrate_rig_input(input).unwrap_err().to_string();
        let (mut input, _) = rig_input();
        input.cameras.truncate(1);
        assert_eq!(err(&input), "requires at least 2 cameras in a rig, got 1");
        let (mut input, _) = rig_input();
        input.rig_frame = Some("top".into());
        assert_eq!(
            err(&input),
            "rig_frame: no camera is named 'top' (the cameras are cam0, cam1, cam2, cam3)"
        );
        let (mut input, _) = rig_input();
        input.cameras[1].views[1].key = input.cameras[1].views[0].key.clone();
        assert_eq!(
            err(&input),
            "camera cam1: two views of frame 0: cam1_000 and cam1_002; keep one"
        );
        let (mut input, _) = rig_input();
        input.cameras[2].name = "cam0".into();
        assert_eq!(
            err(&input),
            "cameras[2].name: 'cam0' is used twice: camera names must be unique"
        );
        let (mut input, _) = rig_input();
        input.cameras[0].image_size_px = None;
        assert_eq!(
            err(&input),
            "cameras[0].image_size_px: required when the views are not detections and no \
             camera is given"
        );
        let (mut input, _) = rig_input();
        input.cameras[0].views[0]
            .image_px
            .as_mut()
            .expect("points")
            .pop();
        assert!(
            err(&input).starts_with("cameras[0].views[0].image_px: "),
            "{}",
            err(&input)
        );
        let e = calibrate_rig_json("{\"model\": \"brown\"}")
            .unwrap_err()
            .to_string();
        assert!(e.contains("rig input: missing field `cameras`"), "{e}");
    }
}
