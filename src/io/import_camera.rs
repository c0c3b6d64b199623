//! Reading cameras back: robocal JSON (a camera export or a calibration
//! report), OpenCV FileStorage YAML and XML, ROS `camera_info` YAML, a
//! Kalibr camchain and an mrcal `.cameramodel` (the last two in
//! [`super::import_camera_tools`]), HALCON camera parameters (an HDevelop
//! tuple or a `write_cam_par` `.dat` file, [`super::import_camera_halcon`]),
//! robocal's MATLAB script and its text matrix
//! ([`super::import_camera_matlab`]): every camera format `robocal export`
//! writes. The format is recognised from the content, in the order of
//! [`NOT_A_CAMERA`]'s list.

use super::import_camera_halcon::{
    from_halcon_dat, from_halcon_tuple, is_halcon_dat, is_halcon_tuple,
};
use super::import_camera_matlab::{from_matlab, from_text, is_matlab, is_text_matrix};
use super::import_camera_tools::{from_kalibr, from_mrcal, is_kalibr, is_mrcal};
use crate::camera::splined::MAX_KNOTS;
use crate::camera::{Camera, Distortion, Spline};
use crate::error::{Error, Result};

/// The formats [`import_camera`] recognises.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraSource {
    /// robocal JSON.
    Json,
    /// OpenCV FileStorage YAML.
    OpencvYaml,
    /// OpenCV FileStorage XML.
    OpencvXml,
    /// ROS camera_info YAML.
    RosYaml,
    /// A Kalibr camchain YAML (its first camera).
    Kalibr,
    /// An mrcal `.cameramodel`.
    Mrcal,
    /// HALCON camera parameters: an HDevelop tuple (robocal's `halcon`
    /// export) or HALCON's `write_cam_par` `.dat` file.
    Halcon,
    /// robocal's MATLAB script (`cameraIntrinsics`).
    Matlab,
    /// robocal's text camera matrix (with its image-size comment).
    Text,
}

/// The error of a text that is no camera file: the formats, in the order
/// they are recognised.
pub const NOT_A_CAMERA: &str = "not a camera file: expected robocal JSON, OpenCV YAML/XML (camera_matrix, distortion_coefficients), ROS camera_info YAML, a Kalibr camchain, an mrcal .cameramodel, HALCON camera parameters (a .dat file or a CameraParam tuple), robocal's MATLAB script or a 3x3 camera matrix";

/// Read a camera from text in any of the [`CameraSource`] formats.
pub fn import_camera(text: &str) -> Result<(Camera, CameraSource)> {
    let trimmed = text.trim_start();
    if is_mrcal(text) {
        return from_mrcal(text).map(|c| (c, CameraSource::Mrcal));
    }
    if trimmed.starts_with('{') {
        return from_json(text).map(|c| (c, CameraSource::Json));
    }
    if trimmed.starts_with("<?xml") || trimmed.starts_with("<opencv_storage>") {
        return from_xml(text).map(|c| (c, CameraSource::OpencvXml));
    }
    if text.contains("!!opencv-matrix") {
        return from_yaml(text, false).map(|c| (c, CameraSource::OpencvYaml));
    }
    if text.contains("camera_matrix:") && text.contains("distortion_model:") {
        return from_yaml(text, true).map(|c| (c, CameraSource::RosYaml));
    }
    if is_kalibr(text) {
        return from_kalibr(text).map(|c| (c, CameraSource::Kalibr));
    }
    if is_halcon_dat(text) {
        return from_halcon_dat(text).map(|c| (c, CameraSource::Halcon));
    }
    if is_halcon_tuple(text) {
        return from_halcon_tuple(text).map(|c| (c, CameraSource::Halcon));
    }
    if is_matlab(text) {
        return from_matlab(text).map(|c| (c, CameraSource::Matlab));
    }
    if is_text_matrix(text) {
        return from_text(text).map(|c| (c, CameraSource::Text));
    }
    Err(Error::parse(0, 0, NOT_A_CAMERA))
}

