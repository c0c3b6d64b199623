//! The JSON requests of the laser-line capability ([`super::laser`]) for the
//! wasm functions `laser_plane`, `laser_points` and `laser_stripe` (the web
//! app's laser step and the npm package). The host decodes the images (bytes
//! in wasm) and passes them beside the request, in the order `robocal laser
//! plane` takes its files.
//!
//! Plane request (images: one per pose showing board and stripe, or with
//! `pairs` board (laser off), stripe (laser on), board, stripe, ...):
//!
//! ```json
//! {"camera": "<the calibrated camera file's text>",
//!  "target": "chessboard:9x6:30mm",
//!  "pairs": true, "names": ["view_000", "view_001"],
//!  "residual": "image_px",
//!  "stripe": {"extractor": "cog", "axis": "auto", "min_contrast": 20, "max_width_px": 24}}
//! ```
//!
//! Points request (images: the stripe image, and the laser-off image when given):
//!
//! ```json
//! {"camera": "<file text>", "plane": {"laser_plane": {...}} or a laser_plane report,
//!  "gripper_from_camera": {pose}, "base_from_gripper": {pose}, "stripe": {...}}
//! ```
//!
//! `camera` is any camera file robocal reads ([`crate::io::import_camera`]);
//! `target` a CLI spec or a target JSON object; every key but `camera`,
//! `target` and `plane` may be left out (the CLI's defaults).

use super::detect::DetectRequest;
use super::laser::{
    laser_plane, laser_points, plane_from_json, LaserPlaneReport, LaserPlaneSettings,
    LaserPointsReport, LaserView,
};
use crate::error::{Error, Result};
use crate::geometry::PoseInput;
use crate::image::GrayImage;
use crate::io::import_camera::import_camera;
use crate::laser::{extract_stripe, PlaneResidual, ScanAxis, Stripe, StripeMethod, StripeOptions};
use serde::Deserialize;

/// The stripe extractor's settings, as `robocal laser`'s flags name them.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StripeSettings {
    /// `cog` (default) or `ridge`.
    #[serde(default)]
    pub extractor: Option<String>,
    /// `auto` (default), `columns` (a horizontal stripe) or `rows`.
    #[serde(default)]
    pub axis: Option<String>,
    /// Smallest peak contrast above the local background, grey levels (default 20).
    #[serde(default)]
    pub min_contrast: Option<f64>,
    /// Widest stripe expected, pixels (default 24).
    #[serde(default)]
    pub max_width_px: Option<f64>,
}

impl StripeSettings {
    /// The extractor's options; an unknown name is an error naming the
    /// choices (the extractor checks the numbers' ranges).
    pub fn options(&self) -> Result<StripeOptions> {
        let defaults = StripeOptions::default();
        let method = match self.extractor.as_deref() {
            None => defaults.method,
            Some(name) => StripeMethod::from_name(name)?,
        };
        let axis = match self.axis.as_deref() {
            None | Some("auto") => None,
            Some("columns") => Some(ScanAxis::Columns),
            Some("rows") => Some(ScanAxis::Rows),
            Some(other) => {
                return Err(Error::invalid(
                    "axis",
                    format!("unknown axis '{other}' (expected auto, columns or rows)"),
                ))
            }
        };
        Ok(StripeOptions {
            method,
            axis,
            min_contrast: self.min_contrast.unwrap_or(defaults.min_contrast),
            max_width_px: self.max_width_px.unwrap_or(defaults.max_width_px),
            ..defaults
        })
    }
}

/// The request of [`laser_plane_request`].
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaserPlaneRequest {
    /// The calibrated camera: a camera file's text.
    pub camera: String,
    /// The board: a CLI spec (`chessboard:9x6:30mm`) or a target JSON object.
    pub target: serde_json::Value,
    /// The images come in pairs: board (laser off), stripe (laser on).
    #[serde(default)]
    pub pairs: bool,
    /// A name per pose (default `pose_1`, `pose_2`, ...), carried into the report.
    #[serde(default)]
    pub names: Option<Vec<String>>,
    /// `image_px` (default) or `point_to_plane`.
    #[serde(default)]
    pub residual: Option<String>,
    /// The stripe extractor.
    #[serde(default)]
    pub stripe: StripeSettings,
}

