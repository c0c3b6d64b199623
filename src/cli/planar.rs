//! `robocal planar fit|solve`: eye-to-hand calibration at any height (seed 001).

use super::args::{Args, Spec};
use super::{read_text, write_output, CliError};
use robocal::io::workflow_csv::{parse_planar_matrices, parse_planar_points};
use robocal::workflows::planar::TransformKind;
use robocal::workflows::planar_api::{
    planar_fit, planar_solve, PlanarFitRequest, PlanarSolveRequest, PredictRequest,
};
use robocal::workflows::planar_solve::PlanarSolveOptions;

pub const HELP: &str = "robocal planar - eye-to-hand calibration at any height (planar plate)

Usage: robocal planar fit MATRICES.csv [options]
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
points) with 'exact_predictions_mm' for the --point pixels.

Options:
  --transform KIND      solve: rigid, similarity or affine (default: affine,
                        the model of the seed article's Table 4)
  --reject SIGMA        reject heights whose residual exceeds SIGMA standard
                        deviations (externally studentized, per parameter,
                        at most a quarter of them), then refit
  --camera FILE         solve: a calibrated camera (robocal JSON, OpenCV
                        YAML/XML or ROS camera_info); the image points are
                        undistorted with it first
  --plate-size-mm L,W   solve: plate length |AB| and width |BC| for the pixel
                        density (default: from the robot coordinates)
  --predict HEIGHT_MM   map pixels at this height (with --point)
  --point U,V           the pixel to map (repeatable); prints robot_mm and a
                        one-sigma std_mm from the fitted lines
  -o FILE               write the JSON to FILE instead of stdout

Examples:
  robocal planar fit fixtures/seed001/table4_matrices.csv --predict 60 --point 2000,1500
  robocal planar solve corners.csv --transform similarity --reject 3 -o planar.json";

pub fn run(raw: &[String]) -> Result<(), CliError> {
    let spec = Spec {
        command: "planar",
        valued: &[
            "transform",
            "reject",
            "plate-size-mm",
            "camera",
            "predict",
            "point",
        ],
        switches: &[],
    };
    let args = Args::parse(raw, &spec)?;
    let (sub, file) = match args.positionals.as_slice() {
        [sub, file] => (sub.as_str(), file.as_str()),
        [] | [_] => {
            return Err(CliError::usage(
                "planar",
                "give 'fit MATRICES.csv' or 'solve POINTS.csv'",
            ))
        }
        [_, _, extra, ..] => {
            return Err(CliError::usage(
                "planar",
                format!("unexpected argument '{extra}'"),
            ))
        }
    };
    let reject = match args.value("reject") {
        None => None,
        Some(_) => Some(args.parsed("planar", "reject", 3.0)?),
    };
    let predict = predictions(&args)?;
    let text = read_text(file)?;
    let json = match sub {
        "fit" => {
            if ["transform", "plate-size-mm", "camera"]
                .iter()
                .any(|f| args.value(f).is_some())
            {
                return Err(CliError::usage(
                    "planar",
                    "--transform, --plate-size-mm and --camera belong to 'solve'",
                ));
            }
            let request = PlanarFitRequest {
                matrices: parse_planar_matrices(&text).map_err(|e| in_file(file, e))?,
                reject_threshold: reject,
                predict,
            };
            serde_json::to_string_pretty(&planar_fit(&request)?)
        }
        "solve" => {
            let transform = match args.value("transform") {
                Some(t) => TransformKind::parse(t)?,
                None => TransformKind::Affine,
            };
            let camera = match args.value("camera") {
                None => None,
                Some(path) => Some(
                    robocal::io::import_camera::import_camera(&read_text(path)?)
                        .map_err(|e| CliError::Io(format!("{path}: {e}")))?
                        .0,
                ),
            };
            let plate_size_mm = args
                .value("plate-size-mm")
                .map(|v| pair(v, "plate-size-mm"))
                .transpose()?;
            let request = PlanarSolveRequest {
                points: parse_planar_points(&text).map_err(|e| in_file(file, e))?,
                options: PlanarSolveOptions {
                    transform,
                    reject_threshold: reject,
                    plate_size_mm,
                    camera,
                },
                predict,
            };
            serde_json::to_string_pretty(&planar_solve(&request)?)
        }
        other => {
            return Err(CliError::usage(
                "planar",
                format!("unknown subcommand '{other}' (expected fit or solve)"),
            ))
        }
    }
    .map_err(|e| CliError::Io(format!("cannot encode the result as JSON: {e}")))?;
    write_output(args.value("output"), &format!("{json}\n"))
}

/// Prefix a parse error with the file name.
fn in_file(file: &str, e: robocal::Error) -> CliError {
    CliError::Io(format!("{file}: {e}"))
}

fn predictions(args: &Args) -> Result<Vec<PredictRequest>, CliError> {
    let points = args.values("point");
    match (args.value("predict"), points.is_empty()) {
        (None, true) => Ok(Vec::new()),
        (None, false) => Err(CliError::usage(
            "planar",
            "--point needs --predict HEIGHT_MM",
        )),
        (Some(_), true) => Err(CliError::usage(
            "planar",
            "--predict needs at least one --point U,V",
        )),
        (Some(_), false) => {
            let height_mm: f64 = args.parsed("planar", "predict", 0.0)?;
            points
                .iter()
                .map(|p| {
                    pair(p, "point").map(|image_px| PredictRequest {
                        height_mm,
                        image_px,
                    })
                })
                .collect()
        }
    }
}

fn pair(text: &str, flag: &str) -> Result<[f64; 2], CliError> {
    let parsed: Vec<Option<f64>> = text.split(',').map(|t| t.trim().parse().ok()).collect();
    match parsed.as_slice() {
        [Some(a), Some(b)] if a.is_finite() && b.is_finite() => Ok([*a, *b]),
        _ => Err(CliError::usage(
            "planar",
            format!("--{flag}: expected two numbers 'A,B', got '{text}'"),
        )),
    }
}
