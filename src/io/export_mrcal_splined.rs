//! The splined model in mrcal's terms:
//! `LENSMODEL_SPLINED_STEREOGRAPHIC_order=O_Nx=NX_Ny=NY_fov_x_deg=F`.
//!
//! mrcal projects `q = f (u + deltau(u)) + c` with `u` the stereographic
//! point, as robocal does, and its B-spline is the same uniform one (the
//! same cubic and quadratic weights, the edge cells' polynomials extended
//! beyond the grid, control values `[dx, dy]` per control point, row by
//! row from the top, after `fx fy cx cy`). Its layout differs: the knot
//! spacing is `2 u_edge / (Nx - order)` with `u_edge = 2 tan(fov_x_deg / 4)`
//! for an integer `fov_x_deg`, and the same spacing along y (`Ny` sets the
//! y extent). robocal's calibration sets its field `u_max` from the image,
//! independently along x and y, so a calibrated spline maps to mrcal
//! exactly only when both spacings are equal and `u_max[0]` is the edge of
//! an integer field of view; otherwise the export is refused (a model
//! that looks like mrcal's but projects differently is not written).

use crate::camera::Spline;
use crate::error::{Error, Result};

/// Relative tolerance of "equal" spacings and of an integer field of view.
const EXACT: f64 = 1e-9;

/// The lens model string of `spline`, or the refusal that says why mrcal
/// cannot hold it.
pub(super) fn mrcal_splined_name(spline: &Spline) -> Result<String> {
    spline.check()?;
    let p = spline.order as f64;
    let h_x = 2.0 * spline.u_max[0] / (spline.nx as f64 - p);
    let h_y = 2.0 * spline.u_max[1] / (spline.ny as f64 - p);
    let fov_x_deg = 4.0 * (0.5 * spline.u_max[0]).atan().to_degrees();
    let rounded = fov_x_deg.round();
    let refuse = |why: String| {
        Error::invalid(
            "format",
            format!(
                "the splined model cannot be written for mrcal exactly: {why}; mrcal's \
                 LENSMODEL_SPLINED_STEREOGRAPHIC spaces its knots by an integer fov_x_deg and \
                 uses one spacing along x and y, and robocal's calibration sets its knot field \
                 from the image along each axis; export it as json, or resample its images with \
                 --format remap"
            ),
        )
    };
    if (h_x - h_y).abs() > EXACT * h_x.max(h_y) {
        return Err(refuse(format!(
            "its knot spacing is {h_x:.6} along x and {h_y:.6} along y (stereographic units, \
             {}x{} control points over u_max {:.6} x {:.6})",
            spline.nx, spline.ny, spline.u_max[0], spline.u_max[1]
        )));
    }
    if !(rounded >= 1.0 && rounded <= f64::from(u16::MAX))
        || (fov_x_deg - rounded).abs() > EXACT * rounded
    {
        return Err(refuse(format!(
            "its knot field spans {fov_x_deg:.6} deg along x, not a whole number of degrees"
        )));
    }
    Ok(format!(
        "LENSMODEL_SPLINED_STEREOGRAPHIC_order={}_Nx={}_Ny={}_fov_x_deg={}",
        spline.order, spline.nx, spline.ny, rounded as u16
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Camera, Distortion};
    use crate::io::export_camera::{export_camera, CameraExportInfo, CameraFormat};

    /// A 10x8 cubic spline laid out as mrcal's `fov_x_deg=150`.
    fn mrcal_like() -> Camera {
        let mut spline = Spline::new(3, 10, 8);
        let u_edge = 2.0 * (150f64.to_radians() / 4.0).tan();
        let h = 2.0 * u_edge / 7.0;
        spline.u_max = [u_edge, 0.5 * h * 5.0];
        for (k, c) in spline.control.iter_mut().enumerate() {
            *c = 1e-3 * ((k as f64) * 0.37).sin();
        }
        Camera {
            fx: 400.0,
            fy: 401.0,
            cx: 639.5,
            cy: 479.5,
            skew: 0.0,
            width: 1280,
            height: 960,
            distortion: Distortion::Splined(spline),
        }
    }

    #[test]
    fn a_spline_on_mrcal_s_grid_is_written_with_its_configuration() {
        let camera = mrcal_like();
        let text = export_camera(&camera, &CameraExportInfo::default(), CameraFormat::Mrcal)
            .expect("written");
        assert!(
            text.contains("'LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=10_Ny=8_fov_x_deg=150'"),
            "{text}"
        );
        // fx fy cx cy, then the 160 control values in robocal's order.
        let start = text.find("'intrinsics': [ ").expect("intrinsics") + 16;
        let end = start + text[start..].find(" ]").expect("end");
        let values: Vec<f64> = text[start..end]
            .split(", ")
            .map(|v| v.parse().expect("number"))
            .collect();
        assert_eq!(values.len(), 4 + 2 * 10 * 8);
        assert_eq!(&values[..4], &[400.0, 401.0, 639.5, 479.5]);
        let Distortion::Splined(s) = &camera.distortion else {
            unreachable!()
        };
        assert_eq!(&values[4..], &s.control[..]);
    }

    #[test]
    fn a_calibrated_spline_s_own_field_is_refused_with_the_reason() {
        let camera = Camera::example_splined();
        let err = export_camera(&camera, &CameraExportInfo::default(), CameraFormat::Mrcal)
            .unwrap_err()
            .to_string();
        assert!(err.contains("cannot be written for mrcal exactly"), "{err}");
        assert!(err.contains("along x and"), "{err}");
        // Square cells over a field that is no whole number of degrees.
        let mut camera = mrcal_like();
        if let Distortion::Splined(s) = &mut camera.distortion {
            s.u_max = [s.u_max[0] * 1.001, s.u_max[1] * 1.001];
        }
        let err = export_camera(&camera, &CameraExportInfo::default(), CameraFormat::Mrcal)
            .unwrap_err()
            .to_string();
        assert!(err.contains("not a whole number of degrees"), "{err}");
    }
}
