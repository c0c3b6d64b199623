//! The JSON boundary of camera calibration, shared by the wasm function
//! `calibrate_camera` and `robocal intrinsics`.
//!
//! Input:
//!
//! ```json
//! {"model": "brown", "method": "zhang",
//!  "options": {"fix_principal_point": false, "fix_aspect_ratio": false, "aspect_ratio": null,
//!              "zero_skew": true, "robust": false, "fixed_coefficients": []},
//!  "views": [{"name": "left01.jpg", "detection": {"image_size_px": [640, 480], "target": {...}, "points": [...]}},
//!            {"name": "rig", "object_m": [[0, 0, 0], ...], "image_px": [[320.5, 240.1], ...]}],
//!  "image_size_px": [640, 480]}
//! ```
//!
//! `model` ([`LensModel`]) and `method` ([`MethodChoice`]) are read by serde
//! as choices: an unknown name is an error naming the known ones.
//! `model` is one of `brown` (default), `radial_k1_k2_k5`, `rational`,
//! `division`, `kannala_brandt`, `eucm`, `none`, `tilted` (Scheimpflug);
//! `method` one of `zhang`
//! (default), `dlt` (non-coplanar points), `tsai` (planar), `ekf` (planar)
//! or `all`. `image_size_px` may be left out when the views carry
//! detections (which must then agree on it). `robust` means a Huber loss
//! (1 px) plus rejection of points beyond 3 robust sigmas, reported per view
//! as `outliers`.
//!
//! Output: `{"report": <CameraCalibration>, "comparison": null | [rows]}`,
//! the report of the chosen method (Zhang's for `all`) and, for `all`, one
//! [`ComparisonRow`] per method; with circle-grid or dot-plate detections
//! also `centre_model` (the views' circle-centre model, or `mixed` with
//! `centre_models` listing the views of each; see
//! [`crate::calib::centre_models`]).

use crate::calib::centre_models::{centre_models, CentreModelViews};
use crate::calib::compare::{calibrate_with, compare_methods, ComparisonRow, Method};
use crate::calib::usable::{left_out_clause, usable_views, LeftOut};
use crate::calib::{CalibrationOptions, CameraCalibration, View};
use crate::camera::Distortion;
use crate::error::{Error, Result};
use crate::optim::Loss;
use crate::target::Detection;
use serde::{Deserialize, Serialize};

pub use super::camera_views::views_of;

pub use super::choices::{LensModel, MethodChoice};

/// Fewest views the JSON API accepts (Zhang's closed form with free skew
/// needs 3; fewer views leave the focal length poorly determined anyway).
pub const MIN_VIEWS: usize = 3;
/// Most views (or stereo pairs) one calibration takes: time and memory grow
/// linearly, 10,000 views of 54 points took 19 s and 560 MB natively
/// (docs/bounds.md); a browser worker has at most 4 GiB.
pub const MAX_VIEWS: usize = 5000;
/// Most target points over all views of one calibration (memory, as above).
pub const MAX_POINTS: usize = 500_000;

/// Refuse more views or points than [`MAX_VIEWS`] / [`MAX_POINTS`], with the
/// subset to keep. `what` is "views" or "pairs".
pub fn check_size(what: &str, views: &[JsonView]) -> Result<()> {
    let n = views.len();
    if n > MAX_VIEWS {
        return Err(Error::invalid(
            what,
            format!(
                "{n} {what}: at most {MAX_VIEWS} are supported in one calibration; keep a subset \
                 that covers the image and the angles, e.g. one in every {}",
                n.div_ceil(MAX_VIEWS)
            ),
        ));
    }
    let points: usize = views
        .iter()
        .map(|v| {
            v.detection
                .as_ref()
                .map(|d| d.points.len())
                .or(v.image_px.as_ref().map(Vec::len))
                .unwrap_or(0)
        })
        .sum();
    if points > MAX_POINTS {
        return Err(Error::invalid(
            what,
            format!(
                "{points} target points in {n} {what}: at most {MAX_POINTS} are supported in one \
                 calibration; use fewer {what} or a target with fewer points"
            ),
        ));
    }
    Ok(())
}
/// Huber threshold of the robust option, px.
pub const ROBUST_HUBER_PX: f64 = 1.0;
/// Outlier threshold of the robust option, robust sigmas.
pub const ROBUST_OUTLIER_SIGMA: f64 = 3.0;

