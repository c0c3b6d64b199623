//! Calibration with the splined lens model ([`crate::camera::splined`]):
//! a parametric fit first (Kannala-Brandt, which follows narrow and fisheye
//! lenses alike), a spline fitted to reproduce it over the image, then the
//! bundle adjustment of the spline with the base projection (fx fy cx cy)
//! held at the parametric fit's (the spline's constant and linear terms
//! would otherwise trade with them), its smoothness prior keeping the
//! correction smooth where no point falls; and the report's data-support
//! mask of the knots.

use super::refine::CalibProblem;
use super::zhang::{calibrate_usable, CalibrationOptions};
use super::{CameraCalibration, View};
use crate::camera::{splined::stereographic, Camera, Distortion, Spline};
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// Image cells per side (x, y) of [`SplineSupport::image_coverage`].
const COVERAGE_GRID: (usize, usize) = (16, 12);

/// Where the data constrain a splined lens.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SplineSupport {
    /// Control points along x and y.
    pub knots: [usize; 2],
    /// Control points whose support holds at least one used point.
    pub supported: usize,
    /// `supported` over all control points.
    pub fraction: f64,
    /// Of a 16x12 grid of image cells, the fraction holding a used point.
    pub image_coverage: f64,
    /// One string per row of control points (top first): `#` where data
    /// constrain the control point, `.` where only the smoothness prior does.
    pub mask: Vec<String>,
}

/// [`super::calibrate`] for a splined model without a given camera: the
/// parametric fit, the spline that reproduces it, the spline's fit.
pub(crate) fn calibrate_splined(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
    spline: &Spline,
) -> Result<CameraCalibration> {
    let parametric = CalibrationOptions {
        model: Distortion::KannalaBrandt {
            k1: 0.0,
            k2: 0.0,
            k3: 0.0,
            k4: 0.0,
        },
        fixed_coefficients: Vec::new(),
        ..options.clone()
    };
    let first = calibrate_usable(views, image_size_px, &parametric)?;
    let start = first.camera.splined_like(spline)?;
    let refined = CalibrationOptions {
        model: start.distortion.clone(),
        initial_camera: Some(start),
        ..options.clone()
    };
    let mut report = calibrate_usable(views, image_size_px, &refined)?;
    report.options = options.clone();
    Ok(report)
}

/// The support mask of a splined `camera` fitted to the problem's used
/// points; `None` for the other models.
pub(crate) fn spline_support(problem: &CalibProblem, camera: &Camera) -> Option<SplineSupport> {
    let Distortion::Splined(s) = &camera.distortion else {
        return None;
    };
    let mut seen = vec![false; s.nx * s.ny];
    let mut cells = vec![false; COVERAGE_GRID.0 * COVERAGE_GRID.1];
    let (w, h) = (camera.width.max(1) as f64, camera.height.max(1) as f64);
    for (view, used) in problem.views.iter().zip(problem.used) {
        for (px, _) in view.image_px.iter().zip(used).filter(|(_, u)| **u) {
            let cx = ((px.x + 0.5) / w * COVERAGE_GRID.0 as f64).floor();
            let cy = ((px.y + 0.5) / h * COVERAGE_GRID.1 as f64).floor();
            if cx >= 0.0 && cy >= 0.0 {
                let (cx, cy) = (cx as usize, cy as usize);
                if cx < COVERAGE_GRID.0 && cy < COVERAGE_GRID.1 {
                    cells[cy * COVERAGE_GRID.0 + cx] = true;
                }
            }
            let Ok(ray) = camera.unproject(px) else {
                continue;
            };
            let Ok((u, _)) = stereographic(&ray) else {
                continue;
            };
            for (k, w) in s.weights(&u) {
                if w != 0.0 {
                    if let Some(v) = seen.get_mut(k) {
                        *v = true;
                    }
                }
            }
        }
    }
    let supported = seen.iter().filter(|v| **v).count();
    let mask = seen
        .chunks(s.nx)
        .map(|row| row.iter().map(|v| if *v { '#' } else { '.' }).collect())
        .collect();
    Some(SplineSupport {
        knots: [s.nx, s.ny],
        supported,
        fraction: supported as f64 / seen.len().max(1) as f64,
        image_coverage: cells.iter().filter(|v| **v).count() as f64 / cells.len() as f64,
        mask,
    })
}

/// The warning of a spline with knots no data constrain.
pub(crate) fn support_warning(support: &SplineSupport) -> Option<String> {
    let total = support.knots[0] * support.knots[1];
    (support.supported < total).then(|| {
        format!(
            "{} of the spline's {total} control points have no data in their support (the \
             points cover {:.0} % of the image): there the lens model is the smoothness \
             prior's extrapolation, trust it only where the projection uncertainty is small",
            total - support.supported,
            100.0 * support.image_coverage
        )
    })
}
