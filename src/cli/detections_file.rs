//! `robocal detect`'s output read back (`--detections FILE`), for the
//! commands that otherwise detect in images: one outcome per listed image,
//! in the file's order. A detection may hold any subset of the target's
//! points (docs/detection-json.md).

use super::detect::Outcome;
use super::{read_text, CliError};
use robocal::target::{Detection, Target};
use serde::Deserialize;

/// The `error` of an entry whose detection failed.
#[derive(Deserialize)]
struct FailureIn {
    kind: String,
    message: String,
}

/// One entry of `robocal detect`'s output.
#[derive(Deserialize)]
struct DetectedImage {
    file: String,
    #[serde(default)]
    detection: Option<Detection>,
    #[serde(default)]
    error: Option<FailureIn>,
}

/// `robocal detect`'s output file.
#[derive(Deserialize)]
struct DetectionsFile {
    images: Vec<DetectedImage>,
}

/// The image names and outcomes of a `robocal detect` output file; with
/// `target`, every detection must be of that target.
pub(super) fn read_detections(
    command: &str,
    file: &str,
    target: Option<&Target>,
) -> Result<(Vec<String>, Vec<Outcome>), CliError> {
    let text = read_text(file)?;
    let parsed: DetectionsFile = serde_json::from_str(&text).map_err(|e| {
        CliError::Io(format!(
            "'{file}' is not a 'robocal detect' output (an object with \"images\"): {e}"
        ))
    })?;
    if parsed.images.is_empty() {
        return Err(CliError::Io(format!(
            "'{file}' lists no images: write it with 'robocal detect --target SPEC IMAGES... -o {file}'"
        )));
    }
    let mut names = Vec::with_capacity(parsed.images.len());
    let mut outcomes = Vec::with_capacity(parsed.images.len());
    for image in parsed.images {
        let outcome = match (image.detection, image.error) {
            (Some(detection), _) => {
                if let Some(t) = target {
                    if *t != detection.target {
                        return Err(CliError::usage(
                            command,
                            format!(
                                "--target does not match the target of the detection of '{}'",
                                image.file
                            ),
                        ));
                    }
                }
                Outcome::Found(detection, 0.0)
            }
            (None, Some(e)) => Outcome::Failed(e.kind, e.message),
            (None, None) => Outcome::Failed("missing".into(), "no detection".into()),
        };
        names.push(image.file);
        outcomes.push(outcome);
    }
    Ok((names, outcomes))
}
