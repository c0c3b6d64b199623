//! The command line: the clap definitions of every subcommand, dispatch, the
//! shared file helpers and the CLI's error type.
//!
//! clap reads the arguments (unknown flags, missing values and values that
//! do not parse are its usage errors, exit 2); the checks that need more than
//! one flag stay in each subcommand's `run`, with messages that say what to
//! change. Every subcommand accepts a flag again and keeps the last value
//! (`args_override_self`), as scripts that append an override expect.

mod check;
mod detect;
mod detections_file;
mod export;
mod handeye;
mod handeye_images;
mod image_file;
mod info;
mod input;
mod intrinsics;
mod laser;
mod laser_sphere;
mod memory_budget;
pub mod output;
mod plan;
mod planar;
mod render;
mod render_laser;
mod render_rig;
mod render_video;
mod rig;
mod rig_handeye;
mod rig_summary;
mod rig_video;
mod robot_poses;
mod serve;
mod stereo;
mod target;
mod values;
mod video;
mod video_frames;
mod video_inputs;
mod xytable;

pub use input::{read_pose_text, read_text};

use clap::{CommandFactory, Parser, Subcommand, ValueEnum};
use robocal::target::Target;
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
    /// Standard output was closed by its reader (`| head -1`): the command
    /// ends quietly with [`BROKEN_PIPE_EXIT`].
    BrokenPipe,
}

/// The exit code after the reader of stdout went away: 128 + SIGPIPE (13),
/// what a shell reports for a process killed by a closed pipe.
pub const BROKEN_PIPE_EXIT: i32 = 141;

impl CliError {
    /// A usage error of `command`, pointing at its help.
    pub fn usage(command: &str, message: impl Into<String>) -> Self {
        CliError::Usage(format!(
            "{command}: {} (see 'robocal {command} --help')",
            message.into()
        ))
    }

    /// The same error, naming the file it came from: `'p.csv': line 2, ...`.
    pub fn in_file(self, path: &str) -> Self {
        match self {
            CliError::Robocal(e) => CliError::Io(format!("'{path}': {e}")),
            other => other,
        }
    }

    /// The process exit code for this error.
    pub fn exit_code(&self) -> i32 {
        match self {
            CliError::Usage(_) => 2,
            CliError::Io(_) | CliError::Robocal(_) => 1,
            CliError::BrokenPipe => BROKEN_PIPE_EXIT,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Usage(m) | CliError::Io(m) => write!(f, "{m}"),
            CliError::Robocal(e) => write!(f, "{e}"),
            CliError::BrokenPipe => write!(f, "the reader of standard output went away"),
        }
    }
}

impl From<robocal::Error> for CliError {
    fn from(e: robocal::Error) -> Self {
        CliError::Robocal(e)
    }
}

/// `robocal`: camera and robot hand-eye calibration.
#[derive(Parser)]
#[command(
    name = "robocal",
    version = robocal::VERSION,
    about = "robocal - camera and robot hand-eye calibration",
    propagate_version = true,
    after_help = "Run 'robocal <command> --help' for the options and examples of each command."
)]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

// The variants carry no doc comments: each subcommand's about, long_about
// and examples are on its own Args struct, beside the flags they describe.
#[derive(Subcommand)]
enum Command {
    Serve(serve::ServeArgs),
    Export(export::ExportArgs),
    Handeye(handeye::HandeyeArgs),
    Detect(detect::DetectArgs),
    Intrinsics(intrinsics::IntrinsicsArgs),
    Stereo(stereo::StereoArgs),
    Rig(rig::RigArgs),
    Info(info::InfoArgs),
    Render(render::RenderArgs),
    Laser(laser::LaserArgs),
    Planar(planar::PlanarArgs),
    Plan(plan::PlanArgs),
    Xytable(xytable::XytableArgs),
    Target(target::TargetArgs),
    Check(check::CheckArgs),
    Diff(check::DiffArgs),
    Completions(CompletionsArgs),
}

/// The shells `robocal completions` writes scripts for.
#[derive(Clone, Copy, ValueEnum)]
enum Shell {
    Bash,
    Zsh,
    Fish,
}

#[derive(clap::Args)]
#[command(
    about = "print a shell completion script (bash, zsh or fish) to standard output",
    after_help = "Examples:
  robocal completions bash > ~/.local/share/bash-completion/completions/robocal
  robocal completions zsh > \"${fpath[1]}/_robocal\"
  robocal completions fish > ~/.config/fish/completions/robocal.fish"
)]
struct CompletionsArgs {
    /// The shell
    shell: Shell,
}

