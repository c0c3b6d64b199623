//! Plausibility checks of a fitted camera, and the error-level warning of a
//! fit that did not converge (issue 35, item 2).
//!
//! A converged fit can still be a wrong minimum. Three signatures are
//! checked, each a warning that says what is wrong and what to do:
//!
//! - fx / fy off 1 by more than [`ASPECT_OFF`] while a fit with square
//!   pixels reaches the same RMS (within [`SAME_FIT_RATIO`] plus
//!   [`SAME_FIT_PX`]): the views do not determine the aspect ratio;
//! - the principal point farther from the image centre than
//!   [`CENTRE_OFF_FRACTION`] of the width or height;
//! - radial distortion that folds inside the image: along the ray towards
//!   an image corner the distorted radius r_d(r) stops increasing before it
//!   reaches the corner, so points beyond the fold have two projections.
//!   A splined lens is not radial and is only the smoothness prior's
//!   extrapolation outside its valid region (the image cells holding
//!   points): its check is the determinant of the spline's local Jacobian
//!   where it maps into the valid region ([`Camera::splined_fold`]).
//!
//! The report's `severity` is the worst level of its warnings: `error` when
//! the first warning is error-level (it then begins with `error: `),
//! `warning` when there are warnings, `ok` otherwise.

use super::report::CameraCalibration;
use super::SplineSupport;
use crate::camera::{Camera, Distortion};
use nalgebra::{Point2, Point3};
use serde::{Deserialize, Serialize};

/// |fx / fy - 1| above which the aspect ratio is checked against a fit
/// with square pixels.
pub const ASPECT_OFF: f64 = 0.05;
/// Principal point offset from the image centre, as a fraction of the width
/// (x) or height (y), above which it is implausible (lenses put it within a
/// few per cent).
pub const CENTRE_OFF_FRACTION: f64 = 0.15;
/// A square-pixel fit "fits as well" at this times the RMS, plus [`SAME_FIT_PX`].
pub const SAME_FIT_RATIO: f64 = 1.05;
/// See [`SAME_FIT_RATIO`], px.
pub const SAME_FIT_PX: f64 = 0.005;
/// Ray angles sampled from the optical axis to 89.5 deg when looking for a
/// fold (0.18 deg apart); a fold found between two samples is then located
/// by a golden-section search ([`FOLD_REFINE_STEPS`]).
const FOLD_SAMPLES: usize = 500;
/// Golden-section steps that locate the peak of r_d between two samples
/// (the bracket shrinks 0.618x a step: 40 steps leave 1e-8 of 0.36 deg).
const FOLD_REFINE_STEPS: usize = 40;
/// Largest ray angle sampled, radians (89.5 deg: the perspective models end at 90).
const FOLD_MAX_ANGLE: f64 = 89.5 * std::f64::consts::PI / 180.0;
/// Prefix of an error-level warning.
pub const ERROR_PREFIX: &str = "error: ";

/// How bad the worst warning of a report is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    /// No warnings.
    #[default]
    Ok,
    /// Warnings to read; the result stands.
    Warning,
    /// The result is not a calibration (e.g. the fit did not converge);
    /// the first warning says why.
    Error,
}

impl Severity {
    /// The severity of a list of warnings (error-level ones begin with
    /// [`ERROR_PREFIX`]).
    pub fn of(warnings: &[String]) -> Severity {
        if warnings.iter().any(|w| w.starts_with(ERROR_PREFIX)) {
            Severity::Error
        } else if warnings.is_empty() {
            Severity::Ok
        } else {
            Severity::Warning
        }
    }
}

impl CameraCalibration {
    /// Set `severity` from the warnings, with error-level ones moved first:
    /// call after adding warnings.
    pub fn refresh_severity(&mut self) {
        let (mut errors, rest): (Vec<String>, Vec<String>) = std::mem::take(&mut self.warnings)
            .into_iter()
            .partition(|w| w.starts_with(ERROR_PREFIX));
        errors.extend(rest);
        self.warnings = errors;
        self.severity = Severity::of(&self.warnings);
    }
}