/// The options object of the input.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct JsonOptions {
    /// Hold the principal point at the image centre.
    pub fix_principal_point: bool,
    /// Hold fy / fx at its closed-form value (or at `aspect_ratio`).
    pub fix_aspect_ratio: bool,
    /// Hold fx / fy at this value (OpenCV's aspectRatio; 1 = fx = fy);
    /// implies `fix_aspect_ratio`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub aspect_ratio: Option<f64>,
    /// Hold the skew at 0 (default true).
    pub zero_skew: bool,
    /// Huber loss and 3-sigma outlier rejection.
    pub robust: bool,
    /// Coefficient names of the model held at 0.
    pub fixed_coefficients: Vec<String>,
    /// Estimate the board's flex (mrcal's two-parameter paraboloid).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub board_warp: bool,
    /// The splined model's control points `[nx, ny]` (default 12 x 8).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spline_knots: Option<[usize; 2]>,
    /// The splined model's degree, 2 or 3 (default 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spline_order: Option<usize>,
    /// Calibrate two halves of the views with this model and the others and
    /// report their projection difference beside its predicted uncertainty
    /// (report key `cross_validation`, see docs/lens-models.md).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub cross_validate: bool,
}

impl Default for JsonOptions {
    fn default() -> Self {
        JsonOptions {
            fix_principal_point: false,
            fix_aspect_ratio: false,
            aspect_ratio: None,
            zero_skew: true,
            robust: false,
            fixed_coefficients: vec![],
            board_warp: false,
            spline_knots: None,
            spline_order: None,
            cross_validate: false,
        }
    }
}

/// One view of the input: a detection, or explicit correspondences.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JsonView {
    /// Image name, carried into the report.
    pub name: String,
    /// A target detection (`robocal detect` / `detect_target` output).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detection: Option<Detection>,
    /// Target points, metres (with `image_px`, instead of `detection`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object_m: Option<Vec<[f64; 3]>>,
    /// Observed pixels, same order as `object_m`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image_px: Option<Vec<[f64; 2]>>,
}

/// The whole input of [`calibrate_json`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationInput {
    /// Lens model (default `brown`).
    #[serde(default)]
    pub model: LensModel,
    /// Method or `all` (default `zhang`).
    #[serde(default)]
    pub method: MethodChoice,
    /// Options.
    #[serde(default)]
    pub options: JsonOptions,
    /// The views.
    pub views: Vec<JsonView>,
    /// Image width and height, px; optional when every view is a detection.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image_size_px: Option<[u32; 2]>,
}

/// The output of [`calibrate_json`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CalibrationOutput {
    /// The report of the chosen method (Zhang's for `all`).
    pub report: CameraCalibration,
    /// With method `all`: every method's row; otherwise `None` (JSON null).
    pub comparison: Option<Vec<ComparisonRow>>,
    /// With method `all`: why methods were left out of `comparison` (the
    /// DLT on flat boards), said once; absent when none was.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub comparison_note: Option<String>,
    /// Circle grids and dot plates: the centre model of the views'
    /// detections (`perspective_pole`, `local_quadratic`, `ellipse_centre`
    /// for files written before detections said it), or `mixed` when the
    /// views differ; absent when no view is a circle or dot detection.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_model: Option<String>,
    /// With `centre_model` `mixed`: the views of each model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_models: Option<Vec<CentreModelViews>>,
}

/// Calibrate from the JSON input described in the module docs; returns the
/// output JSON.
pub fn calibrate_json(input_json: &str) -> Result<String> {
    let input: CalibrationInput = serde_json::from_str(input_json)
        .map_err(|e| super::request_error("calibration input", e))?;
    let output = calibrate_input(&input)?;
    serde_json::to_string(&output)
        .map_err(|e| Error::invalid("report", format!("cannot serialise: {e}")))
}

