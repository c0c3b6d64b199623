//! Reading back the cameras of other tools' own formats, as
//! [`super::export_camera_tools`] writes them and as those tools write
//! them: a Kalibr camchain (the first camera, `cam0`, unless asked for
//! another) and an mrcal `.cameramodel`.

use crate::camera::{Camera, Distortion};
use crate::error::{Error, Result};

/// Whether `text` looks like a Kalibr camchain (a `camN:` block with
/// `camera_model`, `intrinsics` and `resolution`).
pub(super) fn is_kalibr(text: &str) -> bool {
    text.lines().any(|l| camera_block_name(l).is_some())
        && text.contains("camera_model:")
        && text.contains("intrinsics:")
        && text.contains("resolution:")
}

/// Whether `text` looks like an mrcal `.cameramodel` (a Python-style dict
/// with a `lensmodel` key).
pub(super) fn is_mrcal(text: &str) -> bool {
    text.contains("'lensmodel'") || text.contains("\"lensmodel\"")
}

/// `cam3` of a line `cam3:` (unindented), else `None`.
fn camera_block_name(line: &str) -> Option<&str> {
    let name = line
        .strip_suffix(':')
        .or_else(|| line.trim_end().strip_suffix(':'))?;
    let digits = name.strip_prefix("cam")?;
    (!digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit())).then_some(name)
}

/// The first camera of a Kalibr camchain: `camera_model` pinhole (with
/// `distortion_model` none, radtan or equidistant) or eucm, `intrinsics`,
/// `distortion_coeffs` and `resolution`.
pub(super) fn from_kalibr(text: &str) -> Result<Camera> {
    let mut lines = text
        .lines()
        .enumerate()
        .skip_while(|(_, l)| camera_block_name(l).is_none());
    let Some((_, first)) = lines.next() else {
        return Err(Error::invalid(
            "kalibr",
            "the camchain has no camera block (cam0:)",
        ));
    };
    let name = camera_block_name(first).unwrap_or("cam0").to_string();
    // The block: its indented lines (flow lists may span lines).
    let block: String = lines
        .take_while(|(_, l)| l.is_empty() || l.starts_with(' ') || l.starts_with('\t'))
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    let at = |what: &str| format!("{name}.{what}");
    let scalar = |key: &str| -> Option<String> {
        block.lines().find_map(|l| {
            let (k, v) = l.trim().split_once(':')?;
            (k.trim() == key).then(|| v.split('#').next().unwrap_or_default().trim().to_string())
        })
    };
    let numbers = |key: &str| -> Result<Option<Vec<f64>>> {
        let Some(start) = block.find(&format!("{key}:")) else {
            return Ok(None);
        };
        let rest = &block[start + key.len() + 1..];
        let (Some(open), Some(close)) = (rest.find('['), rest.find(']')) else {
            return Err(Error::invalid(at(key), "expected a list [a, b, ...]"));
        };
        if close < open {
            return Err(Error::invalid(at(key), "expected a list [a, b, ...]"));
        }
        let body = &rest[open + 1..close];
        if body.trim().is_empty() {
            return Ok(Some(Vec::new()));
        }
        body.split(',')
            .map(|s| {
                s.trim()
                    .parse::<f64>()
                    .map_err(|_| Error::invalid(at(key), format!("'{}' is not a number", s.trim())))
            })
            .collect::<Result<Vec<f64>>>()
            .map(Some)
    };
    let model = scalar("camera_model").unwrap_or_else(|| "pinhole".into());
    let intrinsics = numbers("intrinsics")?
        .ok_or_else(|| Error::invalid(at("intrinsics"), "the camera has no intrinsics list"))?;
    let resolution = numbers("resolution")?.ok_or_else(|| {
        Error::invalid(
            at("resolution"),
            "the camera has no resolution [width, height]",
        )
    })?;
    let size = |v: f64| (v >= 1.0 && v.fract() == 0.0 && v <= u32::MAX as f64).then_some(v as u32);
    let (Some(width), Some(height)) = (
        resolution.first().copied().and_then(size),
        resolution.get(1).copied().and_then(size),
    ) else {
        return Err(Error::invalid(
            at("resolution"),
            "expected [width, height]: two whole numbers of pixels",
        ));
    };
    let coeffs = numbers("distortion_coeffs")?.unwrap_or_default();
    let distortion_model = scalar("distortion_model").unwrap_or_else(|| "none".into());
    let (pinhole, distortion) = match (model.as_str(), distortion_model.as_str(), coeffs.len()) {
        ("pinhole", "none", _) => (&intrinsics[..], Distortion::None),
        ("pinhole", "radtan", 4) => (
            &intrinsics[..],
            Distortion::Brown {
                k1: coeffs[0],
                k2: coeffs[1],
                p1: coeffs[2],
                p2: coeffs[3],
                k3: 0.0,
            },
        ),
        ("pinhole", "equidistant", 4) => (
            &intrinsics[..],
            Distortion::KannalaBrandt {
                k1: coeffs[0],
                k2: coeffs[1],
                k3: coeffs[2],
                k4: coeffs[3],
            },
        ),
        ("eucm", "none", _) if intrinsics.len() == 6 => (
            &intrinsics[2..],
            Distortion::Eucm {
                alpha: intrinsics[0],
                beta: intrinsics[1],
            },
        ),
        ("pinhole", "radtan" | "equidistant", n) => {
            return Err(Error::invalid(
                at("distortion_coeffs"),
                format!("the {distortion_model} model has 4 coefficients, the file gives {n}"),
            ))
        }
        _ => {
            return Err(Error::invalid(
                at("camera_model"),
                format!(
                    "Kalibr's {model} camera with {distortion_model} distortion has no robocal \
                     model: robocal reads pinhole with none, radtan or equidistant, and eucm"
                ),
            ))
        }
    };
    let [fx, fy, cx, cy] = pinhole else {
        return Err(Error::invalid(
            at("intrinsics"),
            format!(
                "expected [fu, fv, pu, pv] for {model} (eucm: [alpha, beta, fu, fv, pu, pv]), got {} numbers",
                intrinsics.len()
            ),
        ));
    };
    let camera = Camera {
        fx: *fx,
        fy: *fy,
        cx: *cx,
        cy: *cy,
        skew: 0.0,
        width,
        height,
        distortion,
    };
    checked(camera, "kalibr")
}

