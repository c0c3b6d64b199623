//! `robocal detect`: find a calibration target in images, in parallel
//! (rayon), with a progress bar on a terminal (indicatif).

use super::image_file::open_image;
use super::memory_budget::{MemoryBudget, DETECT_BYTES_PER_PIXEL, DETECT_MEMORY_BUDGET};
use super::{parse_target_print, CliError, ImageLimits};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use robocal::api::detect::{detect_target, has_other_boards, DetectRequest, Found};
use robocal::detect::{CentreModel, DetectOptions};
use robocal::image::DecodeOptions;
use robocal::target::{Detection, Target};
use serde_json::json;
use std::io::IsTerminal;
use std::time::Instant;

#[derive(clap::Args)]
#[command(
    about = "find a calibration target (chessboard, circles, dots, ChArUco, AprilGrid) in images",
    after_help = "Output: {\"robocal_version\", \"target\", \"images\": [{\"file\",
\"detection\": {image_size_px, target, points: [{id, x_px, y_px}]},
\"detect_ms\"} or {\"file\", \"error\": {\"kind\", \"message\"}}]} in the order
the files were given (see docs/detection-json.md). Marker boards: an
image that also shows boards of the same layout printed with other blocks of
ids gets \"other_boards\": [detection, ...] (each with its target's first_id;
pass --target ...:first=N to make one of them the target). Failures are also
printed on standard error; the other images go on. Exits with 1 when no
image gave a detection.

