//! `robocal target`: a target spec read back as JSON, or its printable sheet.

use super::{write_output, CliError};
use robocal::target::svg::board_svg;
use robocal::target::Target;

#[derive(clap::Args)]
#[command(
    about = "print a target's JSON, or write its printable board (SVG at true scale)",
    long_about = "print a target's JSON, or write its printable board

Without --svg, prints the target as robocal reads it (the JSON object that
'robocal detect' writes as \"target\"). With --svg, writes one sheet at true
scale (width and height in millimetres): the board, a 100 mm check bar with
the words to measure it, and the spec, so a print can be checked and typed
back in. Print it at 100 % (actual size, no fit to page).",
    after_help = "Examples:
  robocal target chessboard:9x6:30mm
  robocal target chessboard:9x6:30mm --svg board.svg
  robocal target circles:4x11:20mm:asymmetric --svg acircles.svg
  robocal target charuco:12x9:20mm:15mm:DICT_5X5_100 --svg charuco.svg
  robocal target aprilgrid:6x6:88mm:0.3 --svg aprilgrid.svg
  robocal target arucogrid:5x7:40mm:10mm:DICT_6X6_250 --svg arucogrid.svg
  robocal target circles:10x10:25mm:origin-dot --svg ros_industrial.svg",
    args_override_self = true
)]
pub struct TargetArgs {
    /// The target, as for 'robocal detect' (chessboard:9x6:30mm,
    /// circles:4x11:20mm:asymmetric, dots:7x7:25mm, circle:10mm,
    /// squares:8x8:12.7mm:22.5778mm, charuco:12x9:20mm:15mm:DICT_5X5_100,
    /// aprilgrid:6x6:88mm:0.3, arucogrid:5x7:40mm:10mm:DICT_6X6_250[:first=N]
    /// (OpenCV's GridBoard), circles:10x10:25mm:origin-dot (ROS-Industrial's
    /// modified circle grid)) or a target JSON object
    #[arg(value_name = "SPEC")]
    spec: Option<String>,
    /// Write the printable sheet there (SVG; '-' for standard output)
    #[arg(long, value_name = "FILE")]
    svg: Option<String>,
}

pub fn run(args: TargetArgs) -> Result<(), CliError> {
    let Some(spec) = args.spec.as_deref() else {
        return Err(CliError::usage(
            "target",
            "give the target, e.g. robocal target chessboard:9x6:30mm",
        ));
    };
    let (target, print) = super::parse_target_print("target", spec)?;
    if let (Some(_), Some(robocal::target::Polarity::LightOnDark)) = (&args.svg, print) {
        if !matches!(target, Target::CircleGrid { .. }) {
            return Err(CliError::usage(
                "target",
                format!(
                    "the printable sheet of {} is drawn dark on light only; ':light-on-dark' is a detection option for it (print the sheet inverted, or leave the option out: detection finds either print)",
                    target.to_spec()
                ),
            ));
        }
    }
    match args.svg.as_deref() {
        None => {
            let json = serde_json::to_string_pretty(&target)
                .map_err(|e| CliError::Io(format!("cannot encode the target as JSON: {e}")))?;
            write_output(None, &format!("{json}\n"))
        }
        Some(path) => {
            write_output(Some(path), &board_svg(&target))?;
            if path != "-" {
                eprintln!(
                    "robocal target: wrote {path}: the {} sheet at true scale; print at 100 % and measure the 100 mm bar",
                    target.to_spec()
                );
            }
            Ok(())
        }
    }
}
