//! The request and report of stereo calibration: the wasm function
//! `calibrate_stereo` and the npm call take a [`StereoInput`]
//! ([`calibrate_stereo_input`]); `robocal stereo`, whose detections are
//! read by the CLI, enters at [`calibrate_stereo_views`], the same option
//! mapping and solve.
//!
//! Input:
//!
//! ```json
//! {"model": "brown",
//!  "options": {"fix_principal_point": false, "fix_aspect_ratio": false,
//!              "zero_skew": true, "robust": false, "fixed_coefficients": []},
//!  "left":  [{"name": "left01.jpg",  "detection": {...}}, ...],
//!  "right": [{"name": "right01.jpg", "detection": {...}}, ...],
//!  "left_image_size_px": [640, 480], "right_image_size_px": [640, 480]}
//! ```
//!
//! `left[i]` and `right[i]` are one pair (the same board pose seen by both
//! cameras): the caller pairs the images (by order or by name) and leaves out
//! pairs where either image has no detection. Views are detections or
//! explicit correspondences, as in [`super::camera`]; the image sizes may
//! be left out when the views are detections (which must then agree). The
//! options apply to both cameras, with the meaning of [`super::camera`]'s.
//!
//! Output: the [`StereoCalibration`] JSON (`left`, `right`,
//! `right_from_left`, `initial_right_from_left`, `baseline_m`,
//! `right_from_left_std`, `rms_px`, ...), the report `robocal stereo` writes.

