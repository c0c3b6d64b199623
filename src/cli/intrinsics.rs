//! `robocal intrinsics`: calibrate a camera from images or from the
//! detections `robocal detect` wrote.

use super::detect::Outcome;
use super::detections_file::read_detections;
use super::{write_output, CliError};
use robocal::api::camera::{
    calibrate_input, CalibrationInput, CalibrationOutput, JsonOptions, JsonView, LensModel,
    MethodChoice,
};
use robocal::calib::compare::ComparisonRow;
use robocal::detect::DetectOptions;
use robocal::target::Target;

#[derive(clap::Args)]
#[command(
    about = "calibrate a camera (Zhang, DLT, Tsai, EKF) from images or detections",
    long_about = "calibrate a camera (intrinsics and lens distortion)

  robocal intrinsics --target SPEC IMAGES... [options] -o camera.json
  robocal intrinsics --detections detections.json [options] -o camera.json

Images where the target is not found are listed on standard error and skipped.
The report (JSON) has camera_matrix, distortion, rms_px, std, per-view residuals,
correlations, projection uncertainty and warnings; 'robocal export' converts it.
A fit that stops at its iteration limit or looks implausible is solved again
from every other start (Tsai, DLT, square pixels, centred principal point,
distortion held then freed) and the lowest cost wins (report keys start,
starts); severity is ok, warning or error (no start converged: the first
warning says so, and is printed as 'error:').",
    after_help = "Examples:
  robocal intrinsics --target chessboard:9x6:25mm left*.jpg -o camera.json
  robocal intrinsics --detections detections.json --fix-aspect-ratio --fix k3 -o camera.json
  robocal intrinsics --target chessboard:9x6:25mm --method all --robust left*.jpg
  robocal export camera.json --format opencv-yaml -o camera.yaml",
    args_override_self = true
)]
pub struct IntrinsicsArgs {
    /// The target, as for 'robocal detect' (chessboard:9x6:30mm,
    /// circles:4x11:20mm:asymmetric, dots:7x7:25mm, squares:8x8:12.7mm:22.5778mm);
    /// required with images, checked against the file with --detections
    #[arg(long, value_name = "SPEC")]
    target: Option<String>,
    /// Use the JSON written by 'robocal detect' instead of images
    #[arg(long, value_name = "FILE")]
    detections: Option<String>,
    #[arg(long, value_name = "NAME", help = robocal::camera::model_help("the camera"))]
    model: Option<String>,
    /// zhang (default), dlt (non-coplanar points), tsai, ekf, or all (every
    /// method side by side, as seed 000's Table II; the report is Zhang's, the
    /// comparison goes to standard error)
    #[arg(long, value_name = "NAME")]
    method: Option<String>,
    /// Hold the principal point at the image centre
    #[arg(long)]
    fix_principal_point: bool,
    /// Hold fy/fx at its closed-form value
    #[arg(long)]
    fix_aspect_ratio: bool,
    /// Hold fx/fy at R exactly (1 = square pixels, fx = fy); as OpenCV's
    /// CALIB_FIX_ASPECT_RATIO with aspectRatio R (the OpenCV calibration
    /// sample's -a), implies --fix-aspect-ratio
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    aspect_ratio: Option<f64>,
    /// Estimate the skew (default: held at 0, as OpenCV)
    #[arg(long)]
    free_skew: bool,
    /// Hold a distortion coefficient at 0 (repeatable: --fix k3)
    #[arg(long, value_name = "NAME")]
    fix: Vec<String>,
    /// Huber loss and rejection of points beyond 3 robust sigmas
    #[arg(long)]
    robust: bool,
    /// Estimate the board's flex with the calibration (mrcal's two-parameter
    /// paraboloid; reported in mm as board_warp, a warning above 1 mm)
    #[arg(long)]
    board_warp: bool,
    /// With --model splined: control points across x and y (default 12x8;
    /// 4 to 40 each, more than the order)
    #[arg(long, value_name = "NXxNY")]
    spline_knots: Option<String>,
    /// With --model splined: the B-spline's degree, 2 or 3 (default 3)
    #[arg(long, value_name = "N")]
    spline_order: Option<usize>,
    /// Calibrate two halves of the views (even and odd) with this model and
    /// the others (brown, rational, kannala_brandt, eucm) and report their
    /// projection difference beside its predicted uncertainty (report key
    /// cross_validation); a warning names a model whose halves agree when
    /// the chosen one's do not
    #[arg(long)]
    cross_validate: bool,
    /// Images detected in parallel (default: all cores)
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    #[command(flatten)]
    limits: super::ImageLimits,
    #[command(flatten)]
    video: super::video_frames::VideoFlags,
    /// Benchmarking: solve N times and print the median solve time (detections
    /// in, report out; no file or detection time) on standard error (1: no
    /// timing line)
    #[arg(long, value_name = "N", default_value_t = 1)]
    repeat: usize,
    /// Write the report there (default: standard output)
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<String>,
    /// The images (instead of --detections); videos (.mp4 .mov .webm ...,
    /// read through ffmpeg) give their frames kept by the live capture's rules
    #[arg(value_name = "IMAGES")]
    images: Vec<String>,
}