/// An mrcal `.cameramodel`: `lensmodel` (PINHOLE, OPENCV4, OPENCV5, OPENCV8
/// or OPENCV12), `intrinsics` (fx fy cx cy, then the coefficients in
/// OpenCV's order) and `imagersize`. Comments (`#` to the end of a line)
/// are left out; the extrinsics are not read.
pub(super) fn from_mrcal(text: &str) -> Result<Camera> {
    let code: String = text
        .lines()
        .map(|l| match l.find('#') {
            Some(i) if !l[..i].contains('\'') && !l[..i].contains('"') => &l[..i],
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n");
    let value_of = |key: &str| -> Option<&str> {
        let at = code
            .find(&format!("'{key}'"))
            .or_else(|| code.find(&format!("\"{key}\"")))?;
        let rest = &code[at + key.len() + 2..];
        Some(rest.trim_start().strip_prefix(':')?.trim_start())
    };
    let list = |key: &str| -> Result<Vec<f64>> {
        let rest = value_of(key)
            .ok_or_else(|| Error::invalid(format!("mrcal.{key}"), "the model has no such list"))?;
        let body = rest
            .strip_prefix('[')
            .and_then(|r| r.split_once(']'))
            .map(|(b, _)| b)
            .ok_or_else(|| {
                Error::invalid(format!("mrcal.{key}"), "expected a list [ a, b, ... ]")
            })?;
        body.split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(|s| {
                s.parse::<f64>().map_err(|_| {
                    Error::invalid(format!("mrcal.{key}"), format!("'{s}' is not a number"))
                })
            })
            .collect()
    };
    let lensmodel = value_of("lensmodel")
        .and_then(|r| {
            let quote = r.chars().next().filter(|c| *c == '\'' || *c == '"')?;
            r[1..].split(quote).next()
        })
        .ok_or_else(|| Error::invalid("mrcal.lensmodel", "expected a quoted model name"))?
        .to_string();
    let intrinsics = list("intrinsics")?;
    let size = list("imagersize")?;
    let whole = |v: f64| (v >= 1.0 && v.fract() == 0.0 && v <= u32::MAX as f64).then_some(v as u32);
    let (Some(width), Some(height), 2) = (
        size.first().copied().and_then(whole),
        size.get(1).copied().and_then(whole),
        size.len(),
    ) else {
        return Err(Error::invalid(
            "mrcal.imagersize",
            "expected [ width, height ]: two whole numbers of pixels",
        ));
    };
    let want = match lensmodel.as_str() {
        "LENSMODEL_PINHOLE" => 0,
        "LENSMODEL_OPENCV4" => 4,
        "LENSMODEL_OPENCV5" => 5,
        "LENSMODEL_OPENCV8" => 8,
        "LENSMODEL_OPENCV12" => 12,
        other => {
            return Err(Error::invalid(
                "mrcal.lensmodel",
                format!(
                    "{other} has no robocal model: robocal reads LENSMODEL_PINHOLE and \
                     LENSMODEL_OPENCV4, 5, 8 and 12"
                ),
            ))
        }
    };
    if intrinsics.len() != 4 + want {
        return Err(Error::invalid(
            "mrcal.intrinsics",
            format!(
                "{lensmodel} has {} intrinsics (fx fy cx cy and {want} coefficients), the file gives {}",
                4 + want,
                intrinsics.len()
            ),
        ));
    }
    // mrcal's OPENCVn coefficients are OpenCV's, in OpenCV's order.
    let distortion = super::import_camera::distortion_from_opencv(&intrinsics[4..], false)?;
    let camera = Camera {
        fx: intrinsics[0],
        fy: intrinsics[1],
        cx: intrinsics[2],
        cy: intrinsics[3],
        skew: 0.0,
        width,
        height,
        distortion,
    };
    checked(camera, "mrcal")
}

/// The camera when its numbers are finite and its focal lengths positive.
fn checked(camera: Camera, what: &str) -> Result<Camera> {
    let numbers = [camera.fx, camera.fy, camera.cx, camera.cy]
        .into_iter()
        .chain(camera.distortion.coefficients());
    if numbers.into_iter().any(|v| !v.is_finite()) {
        return Err(Error::invalid(what, "the camera's numbers must be finite"));
    }
    if camera.fx <= 0.0 || camera.fy <= 0.0 {
        return Err(Error::invalid(
            what,
            format!(
                "focal lengths must be positive, got fx {} fy {}",
                camera.fx, camera.fy
            ),
        ));
    }
    Ok(camera)
}
