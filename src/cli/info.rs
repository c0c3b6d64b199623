//! `robocal info`: decode images and print their format and size.

use super::image_file::read_image;
use super::CliError;

#[derive(clap::Args)]
#[command(
    about = "decode images and print their format and size",
    long_about = "decode images and print what they are

Prints one JSON object per line: {\"file\", \"format\", \"width\", \"height\",
\"channels\", \"bits_per_channel\"} or {\"file\", \"error\"} for files that are not
supported images. A file with an EXIF Orientation tag is rotated as viewers
and OpenCV's imread do: \"exif_orientation\" (2-8) says which, and width and
height are the size after it. Only regular files are read, at most as many
bytes as the decoder's memory limit (1 GiB, raised by --max-pixels); a
truncated file is an error. Exits with 1 if any file failed.",
    after_help = "Example:
  robocal info left01.jpg board.tiff
  robocal info --max-pixels 250MP wafer_scan.tiff",
    args_override_self = true
)]
pub struct InfoArgs {
    /// Image files
    #[arg(value_name = "IMAGES")]
    files: Vec<String>,
    #[command(flatten)]
    limits: super::ImageLimits,
}

pub fn run(args: InfoArgs) -> Result<(), CliError> {
    if args.files.is_empty() {
        return Err(CliError::usage("info", "give at least one image file"));
    }
    let mut failed = 0;
    for file in &args.files {
        let options = args.limits.decode_options();
        let line = match read_image(file, &options)
            .and_then(|b| robocal::image::decode(&b, &options).map_err(CliError::from))
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
        super::output::println_stdout(&line.to_string())?;
    }
    if failed > 0 {
        return Err(CliError::Io(format!(
            "{failed} of {} files could not be decoded",
            args.files.len()
        )));
    }
    Ok(())
}
