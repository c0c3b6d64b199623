//! Camera exports for other tools' own formats: Kalibr camchain, mrcal
//! `.cameramodel`, Halcon camera parameters, MATLAB (1-based) and a plain
//! 3x3 text matrix. The dispatch and the OpenCV/ROS/JSON writers are in
//! [`super::export_camera`].

use super::export_camera::{
    float, k_row_major, list, unsupported, unsupported_listing, CameraExportInfo,
};
use super::import_camera_halcon::{undistorting_polynomial, FITTED_MARK, HALCON_EXPORT_MAX_PX};
use crate::camera::{Camera, Distortion};
use crate::error::{Error, Result};

/// What Kalibr can express, for the error on any other lens model.
pub(super) const KALIBR_MODELS: &str = "none, brown with k3 = 0 (radtan), radial_k1_k2_k5 with k5 = 0 (radtan), kannala_brandt (equidistant), eucm";

pub(super) fn kalibr(c: &Camera, info: &CameraExportInfo) -> Result<String> {
    Ok(format!("cam0:\n{}", kalibr_camera(c, &info.name)?))
}

/// The lines of one camera in a Kalibr camchain (indented two spaces),
/// its images on `/<name>/image_raw`; no `T_cn_cnm1` (the rig export adds it).
pub(super) fn kalibr_camera(c: &Camera, name: &str) -> Result<String> {
    if c.skew != 0.0 {
        return Err(Error::invalid(
            "format",
            "Kalibr has no skew: calibrate with zero skew to export to Kalibr",
        ));
    }
    let (camera_model, mut intrinsics, distortion_model, coeffs) = match c.distortion {
        Distortion::None => ("pinhole", vec![], "none", vec![]),
        Distortion::Brown {
            k1,
            k2,
            k3: 0.0,
            p1,
            p2,
        } => ("pinhole", vec![], "radtan", vec![k1, k2, p1, p2]),
        Distortion::RadialK1K2K5 { k1, k2, k5: 0.0 } => {
            ("pinhole", vec![], "radtan", vec![k1, k2, 0.0, 0.0])
        }
        Distortion::KannalaBrandt { k1, k2, k3, k4 } => {
            ("pinhole", vec![], "equidistant", vec![k1, k2, k3, k4])
        }
        Distortion::Eucm { alpha, beta } => ("eucm", vec![alpha, beta], "none", vec![]),
        Distortion::Brown { .. } | Distortion::RadialK1K2K5 { .. } => {
            return Err(Error::invalid(
                "format",
                "Kalibr's radtan model has no k3: calibrate with k3 fixed at 0 to export to Kalibr",
            ))
        }
        Distortion::Rational { .. } | Distortion::Division { .. } | Distortion::Splined(_) => {
            return Err(unsupported(
                c,
                &format!("Kalibr (it takes {KALIBR_MODELS})"),
            ))
        }
        Distortion::Tilted { .. } => return Err(unsupported_listing(c, "Kalibr")),
    };
    intrinsics.extend([c.fx, c.fy, c.cx, c.cy]);
    let mut out = format!(
        "  camera_model: {camera_model}\n  intrinsics: [{}]\n",
        list(&intrinsics)
    );
    out += &format!(
        "  distortion_model: {distortion_model}\n  distortion_coeffs: [{}]\n",
        list(&coeffs)
    );
    out += &format!(
        "  resolution: [{}, {}]\n  rostopic: {}\n",
        c.width,
        c.height,
        super::export::yaml_scalar(&format!("/{name}/image_raw"))
    );
    Ok(out)
}

pub(super) fn mrcal(c: &Camera) -> Result<String> {
    mrcal_model(c, None)
}