/// `--spline-knots 12x8` as `[12, 8]`.
fn parse_knots(text: &str) -> Result<[usize; 2], CliError> {
    let bad = || {
        CliError::usage(
            "intrinsics",
            format!("--spline-knots takes NXxNY, e.g. 12x8, got '{text}'"),
        )
    };
    super::values::by_pair(text, true).ok_or_else(bad)
}

pub fn run(args: IntrinsicsArgs) -> Result<(), CliError> {
    use super::{bounds, check_bounds, check_optional_bounds};
    check_optional_bounds("intrinsics", "--threads", args.threads, bounds::THREADS)?;
    check_bounds("intrinsics", "--repeat", args.repeat, bounds::REPEAT)?;
    check_optional_bounds(
        "intrinsics",
        "--aspect-ratio",
        args.aspect_ratio,
        bounds::ASPECT_RATIO,
    )?;
    let target = match args.target.as_deref() {
        Some(t) => {
            Some(Target::parse_spec(t).map_err(|e| CliError::usage("intrinsics", e.to_string()))?)
        }
        None => None,
    };
    let views = match (args.detections.as_deref(), args.images.is_empty()) {
        (Some(_), false) => {
            return Err(CliError::usage(
                "intrinsics",
                "give either IMAGES or --detections, not both",
            ))
        }
        (Some(file), true) => views_from_file(file, target.as_ref())?,
        (None, false) => {
            let target = target.ok_or_else(|| {
                CliError::usage(
                    "intrinsics",
                    "--target is required with images, e.g. --target chessboard:9x6:30mm",
                )
            })?;
            views_from_images(
                &args.images,
                &target,
                &super::detect_options_of(args.target.as_deref()),
                &args.limits,
                &args.video,
                args.threads,
            )?
        }
        (None, true) => {
            return Err(CliError::usage(
                "intrinsics",
                "give IMAGES or --detections FILE",
            ))
        }
    };
    let input = CalibrationInput {
        model: LensModel::from_name(args.model.as_deref().unwrap_or("brown"))?,
        method: MethodChoice::from_name(args.method.as_deref().unwrap_or("zhang"))?,
        options: JsonOptions {
            fix_principal_point: args.fix_principal_point,
            fix_aspect_ratio: args.fix_aspect_ratio,
            aspect_ratio: args.aspect_ratio,
            zero_skew: !args.free_skew,
            robust: args.robust,
            fixed_coefficients: args.fix,
            board_warp: args.board_warp,
            spline_knots: args.spline_knots.as_deref().map(parse_knots).transpose()?,
            spline_order: args.spline_order,
            cross_validate: args.cross_validate,
        },
        views,
        image_size_px: None,
    };
    let output = if args.repeat > 1 {
        timed(&input, args.repeat)?
    } else {
        calibrate_input(&input)?
    };
    if let Some(rows) = &output.comparison {
        eprint!("{}", comparison_table(rows));
    }
    if let Some(note) = &output.comparison_note {
        eprintln!("robocal intrinsics: {note}");
    }
    let r = &output.report;
    eprintln!(
        "robocal intrinsics: {} views, {} points, rms {:.4} px, fx {:.3} fy {:.3} cx {:.3} cy {:.3}",
        r.views.len(),
        r.n_points,
        r.rms_px,
        r.camera.fx,
        r.camera.fy,
        r.camera.cx,
        r.camera.cy
    );
    if let Some(rejected) = &r.rejected {
        eprintln!("robocal intrinsics: {}", rejected.summary);
    }
    for w in &r.warnings {
        match w.strip_prefix(robocal::calib::plausibility::ERROR_PREFIX) {
            Some(error) => eprintln!("robocal intrinsics: error: {error}"),
            None => eprintln!("robocal intrinsics: warning: {w}"),
        }
    }
    // The report, with the circle-centre model of circle and dot views
    // beside its keys (`centre_model`, and `centre_models` when mixed).
    let serialise =
        |e: serde_json::Error| CliError::Io(format!("cannot serialise the report: {e}"));
    let mut value = serde_json::to_value(&output.report).map_err(serialise)?;
    if let (Some(model), Some(obj)) = (&output.centre_model, value.as_object_mut()) {
        eprintln!("robocal intrinsics: circle centres: {model}");
        obj.insert(
            "centre_model".into(),
            serde_json::Value::from(model.as_str()),
        );
        if let Some(groups) = &output.centre_models {
            obj.insert(
                "centre_models".into(),
                serde_json::to_value(groups).map_err(serialise)?,
            );
        }
    }
    let text = serde_json::to_string_pretty(&value).map_err(serialise)?;
    write_output(args.output.as_deref(), &(text + "\n"))
}