/// [`calibrate_json`] on the parsed input.
pub fn calibrate_input(input: &CalibrationInput) -> Result<CalibrationOutput> {
    // 1. The views and the image size.
    check_size("views", &input.views)?;
    let (views, left_out) = usable_views(&views_of(&input.views)?);
    if views.len() < MIN_VIEWS && !left_out.is_empty() {
        return Err(Error::invalid(
            "views",
            format!(
                "{} whose points fix a homography, a calibration needs at least {MIN_VIEWS} (10 \
                 or more from varied angles are recommended){}: add images in which more of the \
                 target is found",
                match views.len() {
                    1 => "1 view".to_string(),
                    n => format!("{n} views"),
                },
                left_out_clause(&left_out)
            ),
        ));
    }
    if views.len() < MIN_VIEWS {
        return Err(Error::invalid(
            "views",
            format!(
                "{} with the target found, a calibration needs at least {MIN_VIEWS} (10 or more \
                 from varied angles are recommended): add images in which the whole target is \
                 found, or check the target's size (inner corners for a chessboard)",
                match views.len() {
                    1 => "1 view".to_string(),
                    n => format!("{n} views"),
                }
            ),
        ));
    }
    let size = image_size(input)?;
    // 2. The options, and the circle-centre model the views were detected with.
    let options = calibration_options(&input.model, &input.options)?;
    let (centre_model, models) = centre_models(
        input
            .views
            .iter()
            .map(|v| (v.name.as_str(), v.detection.as_ref())),
    );
    // 3. The method(s).
    if input.method == MethodChoice::All {
        let outcomes = compare_methods(&views, size, &options);
        let zhang = outcomes
            .iter()
            .find(|(m, _)| *m == Method::Zhang)
            .map(|(_, outcome)| outcome.clone())
            .ok_or_else(|| Error::invalid("method", "the comparison has no Zhang row"))??;
        // 4. The chosen result is at least as good as every row.
        let mut report = at_least_as_good(zhang, &outcomes, &views, size, &options);
        let comparison = outcomes
            .iter()
            .map(|(m, outcome)| match m {
                Method::Zhang => ComparisonRow::new(*m, &Ok(report.clone())),
                _ => ComparisonRow::new(*m, outcome),
            })
            .collect();
        report
            .warnings
            .extend(left_out.iter().map(LeftOut::warning));
        report.refresh_severity();
        return Ok(CalibrationOutput {
            report,
            comparison: Some(comparison),
            comparison_note: crate::calib::compare::left_out(&views),
            centre_model,
            centre_models: models,
        });
    }
    let method = match input.method {
        MethodChoice::One(method) => method,
        MethodChoice::All => Method::Zhang,
    };
    let mut report = calibrate_with(method, &views, size, &options)?;
    let advice = crate::calib::model_advice::advise_model(&views, size, &options, &report);
    report.warnings.extend(advice);
    if input.options.cross_validate {
        use crate::calib::cross_validation::{cross_validate, cross_validation_warning};
        let cv = cross_validate(&views, size, &options, &report)?;
        report.warnings.extend(cross_validation_warning(&cv));
        report.cross_validation = Some(cv);
    }
    report
        .warnings
        .extend(left_out.iter().map(LeftOut::warning));
    report.refresh_severity();
    Ok(CalibrationOutput {
        report,
        comparison: None,
        comparison_note: None,
        centre_model,
        centre_models: models,
    })
}

/// Relative margin by which another method's RMS must be lower than the
/// chosen result's to count as better (round-off of equal minima).
const BETTER_MARGIN: f64 = 1e-9;

/// Zhang's report, or, when another method of the comparison reaches a
/// lower RMS, Zhang's bundle adjustment refined from that method's camera
/// if it ends lower: a row of the table below the chosen result is a bug,
/// not a footnote. A row that stays lower (a method fitting parameters the
/// options hold, such as the DLT's skew) is named in a warning.
pub(crate) fn at_least_as_good(
    zhang: CameraCalibration,
    outcomes: &[(Method, Result<CameraCalibration>)],
    views: &[View],
    size: (u32, u32),
    options: &CalibrationOptions,
) -> CameraCalibration {
    let mut report = zhang;
    let mut notes = Vec::new();
    for (method, outcome) in outcomes {
        let Ok(other) = outcome else { continue };
        let lower = other.rms_px < report.rms_px * (1.0 - BETTER_MARGIN);
        if *method == Method::Zhang || !lower {
            continue;
        }
        let from_other = CalibrationOptions {
            initial_camera: Some(other.camera.clone()),
            ..options.clone()
        };
        match crate::calib::calibrate(views, size, &from_other) {
            Ok(mut refined) if refined.rms_px < report.rms_px => {
                refined.warnings.insert(
                    0,
                    format!(
                        "the bundle adjustment from its own start reached {:.3} px, above {}'s {:.3} px: refined from {}'s camera instead, to {:.3} px",
                        report.rms_px,
                        method.name(),
                        other.rms_px,
                        method.name(),
                        refined.rms_px
                    ),
                );
                refined.start = Some(format!("comparison:{}", method.name()));
                report = refined;
            }
            _ => notes.push((*method, other.rms_px)),
        }
    }
    for (method, rms) in notes {
        if rms < report.rms_px * (1.0 - BETTER_MARGIN) {
            report.warnings.push(format!(
                "{} reaches {rms:.3} px, below the chosen result's {:.3} px, and the bundle adjustment refined from it does not: it fits parameters these options hold (free skew, no held coefficients); solve with its options to compare",
                method.name(),
                report.rms_px
            ));
        }
    }
    report.refresh_severity();
    report
}