/// The principal point's offset from the image centre (px), when it is
/// beyond [`CENTRE_OFF_FRACTION`] of the width or the height.
pub fn principal_point_off(camera: &Camera) -> Option<(f64, f64)> {
    let (w, h) = (camera.width as f64, camera.height as f64);
    let (dx, dy) = (camera.cx - 0.5 * (w - 1.0), camera.cy - 0.5 * (h - 1.0));
    (dx.abs() > CENTRE_OFF_FRACTION * w || dy.abs() > CENTRE_OFF_FRACTION * h).then_some((dx, dy))
}

/// Whether fx / fy is off 1 by more than [`ASPECT_OFF`].
pub fn aspect_off(camera: &Camera) -> bool {
    (camera.fx / camera.fy - 1.0).abs() > ASPECT_OFF
}

/// Where the distortion folds inside the image: `(fold radius, corner
/// radius)` in px from the principal point, along the ray towards the
/// image corner where the fold is nearest; `None` when r_d(r) increases
/// all the way to every corner.
pub fn distortion_fold(camera: &Camera) -> Option<(f64, f64)> {
    let (w, h) = (camera.width as f64 - 0.5, camera.height as f64 - 0.5);
    let corners = [(-0.5, -0.5), (w, -0.5), (-0.5, h), (w, h)];
    let centre = Point2::new(camera.cx, camera.cy);
    let mut worst: Option<(f64, f64)> = None;
    for (u, v) in corners {
        let corner = Point2::new(u, v);
        let corner_r = (corner - centre).norm();
        // The ray's direction around the axis, from the pinhole part alone.
        let ny = (v - camera.cy) / camera.fy;
        let nx = (u - camera.cx - camera.skew * ny) / camera.fx;
        let theta = ny.atan2(nx);
        // The distorted radius (px) of the ray `phi` off the axis; NaN where
        // the model refuses the ray (the polynomial models refuse rays
        // beyond their first fold: a refusal before the corner is a fold
        // inside the image).
        let radius = |phi: f64| {
            let ray = Point3::new(phi.sin() * theta.cos(), phi.sin() * theta.sin(), phi.cos());
            camera
                .project(&ray)
                .map_or(f64::NAN, |p| (p - centre).norm())
        };
        let step = FOLD_MAX_ANGLE / FOLD_SAMPLES as f64;
        let mut last = 0.0;
        for i in 1..=FOLD_SAMPLES {
            if last >= corner_r {
                break;
            }
            let r = radius(step * i as f64);
            if r.is_nan() || r < last {
                // r_d rose up to sample i - 1 and fell (or ended) by sample
                // i: its peak lies between samples i - 2 and i.
                let fold = peak(
                    &radius,
                    step * (i as f64 - 2.0).max(0.0),
                    step * i as f64,
                    last,
                );
                if worst.map_or(true, |(f, _)| fold < f) {
                    worst = Some((fold, corner_r));
                }
                break;
            }
            last = r;
        }
    }
    worst
}

/// The largest value of `f` on `[lo, hi]` by golden-section search, for a
/// function that rises to one peak and then falls or ends (NaN counts as
/// lower than everything); `known` is a value already seen in the bracket.
fn peak(f: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, known: f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let higher = |a: f64, b: f64| a > b || (b.is_nan() && !a.is_nan());
    let (mut c, mut d) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut fc, mut fd) = (f(c), f(d));
    let mut best = known;
    for _ in 0..FOLD_REFINE_STEPS {
        best = [fc, fd]
            .into_iter()
            .filter(|v| !v.is_nan())
            .fold(best, f64::max);
        if higher(fd, fc) {
            lo = c;
            (c, fc) = (d, fd);
            d = lo + g * (hi - lo);
            fd = f(d);
        } else {
            hi = d;
            (d, fd) = (c, fc);
            c = hi - g * (hi - lo);
            fc = f(c);
        }
    }
    [fc, fd]
        .into_iter()
        .filter(|v| !v.is_nan())
        .fold(best, f64::max)
}

