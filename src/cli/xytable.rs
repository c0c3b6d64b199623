//! `robocal xytable`: XY-table / camera calibration with one circular target
//! (seed 002), and `--known-motion` for the camera-to-reference frame from
//! known motions of one point (seed 000, Eq. 27-28).

use super::{read_text, write_output, CliError};
use robocal::api::xytable::{known_motion, xytable};
use robocal::calib::dlt_kalman::KalmanMode;
use robocal::io::workflow_csv::{parse_known_motion, parse_xytable_with};

#[derive(clap::Args)]
#[command(
    about = "camera over an XY-table with one circular target (batch DLT and Kalman filter); --known-motion: camera-to-reference frame",
    long_about = "calibrate a camera over an XY-table with one circular target

  robocal xytable POSITIONS.csv [--noise-px SIGMA] [--kalman extended|linearized] [-o FILE]
  robocal xytable --known-motion MOTIONS.csv [--start-mm X,Y,Z] [-o FILE]

POSITIONS.csv: the target centre at N >= 6 non-coplanar stage positions,
header
  x_mm,y_mm,z_mm,u_px,v_px[,role]
role (optional column): empty or 'calibration'; 'verify' for four extra
positions A, B, C, D in order around a quadrilateral (the intersection of
its diagonals AC, BD is the verification point); 'still' for repeated
images of the target standing still (their u, v scatter is the Kalman
filter's measurement noise R; x, y, z are ignored). Calibration rows are
processed by the filter in file order. An 'image' column instead of u_px,
v_px names image files (relative to the CSV's folder): the circular target's
centre is detected in each (--target circle:DIAMETER, default circle:10mm).

Prints JSON: 'batch' and 'kalman', each {projection_matrix (3x4 row-major,
for stage mm; third row = depth in mm), camera_matrix (3x3 row-major),
camera_from_world {translation_m, quaternion_xyzw}, residuals_px, rms_px};
'kalman.history' (per observation: projection_row_major, rms_px of all
positions, covariance_trace); 'measurement_noise_px2', 'noise_source'
(still_target, given or batch_residuals); 'verification' {measured_px,
stage_mm, batch_predicted_px, batch_error_px, kalman_predicted_px,
kalman_error_px, diagonal_gap_mm} or null.

--known-motion: MOTIONS.csv holds a point moved by known increments in the
reference frame (robot/stage) and seen by a calibrated stereo camera, header
  dx_mm,dy_mm,dz_mm,x_cam_mm,y_cam_mm,z_cam_mm
(first row usually 0,0,0: the start; >= 3 rows with increments in at least
two directions). Prints camera_from_reference {translation_m,
quaternion_xyzw}, start_camera_mm, residuals_mm, rms_mm. Only the rotation
and the start point in the camera frame are observable; the translation
needs the start position in the reference frame (--start-mm), otherwise the
reference origin is placed at the start (reference_origin_given: false).",
    after_help = "Examples:
  robocal xytable positions.csv --kalman extended -o xytable.json
  robocal xytable --known-motion motions.csv --start-mm 100,-50,20",
    args_override_self = true
)]
pub struct XytableArgs {
    /// POSITIONS.csv, or MOTIONS.csv with --known-motion
    #[arg(value_name = "FILE")]
    file: Option<String>,
    /// Measurement noise std (px) when there are no 'still' rows (default:
    /// from the batch residuals)
    #[arg(long, value_name = "SIGMA", allow_negative_numbers = true)]
    noise_px: Option<f64>,
    /// extended (default: EKF once the state is determined) or linearized (the
    /// DLT constraint throughout)
    #[arg(long, value_name = "MODE")]
    kalman: Option<String>,
    /// Solve the seed-000 frame from MOTIONS.csv instead
    #[arg(long)]
    known_motion: bool,
    /// known-motion: the start position in the reference frame
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    start_mm: Option<String>,
    /// The target in image files (default circle:10mm)
    #[arg(long, value_name = "SPEC")]
    target: Option<String>,
    /// Write the JSON to FILE instead of stdout
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<String>,
    #[command(flatten)]
    limits: super::ImageLimits,
}