/// The lens model of a name, with the coefficients the solver starts from
/// (the table `camera::LENS_MODELS`).
pub fn model_from_name(name: &str) -> Result<Distortion> {
    Distortion::named(name).ok_or_else(|| {
        Error::invalid(
            "model",
            format!(
                "unknown model '{name}' (expected one of {})",
                crate::camera::model_list()
            ),
        )
    })
}

/// The solver options of the JSON options.
pub fn calibration_options(model: &LensModel, o: &JsonOptions) -> Result<CalibrationOptions> {
    let (loss, outlier_sigma) = if o.robust {
        (
            Loss::Huber {
                scale: ROBUST_HUBER_PX,
            },
            Some(ROBUST_OUTLIER_SIGMA),
        )
    } else {
        (Loss::Squared, None)
    };
    let mut start = model.start().clone();
    match &mut start {
        Distortion::Splined(s) => {
            if let Some([nx, ny]) = o.spline_knots {
                (s.nx, s.ny) = (nx, ny);
            }
            s.order = o.spline_order.unwrap_or(s.order);
            let check = crate::camera::Spline {
                u_max: [1.0, 1.0],
                control: vec![0.0; 2 * s.nx * s.ny],
                ..s.clone()
            };
            check.check()?;
        }
        _ if o.spline_knots.is_some() || o.spline_order.is_some() => {
            return Err(Error::invalid(
                "spline_knots",
                format!(
                    "spline knots and order are options of the splined model, not of {}",
                    start.model_name()
                ),
            ))
        }
        _ => {}
    }
    Ok(CalibrationOptions {
        model: start,
        board_warp: o.board_warp,
        fix_principal_point: o.fix_principal_point,
        fix_aspect_ratio: o.fix_aspect_ratio || o.aspect_ratio.is_some(),
        aspect_ratio: o.aspect_ratio,
        zero_skew: o.zero_skew,
        fixed_coefficients: o.fixed_coefficients.clone(),
        loss,
        outlier_sigma,
        ..CalibrationOptions::default()
    })
}

/// The image size: given, or the one all detections agree on.
fn image_size(input: &CalibrationInput) -> Result<(u32, u32)> {
    agreed_image_size(
        "image_size_px",
        input.image_size_px,
        detection_sizes(
            input
                .views
                .iter()
                .map(|v| (v.name.as_str(), v.detection.as_ref())),
        ),
        "required when the views are not detections",
    )
}

/// `(name, image size)` of the views that are detections.
pub(crate) fn detection_sizes<'a>(
    views: impl Iterator<Item = (&'a str, Option<&'a Detection>)>,
) -> impl Iterator<Item = (&'a str, [u32; 2])> {
    views.filter_map(|(name, d)| d.map(|d| (name, d.image_size_px)))
}

/// One camera's image size (the camera, stereo and rig inputs): `given`, or
/// the one all its detections agree on; `missing` says why it is needed
/// when neither is there. Errors name `field`.
pub(crate) fn agreed_image_size<'a>(
    field: &str,
    given: Option<[u32; 2]>,
    mut sizes: impl Iterator<Item = (&'a str, [u32; 2])>,
    missing: &str,
) -> Result<(u32, u32)> {
    if let Some([w, h]) = given {
        if let Some((name, s)) = sizes.find(|(_, s)| *s != [w, h]) {
            return Err(Error::invalid(
                field,
                format!(
                    "{w}x{h} given but the detection of {name} is {}x{}",
                    s[0], s[1]
                ),
            ));
        }
        return Ok((w, h));
    }
    let Some((_, first)) = sizes.next() else {
        return Err(Error::invalid(field, missing));
    };
    if let Some((name, s)) = sizes.find(|(_, s)| *s != first) {
        return Err(Error::invalid(
            field,
            format!(
                "the detections disagree: {}x{} and {}x{} ({name}): one calibration takes \
                 the images of one camera at one resolution",
                first[0], first[1], s[0], s[1]
            ),
        ));
    }
    Ok((first[0], first[1]))
}