fn from_json(text: &str) -> Result<Camera> {
    let v: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| Error::parse(e.line(), e.column(), format!("invalid JSON: {e}")))?;
    // A full calibration report nests nothing: the camera keys are top level.
    let size = v["image_size_px"]
        .as_array()
        .filter(|a| a.len() == 2)
        .ok_or_else(|| missing("image_size_px", IMAGE_SIZE))?;
    let dim = |i: usize| {
        size[i]
            .as_u64()
            .filter(|&d| d > 0 && d <= u32::MAX as u64)
            .map(|d| d as u32)
    };
    let (width, height) = (
        dim(0).ok_or_else(|| missing("image_size_px", IMAGE_SIZE))?,
        dim(1).ok_or_else(|| missing("image_size_px", IMAGE_SIZE))?,
    );
    let k: Vec<f64> = super::json_matrix_numbers(&v["camera_matrix"])
        .filter(|k| k.len() == 9)
        .ok_or_else(|| {
            missing(
                "camera_matrix",
                "3 rows of 3 numbers [[fx, s, cx], [0, fy, cy], [0, 0, 1]]",
            )
        })?;
    let model = v["model"]
        .as_str()
        .ok_or_else(|| missing("model", "the lens model's name, e.g. \"brown\""))?;
    let mut template = distortion_template(model)?;
    if let (Distortion::Splined(_), Some(layout)) = (&template, spline_layout(&v)) {
        template = Distortion::Splined(layout?);
    }
    let coeffs = template
        .coefficient_names()
        .iter()
        .map(|name| {
            v["distortion"][*name].as_f64().ok_or_else(|| {
                Error::invalid(
                    "distortion",
                    format!("the {model} model needs coefficient '{name}' (a number)"),
                )
            })
        })
        .collect::<Result<Vec<f64>>>()?;
    let distortion = template.with_coefficients(&coeffs)?;
    if let Distortion::Splined(s) = &distortion {
        if !s.control.is_empty() {
            s.check()?;
        }
    }
    camera_from_k(&k, width, height, distortion)
}

/// A splined camera's layout (degree, control points, knot field): the
/// camera JSON's `spline` (robocal's JSON export) or a calibration report's
/// `camera.distortion`; None when the JSON has neither (then the model
/// reads without its control values). The values themselves are the
/// coefficients `dx0 dy0 ...` of `distortion`.
fn spline_layout(v: &serde_json::Value) -> Option<Result<Spline>> {
    let layout = [&v["spline"], &v["camera"]["distortion"]]
        .into_iter()
        .find(|l| l.is_object())?;
    let count = |key: &str| {
        layout[key]
            .as_u64()
            .filter(|&n| n >= 1 && n <= MAX_KNOTS as u64)
            .map(|n| n as usize)
            .ok_or_else(|| {
                Error::invalid(
                    "spline",
                    format!("the splined model's layout needs '{key}': a whole number from 1 to {MAX_KNOTS}"),
                )
            })
    };
    let field = layout["u_max"]
        .as_array()
        .filter(|a| a.len() == 2)
        .and_then(|a| Some([a[0].as_f64()?, a[1].as_f64()?]))
        .ok_or_else(|| {
            Error::invalid(
                "spline",
                "the splined model's layout needs 'u_max': [x, y], the knot field's half extent",
            )
        });
    let read = || {
        let mut spline = Spline::new(count("order")?, count("nx")?, count("ny")?);
        spline.u_max = field?;
        if let Some(w) = layout["smoothness"].as_f64() {
            spline.smoothness = w;
        }
        Ok(spline)
    };
    Some(read())
}

/// What a camera JSON's `image_size_px` must be.
const IMAGE_SIZE: &str = "[width, height]: two whole numbers of pixels, both > 0";

fn missing(key: &str, expected: &str) -> Error {
    Error::invalid(key, format!("the camera JSON needs {expected}"))
}

