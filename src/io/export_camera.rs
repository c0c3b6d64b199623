//! Camera exports: one writer per format, all from the same [`Camera`].
//!
//! Conventions converted here (see the crate's conventions): OpenCV, ROS,
//! Kalibr and mrcal share ours (pixel centres at integer coordinates, so the
//! principal point is written as is); MATLAB is 1-based (principal point
//! plus 1) and stores the transposed camera matrix; Halcon's camera parameters
//! are metric (focal length and pixel size in metres, distortion scaled by
//! powers of the focal length) with the principal point in pixels.

use super::export_camera_tools::{halcon, kalibr, matlab, mrcal, text3x3};
use crate::camera::{Camera, Distortion};
use crate::error::{Error, Result};

/// The camera formats robocal writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraFormat {
    /// robocal's own JSON (`robocal.camera.v1`), read back by [`super::import_camera`].
    Json,
    /// OpenCV FileStorage YAML (`cv2.FileStorage`), `camera_matrix` + `distortion_coefficients`.
    OpencvYaml,
    /// OpenCV FileStorage XML.
    OpencvXml,
    /// ROS `camera_info` YAML (camera_calibration_parsers).
    RosYaml,
    /// Kalibr camchain YAML (`cam0`).
    Kalibr,
    /// mrcal `.cameramodel`.
    Mrcal,
    /// Halcon camera parameter tuple (HDevelop syntax).
    Halcon,
    /// MATLAB script building `cameraIntrinsics` (1-based principal point).
    Matlab,
    /// The 3x3 camera matrix as plain text.
    Text,
}

impl CameraFormat {
    /// Every format, in menu order.
    pub const ALL: [CameraFormat; 9] = [
        CameraFormat::Json,
        CameraFormat::OpencvYaml,
        CameraFormat::OpencvXml,
        CameraFormat::RosYaml,
        CameraFormat::Kalibr,
        CameraFormat::Mrcal,
        CameraFormat::Halcon,
        CameraFormat::Matlab,
        CameraFormat::Text,
    ];

    /// The name used by the CLI and the wasm boundary.
    pub fn name(self) -> &'static str {
        match self {
            CameraFormat::Json => "json",
            CameraFormat::OpencvYaml => "opencv-yaml",
            CameraFormat::OpencvXml => "opencv-xml",
            CameraFormat::RosYaml => "ros-yaml",
            CameraFormat::Kalibr => "kalibr",
            CameraFormat::Mrcal => "mrcal",
            CameraFormat::Halcon => "halcon",
            CameraFormat::Matlab => "matlab",
            CameraFormat::Text => "text",
        }
    }

    /// The usual file name extension.
    pub fn extension(self) -> &'static str {
        match self {
            CameraFormat::Json => "json",
            CameraFormat::OpencvYaml | CameraFormat::RosYaml | CameraFormat::Kalibr => "yaml",
            CameraFormat::OpencvXml => "xml",
            CameraFormat::Mrcal => "cameramodel",
            CameraFormat::Halcon => "hdev.txt",
            CameraFormat::Matlab => "m",
            CameraFormat::Text => "txt",
        }
    }

    /// Parse a format name; an unknown name lists the known ones.
    pub fn from_name(name: &str) -> Result<CameraFormat> {
        CameraFormat::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| {
                let known: Vec<&str> = CameraFormat::ALL.iter().map(|f| f.name()).collect();
                Error::invalid(
                    "format",
                    format!(
                        "unknown camera format '{name}' (known: {})",
                        known.join(", ")
                    ),
                )
            })
    }
}

/// What a camera export says besides the camera itself.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraExportInfo {
    /// Camera name (ROS `camera_name`, Kalibr topic `/<name>/image_raw`).
    pub name: String,
    /// Reprojection RMS of the calibration, when known.
    pub rms_px: Option<f64>,
    /// Physical pixel size for Halcon's metric parameters, metres
    /// (default [`DEFAULT_PIXEL_SIZE_M`]; only the ratio focal/pixel matters).
    pub pixel_size_m: f64,
}

/// Nominal pixel size used for Halcon when none is known: 5 µm.
pub const DEFAULT_PIXEL_SIZE_M: f64 = 5e-6;

impl Default for CameraExportInfo {
    fn default() -> Self {
        CameraExportInfo {
            name: "camera".into(),
            rms_px: None,
            pixel_size_m: DEFAULT_PIXEL_SIZE_M,
        }
    }
}

