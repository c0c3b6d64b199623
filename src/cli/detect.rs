//! `robocal detect`: find a calibration target in images, in parallel.

use super::args::{Args, Spec};
use super::{read_file, CliError};
use robocal::detect::{detect, DetectOptions};
use robocal::target::{Detection, Target};
use serde_json::json;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

pub const HELP: &str = "robocal detect - find a calibration target in images

Usage: robocal detect --target SPEC [-o FILE] [--threads N] IMAGES...

Options:
  --target SPEC   the target: chessboard:COLSxROWS:SQUARE (inner corners),
                  circles:COLSxROWS:SPACING[:asymmetric][:light-on-dark],
                  dots:COLSxROWS:PITCH[:DIAMETER], circle:DIAMETER,
                  squares:COLSxROWS:SIDE:PITCH (separate dark squares, 4
                  corners each, e.g. Zhang's squares:8x8:12.7mm:22.5778mm)
                  (lengths with mm, cm or m), or a target JSON object
  -o FILE         write the JSON result to FILE (default: standard output)
  --threads N     images processed in parallel (default: all cores)
  --max-side N    long side of the pyramid level searched, pixels
                  (default 256; corners are always refined at full size)

Output: {\"robocal_version\", \"target\", \"images\": [{\"file\",
\"detection\": {image_size_px, target, points: [{id, x_px, y_px}]},
\"detect_ms\"} or {\"file\", \"error\": {\"kind\", \"message\"}}]} in the order
the files were given (see docs/detection-json.md). Failures are also
printed on standard error; the other images go on. Exits with 1 when no
image gave a detection.

Examples:
  robocal detect --target chessboard:9x6:30mm left*.jpg -o detections.json
  robocal detect --target circles:4x11:20mm:asymmetric acircles*.png
  robocal detect --target dots:7x7:25mm plate.tiff
  robocal detect --target squares:8x8:12.7mm:22.5778mm image*.gif
  robocal detect --target circle:10mm --threads 1 table_*.png";

/// One image's outcome (also used by `robocal intrinsics`).
pub(super) enum Outcome {
    /// The detection and the detection time in seconds.
    Found(Detection, f64),
    Failed(String, String),
}

pub fn run(raw: &[String]) -> Result<(), CliError> {
    let spec = Spec {
        command: "detect",
        valued: &["target", "output", "threads", "max-side"],
        switches: &[],
    };
    let args = Args::parse(raw, &spec)?;
    let target = parse_target(&args)?;
    if args.positionals.is_empty() {
        return Err(CliError::usage("detect", "give at least one image file"));
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads: usize = args.parsed("detect", "threads", cores)?;
    let options = DetectOptions {
        max_working_side_px: args.parsed(
            "detect",
            "max-side",
            DetectOptions::default().max_working_side_px,
        )?,
    };
    let files = &args.positionals;
    let outcomes = run_all(files, &target, &options, threads.max(1));
    let mut images = Vec::with_capacity(files.len());
    let mut found = 0;
    for (file, outcome) in files.iter().zip(outcomes) {
        images.push(match outcome {
            Outcome::Found(d, seconds) => {
                found += 1;
                let ms = (seconds * 1e6).round() / 1e3;
                json!({"file": file, "detection": d, "detect_ms": ms})
            }
            Outcome::Failed(kind, message) => {
                eprintln!("robocal detect: {file}: {message}");
                json!({"file": file, "error": {"kind": kind, "message": message}})
            }
        });
    }
    let doc = json!({
        "robocal_version": robocal::VERSION,
        "target": target,
        "images": images,
    });
    let text = serde_json::to_string_pretty(&doc).map_err(|e| CliError::Io(e.to_string()))?;
    match args.value("output") {
        Some(path) => std::fs::write(path, text + "\n")
            .map_err(|e| CliError::Io(format!("cannot write '{path}': {e}")))?,
        None => println!("{text}"),
    }
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

fn parse_target(args: &Args) -> Result<Target, CliError> {
    let Some(text) = args.value("target") else {
        return Err(CliError::usage(
            "detect",
            "--target is required, e.g. --target chessboard:9x6:30mm",
        ));
    };
    if text.trim_start().starts_with('{') {
        let t: Target = serde_json::from_str(text)
            .map_err(|e| CliError::usage("detect", format!("--target JSON: {e}")))?;
        return Ok(t.validated()?);
    }
    Target::parse_spec(text).map_err(|e| CliError::usage("detect", e.to_string()))
}

/// Columns of the terminal progress line.
const PROGRESS_WIDTH: usize = 79;

/// `robocal [#########...........]  9/20 left09.jpg`, at most
/// [`PROGRESS_WIDTH`] columns, the file name cut from the left when long.
fn progress_bar(done: usize, total: usize, file: &str) -> String {
    const BAR: usize = 24;
    let filled = if total == 0 { BAR } else { done * BAR / total };
    let count = format!("{done:>w$}/{total}", w = total.to_string().len());
    let head = format!(
        "robocal [{}{}] {count} ",
        "#".repeat(filled),
        ".".repeat(BAR - filled)
    );
    let room = PROGRESS_WIDTH.saturating_sub(head.chars().count());
    let name: Vec<char> = file.chars().collect();
    let shown: String = if name.len() > room {
        name[name.len() - room..].iter().collect()
    } else {
        file.to_string()
    };
    format!("{head}{shown:<room$}")
}

/// Detect in every file with `threads` workers pulling from a shared index.
pub(super) fn run_all(
    files: &[String],
    target: &Target,
    options: &DetectOptions,
    threads: usize,
) -> Vec<Outcome> {
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    // A progress line on a terminal; nothing when stderr is piped or logged.
    let progress = files.len() > 1 && std::io::IsTerminal::is_terminal(&std::io::stderr());
    let mut results: Vec<(usize, Outcome)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads.min(files.len()))
            .map(|_| {
                scope.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(file) = files.get(i) else { break };
                        mine.push((i, one(file, target, options)));
                        let finished = done.fetch_add(1, Ordering::Relaxed) + 1;
                        if progress {
                            eprint!("\r{}", progress_bar(finished, files.len(), file));
                        }
                    }
                    mine
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_else(|_| vec![]))
            .collect()
    });
    if progress {
        // Clear the bar: the summary that follows starts on a clean line.
        eprint!("\r{:width$}\r", "", width = PROGRESS_WIDTH);
    }
    results.sort_by_key(|r| r.0);
    // A worker that panicked leaves holes: report them rather than lose them.
    let mut slots: Vec<Option<Outcome>> = (0..files.len()).map(|_| None).collect();
    for (i, o) in results {
        slots[i] = Some(o);
    }
    slots
        .into_iter()
        .map(|o| {
            o.unwrap_or_else(|| {
                Outcome::Failed(
                    "internal".into(),
                    "the detector crashed on this image".into(),
                )
            })
        })
        .collect()
}

fn one(file: &str, target: &Target, options: &DetectOptions) -> Outcome {
    let bytes = match read_file(file) {
        Ok(b) => b,
        Err(e) => return Outcome::Failed("io".into(), e.to_string()),
    };
    let image = match robocal::image::decode_gray(&bytes) {
        Ok(i) => i,
        Err(e) => return Outcome::Failed(e.kind().into(), e.to_string()),
    };
    let start = Instant::now();
    match detect(&image, target, options) {
        Ok(d) => Outcome::Found(d, start.elapsed().as_secs_f64()),
        Err(e) => Outcome::Failed(e.kind().into(), e.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_bar_fills_in_proportion_and_keeps_its_width() {
        let line = progress_bar(5, 20, "left05.jpg");
        assert!(line.starts_with("robocal [######..................]  5/20 left05.jpg"));
        assert_eq!(line.chars().count(), PROGRESS_WIDTH);
        let long = format!("/data/{}/view.png", "x".repeat(100));
        let line = progress_bar(20, 20, &long);
        assert!(line.starts_with("robocal [########################] 20/20 "));
        assert!(line.ends_with("xx/view.png"));
        assert_eq!(line.chars().count(), PROGRESS_WIDTH);
    }
}