/// A fold of the lens model: radial for the parametric models, local for
/// the splined one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fold {
    /// [`distortion_fold`]: the fold's and the corner's radius, px.
    Radial {
        /// Distance of the fold from the principal point, px.
        fold_px: f64,
        /// Distance of the image corner beyond it, px.
        corner_px: f64,
    },
    /// [`Camera::splined_fold`]: the pixel where the spline's local
    /// Jacobian turns over most, and its determinant there.
    Splined {
        /// The pixel, px.
        at_px: [f64; 2],
        /// Determinant of d m / d u there (not positive).
        determinant: f64,
    },
}

/// Where `camera` folds where its projection matters: the radial check over
/// the image for the parametric models; for a splined one its local
/// Jacobian over `support`'s valid region (the whole image without one).
pub fn fold(camera: &Camera, support: Option<&SplineSupport>) -> Option<Fold> {
    let size = (camera.width, camera.height);
    match &camera.distortion {
        Distortion::Splined(_) => camera
            .splined_fold(|p| support.map_or(true, |s| s.is_valid_px(p.x, p.y, size)))
            .map(|(at, determinant)| Fold::Splined {
                at_px: [at.x, at.y],
                determinant,
            }),
        _ => {
            distortion_fold(camera).map(|(fold_px, corner_px)| Fold::Radial { fold_px, corner_px })
        }
    }
}

/// Whether a camera shows a signature of a wrong minimum (principal point
/// far off, fx / fy far from 1, distortion folding inside the image):
/// reason enough to try the other starts.
pub fn implausible(camera: &Camera) -> bool {
    principal_point_off(camera).is_some() || aspect_off(camera) || fold(camera, None).is_some()
}

/// The warnings of the checks on `camera`; `square_fit` is the RMS (px) of
/// a fit with square pixels when fx / fy is off ([`aspect_off`]), `rms_px`
/// the report's; `support` a splined fit's valid region (the fold check's
/// domain, see [`fold`]).
pub fn warnings(
    camera: &Camera,
    rms_px: f64,
    square_fit: Option<f64>,
    support: Option<&SplineSupport>,
) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(square) = square_fit {
        if square <= SAME_FIT_RATIO * rms_px + SAME_FIT_PX {
            out.push(format!(
                "fx / fy is {:.3} (fx {:.1} px, fy {:.1} px), yet a fit with square pixels \
                 reaches {square:.3} px against {rms_px:.3} px: the views do not determine the \
                 aspect ratio and the fit is likely a wrong minimum: hold square pixels (CLI: \
                 --aspect-ratio 1) or add views tilted about both axes",
                camera.fx / camera.fy,
                camera.fx,
                camera.fy
            ));
        }
    }
    if let Some((dx, dy)) = principal_point_off(camera) {
        out.push(format!(
            "the principal point ({:.1}, {:.1}) px is {dx:.0} px, {dy:.0} px from the image \
             centre ({:.1}, {:.1}) ({:.0} % of the width, {:.0} % of the height; lenses put it \
             within a few per cent): the fit is likely a wrong minimum or the views do not \
             determine it: add views that fill the image and tilt the board, or hold it at \
             the centre (CLI: --fix-principal-point)",
            camera.cx,
            camera.cy,
            0.5 * (camera.width as f64 - 1.0),
            0.5 * (camera.height as f64 - 1.0),
            100.0 * dx.abs() / camera.width as f64,
            100.0 * dy.abs() / camera.height as f64,
        ));
    }
    match fold(camera, support) {
        Some(Fold::Radial { fold_px, corner_px }) => out.push(format!(
            "the lens distortion folds inside the image: the distorted radius stops increasing \
             {fold_px:.0} px from the principal point, while the image corner is {corner_px:.0} px \
             away, so points beyond the fold have two projections: the distortion is \
             extrapolated beyond the target's points or the fit is a wrong minimum: add views \
             with the target in the image corners, or hold coefficients (CLI: --fix k3)"
        )),
        Some(Fold::Splined { at_px, determinant }) => out.push(format!(
            "the splined lens model folds inside its valid region: at pixel ({:.0}, {:.0}) \
             the determinant of the spline's local Jacobian is {determinant:.3} (a lens keeps \
             it positive), so rays on both sides of the fold share pixels: the spline follows \
             wrong detections or has more knots than the data there hold: check the \
             detections near that pixel, or lower --spline-knots",
            at_px[0], at_px[1]
        )),
        None => {}
    }
    out
}