/// Solve `repeat` times; the median wall time of one solve goes to
/// standard error. Timed here, at the CLI edge: the core never reads a clock.
fn timed(input: &CalibrationInput, repeat: usize) -> Result<CalibrationOutput, CliError> {
    let mut times_ms = Vec::with_capacity(repeat);
    let mut output = None;
    for _ in 0..repeat {
        let start = std::time::Instant::now();
        let out = calibrate_input(input)?;
        times_ms.push(start.elapsed().as_secs_f64() * 1e3);
        output = Some(out);
    }
    times_ms.sort_by(f64::total_cmp);
    let median = times_ms[times_ms.len() / 2];
    eprintln!("robocal intrinsics: solve time median {median:.3} ms over {repeat} runs");
    output.ok_or_else(|| CliError::Io("no solve ran".into()))
}

fn views_from_file(file: &str, target: Option<&Target>) -> Result<Vec<JsonView>, CliError> {
    let (names, outcomes) = read_detections("intrinsics", file, target)?;
    let mut views = vec![];
    for (name, outcome) in names.into_iter().zip(outcomes) {
        let Outcome::Found(detection, _) = outcome else {
            eprintln!("robocal intrinsics: {name}: no detection, skipped");
            continue;
        };
        views.push(JsonView {
            name,
            detection: Some(detection),
            object_m: None,
            image_px: None,
        });
    }
    Ok(views)
}

fn views_from_images(
    files: &[String],
    target: &Target,
    options: &DetectOptions,
    limits: &super::ImageLimits,
    video: &super::video_frames::VideoFlags,
    threads: Option<usize>,
) -> Result<Vec<JsonView>, CliError> {
    let inputs = super::video_inputs::expand("intrinsics", files, target, options, video, threads)?;
    let outcomes = inputs.detect(target, options, &limits.decode_options(), threads)?;
    let mut views = vec![];
    for (file, outcome) in inputs.names.iter().zip(outcomes) {
        match outcome {
            Outcome::Found(detection, _) => views.push(JsonView {
                name: file.clone(),
                detection: Some(detection),
                object_m: None,
                image_px: None,
            }),
            Outcome::Failed(_, message) => {
                eprintln!("robocal intrinsics: {file}: {message}; skipped")
            }
        }
    }
    Ok(views)
}

fn comparison_table(rows: &[ComparisonRow]) -> String {
    let f = |v: Option<f64>, d: usize| v.map_or("-".to_string(), |v| format!("{v:.d$}"));
    let mut out = format!(
        "{:<8} {:>10} {:>10} {:>9} {:>9} {:>9} {:>8} {:>8} {:>8}\n",
        "method", "fx", "fy", "cx", "cy", "k1", "rms_px", "std_u", "std_v"
    );
    for r in rows {
        match &r.error {
            Some(e) => out += &format!("{:<8} not applicable: {e}\n", r.method),
            None => {
                out += &format!(
                    "{:<8} {:>10} {:>10} {:>9} {:>9} {:>9} {:>8} {:>8} {:>8}\n",
                    r.method,
                    f(r.fx, 3),
                    f(r.fy, 3),
                    f(r.cx, 3),
                    f(r.cy, 3),
                    f(r.k1, 5),
                    f(r.rms_px, 4),
                    f(r.std_u_px, 4),
                    f(r.std_v_px, 4)
                )
            }
        }
    }
    out
}
