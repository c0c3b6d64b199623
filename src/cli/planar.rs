//! `robocal planar fit|solve`: eye-to-hand calibration at any height (seed 001).

use super::{read_text, write_output, CliError};
use robocal::api::planar::{
    planar_fit, planar_solve, PlanarFitRequest, PlanarSolveRequest, PredictRequest,
};
use robocal::io::workflow_csv::{parse_planar_matrices, parse_planar_points};
use robocal::workflows::planar::TransformKind;
use robocal::workflows::planar_solve::PlanarSolveOptions;

#[derive(clap::Args)]
#[command(
    about = "eye-to-hand calibration at any height (plate corners per height)",
    long_about = "eye-to-hand calibration at any height (planar plate)

  robocal planar fit MATRICES.csv [options]
  robocal planar solve POINTS.csv [--transform rigid|similarity|affine] [options]

'fit' takes one 2x3 image->robot matrix per calibration height, header
  height_mm,a11,a12,tx,a21,a22,ty
  (x_mm = a11 u + a12 v + tx, y_mm = a21 u + a22 v + ty, u and v in px)
and fits every parameter linearly against height.

'solve' takes point pairs (undistorted image px <-> robot mm), header
  height_mm,u_px,v_px,x_mm,y_mm
  (extra columns such as a corner label are ignored; rows with the same
  height_mm form one calibration height, at least 3 non-collinear points
  each, at least 2 heights), fits the transform per height (least squares,
  per-point residuals), then every parameter against height. When every
  height has exactly 4 points (plate corners A, B, C, D in order) it also
  reports the pixel density (px/mm along AB and BC) against height.

Both print JSON: 'fit' keyed a11 a12 tx a21 a22 ty, each {intercept, slope,
r2, pearson_r, adj_r2, rss, n, intercept_std, slope_std, ...} (r2, pearson_r
and adj_r2 are null where undefined), 'rejected_heights_mm', 'predictions';
'solve' adds 'heights' (per height: robot_from_image, reflected,
residuals_mm, rms_mm), 'pixel_density', 'density_fit', and 'exact_family'
{projection_matrix, rms_px}: the physically exact alternative (the 3x4
projection of robot (x, y, z = height) in mm fitted by the 12-parameter DLT;
the image of each plane is a homography, linear in height; needs >= 6
points) with 'exact_predictions_mm' for the --point pixels.",
    after_help = "Examples:
  robocal planar fit fixtures/seed001/table4_matrices.csv --predict 60 --point 2000,1500
  robocal planar solve corners.csv --transform similarity --reject 3 -o planar.json",
    args_override_self = true
)]
pub struct PlanarArgs {
    /// fit (one 2x3 matrix per height) or solve (point pairs per height)
    #[arg(value_name = "fit|solve")]
    mode: Option<Mode>,
    /// MATRICES.csv for fit, POINTS.csv for solve
    #[arg(value_name = "FILE")]
    file: Option<String>,
    /// solve: rigid, similarity or affine (default: affine, the model of the
    /// seed article's Table 4)
    #[arg(long, value_name = "KIND")]
    transform: Option<String>,
    /// Reject heights whose residual exceeds SIGMA standard deviations
    /// (externally studentized, per parameter, at most a quarter of them),
    /// then refit
    #[arg(long, value_name = "SIGMA", allow_negative_numbers = true)]
    reject: Option<f64>,
    /// solve: a calibrated camera (any camera format robocal exports: robocal
    /// JSON, OpenCV YAML/XML, ROS camera_info, Kalibr, mrcal, HALCON, MATLAB,
    /// text); the image points are undistorted with it first
    #[arg(long, value_name = "FILE")]
    camera: Option<String>,
    /// solve: plate length |AB| and width |BC| for the pixel density
    /// (default: from the robot coordinates)
    #[arg(long, value_name = "L,W", allow_hyphen_values = true)]
    plate_size_mm: Option<String>,
    /// Map pixels at this height (with --point)
    #[arg(long, value_name = "HEIGHT_MM", allow_negative_numbers = true)]
    predict: Option<f64>,
    /// The pixel to map (repeatable); prints robot_mm and a one-sigma std_mm
    /// from the fitted lines
    #[arg(long, value_name = "U,V", allow_hyphen_values = true)]
    point: Vec<String>,
    /// Write the JSON to FILE instead of stdout
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<String>,
}