/// The error-level warning of a fit that did not converge from any start.
pub fn not_converged(iterations: usize, rms_px: f64, starts: &[String]) -> String {
    format!(
        "{ERROR_PREFIX}the fit did not converge: from the best of {} ({}) the solver stopped at \
         its iteration limit ({iterations} iterations) at {rms_px:.3} px; these parameters are \
         not a calibration: add views that fill the image and tilt the board 20-45 deg, or \
         hold parameters (--fix-principal-point, --aspect-ratio 1, --fix k3)",
        match starts.len() {
            1 => "1 start".to_string(),
            n => format!("{n} starts"),
        },
        starts.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Distortion;

    fn webcam(k1: f64) -> Camera {
        Camera {
            fx: 910.0,
            fy: 910.0,
            cx: 639.5,
            cy: 359.5,
            skew: 0.0,
            width: 1280,
            height: 720,
            distortion: Distortion::Brown {
                k1,
                k2: 0.0,
                k3: 0.0,
                p1: 0.0,
                p2: 0.0,
            },
        }
    }

    /// r_d = r (1 + k1 r^2) peaks at r = 1 / sqrt(-3 k1): for k1 = -0.4 at
    /// r_d = 0.60858, 553.8 px at fx 910, inside the 734 px of the corner.
    /// Tolerance 1e-6 px: the peak is located by a golden-section search.
    #[test]
    fn a_fold_inside_the_image_is_found_where_r_d_peaks() {
        let (fold, corner) = distortion_fold(&webcam(-0.4)).expect("a fold");
        let r = 1.0 / (1.2f64).sqrt();
        let want = 910.0 * r * (1.0 - 0.4 * r * r);
        assert!((fold - want).abs() < 1e-6, "fold {fold} px, want {want} px");
        assert!(
            (corner - 640.0f64.hypot(360.0)).abs() < 1e-9,
            "corner {corner} px"
        );
        assert_eq!(distortion_fold(&webcam(-0.1)), None);
        assert_eq!(distortion_fold(&webcam(0.2)), None);
        let w = warnings(&webcam(-0.4), 0.2, None, None);
        assert_eq!(w.len(), 1);
        assert!(w[0].starts_with("the lens distortion folds inside the image: the distorted radius stops increasing 554 px"), "{}", w[0]);
    }

    #[test]
    fn an_off_centre_principal_point_and_non_square_pixels_are_named() {
        let c = Camera {
            fx: 733.0,
            fy: 967.0,
            cx: 268.0,
            ..webcam(0.0)
        };
        assert!(implausible(&c));
        let w = warnings(&c, 0.319, Some(0.156), None);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w[0].starts_with("fx / fy is 0.758 (fx 733.0 px, fy 967.0 px), yet a fit with square pixels reaches 0.156 px against 0.319 px"), "{}", w[0]);
        assert!(w[1].starts_with("the principal point (268.0, 359.5) px is -372 px, 0 px from the image centre (639.5, 359.5) (29 % of the width, 0 % of the height"), "{}", w[1]);
        assert!(!implausible(&webcam(-0.1)));
        assert_eq!(Severity::of(&w), Severity::Warning);
        assert_eq!(
            Severity::of(&[not_converged(400, 0.3, &["tsai".into()])]),
            Severity::Error
        );
        assert_eq!(Severity::of(&[]), Severity::Ok);
    }
}
