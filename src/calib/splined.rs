//! Calibration with the splined lens model ([`crate::camera::splined`]):
//! a parametric fit first (EUCM, or Kannala-Brandt where EUCM fits
//! clearly worse: a pincushion lens), a spline fitted to reproduce
//! it over the image, then the bundle adjustment of the spline with the
//! base projection (fx fy cx cy) held at the parametric fit's (the spline's
//! constant and linear terms would otherwise trade with them), its
//! smoothness prior keeping the correction smooth where no point falls;
//! and the report's data-support mask of the knots.

use super::refine::{block_from_pose, CalibProblem};
use super::zhang::{calibrate_from, calibrate_usable, CalibrationOptions};
use super::{CameraCalibration, View};
use crate::camera::{splined::stereographic, Camera, Distortion, Spline};
use crate::error::Result;
use nalgebra::DMatrix;
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
    /// The valid region over the image: one string per row of the 16x12
    /// grid of image cells (top first), `#` where a used point falls in the
    /// cell, `.` where none does (there the model is the smoothness prior's
    /// extrapolation of the cells around).
    /// Empty in reports written before the key existed.
    #[serde(default)]
    pub image_mask: Vec<String>,
}

impl SplineSupport {
    /// Whether pixel `(x, y)` of an image of `size` lies in the valid
    /// region ([`SplineSupport::image_mask`]); false without a mask.
    pub fn is_valid_px(&self, x: f64, y: f64, size: (u32, u32)) -> bool {
        let Some((cx, cy)) = coverage_cell(x, y, size) else {
            return false;
        };
        self.image_mask
            .get(cy)
            .and_then(|row| row.as_bytes().get(cx))
            .is_some_and(|c| *c == b'#')
    }
}

/// The cell of [`COVERAGE_GRID`] holding pixel `(x, y)`, if inside.
pub(crate) fn coverage_cell(x: f64, y: f64, size: (u32, u32)) -> Option<(usize, usize)> {
    let (w, h) = (size.0.max(1) as f64, size.1.max(1) as f64);
    let cx = ((x + 0.5) / w * COVERAGE_GRID.0 as f64).floor();
    let cy = ((y + 0.5) / h * COVERAGE_GRID.1 as f64).floor();
    let inside = cx >= 0.0
        && cy >= 0.0
        && (cx as usize) < COVERAGE_GRID.0
        && (cy as usize) < COVERAGE_GRID.1;
    inside.then_some((cx as usize, cy as usize))
}

/// How much larger the EUCM pre-fit's RMS may be than Kannala-Brandt's for
/// the splined fit to start from EUCM (on the bumpy lenses of BENCHMARKS 17
/// L3 the two are within 1 %; on a pincushion lens EUCM's is 12x).
const PREFIT_RMS_RATIO: f64 = 1.25;