/// The request of [`laser_points_request`].
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaserPointsRequest {
    /// The calibrated camera: a camera file's text.
    pub camera: String,
    /// The plane: a `laser_plane` report, `{"laser_plane": {...}}` or
    /// `{"normal_camera", "distance_m"}`.
    pub plane: serde_json::Value,
    /// The camera's mounting on the flange: adds `flange_m` to every point.
    #[serde(default)]
    pub gripper_from_camera: Option<PoseInput>,
    /// The flange's pose for this image: adds `base_m`.
    #[serde(default)]
    pub base_from_gripper: Option<PoseInput>,
    /// The stripe extractor.
    #[serde(default)]
    pub stripe: StripeSettings,
}

fn parse<T: serde::de::DeserializeOwned>(what: &str, json: &str) -> Result<T> {
    serde_json::from_str(json).map_err(|e| super::request_error(what, e))
}

fn camera_of(text: &str) -> Result<crate::camera::Camera> {
    import_camera(text)
        .map(|(camera, _)| camera)
        .map_err(|e| Error::invalid("camera", e.to_string()))
}

/// The laser plane from a JSON request and the decoded images (see the
/// module docs): the report of [`laser_plane`].
pub fn laser_plane_request(request_json: &str, images: Vec<GrayImage>) -> Result<LaserPlaneReport> {
    let request: LaserPlaneRequest = parse("laser plane request", request_json)?;
    let camera = camera_of(&request.camera)?;
    let spec = match &request.target {
        serde_json::Value::String(spec) => spec.clone(),
        other => other.to_string(),
    };
    let detect = DetectRequest::from_spec_or_json(&spec)?;
    let residual = match request.residual.as_deref() {
        None => PlaneResidual::default(),
        Some(name) => PlaneResidual::from_name(name)?,
    };
    let step = if request.pairs { 2 } else { 1 };
    if images.len() % step != 0 {
        return Err(Error::invalid(
            "images",
            format!(
                "pairs needs an even number of images (board, stripe, board, stripe, ...), got {}",
                images.len()
            ),
        ));
    }
    let poses = images.len() / step;
    if let Some(names) = request.names.as_ref().filter(|n| n.len() != poses) {
        return Err(Error::invalid(
            "names",
            format!(
                "{} names for {poses} poses: give one name per pose",
                names.len()
            ),
        ));
    }
    let mut views = Vec::with_capacity(poses);
    let mut images = images.into_iter();
    for k in 0..poses {
        let Some(board) = images.next() else { break };
        let stripe = if request.pairs { images.next() } else { None };
        let name = match &request.names {
            Some(names) => names[k].clone(),
            None => format!("pose_{}", k + 1),
        };
        views.push(LaserView {
            name,
            board,
            stripe,
        });
    }
    let settings = LaserPlaneSettings {
        residual,
        stripe: request.stripe.options()?,
        detect: detect.options,
    };
    laser_plane(&camera, &detect.target, &views, &settings)
}

/// A stripe image (and its laser-off image) to 3-D points from a JSON
/// request (see the module docs): the report of [`laser_points`].
pub fn laser_points_request(
    request_json: &str,
    image: &GrayImage,
    off: Option<&GrayImage>,
) -> Result<LaserPointsReport> {
    let request: LaserPointsRequest = parse("laser points request", request_json)?;
    let camera = camera_of(&request.camera)?;
    let (plane, _) = plane_from_json(&request.plane.to_string())?;
    let pose = |field: &str, p: &Option<PoseInput>| {
        p.as_ref()
            .map(|p| {
                p.to_pose()
                    .map_err(|e| Error::invalid(field, e.to_string()))
            })
            .transpose()
    };
    let mount = pose("gripper_from_camera", &request.gripper_from_camera)?;
    let robot = pose("base_from_gripper", &request.base_from_gripper)?;
    laser_points(
        &camera,
        &plane,
        image,
        off,
        &request.stripe.options()?,
        mount.as_ref(),
        robot.as_ref(),
    )
}

