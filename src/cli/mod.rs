//! The command line: the clap definitions of every subcommand, dispatch, the
//! shared file helpers and the CLI's error type.
//!
//! clap reads the arguments (unknown flags, missing values and values that
//! do not parse are its usage errors, exit 2); the checks that need more than
//! one flag stay in each subcommand's `run`, with messages that say what to
//! change. Every subcommand accepts a flag again and keeps the last value
//! (`args_override_self`), as scripts that append an override expect.

mod detect;
mod detections_file;
mod export;
mod handeye;
mod handeye_images;
mod image_file;
mod info;
mod intrinsics;
mod memory_budget;
mod planar;
mod render;
mod render_rig;
mod render_video;
mod rig;
mod rig_handeye;
mod rig_summary;
mod serve;
mod stereo;
mod target;
mod xytable;

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
}

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
    Planar(planar::PlanarArgs),
    Xytable(xytable::XytableArgs),
    Target(target::TargetArgs),
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
        return Cli::command()
            .print_help()
            .map_err(|e| CliError::Io(format!("cannot write to stdout: {e}")));
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
        Command::Planar(a) => planar::run(a),
        Command::Xytable(a) => xytable::run(a),
        Command::Target(a) => target::run(a),
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

/// A pixel count: digits, or digits with the suffix MP (megapixels).
fn parse_pixel_count(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let (digits, scale) = match t.strip_suffix("MP").or_else(|| t.strip_suffix("mp")) {
        Some(d) => (d.trim(), 1_000_000),
        None => (t, 1),
    };
    match digits.parse::<u64>() {
        Ok(n) if n > 0 => n
            .checked_mul(scale)
            .ok_or_else(|| format!("'{text}' is too large")),
        _ => Err(format!(
            "'{text}' is not a pixel count: give a whole number > 0, e.g. 150000000 or 150MP"
        )),
    }
}

/// The target of `--target TEXT`: a spec (`chessboard:9x6:30mm`) or a target
/// JSON object; mistakes are usage errors of `command`.
pub fn parse_target(command: &str, text: &str) -> Result<Target, CliError> {
    if text.trim_start().starts_with('{') {
        let t: Target = serde_json::from_str(text)
            .map_err(|e| CliError::usage(command, format!("--target JSON: {e}")))?;
        return Ok(t.validated()?);
    }
    Target::parse_spec(text).map_err(|e| CliError::usage(command, e.to_string()))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clap_definitions_are_consistent() {
        Cli::command().debug_assert();
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
