//! Reading back robocal's MATLAB script (`focalLength = [...]; ...
//! intrinsics = cameraIntrinsics(...)`, 1-based principal point,
//! `imageSize = [rows, columns]`) and its plain-text camera matrix (three
//! rows of three numbers, then `# image_size_px: W H`).

use super::import_camera::camera_from_k;
use crate::camera::{Camera, Distortion};
use crate::error::{Error, Result};

/// Whether `text` looks like a MATLAB camera script.
pub(super) fn is_matlab(text: &str) -> bool {
    text.contains("cameraIntrinsics")
        || text.contains("cameraParameters")
        || assignment(text, "focalLength").is_some()
}

/// The value text of `name = value;` and its 1-based line.
fn assignment<'a>(text: &'a str, name: &str) -> Option<(&'a str, usize)> {
    text.lines().enumerate().find_map(|(n, line)| {
        let code = line.split('%').next().unwrap_or_default();
        let (lhs, rhs) = code.split_once('=')?;
        (lhs.trim() == name).then(|| (rhs.trim().trim_end_matches(';').trim(), n + 1))
    })
}

/// The numbers of `name = [a, b, ...];` (or a scalar `name = a;`).
fn numbers(text: &str, name: &str, expected: &str) -> Result<(Vec<f64>, usize)> {
    let (value, line) = assignment(text, name).ok_or_else(|| {
        Error::parse(
            0,
            0,
            format!("the MATLAB script has no '{name} = {expected};' line"),
        )
    })?;
    let body = value.trim_start_matches('[').trim_end_matches(']');
    let values = body
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>().map_err(|_| {
                Error::parse(
                    line,
                    0,
                    format!("{name}: '{s}' is not a number (expected {expected})"),
                )
            })
        })
        .collect::<Result<Vec<f64>>>()?;
    Ok((values, line))
}

/// A camera from robocal's MATLAB script.
pub(super) fn from_matlab(text: &str) -> Result<Camera> {
    let exactly = |name: &str, expected: &str, counts: &[usize]| -> Result<Vec<f64>> {
        let (v, line) = numbers(text, name, expected)?;
        if counts.contains(&v.len()) {
            Ok(v)
        } else {
            Err(Error::parse(
                line,
                0,
                format!("{name} has {} numbers, expected {expected}", v.len()),
            ))
        }
    };
    let focal = exactly("focalLength", "[fx, fy]", &[2])?;
    let principal = exactly("principalPoint", "[cx, cy] (1-based)", &[2])?;
    let size = exactly("imageSize", "[rows, columns]", &[2])?;
    let radial = exactly("radialDistortion", "[k1, k2] or [k1, k2, k3]", &[2, 3])?;
    let tangential = exactly("tangentialDistortion", "[p1, p2]", &[2])?;
    let skew = exactly("skew", "a number", &[1])?;
    let whole = |x: f64, what: &str| {
        (x >= 1.0 && x.fract() == 0.0 && x <= u32::MAX as f64)
            .then_some(x as u32)
            .ok_or_else(|| {
                Error::invalid(
                    "imageSize",
                    format!("{what} must be a whole number of pixels > 0, got {x}"),
                )
            })
    };
    let (height, width) = (whole(size[0], "rows")?, whole(size[1], "columns")?);
    let coefficients = [
        radial[0],
        radial[1],
        radial.get(2).copied().unwrap_or(0.0),
        tangential[0],
        tangential[1],
    ];
    // MATLAB's tangential p1 p2 are OpenCV's (and Brown's).
    let distortion = if coefficients.iter().all(|c| *c == 0.0) {
        Distortion::None
    } else {
        Distortion::Brown {
            k1: coefficients[0],
            k2: coefficients[1],
            k3: coefficients[2],
            p1: coefficients[3],
            p2: coefficients[4],
        }
    };
    let k = [
        focal[0],
        skew[0],
        principal[0] - 1.0,
        0.0,
        focal[1],
        principal[1] - 1.0,
        0.0,
        0.0,
        1.0,
    ];
    camera_from_k(&k, width, height, distortion)
}

/// The comment of robocal's text matrix that gives the image size.
pub const TEXT_SIZE_COMMENT: &str = "# image_size_px:";
/// The comment of robocal's text matrix that names a lens model it left out.
pub const TEXT_MODEL_COMMENT: &str = "# lens model:";

/// The rows of numbers of a text file (comments `#`/`%` and blank lines
/// left out), each with its 1-based line; `None` if a line is not numbers.
fn number_rows(text: &str) -> Option<Vec<(Vec<f64>, usize)>> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| {
            let l = l.trim();
            !l.is_empty() && !l.starts_with('#') && !l.starts_with('%')
        })
        .map(|(n, l)| {
            l.split(|c: char| c == ',' || c == ';' || c.is_whitespace())
                .filter(|s| !s.is_empty())
                .map(|s| s.parse::<f64>().ok())
                .collect::<Option<Vec<f64>>>()
                .map(|v| (v, n + 1))
        })
        .collect()
}

/// Whether `text` is a matrix of numbers with 3 rows of 3.
pub(super) fn is_text_matrix(text: &str) -> bool {
    number_rows(text).is_some_and(|rows| rows.len() == 3 && rows.iter().all(|(r, _)| r.len() == 3))
}

/// A camera from robocal's text matrix: `fx s cx / 0 fy cy / 0 0 1`, the
/// image size from its `# image_size_px: W H` comment.
pub(super) fn from_text(text: &str) -> Result<Camera> {
    let rows = number_rows(text).unwrap_or_default();
    let k: Vec<f64> = rows.iter().flat_map(|(r, _)| r.iter().copied()).collect();
    let comment = |prefix: &str| {
        text.lines().enumerate().find_map(|(n, l)| {
            l.trim()
                .strip_prefix(prefix)
                .map(|rest| (rest.trim().to_string(), n + 1))
        })
    };
    if let Some((model, line)) = comment(TEXT_MODEL_COMMENT) {
        let name = model.split_whitespace().next().unwrap_or_default();
        if name != "none" {
            return Err(Error::parse(
                line,
                0,
                format!(
                    "this camera matrix was written from a camera with the {name} lens model, \
                     which the text format does not hold: export the camera as json (or a format \
                     that holds {name}) and read that"
                ),
            ));
        }
    }
    let Some((size, line)) = comment(TEXT_SIZE_COMMENT) else {
        return Err(Error::parse(
            0,
            0,
            format!(
                "a 3x3 camera matrix holds no image size: add the line '{TEXT_SIZE_COMMENT} \
                 WIDTH HEIGHT' (robocal's text export writes it), or give the camera as \
                 json, OpenCV or ROS YAML"
            ),
        ));
    };
    let dims: Vec<u32> = size
        .split_whitespace()
        .filter_map(|s| s.parse::<u32>().ok())
        .filter(|d| *d > 0)
        .collect();
    let [width, height] = dims[..] else {
        return Err(Error::parse(
            line,
            0,
            format!(
                "expected '{TEXT_SIZE_COMMENT} WIDTH HEIGHT' (two whole numbers > 0), got '{size}'"
            ),
        ));
    };
    camera_from_k(&k, width, height, Distortion::None)
}