Examples:
  robocal detect --target chessboard:9x6:30mm left*.jpg -o detections.json
  robocal detect --target circles:4x11:20mm:asymmetric acircles*.png
  robocal detect --target dots:7x7:25mm plate.tiff
  robocal detect --target squares:8x8:12.7mm:22.5778mm image*.gif
  robocal detect --target charuco:12x9:20mm:15mm:DICT_5X5_100 view*.png
  robocal detect --target charuco:4x5:54mm:40.5mm:DICT_4X4_1000:light-on-dark inverted*.png
  robocal detect --target aprilgrid:6x6:88mm:0.3 cam0/*.png
  robocal detect --target circle:10mm --threads 1 table_*.png",
    args_override_self = true
)]
pub struct DetectArgs {
    /// The target: chessboard:COLSxROWS:SQUARE (inner corners),
    /// circles:COLSxROWS:SPACING[:asymmetric][:light-on-dark],
    /// dots:COLSxROWS:PITCH[:DIAMETER], circle:DIAMETER,
    /// squares:COLSxROWS:SIDE:PITCH (separate dark squares, 4 corners each,
    /// e.g. Zhang's squares:8x8:12.7mm:22.5778mm),
    /// charuco:SQUARESXxSQUARESY:SQUARE:MARKER:DICT[:first=N][:ids=A,B,...][:legacy]
    /// (OpenCV's ChArUco board; legacy: made before OpenCV 4.6),
    /// aprilgrid:TAGCOLSxTAGROWS:TAGSIZE:SPACINGRATIO[:first=N] (Kalibr's),
    /// arucogrid:COLSxROWS:MARKER:SEPARATION:DICT[:first=N] (OpenCV's ArUco
    /// GridBoard: 4 corners per marker),
    /// circles:COLSxROWS:PITCH:origin-dot (ROS-Industrial's modified circle
    /// grid, the big origin dot fixes the orientation)
    /// (lengths with mm, cm or m), or a target JSON object. Either print
    /// (dark on light, light on dark) is found without an option; add
    /// :dark-on-light or :light-on-dark to any spec to search only that one
    /// (written to each detection as "polarity")
    #[arg(long, value_name = "SPEC")]
    target: Option<String>,
    /// Write the JSON result to FILE (default: standard output)
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<String>,
    /// Images processed in parallel (default: all cores)
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Long side of the pyramid level searched, pixels (default 256; corners
    /// are always refined at full size)
    #[arg(long, value_name = "N")]
    max_side: Option<u32>,
    /// Circle grids and dot plates: which point of each imaged circle is
    /// reported (default perspective_pole: the image of the circle's centre;
    /// ellipse_centre turns the perspective correction off, for comparison;
    /// written to each detection as "centre_model")
    #[arg(long, value_name = "MODEL", value_parser = ["perspective_pole", "local_quadratic", "ellipse_centre"])]
    circle_centres: Option<String>,
    #[command(flatten)]
    limits: ImageLimits,
    #[command(flatten)]
    video: super::video_frames::VideoFlags,
    /// The images (and videos: their frames chosen by the live capture's
    /// rules, named FILE#frameNNNN)
    #[arg(value_name = "IMAGES")]
    images: Vec<String>,
}

/// One image's outcome (also used by `robocal intrinsics`).
pub(super) enum Outcome {
    /// The detection and the detection time in seconds.
    Found(Detection, f64),
    Failed(String, String),
}

pub fn run(args: DetectArgs) -> Result<(), CliError> {
    super::check_optional_bounds("detect", "--threads", args.threads, super::bounds::THREADS)?;
    super::check_optional_bounds(
        "detect",
        "--max-side",
        args.max_side,
        super::bounds::MAX_SIDE_PX,
    )?;
    let Some(text) = args.target.as_deref() else {
        return Err(CliError::usage(
            "detect",
            "--target is required, e.g. --target chessboard:9x6:30mm",
        ));
    };
    let (target, print) = parse_target_print("detect", text)?;
    if args.images.is_empty() {
        return Err(CliError::usage("detect", "give at least one image file"));
    }
    let options = DetectOptions {
        max_working_side_px: args
            .max_side
            .unwrap_or(DetectOptions::default().max_working_side_px),
        circle_centres: CentreModel::ALL
            .into_iter()
            .find(|m| Some(m.name()) == args.circle_centres.as_deref())
            .unwrap_or_default(),
        polarity: print,
    };
    let inputs = super::video_inputs::expand(
        "detect",
        &args.images,
        &target,
        &options,
        &args.video,
        args.threads,
    )?;
    let files = &inputs.names;
    let decode = args.limits.decode_options();
    let all_boards = has_other_boards(&target);
    let images_only: Vec<String> = files
        .iter()
        .filter(|f| inputs.frame(f).is_none())
        .cloned()
        .collect();
    let mut detected = run_with(
        &images_only,
        &target,
        &options,
        &decode,
        args.threads,
        all_boards,
    )?
    .into_iter();
    let outcomes: Vec<Processed> = files
        .iter()
        .filter_map(|f| match inputs.frame(f) {
            Some((d, seconds)) => Some(Processed {
                outcome: Outcome::Found(d.clone(), *seconds),
                others: Vec::new(),
                exif_orientation: None,
            }),
            None => detected.next(),
        })
        .collect();
    let mut images = Vec::with_capacity(files.len());
    let mut found = 0;
    for (
        file,
        Processed {
            outcome,
            others,
            exif_orientation,
        },
    ) in files.iter().zip(outcomes)
    {
        let mut entry = match outcome {
            Outcome::Found(d, seconds) => {
                found += 1;
                let ms = (seconds * 1e6).round() / 1e3;
                json!({"file": file, "detection": d, "detect_ms": ms})
            }
            Outcome::Failed(kind, message) => {
                eprintln!("robocal detect: {file}: {message}");
                json!({"file": file, "error": {"kind": kind, "message": message}})
            }
        };
        if let Some(o) = exif_orientation {
            entry["exif_orientation"] = json!(o);
        }
        if !others.is_empty() {
            let firsts: Vec<String> = others.iter().map(|d| d.target.to_spec()).collect();
            eprintln!(
                "robocal detect: {file}: other boards in view: {} (other_boards)",
                firsts.join(", ")
            );
            entry["other_boards"] = json!(others);
        }
        images.push(entry);
    }
    let doc = json!({
        "robocal_version": robocal::VERSION,
        "target": target,
        "images": images,
    });
    let text = serde_json::to_string_pretty(&doc).map_err(|e| CliError::Io(e.to_string()))?;
    super::write_output(args.output.as_deref(), &(text + "\n"))?;
    eprintln!(
        "robocal detect: target found in {found} of {} images",
        files.len()
    );
    if found == 0 {
        return Err(CliError::Io(
            "the target was not found in any image".to_string(),
        ));
    }
    Ok(())
}

/// `robocal [#########...............]  9/20 left09.jpg`: the bar's layout.
const PROGRESS_TEMPLATE: &str = "robocal [{bar:24}] {pos:>3}/{len} {wide_msg}";

/// A progress bar over `total` images on a terminal's stderr; a hidden one
/// when stderr is piped or logged, or for a single image.
fn progress(total: usize) -> ProgressBar {
    if total < 2 || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let style = ProgressStyle::with_template(PROGRESS_TEMPLATE)
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("#.");
    ProgressBar::new(total as u64).with_style(style)
}

/// Detect in every file on `threads` workers (default: rayon's, one per
/// core); the outcomes are in the order of `files`.
pub(super) fn run_all(
    files: &[String],
    target: &Target,
    options: &DetectOptions,
    decode: &DecodeOptions,
    threads: Option<usize>,
) -> Result<Vec<Outcome>, CliError> {
    let outcomes = run_with(files, target, options, decode, threads, false)?;
    Ok(outcomes.into_iter().map(|p| p.outcome).collect())
}

/// One image's outcome, the other boards in view and the EXIF orientation
/// applied to it.
struct Processed {
    outcome: Outcome,
    others: Vec<Detection>,
    exif_orientation: Option<u8>,
}

impl Processed {
    fn failed(kind: &str, message: String) -> Self {
        Processed {
            outcome: Outcome::Failed(kind.into(), message),
            others: Vec::new(),
            exif_orientation: None,
        }
    }
}

/// [`run_all`], with `all_boards` also the other boards of a marker
/// board's layout in each image (`detect::detect_all`).
fn run_with(
    files: &[String],
    target: &Target,
    options: &DetectOptions,
    decode: &DecodeOptions,
    threads: Option<usize>,
    all_boards: bool,
) -> Result<Vec<Processed>, CliError> {
    // `--threads 0` has always meant one thread; rayon reads 0 as "default".
    let threads = threads.map_or(0, |n| n.max(1));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| CliError::Io(format!("cannot start the detection threads: {e}")))?;
    let bar = progress(files.len());
    let budget = MemoryBudget::new(DETECT_MEMORY_BUDGET);
    let outcomes = pool.install(|| {
        files
            .par_iter()
            .map(|file| {
                let outcome = guarded(file, target, options, decode, all_boards, &budget);
                bar.set_message(file.clone());
                bar.inc(1);
                outcome
            })
            .collect()
    });
    // The summary that follows starts on a clean line.
    bar.finish_and_clear();
    Ok(outcomes)
}

/// [`one`], with a panic of the detector reported as this image's failure
/// instead of ending the run (nothing shared is mutated inside, so the
/// `AssertUnwindSafe` holds).
fn guarded(
    file: &str,
    target: &Target,
    options: &DetectOptions,
    decode: &DecodeOptions,
    all_boards: bool,
    budget: &MemoryBudget,
) -> Processed {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        one(file, target, options, decode, all_boards, budget)
    }))
    .unwrap_or_else(|_| Processed::failed("internal", "the detector crashed on this image".into()))
}

/// One image: the target's detection and, with `all_boards`, the other
/// boards of its layout (the target's own missing: the failure is
/// [`detect`]'s, whose message names what was seen). The file is read,
/// decoded and searched under a reservation of `budget` for all of it.
fn one(
    file: &str,
    target: &Target,
    options: &DetectOptions,
    decode: &DecodeOptions,
    all_boards: bool,
    budget: &MemoryBudget,
) -> Processed {
    let cli_failed = |e: CliError| match e {
        CliError::Robocal(e) => Processed::failed(e.kind(), e.to_string()),
        other => Processed::failed("io", other.to_string()),
    };
    if super::video::is_video(file) {
        return Processed::failed("io", super::video::not_read_here(file));
    }
    let opened = match open_image(file, decode) {
        Ok(f) => f,
        Err(e) => return cli_failed(e),
    };
    // The header is usually in the first bytes; when it is not, the
    // decoder's limit is the bound.
    let peak = robocal::image::decode_peak(&opened.head, decode).map_or(
        decode.max_alloc_bytes + decode.max_pixels * DETECT_BYTES_PER_PIXEL,
        |p| p.bytes + p.pixels * DETECT_BYTES_PER_PIXEL,
    );
    let _reservation = budget.reserve(opened.len() + peak);
    let bytes = match opened.read_all() {
        Ok(b) => b,
        Err(e) => return cli_failed(e),
    };
    let (image, exif_orientation) = match robocal::image::decode(&bytes, decode) {
        Ok(d) => (d.gray, d.info.exif_orientation),
        Err(e) => return Processed::failed(e.kind(), e.to_string()),
    };
    drop(bytes);
    let found = |outcome: Outcome, others: Vec<Detection>| Processed {
        outcome,
        others,
        exif_orientation,
    };
    let start = Instant::now();
    let request = DetectRequest {
        target: target.clone(),
        options: options.clone(),
        other_boards: all_boards,
    };
    let Found {
        detection,
        other_boards,
    } = detect_target(&image, &request);
    let outcome = match detection {
        Ok(d) => Outcome::Found(d, start.elapsed().as_secs_f64()),
        Err(e) => Outcome::Failed(e.kind().into(), e.to_string()),
    };
    found(outcome, other_boards)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_progress_template_parses() {
        assert!(ProgressStyle::with_template(PROGRESS_TEMPLATE).is_ok());
    }

    #[test]
    fn outcomes_come_in_input_order_on_many_threads() {
        let target = Target::parse_spec("chessboard:9x6:30mm").unwrap();
        let files: Vec<String> = (0..12)
            .map(|i| format!("/nonexistent/view{i}.png"))
            .collect();
        let outcomes = run_all(
            &files,
            &target,
            &DetectOptions::default(),
            &DecodeOptions::default(),
            Some(4),
        )
        .unwrap();
        assert_eq!(outcomes.len(), files.len());
        for (file, o) in files.iter().zip(&outcomes) {
            match o {
                Outcome::Failed(kind, message) => {
                    assert_eq!(kind, "io");
                    assert!(message.contains(file.as_str()), "{message} for {file}");
                }
                Outcome::Found(..) => panic!("{file} does not exist"),
            }
        }
    }
}