/// What `robocal planar` does with the file.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Mode {
    /// Fit one 2x3 image->robot matrix per height against height
    Fit,
    /// Fit the transform per height from point pairs, then against height
    Solve,
}

pub fn run(args: PlanarArgs) -> Result<(), CliError> {
    super::check_optional_bounds(
        "planar",
        "--reject",
        args.reject,
        super::bounds::REJECT_SIGMA,
    )?;
    super::check_optional_bounds(
        "planar",
        "--predict",
        args.predict,
        super::bounds::PREDICT_HEIGHT_MM,
    )?;
    let (Some(mode), Some(file)) = (args.mode, args.file.as_deref()) else {
        return Err(CliError::usage(
            "planar",
            "give 'fit MATRICES.csv' or 'solve POINTS.csv'",
        ));
    };
    let predict = predictions(&args)?;
    let text = read_text(file)?;
    let json = match mode {
        Mode::Fit => {
            if args.transform.is_some() || args.plate_size_mm.is_some() || args.camera.is_some() {
                return Err(CliError::usage(
                    "planar",
                    "--transform, --plate-size-mm and --camera belong to 'solve'",
                ));
            }
            let request = PlanarFitRequest {
                matrices: parse_planar_matrices(&text).map_err(|e| in_file(file, e))?,
                reject_threshold: args.reject,
                predict,
            };
            serde_json::to_string_pretty(&planar_fit(&request)?)
        }
        Mode::Solve => {
            let transform = match args.transform.as_deref() {
                Some(t) => TransformKind::parse(t)?,
                None => TransformKind::Affine,
            };
            let camera = match args.camera.as_deref() {
                None => None,
                Some(path) => Some(
                    robocal::io::import_camera::import_camera(&read_text(path)?)
                        .map_err(|e| CliError::Io(format!("{path}: {e}")))?
                        .0,
                ),
            };
            let plate_size_mm = args
                .plate_size_mm
                .as_deref()
                .map(|v| pair(v, "plate-size-mm"))
                .transpose()?;
            let request = PlanarSolveRequest {
                points: parse_planar_points(&text).map_err(|e| in_file(file, e))?,
                options: PlanarSolveOptions {
                    transform,
                    reject_threshold: args.reject,
                    plate_size_mm,
                    camera,
                },
                predict,
            };
            serde_json::to_string_pretty(&planar_solve(&request)?)
        }
    }
    .map_err(|e| CliError::Io(format!("cannot encode the result as JSON: {e}")))?;
    write_output(args.output.as_deref(), &format!("{json}\n"))
}

/// Prefix a parse error with the file name.
fn in_file(file: &str, e: robocal::Error) -> CliError {
    CliError::Io(format!("{file}: {e}"))
}

fn predictions(args: &PlanarArgs) -> Result<Vec<PredictRequest>, CliError> {
    match (args.predict, args.point.is_empty()) {
        (None, true) => Ok(Vec::new()),
        (None, false) => Err(CliError::usage(
            "planar",
            "--point needs --predict HEIGHT_MM",
        )),
        (Some(_), true) => Err(CliError::usage(
            "planar",
            "--predict needs at least one --point U,V",
        )),
        (Some(height_mm), false) => args
            .point
            .iter()
            .map(|p| {
                pair(p, "point").map(|image_px| PredictRequest {
                    height_mm,
                    image_px,
                })
            })
            .collect(),
    }
}

fn pair(text: &str, flag: &str) -> Result<[f64; 2], CliError> {
    let parsed: Vec<Option<f64>> = text.split(',').map(|t| t.trim().parse().ok()).collect();
    match parsed.as_slice() {
        [Some(a), Some(b)] if a.is_finite() && b.is_finite() => {
            for v in [a, b] {
                super::check_bounds("planar", &format!("--{flag}"), *v, super::bounds::POINT_PX)?;
            }
            Ok([*a, *b])
        }
        _ => Err(CliError::usage(
            "planar",
            format!("--{flag}: expected two numbers 'A,B', got '{text}'"),
        )),
    }
}