/// [`super::calibrate`] for a splined model without a given camera: the
/// parametric fit, the spline that reproduces it, the spline's fit.
pub(crate) fn calibrate_splined(
    views: &[View],
    image_size_px: (u32, u32),
    options: &CalibrationOptions,
    spline: &Spline,
) -> Result<CameraCalibration> {
    // The start, and the lens the smoothness prior measures the spline's
    // change from: the smoother of two parametric fits when it fits about
    // as well. EUCM's two shape parameters cannot bend between the data and
    // the border; Kannala-Brandt's four-term polynomial also fits the
    // radial average of a lens's local bumps and carries that wiggle into
    // the border cells where one or two points hold the spline, and the
    // prior kept it there (noise-free bias 1.24 px vs 0.13 px through a
    // fisheye, BENCHMARKS 17 L3). EUCM cannot follow a pincushion lens
    // (rms 7.8 px vs KB's 0.63 px on one): Kannala-Brandt then.
    let prefit = |model: Distortion| {
        calibrate_usable(
            views,
            image_size_px,
            &CalibrationOptions {
                model,
                fixed_coefficients: Vec::new(),
                ..options.clone()
            },
        )
    };
    let kannala_brandt = prefit(Distortion::KannalaBrandt {
        k1: 0.0,
        k2: 0.0,
        k3: 0.0,
        k4: 0.0,
    });
    let eucm = prefit(Distortion::Eucm {
        alpha: 0.5,
        beta: 1.0,
    });
    let first = match (eucm, kannala_brandt) {
        (Ok(e), Ok(k)) if e.rms_px <= PREFIT_RMS_RATIO * k.rms_px => e,
        (_, Ok(k)) => k,
        (Ok(e), Err(_)) => e,
        (Err(_), Err(k)) => return Err(k),
    };
    let start = first.camera.splined_like(spline)?;
    // The parametric fit's poses: its rays through the points are the
    // spline's start's, so the bundle adjustment starts near its minimum
    // (from the homographies' poses it took ~160 iterations, not ~20).
    let poses = first
        .views
        .iter()
        .map(|v| v.camera_from_target.to_pose().map(|p| block_from_pose(&p)))
        .collect::<Result<Vec<_>>>()
        .ok();
    let refined = CalibrationOptions {
        model: start.distortion.clone(),
        initial_camera: Some(start),
        ..options.clone()
    };
    let mut report = calibrate_from(views, image_size_px, &refined, poses)?;
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
    let size = (camera.width, camera.height);
    for (view, used) in problem.views.iter().zip(problem.used) {
        for (px, _) in view.image_px.iter().zip(used).filter(|(_, u)| **u) {
            if let Some((cx, cy)) = coverage_cell(px.x, px.y, size) {
                cells[cy * COVERAGE_GRID.0 + cx] = true;
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
        image_mask: valid_mask(&cells),
    })
}

/// The rows of [`SplineSupport::image_mask`] from the cells holding a point.
fn valid_mask(cells: &[bool]) -> Vec<String> {
    cells
        .chunks(COVERAGE_GRID.0)
        .map(|row| row.iter().map(|v| if *v { '#' } else { '.' }).collect())
        .collect()
}

/// At one pixel: d pixel / d params (2 x parameters) and d pixel / d
/// camera rotation (2 x 3).
pub(crate) type PixelJacobians = (DMatrix<f64>, DMatrix<f64>);

/// The map `M` (3 x parameters) from a parameter change to the camera
/// rotation that best explains its projection change over the grid (least
/// squares over every grid pixel with Jacobians: `(sum R^T R)^-1 sum R^T J`,
/// `J` d pixel / d params, `R` d pixel / d rotation); `None` when the
/// rotation is not determined (fewer than two grid pixels).
pub(crate) fn implied_rotation(jacobians: &[Vec<Option<PixelJacobians>>]) -> Option<DMatrix<f64>> {
    let cells: Vec<&(DMatrix<f64>, DMatrix<f64>)> = jacobians.iter().flatten().flatten().collect();
    let n = cells.first()?.0.ncols();
    let mut rtr = DMatrix::<f64>::zeros(3, 3);
    let mut rtj = DMatrix::<f64>::zeros(3, n);
    for (j, r) in &cells {
        rtr += r.transpose() * r;
        rtj += r.transpose() * j;
    }
    let inverse = rtr.try_inverse()?;
    Some(inverse * rtj)
}

/// Share of the image in the valid region below which a splined fit draws
/// a warning even when every control point has data.
pub const VALID_REGION_ALERT: f64 = 0.9;
/// RMS residual (px) of a splined fit above which it draws a warning: far
/// above detection noise, a spline that still leaves it does not follow
/// the lens (too few knots) or fits wrong detections.
pub const SPLINED_RMS_ALERT_PX: f64 = 0.5;

/// The warnings of a splined fit: control points no data constrain (and
/// the share of the image in the valid region), and a residual far above
/// detection noise.
pub(crate) fn spline_warnings(support: &SplineSupport, rms_px: f64) -> Vec<String> {
    let mut out = Vec::new();
    let total = support.knots[0] * support.knots[1];
    if support.supported < total {
        out.push(format!(
            "{} of the spline's {total} control points have no data in their support (the \
             points cover {:.0} % of the image, the report's spline_support.image_mask): \
             there the lens model is the smoothness prior's extrapolation, trust it only \
             where the projection uncertainty is small",
            total - support.supported,
            100.0 * support.image_coverage
        ));
    } else if support.image_coverage < VALID_REGION_ALERT {
        out.push(format!(
            "the points cover {:.0} % of the image: outside the valid region (the report's \
             spline_support.image_mask) the splined model is the prior's extrapolation",
            100.0 * support.image_coverage
        ));
    }
    if rms_px > SPLINED_RMS_ALERT_PX {
        out.push(format!(
            "the splined fit leaves rms {rms_px:.3} px, far above detection noise (below \
             {SPLINED_RMS_ALERT_PX} px expected): the {}x{} knots may be too coarse for this \
             lens (raise --spline-knots) or some detections are wrong",
            support.knots[0], support.knots[1]
        ));
    }
    out
}