/// A model from its name (its coefficients are read from the file).
pub fn distortion_template(model: &str) -> Result<Distortion> {
    Distortion::named(model).ok_or_else(|| {
        Error::invalid(
            "model",
            format!(
                "unknown lens model '{model}' (known: {})",
                crate::camera::model_list()
            ),
        )
    })
}

pub(super) fn camera_from_k(
    k: &[f64],
    width: u32,
    height: u32,
    distortion: Distortion,
) -> Result<Camera> {
    if let Some(bad) = k.iter().find(|v| !v.is_finite()) {
        return Err(Error::invalid(
            "camera_matrix",
            format!("every entry must be a finite number, got {bad}"),
        ));
    }
    if k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || (k[8] - 1.0).abs() > 1e-12 {
        return Err(Error::invalid(
            "camera_matrix",
            "expected [fx s cx; 0 fy cy; 0 0 1]",
        ));
    }
    if !(k[0] > 0.0 && k[4] > 0.0) {
        return Err(Error::invalid(
            "camera_matrix",
            format!(
                "focal lengths must be positive, got fx {} fy {}",
                k[0], k[4]
            ),
        ));
    }
    Ok(Camera {
        fx: k[0],
        fy: k[4],
        cx: k[2],
        cy: k[5],
        skew: k[1],
        width,
        height,
        distortion,
    })
}

/// OpenCV's distortion vector to a model (`fisheye` for cv::fisheye's 4).
pub(super) fn distortion_from_opencv(d: &[f64], fisheye: bool) -> Result<Distortion> {
    let g = |i: usize| d.get(i).copied().unwrap_or(0.0);
    Ok(match (d.len(), fisheye) {
        (0, _) => Distortion::None,
        (4, true) => Distortion::KannalaBrandt {
            k1: g(0),
            k2: g(1),
            k3: g(2),
            k4: g(3),
        },
        (4 | 5, false) => Distortion::Brown {
            k1: g(0),
            k2: g(1),
            p1: g(2),
            p2: g(3),
            k3: g(4),
        },
        (8 | 12, false) => Distortion::Rational {
            k1: g(0),
            k2: g(1),
            p1: g(2),
            p2: g(3),
            k3: g(4),
            k4: g(5),
            k5: g(6),
            k6: g(7),
            s1: g(8),
            s2: g(9),
            s3: g(10),
            s4: g(11),
        },
        (14, false) => Distortion::Tilted {
            k1: g(0),
            k2: g(1),
            p1: g(2),
            p2: g(3),
            k3: g(4),
            k4: g(5),
            k5: g(6),
            k6: g(7),
            s1: g(8),
            s2: g(9),
            s3: g(10),
            s4: g(11),
            tau_x: g(12),
            tau_y: g(13),
        },
        (n, _) => {
            return Err(Error::invalid(
                "distortion_coefficients",
                format!(
                    "{n} coefficients: robocal reads 4 (fisheye or k1 k2 p1 p2), 5, 8, 12 or 14 (tilted)"
                ),
            ))
        }
    })
}

/// The numbers of the `data` list that follows the line `key:` (YAML).
fn yaml_data(text: &str, keys: &[&str]) -> Option<Vec<f64>> {
    // Offsets from the lines with their terminators (`lines()` also drops
    // "\r", so counting `len() + 1` drifts off char boundaries on CRLF text).
    let start = text.split_inclusive('\n').scan(0usize, |offset, line| {
        let here = *offset;
        *offset += line.len();
        Some((here, line))
    });
    for (offset, line) in start {
        let name = line.trim_start().split(':').next().unwrap_or("");
        if line.starts_with(' ') || !keys.contains(&name) {
            continue;
        }
        let rest = &text[offset..];
        let open = rest.find("data:")? + 5;
        let body = &rest[open..];
        let lb = body.find('[')?;
        // The first ']' after the '[' (one before it is not the list's end).
        let rb = lb + body[lb..].find(']')?;
        return body[lb + 1..rb]
            .split(',')
            .map(|s| s.trim().parse::<f64>().ok())
            .collect();
    }
    None
}