use super::camera::{
    agreed_image_size, calibration_options, check_size, detection_sizes, views_of, JsonOptions,
    JsonView, LensModel, MIN_VIEWS,
};
use crate::calib::multi::stereo::{calibrate_stereo, StereoCalibration};
use crate::calib::View;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The whole input of [`calibrate_stereo_json`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StereoInput {
    /// Lens model of both cameras (default `brown`).
    #[serde(default)]
    pub model: LensModel,
    /// Options of both cameras.
    #[serde(default)]
    pub options: JsonOptions,
    /// The left camera's views, `left[i]` paired with `right[i]`.
    pub left: Vec<JsonView>,
    /// The right camera's views.
    pub right: Vec<JsonView>,
    /// Left image width and height, px; optional for detections.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left_image_size_px: Option<[u32; 2]>,
    /// Right image width and height, px; optional for detections.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub right_image_size_px: Option<[u32; 2]>,
}

/// Calibrate a stereo pair from the JSON input described in the module
/// docs; returns the [`StereoCalibration`] JSON.
pub fn calibrate_stereo_json(input_json: &str) -> Result<String> {
    let input: StereoInput =
        serde_json::from_str(input_json).map_err(|e| super::request_error("stereo input", e))?;
    let report = calibrate_stereo_input(&input)?;
    serde_json::to_string(&report)
        .map_err(|e| Error::invalid("report", format!("cannot serialise: {e}")))
}

/// [`calibrate_stereo_json`] on the parsed input.
pub fn calibrate_stereo_input(input: &StereoInput) -> Result<StereoCalibration> {
    if input.left.len() != input.right.len() {
        return Err(Error::invalid(
            "right",
            format!(
                "views are paired by order: {} left views but {} right views",
                input.left.len(),
                input.right.len()
            ),
        ));
    }
    if input.left.len() < MIN_VIEWS {
        return Err(Error::too_few("pairs", MIN_VIEWS, input.left.len()));
    }
    check_size("pairs", &input.left)?;
    check_size("pairs", &input.right)?;
    let left_size = side_size("left", &input.left, input.left_image_size_px)?;
    let right_size = side_size("right", &input.right, input.right_image_size_px)?;
    let left = views_of(&input.left).map_err(|e| within("left", e))?;
    let right = views_of(&input.right).map_err(|e| within("right", e))?;
    calibrate_stereo_views(
        &input.model,
        &input.options,
        &left,
        &right,
        left_size,
        right_size,
    )
}

/// [`calibrate_stereo_input`] from the views on: the request's model and
/// options mapped to the solver's, then the solve. `robocal stereo` enters
/// here with the views of its own detections (images it detected, or
/// detection files taken as they are, every point kept as before), so the
/// CLI, the page and npm share the option mapping and the solve.
pub fn calibrate_stereo_views(
    model: &LensModel,
    options: &JsonOptions,
    left: &[View],
    right: &[View],
    left_size_px: (u32, u32),
    right_size_px: (u32, u32),
) -> Result<StereoCalibration> {
    let options = calibration_options(model, options)?;
    calibrate_stereo(left, right, left_size_px, right_size_px, &options)
}

/// Field names of a view error point into the side it came from
/// (`views[2].image_px` becomes `left[2].image_px`).
fn within(side: &str, e: Error) -> Error {
    match e {
        Error::Invalid { field, message } => Error::Invalid {
            field: field.replacen("views", side, 1),
            message,
        },
        other => other,
    }
}

/// One camera's image size: given, or the one all its detections agree on.
fn side_size(side: &str, views: &[JsonView], given: Option<[u32; 2]>) -> Result<(u32, u32)> {
    agreed_image_size(
        &format!("{side}_image_size_px"),
        given,
        detection_sizes(
            views
                .iter()
                .map(|v| (v.name.as_str(), v.detection.as_ref())),
        ),
        "required when the views are not detections",
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::geometry::{rotation_from_rotvec, Pose};
    use crate::synth::Scene;
    use nalgebra::{Translation3, Vector3};
    use wasm_bindgen_test::wasm_bindgen_test;

    /// Noise-free pair: the left views of a seeded scene and the same board
    /// poses seen by a right camera with other intrinsics, 6 cm to the left.
    fn pair_input() -> (StereoInput, Camera, Pose) {
        let left_camera = Camera::example_brown();
        let scene = Scene::calibration(3, &left_camera, (9, 6), 0.03, 6, 0.0).expect("scene");
        let right_camera = Camera {
            fx: left_camera.fx * 1.02,
            cx: left_camera.cx + 7.0,
            ..left_camera.clone()
        };
        let right_from_left = Pose::from_parts(
            Translation3::new(-0.06, 0.002, -0.001),
            rotation_from_rotvec(&Vector3::new(0.01, -0.04, 0.015)),
        );
        let view =
            |name: String, object: &[nalgebra::Point3<f64>], image: Vec<[f64; 2]>| JsonView {
                name,
                detection: None,
                object_m: Some(object.iter().map(|p| [p.x, p.y, p.z]).collect()),
                image_px: Some(image),
            };
        let mut left = vec![];
        let mut right = vec![];
        for (v, pose) in scene.views.iter().zip(&scene.camera_from_target) {
            let l = v.image_px.iter().map(|p| [p.x, p.y]).collect();
            let r = v
                .object_m
                .iter()
                .map(|p| {
                    let px = right_camera
                        .project(&(right_from_left * pose * p))
                        .expect("in front");
                    [px.x, px.y]
                })
                .collect();
            left.push(view(format!("l_{}", v.name), &v.object_m, l));
            right.push(view(format!("r_{}", v.name), &v.object_m, r));
        }
        let size = Some([left_camera.width, left_camera.height]);
        let input = StereoInput {
            model: LensModel::default(),
            options: JsonOptions::default(),
            left,
            right,
            left_image_size_px: size,
            right_image_size_px: size,
        };
        (input, right_camera, right_from_left)
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn json_round_trip_recovers_the_true_pair() {
        let (input, right_camera, truth) = pair_input();
        let text = serde_json::to_string(&input).expect("serialise");
        let out: StereoCalibration =
            serde_json::from_str(&calibrate_stereo_json(&text).expect("solve")).expect("parse");
        // Noise-free correspondences: the optimum is the truth to solver precision.
        let got = out.right_from_left.to_pose().expect("pose");
        assert!((got.translation.vector - truth.translation.vector).norm() < 1e-9);
        assert!(got.rotation.angle_to(&truth.rotation) < 1e-9);
        assert!((out.baseline_m - truth.inverse().translation.vector.norm()).abs() < 1e-9);
        assert!((out.right.camera.fx - right_camera.fx).abs() < 1e-6);
        assert!((out.right.camera.cx - right_camera.cx).abs() < 1e-6);
        assert!(out.rms_px < 1e-6, "rms {}", out.rms_px);
        assert_eq!(out.left.views[0].name, "l_view_000");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn bad_inputs_get_plain_messages() {
        let (mut input, _, _) = pair_input();
        input.right.pop();
        assert_eq!(
            calibrate_stereo_input(&input).unwrap_err().to_string(),
            "right: views are paired by order: 6 left views but 5 right views"
        );
        let (mut input, _, _) = pair_input();
        input.left.truncate(2);
        input.right.truncate(2);
        assert_eq!(
            calibrate_stereo_input(&input).unwrap_err().to_string(),
            "requires at least 3 pairs, got 2"
        );
        let (mut input, _, _) = pair_input();
        input.right[1].image_px.as_mut().expect("points").pop();
        assert_eq!(
            calibrate_stereo_input(&input).unwrap_err().to_string(),
            "right[1].image_px: 54 object points but 53 image points"
        );
        let (mut input, _, _) = pair_input();
        input.left_image_size_px = None;
        assert_eq!(
            calibrate_stereo_input(&input).unwrap_err().to_string(),
            "left_image_size_px: required when the views are not detections"
        );
        let err = calibrate_stereo_json("{\"left\": []}")
            .unwrap_err()
            .to_string();
        assert!(err.contains("stereo input: missing field `right`"), "{err}");
        // The model is a choice read by serde: an unknown name says the known ones.
        let err = calibrate_stereo_json(r#"{"model": "fisheye", "left": [], "right": []}"#)
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("model: unknown model 'fisheye' (expected one of brown, "),
            "{err}"
        );
    }
}