/// Run the parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    let Some(command) = cli.command else {
        // No subcommand: the overview, as `robocal --help` (exit 0).
        return output::write_stdout(&Cli::command().render_help().to_string());
    };
    match command {
        Command::Serve(a) => serve::run(a),
        Command::Export(a) => export::run(a),
        Command::Handeye(a) => handeye::run(a),
        Command::Detect(a) => detect::run(a),
        Command::Intrinsics(a) => intrinsics::run(a),
        Command::Stereo(a) => stereo::run(a),
        Command::Rig(a) => rig::run(a),
        Command::Info(a) => info::run(a),
        Command::Render(a) => render::run(a),
        Command::Laser(a) => laser::run(a),
        Command::Planar(a) => planar::run(a),
        Command::Plan(a) => plan::run(a),
        Command::Xytable(a) => xytable::run(a),
        Command::Target(a) => target::run(a),
        Command::Check(a) => check::run(a),
        Command::Diff(a) => check::run_diff(a),
        Command::Completions(a) => completions(a.shell),
    }
}

fn completions(shell: Shell) -> Result<(), CliError> {
    let shell = match shell {
        Shell::Bash => clap_complete::Shell::Bash,
        Shell::Zsh => clap_complete::Shell::Zsh,
        Shell::Fish => clap_complete::Shell::Fish,
    };
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut Cli::command(), "robocal", &mut script);
    write_output(None, &String::from_utf8_lossy(&script))
}

/// `--max-pixels N`: the decoder's size limit, shared by every command that
/// reads images.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct ImageLimits {
    /// Refuse images with more than N pixels (width x height), checked from
    /// the file header before decoding; the decoder's memory limit grows
    /// with it (default 100000000 = 100 MP, with 1 GiB of decoder memory;
    /// a suffix MP counts megapixels: 250MP)
    #[arg(long, value_name = "N", value_parser = parse_pixel_count)]
    max_pixels: Option<u64>,
}

/// Bytes the decoder may allocate per allowed pixel: a 16-bit RGBA file
/// (8 bytes a pixel) decoded and converted to grey (1 more) fits.
const ALLOC_BYTES_PER_PIXEL: u64 = 10;

impl ImageLimits {
    /// The decode options these flags ask for.
    pub fn decode_options(&self) -> robocal::image::DecodeOptions {
        let mut options = robocal::image::DecodeOptions::default();
        if let Some(n) = self.max_pixels {
            options.max_pixels = n;
            options.max_alloc_bytes = options
                .max_alloc_bytes
                .max(n.saturating_mul(ALLOC_BYTES_PER_PIXEL));
        }
        options
    }
}

/// The bounds of the numeric flags, each far beyond what a real calibration
/// asks for and low enough that no value allocates or runs away
/// (docs/bounds.md lists them with the reasons).
pub mod bounds {
    /// `--threads` of every command that detects (0 and 1 both mean one).
    pub const THREADS: (usize, usize) = (0, 256);
    /// `handeye --bootstrap`: resamples of the pose pairs.
    pub const BOOTSTRAP: (usize, usize) = (0, 1000);
    /// `intrinsics --repeat`: timed solves.
    pub const REPEAT: (usize, usize) = (1, 1000);
    /// `detect --max-side`: the long side of the coarse search level, px.
    pub const MAX_SIDE_PX: (u32, u32) = (16, 100_000);
    /// `--max-pixels`: the decoder's pixel limit (10000 MP).
    pub const MAX_PIXELS: u64 = 10_000_000_000;
    /// `intrinsics --aspect-ratio`: the held fx / fy.
    pub const ASPECT_RATIO: (f64, f64) = (0.01, 100.0);
    /// `planar --reject`: the rejection threshold in sigmas.
    pub const REJECT_SIGMA: (f64, f64) = (0.1, 1000.0);
    /// `planar --predict`: the height, mm (a kilometre either way).
    pub const PREDICT_HEIGHT_MM: (f64, f64) = (-1.0e6, 1.0e6);
    /// `xytable --noise-px`: the measurement noise sigma, px.
    pub const NOISE_PX: (f64, f64) = (0.0, 1000.0);
    /// `planar --point U,V`: each coordinate, px.
    pub const POINT_PX: (f64, f64) = (-1.0e6, 1.0e6);
    /// `xytable --start-mm X,Y,Z`: each coordinate, mm (a kilometre).
    pub const START_MM: (f64, f64) = (-1.0e6, 1.0e6);
}

/// A numeric flag outside `(lo, hi)` (NaN included) is a usage error of
/// `command`: `--bootstrap must be between 0 and 1000`.
pub fn check_bounds<T: PartialOrd + fmt::Display + Copy>(
    command: &str,
    flag: &str,
    value: T,
    (lo, hi): (T, T),
) -> Result<(), CliError> {
    if lo <= value && value <= hi {
        Ok(())
    } else {
        Err(CliError::usage(
            command,
            format!("{flag} must be between {lo} and {hi}"),
        ))
    }
}

/// [`check_bounds`] for a flag that may be absent.
pub fn check_optional_bounds<T: PartialOrd + fmt::Display + Copy>(
    command: &str,
    flag: &str,
    value: Option<T>,
    bounds: (T, T),
) -> Result<(), CliError> {
    value.map_or(Ok(()), |v| check_bounds(command, flag, v, bounds))
}