/// The stripe of one image (the laser-off image subtracted when given):
/// every centre with its width, contrast and std, the gaps and the ends,
/// as the plane and the points extract it (the page draws it on the image).
/// `settings_json`: a [`StripeSettings`] object, or empty for the defaults.
pub fn laser_stripe_request(
    settings_json: &str,
    image: &GrayImage,
    off: Option<&GrayImage>,
) -> Result<Stripe> {
    let settings: StripeSettings = if settings_json.trim().is_empty() {
        StripeSettings::default()
    } else {
        parse("stripe settings", settings_json)?
    };
    extract_stripe(image, off, &settings.options()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAMERA: &str = r#"{"model": "brown", "image_size_px": [64, 48],
        "camera_matrix": [[80, 0, 31.5], [0, 80, 23.5], [0, 0, 1]],
        "distortion": {"k1": 0, "k2": 0, "k3": 0, "p1": 0, "p2": 0}}"#;

    fn grey(n: usize) -> Vec<GrayImage> {
        (0..n)
            .map(|_| GrayImage {
                width: 64,
                height: 48,
                pixels: vec![128; 64 * 48],
            })
            .collect()
    }

    fn plane_error(request: serde_json::Value, images: usize) -> String {
        laser_plane_request(&request.to_string(), grey(images))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn plane_requests_say_what_is_wrong() {
        let base =
            serde_json::json!({"camera": CAMERA, "target": "chessboard:9x6:30mm", "pairs": true});
        assert_eq!(
            plane_error(base.clone(), 3),
            "images: pairs needs an even number of images (board, stripe, board, stripe, ...), got 3"
        );
        let mut named = base.clone();
        named["names"] = serde_json::json!(["a"]);
        assert_eq!(
            plane_error(named, 4),
            "names: 1 names for 2 poses: give one name per pose"
        );
        let mut ridge = base.clone();
        ridge["stripe"] = serde_json::json!({"extractor": "sobel"});
        assert_eq!(
            plane_error(ridge, 4),
            "extractor: unknown extractor 'sobel' (expected cog or ridge)"
        );
        let mut axis = base.clone();
        axis["stripe"] = serde_json::json!({"axis": "diagonal"});
        assert_eq!(
            plane_error(axis, 4),
            "axis: unknown axis 'diagonal' (expected auto, columns or rows)"
        );
        let mut residual = base.clone();
        residual["residual"] = serde_json::json!("manhattan");
        assert_eq!(
            plane_error(residual, 4),
            "residual: unknown residual 'manhattan' (expected image_px or point_to_plane)"
        );
        let mut camera = base.clone();
        camera["camera"] = serde_json::json!("hello");
        assert!(plane_error(camera, 4).starts_with("camera: "));
        let mut extra = base.clone();
        extra["laser"] = serde_json::json!(true);
        assert!(
            plane_error(extra, 4).contains("laser plane request: unknown field `laser`"),
            "unknown keys are refused"
        );
        // One pose: the plane needs two (the core's own check, reached once
        // the request reads).
        let one = serde_json::json!({"camera": CAMERA, "target": {"kind": "chessboard", "cols": 9, "rows": 6, "square_m": 0.03}});
        assert!(plane_error(one, 1).contains("board poses"));
    }

    #[test]
    fn stripe_settings_default_to_the_cli_defaults() {
        let o = StripeSettings::default().options().unwrap();
        assert_eq!(o, StripeOptions::default());
        let ridge: StripeSettings = serde_json::from_str(
            r#"{"extractor": "ridge", "axis": "rows", "min_contrast": 12, "max_width_px": 30}"#,
        )
        .unwrap();
        let o = ridge.options().unwrap();
        assert_eq!(
            (o.method, o.axis, o.min_contrast, o.max_width_px),
            (StripeMethod::Ridge, Some(ScanAxis::Rows), 12.0, 30.0)
        );
        let flat = &grey(1)[0];
        assert_eq!(
            laser_stripe_request(r#"{"max_width_px": 1}"#, flat, None)
                .unwrap_err()
                .to_string(),
            "stripe options: need min_contrast > 0, 0 < threshold < 1 and 2 <= max_width_px <= 200, got 20, 0.3, 1"
        );
    }

    #[test]
    fn points_requests_read_the_plane_and_poses() {
        let flat = &grey(1)[0];
        let request = serde_json::json!({"camera": CAMERA, "plane": {"normal_camera": [0, 0, 1]}});
        assert!(laser_points_request(&request.to_string(), flat, None)
            .unwrap_err()
            .to_string()
            .starts_with("laser_plane: expected"));
        let request = serde_json::json!({"camera": CAMERA, "plane": {"laser_plane": {"normal_camera": [0, -1, 0.2], "distance_m": 0.1}},
            "gripper_from_camera": {"translation_m": [0, 0, 0.1]}});
        let err = laser_points_request(&request.to_string(), flat, None)
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "gripper_from_camera: pose: expected matrix_row_major (4 rows of 4 numbers) or translation_m and quaternion_xyzw, got translation_m alone"
        );
    }
}
