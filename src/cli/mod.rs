//! Subcommand dispatch, help texts and the CLI's error type.

pub mod args;
mod detect;
mod export;
mod handeye;
mod handeye_images;
mod intrinsics;
mod planar;
mod render;
mod serve;
mod stereo;
mod xytable;

use std::fmt;

/// An error of the command line: a usage mistake (exit 2) or a failure (exit 1).
#[derive(Debug)]
pub enum CliError {
    /// Wrong arguments; the message says what to change.
    Usage(String),
    /// A file could not be read or written.
    Io(String),
    /// The library refused the input.
    Robocal(robocal::Error),
}

impl CliError {
    /// A usage error of `command`, pointing at its help.
    pub fn usage(command: &str, message: impl Into<String>) -> Self {
        CliError::Usage(format!(
            "{command}: {} (see 'robocal {command} --help')",
            message.into()
        ))
    }

    /// The process exit code for this error.
    pub fn exit_code(&self) -> i32 {
        match self {
            CliError::Usage(_) => 2,
            CliError::Io(_) | CliError::Robocal(_) => 1,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Usage(m) | CliError::Io(m) => write!(f, "{m}"),
            CliError::Robocal(e) => write!(f, "{e}"),
        }
    }
}

impl From<robocal::Error> for CliError {
    fn from(e: robocal::Error) -> Self {
        CliError::Robocal(e)
    }
}

const HELP: &str = "robocal - camera and robot hand-eye calibration

Usage: robocal <command> [options]

Commands:
  serve       serve the web app (a static folder) on http://127.0.0.1:8080
  export      convert a calibration report into OpenCV, ROS, Kalibr, mrcal, Halcon,
              MATLAB, URDF, robot-controller and other formats
  handeye     hand-eye calibration from robot poses and camera poses
  detect      find a calibration target (chessboard, circles, dots) in images
  intrinsics  calibrate a camera (Zhang, DLT, Tsai, EKF) from images or detections
  stereo      calibrate a stereo pair (both cameras and right_from_left) from paired images
  info        decode images and print their format and size
  render      synthetic target images with exact ground truth (and the demo session)
  planar      eye-to-hand calibration at any height (plate corners per height)
  xytable     camera over an XY-table with one circular target (batch DLT and
              Kalman filter); --known-motion: camera-to-reference frame

Run 'robocal <command> --help' for the options of each command.
Options common to all commands: --help, --version.";

/// Run the command line `args` (without the program name).
pub fn run(args: &[String]) -> Result<(), CliError> {
    let Some((command, rest)) = args.split_first() else {
        println!("{HELP}");
        return Ok(());
    };
    let wants_help = rest.iter().any(|a| a == "--help" || a == "-h");
    match command.as_str() {
        "--help" | "-h" | "help" => {
            println!("{HELP}");
            Ok(())
        }
        "--version" | "-V" => {
            println!("robocal {}", robocal::VERSION);
            Ok(())
        }
        "render" if wants_help => print_help(render::HELP),
        "render" => render::run(rest),
        "serve" if wants_help => print_help(serve::HELP),
        "serve" => serve::run(rest),
        "intrinsics" if wants_help => print_help(intrinsics::HELP),
        "intrinsics" => intrinsics::run(rest),
        "stereo" if wants_help => print_help(stereo::HELP),
        "stereo" => stereo::run(rest),
        "export" if wants_help => print_help(export::HELP),
        "export" => export::run(rest),
        "handeye" if wants_help => print_help(handeye::HELP),
        "handeye" => handeye::run(rest),
        "detect" if wants_help => print_help(detect::HELP),
        "detect" => detect::run(rest),
        "info" if wants_help => print_help(INFO_HELP),
        "info" => info(rest),
        "planar" if wants_help => print_help(planar::HELP),
        "planar" => planar::run(rest),
        "xytable" if wants_help => print_help(xytable::HELP),
        "xytable" => xytable::run(rest),
        other => Err(CliError::Usage(format!(
            "unknown command '{other}'; run 'robocal --help' for the list"
        ))),
    }
}

fn print_help(text: &str) -> Result<(), CliError> {
    println!("{text}");
    Ok(())
}

/// Read a whole text file, with an error that names it.
pub fn read_text(path: &str) -> Result<String, CliError> {
    std::fs::read_to_string(path).map_err(|e| CliError::Io(format!("cannot read '{path}': {e}")))
}

/// Write `text` to `path`, or to stdout when `path` is `None` or `-`.
pub fn write_output(path: Option<&str>, text: &str) -> Result<(), CliError> {
    match path {
        None | Some("-") => {
            use std::io::Write;
            let mut out = std::io::stdout().lock();
            out.write_all(text.as_bytes())
                .map_err(|e| CliError::Io(format!("cannot write to stdout: {e}")))
        }
        Some(p) => {
            std::fs::write(p, text).map_err(|e| CliError::Io(format!("cannot write '{p}': {e}")))
        }
    }
}

/// Read a whole file, with an error that names it.
pub fn read_file(path: &str) -> Result<Vec<u8>, CliError> {
    std::fs::read(path).map_err(|e| CliError::Io(format!("cannot read '{path}': {e}")))
}

const INFO_HELP: &str = "robocal info - decode images and print what they are

Usage: robocal info IMAGES...

Prints one JSON object per line: {\"file\", \"format\", \"width\", \"height\",
\"channels\", \"bits_per_channel\"} or {\"file\", \"error\"} for files that are not
supported images. Exits with 1 if any file failed.

Example:
  robocal info left01.jpg board.tiff";

fn info(raw: &[String]) -> Result<(), CliError> {
    let spec = args::Spec {
        command: "info",
        valued: &[],
        switches: &[],
    };
    let parsed = args::Args::parse(raw, &spec)?;
    if parsed.positionals.is_empty() {
        return Err(CliError::usage("info", "give at least one image file"));
    }
    let mut failed = 0;
    for file in &parsed.positionals {
        let line = match read_file(file)
            .and_then(|b| robocal::image::decode(&b, &Default::default()).map_err(CliError::from))
        {
            Ok(d) => {
                let mut v = serde_json::to_value(&d.info).unwrap_or_default();
                v["file"] = serde_json::Value::String(file.clone());
                v
            }
            Err(e) => {
                failed += 1;
                serde_json::json!({ "file": file, "error": e.to_string() })
            }
        };
        println!("{line}");
    }
    if failed > 0 {
        return Err(CliError::Io(format!(
            "{failed} of {} files could not be decoded",
            parsed.positionals.len()
        )));
    }
    Ok(())
}