/// Write `camera` in `format`.
pub fn export_camera(
    camera: &Camera,
    info: &CameraExportInfo,
    format: CameraFormat,
) -> Result<String> {
    match format {
        CameraFormat::Json => json(camera, info),
        CameraFormat::OpencvYaml => opencv_yaml(camera, info),
        CameraFormat::OpencvXml => opencv_xml(camera, info),
        CameraFormat::RosYaml => ros_camera_info(camera, info, None),
        CameraFormat::Kalibr => kalibr(camera, info),
        CameraFormat::Mrcal => mrcal(camera),
        CameraFormat::Halcon => halcon(camera, info),
        CameraFormat::Matlab => matlab(camera),
        CameraFormat::Text => Ok(text3x3(camera)),
    }
}

/// A float as the shortest text that reads back to the same value, always
/// with a decimal point and never in exponent form (YAML 1.1 readers such
/// as PyYAML take `1e-5` for a string).
pub fn float(x: f64) -> String {
    // -0.0 prints as "-0"; a sign on zero only confuses readers.
    let x = if x == 0.0 { 0.0 } else { x };
    let s = format!("{x}");
    if s.contains('.') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

pub(super) fn list(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| float(*v))
        .collect::<Vec<_>>()
        .join(", ")
}

pub(super) fn k_row_major(c: &Camera) -> [f64; 9] {
    [c.fx, c.skew, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0]
}

/// OpenCV's distortion vector for the models OpenCV has; which API reads it.
pub(super) fn opencv_distortion(c: &Camera) -> Result<(Vec<f64>, bool)> {
    let d = &c.distortion;
    Ok(match d {
        Distortion::None => (vec![0.0; 5], false),
        Distortion::Brown { k1, k2, k3, p1, p2 } => (vec![*k1, *k2, *p1, *p2, *k3], false),
        Distortion::RadialK1K2K5 { k1, k2, k5 } => (vec![*k1, *k2, 0.0, 0.0, *k5], false),
        Distortion::Rational { .. } => {
            let v = d.coefficients();
            let prism = v[8..].iter().any(|s| *s != 0.0);
            (if prism { v } else { v[..8].to_vec() }, false)
        }
        // All 14, in OpenCV's order (CALIB_TILTED_MODEL).
        Distortion::Tilted { .. } => (d.coefficients(), false),
        Distortion::KannalaBrandt { k1, k2, k3, k4 } => (vec![*k1, *k2, *k3, *k4], true),
        Distortion::Splined(_) => {
            return Err(unsupported(
                c,
                "OpenCV (use robocal JSON, or resample its images with an undistortion map)",
            ))
        }
        Distortion::Division { .. } | Distortion::Eucm { .. } => {
            return Err(unsupported(
                c,
                "OpenCV (use robocal JSON, Halcon for division, Kalibr for EUCM)",
            ))
        }
    })
}

/// The refusal of a model that `target` cannot hold, naming the formats of
/// the lens-model table that can (for the models added with that list).
pub(super) fn unsupported_listing(c: &Camera, target: &str) -> Error {
    let model = c.distortion.model_name();
    let formats = crate::camera::LensModel::named(model)
        .map(|m| m.export_formats.join(", "))
        .unwrap_or_default();
    Error::invalid(
        "format",
        format!("the {model} lens model cannot be written for {target}: export it as {formats}"),
    )
}

pub(super) fn unsupported(c: &Camera, target: &str) -> Error {
    Error::invalid(
        "format",
        format!(
            "the {} lens model cannot be written for {target}",
            c.distortion.model_name()
        ),
    )
}

fn json(c: &Camera, info: &CameraExportInfo) -> Result<String> {
    let mut distortion = serde_json::Map::new();
    for (name, value) in c
        .distortion
        .coefficient_names()
        .iter()
        .zip(c.distortion.coefficients())
    {
        distortion.insert((*name).to_string(), serde_json::json!(value));
    }
    let mut value = serde_json::json!({
        "schema": "robocal.camera.v1",
        "robocal_version": crate::VERSION,
        "name": info.name,
        "image_size_px": [c.width, c.height],
        "model": c.distortion.model_name(),
        "camera_matrix": k_row_major(c).chunks(3).collect::<Vec<_>>(),
        "distortion": distortion,
        "rms_px": info.rms_px,
    });
    // The splined model's layout: its values alone (dx0 dy0 ...) do not say
    // where its knots sit.
    if let Distortion::Splined(s) = &c.distortion {
        value["spline"] = serde_json::json!({
            "order": s.order,
            "nx": s.nx,
            "ny": s.ny,
            "u_max": s.u_max,
            "smoothness": s.smoothness,
        });
    }
    Ok(super::to_string_pretty(&value) + "\n")
}