fn yaml_scalar(text: &str, key: &str) -> Option<String> {
    text.lines().find_map(|l| {
        let (k, v) = l.split_once(':')?;
        (k == key).then(|| v.trim().trim_matches('"').to_string())
    })
}

const K_NAMES: [&str; 4] = ["camera_matrix", "cameraMatrix", "K", "M1"];
const D_NAMES: [&str; 6] = [
    "distortion_coefficients",
    "dist_coeffs",
    "distCoeffs",
    "D",
    "D1",
    "distortion",
];

fn size_from(w: Option<String>, h: Option<String>) -> Result<(u32, u32)> {
    let parse = |s: Option<String>, key: &str| {
        s.and_then(|v| v.parse::<u32>().ok())
            .filter(|&v| v > 0)
            .ok_or_else(|| {
                Error::invalid(
                    key,
                    format!("the camera file has no valid {key}: robocal needs the image size"),
                )
            })
    };
    Ok((parse(w, "image_width")?, parse(h, "image_height")?))
}

/// The camera matrix's numbers, when the file had exactly 9 of them.
fn nine_numbers(k: Option<Vec<f64>>) -> Result<Vec<f64>> {
    match k {
        Some(k) if k.len() == 9 => Ok(k),
        Some(k) => Err(Error::invalid(
            "camera_matrix",
            format!(
                "the camera_matrix has {} numbers, a 3x3 matrix needs 9 (fx 0 cx 0 fy cy 0 0 1): \
                 the file is truncated or not a camera file",
                k.len()
            ),
        )),
        None => Err(Error::invalid(
            "camera_matrix",
            "the file has no camera matrix (camera_matrix or K with 9 numbers): give a robocal \
             camera JSON, an OpenCV YAML/XML calibration or a ROS camera_info YAML",
        )),
    }
}

fn from_yaml(text: &str, ros: bool) -> Result<Camera> {
    let k = nine_numbers(yaml_data(text, &K_NAMES))?;
    let d = yaml_data(text, &D_NAMES).unwrap_or_default();
    let (width, height) = size_from(
        yaml_scalar(text, "image_width"),
        yaml_scalar(text, "image_height"),
    )?;
    let fisheye = if ros {
        matches!(
            yaml_scalar(text, "distortion_model").as_deref(),
            Some("equidistant" | "fisheye")
        )
    } else {
        text.contains("cv2.fisheye") || text.contains("fisheye")
    };
    camera_from_k(&k, width, height, distortion_from_opencv(&d, fisheye)?)
}

fn xml_element<'a>(text: &'a str, name: &str) -> Option<&'a str> {
    let open = text.find(&format!("<{name}"))?;
    let body_start = open + text[open..].find('>')? + 1;
    let close = text[body_start..].find(&format!("</{name}>"))?;
    Some(&text[body_start..body_start + close])
}

fn from_xml(text: &str) -> Result<Camera> {
    let matrix = |names: &[&str]| {
        names
            .iter()
            .find_map(|n| xml_element(text, n))
            .and_then(|m| {
                xml_element(m, "data").map(|d| {
                    d.split_whitespace()
                        .map(|t| t.parse::<f64>().ok())
                        .collect::<Option<Vec<f64>>>()
                })
            })
    };
    let k = nine_numbers(matrix(&K_NAMES).flatten())?;
    let d = matrix(&D_NAMES).flatten().unwrap_or_default();
    let get = |n: &str| xml_element(text, n).map(|s| s.trim().to_string());
    let (width, height) = size_from(get("image_width"), get("image_height"))?;
    camera_from_k(
        &k,
        width,
        height,
        distortion_from_opencv(&d, text.contains("fisheye"))?,
    )
}
