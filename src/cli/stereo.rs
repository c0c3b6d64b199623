//! `robocal stereo`: calibrate a stereo pair from paired images of a board.

use super::detect::{run_all, Outcome};
use super::detections_file::read_detections;
use super::{write_output, CliError};
use robocal::api::camera::{JsonOptions, LensModel};
use robocal::api::stereo::calibrate_stereo_views;
use robocal::calib::View;
use robocal::io::pairing::{pair_by_number, PairedBy};
use robocal::target::{Detection, Target};

// No `args_override_self`: a second --left or --right is an error (clap's),
// not a replacement of the first list; the single-valued flags override
// themselves one by one instead.
#[derive(clap::Args)]
#[command(
    about = "calibrate a stereo pair (both cameras and right_from_left) from paired images",
    long_about = "calibrate a stereo camera pair (both cameras and right_from_left)

Left and right images are paired by the number in their file names: the last
run of digits in the name without folders and extension (left07.png pairs with
right07.png, or with r/cam_7.jpg), whatever the order they are given in. Every
image must then have a number, unique on its side, and a partner on the other
side. When no name has a number, the images are paired by order (and the
command says so).

Each camera is calibrated alone (Zhang), right_from_left is averaged over the
pairs (seed 000: R = R_R R_L^-1, T = T_R - R T_L), then everything is refined
jointly. Pairs where the target is not found in either image are dropped and
listed on standard error. A detection may hold any subset of the board's points
(a marker board partly out of view): each camera is fitted to its own points, and
a pair where a side's points cannot fix a homography (fewer than 4, or all but
one on a line) is left out with a warning (the report's warnings). Instead of
images, --left-detections and --right-detections read 'robocal detect' outputs.
Each camera's lens model is compared with the others fitted to the same views
(kannala_brandt and eucm always for a wide-angle lens): the advice names the
model to use and the export formats that hold it (model_advice, and a line per
camera on standard error). The report (JSON) has left, right (camera reports),
right_from_left and initial_right_from_left ({matrix_row_major, translation_m,
quaternion_xyzw}, x_right = R x_left + T as OpenCV's R, T), baseline_m,
right_from_left_std, rms_px, warnings and model_advice. 'robocal export' writes
it as opencv-yaml (K1 D1 K2 D2 R T E F and the rectification R1 R2 P1 P2 Q),
ros (left.yaml and right.yaml, rectified), kalibr (cam0, cam1) or any
transform format (right_from_left).",
    after_help = "Examples:
  robocal stereo --target chessboard:9x6:25mm --left left*.jpg --right right*.jpg -o stereo.json
  robocal stereo --target chessboard:9x6:25mm --model radial_k1_k2_k5 --left l/*.png --right r/*.png
  robocal stereo --left-detections left.json --right-detections right.json -o stereo.json
  robocal export stereo.json --format opencv-yaml -o stereo.yaml
  robocal export stereo.json --format ros -o stereo_ros/
  robocal export stereo.json --format xyz-quat-xyzw"
)]
pub struct StereoArgs {
    /// The target, as for 'robocal detect' (chessboard:9x6:30mm, ...)
    #[arg(long, value_name = "SPEC", overrides_with = "target")]
    target: Option<String>,
    /// The left camera's images (every argument up to the next option)
    #[arg(long, value_name = "IMAGES", num_args = 1.., action = clap::ArgAction::Set)]
    left: Option<Vec<String>>,
    /// The right camera's images, paired with --left by the number in their
    /// names (by order when no name has a number)
    #[arg(long, value_name = "IMAGES", num_args = 1.., action = clap::ArgAction::Set)]
    right: Option<Vec<String>>,
    /// The left camera's detections, a 'robocal detect' output (instead of
    /// --left; its file names pair as images do)
    #[arg(long, value_name = "FILE", overrides_with = "left_detections")]
    left_detections: Option<String>,
    /// The right camera's detections (instead of --right)
    #[arg(long, value_name = "FILE", overrides_with = "right_detections")]
    right_detections: Option<String>,
    #[arg(long, value_name = "NAME", overrides_with = "model", help = robocal::camera::model_help("both cameras"))]
    model: Option<String>,
    /// Images detected in parallel (default: all cores)
    #[arg(long, value_name = "N", overrides_with = "threads")]
    threads: Option<usize>,
    #[command(flatten)]
    limits: super::ImageLimits,
    /// Write the report there (default: standard output)
    #[arg(short = 'o', long, value_name = "FILE", overrides_with = "output")]
    output: Option<String>,
}

/// One side's input: images to detect in, or a detections file read back.
enum Side {
    Images(Vec<String>),
    Detections(Vec<String>, Vec<Outcome>),
}

impl Side {
    fn files(&self) -> &[String] {
        match self {
            Side::Images(f) | Side::Detections(f, _) => f,
        }
    }
}

fn side(
    name: &str,
    images: Option<Vec<String>>,
    detections: Option<&str>,
    target: Option<&Target>,
) -> Result<Option<Side>, CliError> {
    match (images, detections) {
        (Some(_), Some(_)) => Err(CliError::usage(
            "stereo",
            format!("give either --{name} IMAGES... or --{name}-detections FILE, not both"),
        )),
        (Some(files), None) => Ok(Some(Side::Images(files))),
        (None, Some(file)) => {
            let (files, outcomes) = read_detections("stereo", file, target)?;
            Ok(Some(Side::Detections(files, outcomes)))
        }
        (None, None) => Ok(None),
    }
}

pub fn run(args: StereoArgs) -> Result<(), CliError> {
    super::check_optional_bounds("stereo", "--threads", args.threads, super::bounds::THREADS)?;
    let target = args
        .target
        .as_deref()
        .map(Target::parse_spec)
        .transpose()
        .map_err(|e| CliError::usage("stereo", e.to_string()))?;
    let left = side(
        "left",
        args.left,
        args.left_detections.as_deref(),
        target.as_ref(),
    )?;
    let right = side(
        "right",
        args.right,
        args.right_detections.as_deref(),
        target.as_ref(),
    )?;
    let (Some(left_side), Some(right_side)) = (left, right) else {
        return Err(CliError::usage(
            "stereo",
            "give --left IMAGES... and --right IMAGES... once each",
        ));
    };
    let (left_files, right_files) = (left_side.files().to_vec(), right_side.files().to_vec());
    // 1. Pair the files (by name numbers, else by order).
    let pairing = {
        let left: Vec<&str> = left_files.iter().map(String::as_str).collect();
        let right: Vec<&str> = right_files.iter().map(String::as_str).collect();
        pair_by_number(&left, &right).map_err(|e| match e {
            robocal::Error::Invalid { message, .. } => CliError::usage("stereo", message),
            other => other.into(),
        })?
    };
    if pairing.paired_by == PairedBy::Order {
        eprintln!("robocal stereo: no file name has a number: images paired by order");
    }
    // An unknown model is refused before any image is detected.
    let model = LensModel::from_name(args.model.as_deref().unwrap_or("brown"))?;
    // 2. Detect in every image of both sides at once (detection files are
    // read as they are).
    let images: Vec<String> = [&left_side, &right_side]
        .into_iter()
        .flat_map(|s| match s {
            Side::Images(f) => f.clone(),
            Side::Detections(..) => Vec::new(),
        })
        .collect();
    let mut detected = if images.is_empty() {
        Vec::new()
    } else {
        let target = target.as_ref().ok_or_else(|| {
            CliError::usage(
                "stereo",
                "--target is required, e.g. --target chessboard:9x6:30mm",
            )
        })?;
        run_all(
            &images,
            target,
            &super::detect_options_of(args.target.as_deref()),
            &args.limits.decode_options(),
            args.threads,
        )?
    }
    .into_iter();
    let mut outcomes: Vec<Option<Outcome>> = Vec::new();
    for s in [left_side, right_side] {
        match s {
            Side::Images(f) => outcomes.extend(detected.by_ref().take(f.len()).map(Some)),
            Side::Detections(_, o) => outcomes.extend(o.into_iter().map(Some)),
        }
    }
    // 3. Views of the pairs where both images gave a detection.
    let (mut left, mut right) = (vec![], vec![]);
    let (mut left_size, mut right_size) = (None, None);
    for &(l, r) in &pairing.pairs {
        let (lf, rf) = (&left_files[l], &right_files[r]);
        let lo = outcomes[l].take();
        let ro = outcomes[left_files.len() + r].take();
        match (lo, ro) {
            (Some(Outcome::Found(ld, _)), Some(Outcome::Found(rd, _))) => {
                left.push(view(lf, &ld, &mut left_size)?);
                right.push(view(rf, &rd, &mut right_size)?);
            }
            (lo, ro) => {
                let why = |f: &str, o: Option<Outcome>| match o {
                    Some(Outcome::Failed(_, m)) => format!("{f}: {m}"),
                    Some(Outcome::Found(..)) => format!("{f}: found"),
                    None => format!("{f}: in another pair too"),
                };
                eprintln!(
                    "robocal stereo: pair dropped ({}; {})",
                    why(lf, lo),
                    why(rf, ro)
                );
            }
        }
    }
    let (Some(ls), Some(rs)) = (left_size, right_size) else {
        return Err(CliError::Io(
            "stereo: the target was found in no pair of images".into(),
        ));
    };
    // 4. Solve (as `calibrate_stereo` does from its views on) and report.
    let report = calibrate_stereo_views(&model, &JsonOptions::default(), &left, &right, ls, rs)?;
    for w in &report.warnings {
        eprintln!("robocal stereo: warning: {w}");
    }
    if let Some(advice) = &report.model_advice {
        for (side, a) in [("left", &advice.left), ("right", &advice.right)] {
            eprintln!("robocal stereo: {side} camera: {}", a.summary);
        }
    }
    let t = report.right_from_left.translation_m;
    eprintln!(
        "robocal stereo: {} pairs, rms {:.4} px (left {:.4}, right {:.4}), baseline {:.5} m, T [{:.5} {:.5} {:.5}] m",
        report.left.views.len(),
        report.rms_px,
        report.left.rms_px,
        report.right.rms_px,
        report.baseline_m,
        t[0],
        t[1],
        t[2]
    );
    let text = serde_json::to_string_pretty(&report)
        .map_err(|e| CliError::Io(format!("cannot serialise the report: {e}")))?;
    write_output(args.output.as_deref(), &(text + "\n"))
}

/// The view of a detection; all images of one camera must share a size.
fn view(file: &str, d: &Detection, size: &mut Option<(u32, u32)>) -> Result<View, CliError> {
    let s = (d.image_size_px[0], d.image_size_px[1]);
    match size {
        Some(prev) if *prev != s => {
            return Err(CliError::usage(
                "stereo",
                format!(
                    "'{file}' is {}x{} but earlier images of that camera are {}x{}",
                    s.0, s.1, prev.0, prev.1
                ),
            ))
        }
        _ => *size = Some(s),
    }
    Ok(View::from_detection(file, d))
}