fn opencv_yaml(c: &Camera, info: &CameraExportInfo) -> Result<String> {
    let (dist, fisheye) = opencv_distortion(c)?;
    let mut out = String::from("%YAML:1.0\n---\n");
    out += &format!(
        "# robocal {}: {} model{}\n",
        crate::VERSION,
        c.distortion.model_name(),
        if fisheye {
            " (read with cv2.fisheye)"
        } else {
            ""
        }
    );
    out += &format!("image_width: {}\nimage_height: {}\n", c.width, c.height);
    out += &yaml_matrix("camera_matrix", 3, 3, &k_row_major(c));
    out += &yaml_matrix("distortion_coefficients", 1, dist.len(), &dist);
    if let Some(rms) = info.rms_px {
        out += &format!("avg_reprojection_error: {}\n", float(rms));
    }
    Ok(out)
}

pub(super) fn yaml_matrix(name: &str, rows: usize, cols: usize, data: &[f64]) -> String {
    format!(
        "{name}: !!opencv-matrix\n   rows: {rows}\n   cols: {cols}\n   dt: d\n   data: [ {} ]\n",
        list(data)
    )
}

fn opencv_xml(c: &Camera, info: &CameraExportInfo) -> Result<String> {
    let (dist, fisheye) = opencv_distortion(c)?;
    let matrix = |name: &str, rows: usize, cols: usize, data: &[f64]| {
        let values: Vec<String> = data.iter().map(|v| float(*v)).collect();
        format!(
            "<{name} type_id=\"opencv-matrix\">\n  <rows>{rows}</rows>\n  <cols>{cols}</cols>\n  <dt>d</dt>\n  <data>\n    {}</data></{name}>\n",
            values.join(" ")
        )
    };
    let mut out = String::from("<?xml version=\"1.0\"?>\n<opencv_storage>\n");
    out += &format!(
        "<!-- robocal {}: {} model{} -->\n",
        crate::VERSION,
        c.distortion.model_name(),
        if fisheye {
            " (read with cv2.fisheye)"
        } else {
            ""
        }
    );
    out += &format!(
        "<image_width>{}</image_width>\n<image_height>{}</image_height>\n",
        c.width, c.height
    );
    out += &matrix("camera_matrix", 3, 3, &k_row_major(c));
    out += &matrix("distortion_coefficients", 1, dist.len(), &dist);
    if let Some(rms) = info.rms_px {
        out += &format!(
            "<avg_reprojection_error>{}</avg_reprojection_error>\n",
            float(rms)
        );
    }
    out += "</opencv_storage>\n";
    Ok(out)
}

/// A ROS camera_info YAML; `rectified` gives its `rectification_matrix`
/// (3x3) and `projection_matrix` (3x4), row-major, for a camera of a
/// stereo pair (else the identity and `[K | 0]`).
pub(super) fn ros_camera_info(
    c: &Camera,
    info: &CameraExportInfo,
    rectified: Option<(&[f64], &[f64])>,
) -> Result<String> {
    if let Distortion::Tilted { .. } = c.distortion {
        return Err(unsupported_listing(
            c,
            "ROS camera_info (it has no tilted sensor)",
        ));
    }
    let (dist, fisheye) = opencv_distortion(c)?;
    let model = match (&c.distortion, fisheye) {
        (_, true) => "equidistant",
        (Distortion::Rational { .. }, false) => "rational_polynomial",
        _ => "plumb_bob",
    };
    let k = k_row_major(c);
    let p = [
        k[0], k[1], k[2], 0.0, 0.0, k[4], k[5], 0.0, 0.0, 0.0, 1.0, 0.0,
    ];
    let block = |name: &str, rows: usize, cols: usize, data: &[f64]| {
        format!(
            "{name}:\n  rows: {rows}\n  cols: {cols}\n  data: [{}]\n",
            list(data)
        )
    };
    let mut out = format!(
        "image_width: {}\nimage_height: {}\ncamera_name: {}\n",
        c.width,
        c.height,
        super::export::yaml_scalar(&info.name)
    );
    out += &block("camera_matrix", 3, 3, &k);
    out += &format!("distortion_model: {model}\n");
    out += &block("distortion_coefficients", 1, dist.len(), &dist);
    let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let (r, p) = rectified.unwrap_or((&identity[..], &p[..]));
    out += &block("rectification_matrix", 3, 3, r);
    out += &block("projection_matrix", 3, 4, p);
    Ok(out)
}