/// A `.cameramodel`; with `rt_cam_ref` (rotation vector then translation,
/// metres: `p_cam = R p_ref + t`, mrcal's convention) its `extrinsics`.
pub(super) fn mrcal_model(c: &Camera, rt_cam_ref: Option<[f64; 6]>) -> Result<String> {
    if c.skew != 0.0 {
        return Err(Error::invalid(
            "format",
            "mrcal has no skew: calibrate with zero skew to export to mrcal",
        ));
    }
    let (lensmodel, coeffs) = match &c.distortion {
        Distortion::None => ("LENSMODEL_PINHOLE".to_string(), vec![]),
        Distortion::Brown { k1, k2, k3, p1, p2 } => (
            "LENSMODEL_OPENCV5".to_string(),
            vec![*k1, *k2, *p1, *p2, *k3],
        ),
        Distortion::RadialK1K2K5 { k1, k2, k5 } => (
            "LENSMODEL_OPENCV5".to_string(),
            vec![*k1, *k2, 0.0, 0.0, *k5],
        ),
        Distortion::Rational { .. } => {
            let v = c.distortion.coefficients();
            if v[8..].iter().any(|s| *s != 0.0) {
                ("LENSMODEL_OPENCV12".to_string(), v)
            } else {
                ("LENSMODEL_OPENCV8".to_string(), v[..8].to_vec())
            }
        }
        // Written only when its knots sit on mrcal's grid (see the module).
        Distortion::Splined(s) => (
            super::export_mrcal_splined::mrcal_splined_name(s)?,
            s.control.clone(),
        ),
        Distortion::KannalaBrandt { .. }
        | Distortion::Division { .. }
        | Distortion::Eucm { .. } => {
            return Err(unsupported(c, "mrcal (it has no equivalent model)"))
        }
        Distortion::Tilted { .. } => return Err(unsupported_listing(c, "mrcal")),
    };
    let mut intrinsics = vec![c.fx, c.fy, c.cx, c.cy];
    intrinsics.extend(coeffs);
    let extrinsics = rt_cam_ref
        .map(|rt| format!("    'extrinsics': [ {} ],\n", list(&rt)))
        .unwrap_or_default();
    Ok(format!(
        "# generated by robocal {}\n{{\n    'lensmodel':  '{lensmodel}',\n    'intrinsics': [ {} ],\n{extrinsics}    'imagersize': [ {}, {} ],\n}}\n",
        crate::VERSION,
        list(&intrinsics),
        c.width,
        c.height
    ))
}

pub(super) fn halcon(c: &Camera, info: &CameraExportInfo) -> Result<String> {
    if c.skew != 0.0 {
        return Err(Error::invalid(
            "format",
            "Halcon area-scan cameras have no skew: calibrate with zero skew",
        ));
    }
    let sx = info.pixel_size_m;
    let focus = c.fx * sx;
    let sy = focus / c.fy;
    let f2 = focus * focus;
    // HALCON's polynomial maps distorted to undistorted image-plane points,
    // Brown's the other way: the coefficients are fitted, not copied.
    let mut fit_note = String::new();
    let (kind, distortion) = match c.distortion {
        Distortion::None => ("area_scan_division", vec![0.0]),
        Distortion::Division { kappa } => ("area_scan_division", vec![kappa / f2]),
        Distortion::Brown { .. } | Distortion::RadialK1K2K5 { .. } => {
            let ([a1, a2, a3, q1, q2], worst_px) = undistorting_polynomial(c)?;
            if !(worst_px <= HALCON_EXPORT_MAX_PX) {
                return Err(Error::invalid(
                    "format",
                    format!(
                        "HALCON's area_scan_polynomial maps distorted to undistorted points; the \
                         nearest one to this {} model is off by {worst_px:.3} px in this image, \
                         more than {HALCON_EXPORT_MAX_PX} px: calibrate with --model division \
                         for HALCON, or export another format",
                        c.distortion.model_name()
                    ),
                ));
            }
            fit_note = format!(
                "* area_scan_polynomial {FITTED_MARK} image-plane points (HALCON's convention): \
                 fitted to robocal's {} model over the image, worst {} px.\n",
                c.distortion.model_name(),
                float((worst_px * 1e4).ceil() / 1e4)
            );
            (
                "area_scan_polynomial",
                vec![
                    a1 / f2,
                    a2 / (f2 * f2),
                    a3 / (f2 * f2 * f2),
                    q1 / focus,
                    q2 / focus,
                ],
            )
        }
        Distortion::Rational { .. }
        | Distortion::KannalaBrandt { .. }
        | Distortion::Eucm { .. }
        | Distortion::Splined(_) => return Err(unsupported(c, "Halcon area-scan parameters")),
        Distortion::Tilted { .. } => {
            return Err(unsupported_listing(
                c,
                "Halcon area-scan parameters (robocal writes no area_scan_tilt)",
            ))
        }
    };
    let mut values = vec![focus];
    values.extend(distortion);
    values.extend([sx, sy, c.cx, c.cy]);
    let names = if kind == "area_scan_division" {
        "Focus [m], Kappa [1/m^2], Sx [m], Sy [m], Cx [px], Cy [px], ImageWidth, ImageHeight"
    } else {
        "Focus [m], K1, K2, K3, P1, P2, Sx [m], Sy [m], Cx [px], Cy [px], ImageWidth, ImageHeight"
    };
    Ok(format!(
        "* robocal {}: Halcon camera parameters ({names}).\n* Sx is a nominal pixel size of {} m: only Focus/Sx is calibrated.\n{fit_note}CameraParam := ['{kind}', {}, {}, {}]\n",
        crate::VERSION,
        float(sx),
        list(&values),
        c.width,
        c.height
    ))
}