/// A pixel count: digits, or digits with the suffix MP (megapixels).
fn parse_pixel_count(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let (digits, scale) = match t.strip_suffix("MP").or_else(|| t.strip_suffix("mp")) {
        Some(d) => (d.trim(), 1_000_000),
        None => (t, 1),
    };
    let too_large = || {
        format!(
            "'{text}' is more than {}MP: downscale the image first",
            bounds::MAX_PIXELS / 1_000_000
        )
    };
    match digits.parse::<u64>() {
        Ok(n) if n > 0 => n
            .checked_mul(scale)
            .filter(|n| *n <= bounds::MAX_PIXELS)
            .ok_or_else(too_large),
        _ => Err(format!(
            "'{text}' is not a pixel count: give a whole number > 0, e.g. 150000000 or 150MP"
        )),
    }
}

/// The target of `--target TEXT`: a spec (`chessboard:9x6:30mm`) or a target
/// JSON object; mistakes are usage errors of `command`.
pub fn parse_target(command: &str, text: &str) -> Result<Target, CliError> {
    Ok(parse_target_print(command, text)?.0)
}

/// The detection options of a `--target` spec: the print it forces
/// (`:dark-on-light` / `:light-on-dark`), if any; defaults otherwise (a
/// target JSON or an unreadable spec forces none; the spec's own errors are
/// reported where it is parsed).
pub fn detect_options_of(spec: Option<&str>) -> robocal::detect::DetectOptions {
    let polarity = spec
        .filter(|s| !s.trim_start().starts_with('{'))
        .and_then(|s| Target::parse_spec_print(s).ok())
        .and_then(|(_, print)| print);
    robocal::detect::DetectOptions {
        polarity,
        ..robocal::detect::DetectOptions::default()
    }
}

/// [`parse_target`] with the print the spec forces (`:dark-on-light` /
/// `:light-on-dark`; a target JSON forces none), for `DetectOptions::polarity`.
pub fn parse_target_print(
    command: &str,
    text: &str,
) -> Result<(Target, Option<robocal::target::Polarity>), CliError> {
    if text.trim_start().starts_with('{') {
        let t: Target = serde_json::from_str(text)
            .map_err(|e| CliError::usage(command, format!("--target JSON: {e}")))?;
        return Ok((t.validated()?, None));
    }
    Target::parse_spec_print(text).map_err(|e| CliError::usage(command, e.to_string()))
}

/// Write `text` to `path` (replaced atomically), or to stdout when `path`
/// is `None` or `-`.
pub fn write_output(path: Option<&str>, text: &str) -> Result<(), CliError> {
    match path {
        None | Some("-") => output::write_stdout(text),
        Some(p) => output::write_file(std::path::Path::new(p), text.as_bytes()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clap_definitions_are_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn numbers_outside_their_bounds_are_usage_errors_naming_the_flag() {
        assert!(check_bounds("handeye", "--bootstrap", 1000, bounds::BOOTSTRAP).is_ok());
        let e = check_bounds("handeye", "--bootstrap", 1001, bounds::BOOTSTRAP).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert_eq!(
            e.to_string(),
            "handeye: --bootstrap must be between 0 and 1000 (see 'robocal handeye --help')"
        );
        let nan = check_bounds("planar", "--reject", f64::NAN, bounds::REJECT_SIGMA);
        assert_eq!(
            nan.unwrap_err().to_string(),
            "planar: --reject must be between 0.1 and 1000 (see 'robocal planar --help')"
        );
        assert!(check_optional_bounds("detect", "--threads", None, bounds::THREADS).is_ok());
    }

    #[test]
    fn pixel_counts_parse_with_and_without_mp() {
        assert_eq!(parse_pixel_count("150000000"), Ok(150_000_000));
        assert_eq!(parse_pixel_count("250MP"), Ok(250_000_000));
        assert_eq!(
            parse_pixel_count("0"),
            Err(
                "'0' is not a pixel count: give a whole number > 0, e.g. 150000000 or 150MP".into()
            )
        );
        assert_eq!(
            parse_pixel_count("10001MP"),
            Err("'10001MP' is more than 10000MP: downscale the image first".into())
        );
        assert_eq!(parse_pixel_count("10000MP"), Ok(10_000_000_000));
        let raised = ImageLimits {
            max_pixels: Some(300_000_000),
        }
        .decode_options();
        assert_eq!(
            (raised.max_pixels, raised.max_alloc_bytes),
            (300_000_000, 3_000_000_000)
        );
        let lowered = ImageLimits {
            max_pixels: Some(1000),
        }
        .decode_options();
        assert_eq!(
            lowered.max_alloc_bytes,
            robocal::image::DEFAULT_MAX_ALLOC_BYTES
        );
    }
}