pub fn run(args: XytableArgs) -> Result<(), CliError> {
    super::check_optional_bounds(
        "xytable",
        "--noise-px",
        args.noise_px,
        super::bounds::NOISE_PX,
    )?;
    let Some(file) = args.file.as_deref() else {
        return Err(CliError::usage("xytable", "give the positions file"));
    };
    let text = read_text(file)?;
    let json = if args.known_motion {
        if args.noise_px.is_some() || args.kalman.is_some() {
            return Err(CliError::usage(
                "xytable",
                "--noise-px and --kalman do not apply to --known-motion",
            ));
        }
        let mut request =
            parse_known_motion(&text).map_err(|e| CliError::Io(format!("{file}: {e}")))?;
        request.start_reference_mm = args.start_mm.as_deref().map(triple).transpose()?;
        serde_json::to_string_pretty(&known_motion(&request)?)
    } else {
        if args.start_mm.is_some() {
            return Err(CliError::usage(
                "xytable",
                "--start-mm belongs to --known-motion",
            ));
        }
        let target = match args.target.as_deref() {
            Some(spec) => robocal::target::Target::parse_spec(spec)?,
            None => robocal::target::Target::SingleCircle { diameter_m: 0.01 },
        };
        let base = std::path::Path::new(file)
            .parent()
            .map(|p| p.to_path_buf())
            .unwrap_or_default();
        let decode = args.limits.decode_options();
        // Image names are relative to the CSV's folder.
        let mut centre_of = |name: &str| -> robocal::Result<[f64; 2]> {
            let bytes = std::fs::read(base.join(name))
                .map_err(|e| robocal::Error::invalid("image", format!("cannot read it: {e}")))?;
            let gray = robocal::image::decode(&bytes, &decode)?.gray;
            let detection = robocal::detect::detect(&gray, &target, &Default::default())?;
            let p = detection
                .points
                .first()
                .ok_or_else(|| robocal::Error::NotFound {
                    message: "no target centre in the image".into(),
                })?;
            Ok([p.x_px, p.y_px])
        };
        let mut request = parse_xytable_with(&text, &mut centre_of)
            .map_err(|e| CliError::Io(format!("{file}: {e}")))?;
        if let Some(sigma) = args.noise_px {
            if !(sigma >= 0.0 && sigma.is_finite()) {
                return Err(CliError::usage(
                    "xytable",
                    "--noise-px must be a non-negative number of pixels",
                ));
            }
            request.measurement_noise_px2 = Some([[sigma * sigma, 0.0], [0.0, sigma * sigma]]);
        }
        request.kalman_mode = match args.kalman.as_deref() {
            None | Some("extended") => KalmanMode::Extended,
            Some("linearized") => KalmanMode::Linearized,
            Some(other) => {
                return Err(CliError::usage(
                    "xytable",
                    format!("--kalman: expected extended or linearized, got '{other}'"),
                ))
            }
        };
        serde_json::to_string_pretty(&xytable(&request)?)
    }
    .map_err(|e| CliError::Io(format!("cannot encode the result as JSON: {e}")))?;
    write_output(args.output.as_deref(), &format!("{json}\n"))
}

fn triple(text: &str) -> Result<[f64; 3], CliError> {
    let v: Vec<Option<f64>> = text.split(',').map(|t| t.trim().parse().ok()).collect();
    match v.as_slice() {
        [Some(a), Some(b), Some(c)] if a.is_finite() && b.is_finite() && c.is_finite() => {
            for v in [a, b, c] {
                super::check_bounds("xytable", "--start-mm", *v, super::bounds::START_MM)?;
            }
            Ok([*a, *b, *c])
        }
        _ => Err(CliError::usage(
            "xytable",
            format!("--start-mm: expected three numbers 'X,Y,Z', got '{text}'"),
        )),
    }
}