pub(super) fn matlab(c: &Camera) -> Result<String> {
    let (radial, tangential) = match c.distortion {
        Distortion::None => (vec![0.0, 0.0], vec![0.0, 0.0]),
        Distortion::Brown { k1, k2, k3, p1, p2 } => (vec![k1, k2, k3], vec![p1, p2]),
        Distortion::RadialK1K2K5 { k1, k2, k5 } => (vec![k1, k2, k5], vec![0.0, 0.0]),
        Distortion::Rational { .. }
        | Distortion::Division { .. }
        | Distortion::KannalaBrandt { .. }
        | Distortion::Eucm { .. }
        | Distortion::Splined(_) => return Err(unsupported(c, "MATLAB cameraIntrinsics")),
        Distortion::Tilted { .. } => return Err(unsupported_listing(c, "MATLAB cameraIntrinsics")),
    };
    Ok(format!(
        "% robocal {}: MATLAB conventions (1-based pixels: principal point = robocal's + 1)\n\
focalLength = [{}, {}];\nprincipalPoint = [{}, {}];\nimageSize = [{}, {}];\n\
radialDistortion = [{}];\ntangentialDistortion = [{}];\nskew = {};\n\
intrinsics = cameraIntrinsics(focalLength, principalPoint, imageSize, ...\n    'RadialDistortion', radialDistortion, 'TangentialDistortion', tangentialDistortion, 'Skew', skew);\n",
        crate::VERSION,
        float(c.fx),
        float(c.fy),
        float(c.cx + 1.0),
        float(c.cy + 1.0),
        c.height,
        c.width,
        list(&radial),
        list(&tangential),
        float(c.skew)
    ))
}

/// The 3x3 camera matrix, then the image size as a comment (what reads it
/// back needs it; `numpy.loadtxt` skips it) and, for a camera with a lens
/// model, a comment saying the model was left out (the reader refuses it).
pub(super) fn text3x3(c: &Camera) -> String {
    let k = k_row_major(c);
    let mut out: String = k
        .chunks(3)
        .map(|row| row.iter().map(|v| float(*v)).collect::<Vec<_>>().join(" ") + "\n")
        .collect();
    out += &format!(
        "{} {} {}\n",
        super::import_camera_matlab::TEXT_SIZE_COMMENT,
        c.width,
        c.height
    );
    if c.distortion != Distortion::None {
        out += &format!(
            "{} {} (not written: this file holds the camera matrix only)\n",
            super::import_camera_matlab::TEXT_MODEL_COMMENT,
            c.distortion.model_name()
        );
    }
    out
}
