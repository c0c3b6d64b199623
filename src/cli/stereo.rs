//! `robocal stereo`: calibrate a stereo pair from paired images of a board.

use super::args::{Args, Spec};
use super::detect::{run_all, Outcome};
use super::{write_output, CliError};
use robocal::calib::json_api::model_from_name;
use robocal::calib::stereo::calibrate_stereo;
use robocal::calib::{CalibrationOptions, View};
use robocal::detect::DetectOptions;
use robocal::target::{Detection, Target};

pub const HELP: &str =
    "robocal stereo - calibrate a stereo camera pair (both cameras and right_from_left)

Usage: robocal stereo --target SPEC --left IMAGES... --right IMAGES... [options] -o stereo.json

Options:
  --target SPEC      the target, as for 'robocal detect' (chessboard:9x6:30mm, ...)
  --left IMAGES...   the left camera's images (every argument up to the next option)
  --right IMAGES...  the right camera's images, paired with --left by order
  --model NAME       lens model of both cameras: brown (default), radial_k1_k2_k5,
                     rational, division, kannala_brandt, eucm, none
  --threads N        images detected in parallel (default: all cores)
  -o FILE            write the report there (default: standard output)

Each camera is calibrated alone (Zhang), right_from_left is averaged over the
pairs (seed 000: R = R_R R_L^-1, T = T_R - R T_L), then everything is refined
jointly. Pairs where the target is not found in either image are dropped and
listed on standard error. The report (JSON) has left, right (camera reports),
right_from_left and initial_right_from_left ({matrix_row_major, translation_m,
quaternion_xyzw}), baseline_m, right_from_left_std and rms_px.

Examples:
  robocal stereo --target chessboard:9x6:25mm --left left*.jpg --right right*.jpg -o stereo.json
  robocal stereo --target chessboard:9x6:25mm --model radial_k1_k2_k5 --left l/*.png --right r/*.png
  robocal export stereo.json --format xyz-quat-xyzw";

/// Split `--left A B --right C D` lists out of the arguments.
fn split_lists(raw: &[String]) -> (Vec<String>, Vec<String>, Vec<String>, usize, usize) {
    let (mut rest, mut left, mut right) = (vec![], vec![], vec![]);
    let (mut n_left_flags, mut n_right_flags) = (0, 0);
    let mut current: Option<bool> = None;
    for a in raw {
        match a.as_str() {
            "--left" => {
                current = Some(true);
                n_left_flags += 1;
            }
            "--right" => {
                current = Some(false);
                n_right_flags += 1;
            }
            s if s.starts_with('-') && s.len() > 1 => {
                current = None;
                rest.push(a.clone());
            }
            _ => match current {
                Some(true) => left.push(a.clone()),
                Some(false) => right.push(a.clone()),
                None => rest.push(a.clone()),
            },
        }
    }
    (rest, left, right, n_left_flags, n_right_flags)
}

pub fn run(raw: &[String]) -> Result<(), CliError> {
    let (rest, left_files, right_files, nl, nr) = split_lists(raw);
    let spec = Spec {
        command: "stereo",
        valued: &["target", "model", "threads", "output"],
        switches: &[],
    };
    let args = Args::parse(&rest, &spec)?;
    if let Some(p) = args.positionals.first() {
        return Err(CliError::usage(
            "stereo",
            format!("'{p}' is neither after --left nor after --right"),
        ));
    }
    if nl != 1 || nr != 1 || left_files.is_empty() || right_files.is_empty() {
        return Err(CliError::usage(
            "stereo",
            "give --left IMAGES... and --right IMAGES... once each",
        ));
    }
    if left_files.len() != right_files.len() {
        return Err(CliError::usage(
            "stereo",
            format!(
                "images are paired by order: {} left but {} right",
                left_files.len(),
                right_files.len()
            ),
        ));
    }
    let target = args.value("target").ok_or_else(|| {
        CliError::usage(
            "stereo",
            "--target is required, e.g. --target chessboard:9x6:30mm",
        )
    })?;
    let target =
        Target::parse_spec(target).map_err(|e| CliError::usage("stereo", e.to_string()))?;
    let options = CalibrationOptions {
        model: model_from_name(args.value("model").unwrap_or("brown"))?,
        ..CalibrationOptions::default()
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads: usize = args.parsed("stereo", "threads", cores)?;
    let files: Vec<String> = left_files.iter().chain(&right_files).cloned().collect();
    let mut outcomes = run_all(&files, &target, &DetectOptions::default(), threads.max(1));
    let right_outcomes = outcomes.split_off(left_files.len());
    let (mut left, mut right) = (vec![], vec![]);
    let (mut left_size, mut right_size) = (None, None);
    let pairs = left_files.iter().zip(&right_files);
    for ((lf, rf), (lo, ro)) in pairs.zip(outcomes.into_iter().zip(right_outcomes)) {
        match (lo, ro) {
            (Outcome::Found(ld, _), Outcome::Found(rd, _)) => {
                left.push(view(lf, &ld, &mut left_size)?);
                right.push(view(rf, &rd, &mut right_size)?);
            }
            (lo, ro) => {
                let why = |f: &str, o: Outcome| match o {
                    Outcome::Failed(_, m) => format!("{f}: {m}"),
                    Outcome::Found(..) => format!("{f}: found"),
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
    let report = calibrate_stereo(&left, &right, ls, rs, &options)?;
    let t = report.right_from_left.translation_m;
    eprintln!(
        "robocal stereo: {} pairs, rms {:.4} px (left {:.4}, right {:.4}), baseline {:.5} m, T [{:.5} {:.5} {:.5}] m",
        left.len(),
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
    write_output(args.value("output"), &(text + "\n"))
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
    let (object_m, image_px) = d.correspondences();
    Ok(View {
        name: file.to_string(),
        object_m,
        image_px,
    })
}
