//! Kalibr's calibration-target YAML (`target_type: aprilgrid` with
//! `tagCols`, `tagRows`, `tagSize`, `tagSpacing`; `target_type:
//! checkerboard` with `targetCols`, `targetRows`, `rowSpacingMeters`,
//! `colSpacingMeters`) read into a [`Target`].
//!
//! Why a small reader and not a YAML crate: these files are one flat map of
//! scalars (Kalibr's own templates, comments after `#`, values optionally
//! quoted), the only YAML the crate reads besides the camera imports, which
//! read their few keys the same way (`import_camera.rs`); serde_yaml is
//! archived upstream and the maintained successors would add a YAML 1.2
//! parser to the wasm build for five scalars. Nested or multi-document YAML
//! is refused with a message, never half-read.

use crate::error::{Error, Result};
use crate::target::Target;
use std::collections::HashMap;

/// Read a Kalibr target YAML file's text.
///
/// Errors name the line of a malformed entry, a missing or non-numeric key,
/// an unknown `target_type`, and a checkerboard whose row and column
/// spacings differ (robocal's chessboards have square squares).
pub fn parse_kalibr_target(text: &str) -> Result<Target> {
    let map = flat_map(text)?;
    let get = |key: &str| {
        map.get(key)
            .map(|(_, v)| v.as_str())
            .ok_or_else(|| Error::parse(0, 0, format!("Kalibr target: missing key '{key}'")))
    };
    let number = |key: &str| -> Result<f64> {
        let v = get(key)?;
        let line = map.get(key).map_or(0, |(l, _)| *l);
        v.parse::<f64>().map_err(|_| {
            Error::parse(
                line,
                0,
                format!("Kalibr target: '{key}' must be a number, got '{v}'"),
            )
        })
    };
    let count = |key: &str| -> Result<usize> {
        let v = get(key)?;
        let line = map.get(key).map_or(0, |(l, _)| *l);
        v.parse::<usize>().map_err(|_| {
            Error::parse(
                line,
                0,
                format!("Kalibr target: '{key}' must be a whole number, got '{v}'"),
            )
        })
    };
    match get("target_type")? {
        "aprilgrid" => Target::Aprilgrid {
            tag_cols: count("tagCols")?,
            tag_rows: count("tagRows")?,
            tag_m: number("tagSize")?,
            spacing_ratio: number("tagSpacing")?,
            first_id: 0,
        }
        .validated(),
        "checkerboard" => {
            let (row, col) = (number("rowSpacingMeters")?, number("colSpacingMeters")?);
            if row != col {
                return Err(Error::invalid(
                    "target",
                    format!("Kalibr checkerboard with rowSpacingMeters {row} and colSpacingMeters {col}: robocal's chessboards need square squares"),
                ));
            }
            Target::Chessboard {
                cols: count("targetCols")?,
                rows: count("targetRows")?,
                square_m: row,
            }
            .validated()
        }
        other => Err(Error::parse(
            map.get("target_type").map_or(0, |(l, _)| *l),
            0,
            format!("Kalibr target: target_type '{other}' is not supported; expected aprilgrid or checkerboard"),
        )),
    }
}

/// `key: value` lines into a map of (1-based line, value), comments and
/// quotes removed.
fn flat_map(text: &str) -> Result<HashMap<String, (usize, String)>> {
    let mut map = HashMap::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim_end();
        if line.trim().is_empty() || line.trim() == "---" {
            continue;
        }
        if line.starts_with([' ', '\t', '-']) {
            return Err(Error::parse(
                i + 1,
                0,
                "Kalibr target: expected flat 'key: value' lines, got a nested or list entry",
            ));
        }
        let (key, value) = line.split_once(':').ok_or_else(|| {
            Error::parse(
                i + 1,
                0,
                format!(
                    "Kalibr target: expected 'key: value', got '{}'",
                    line.trim()
                ),
            )
        })?;
        let value = value
            .trim()
            .trim_matches(|c| c == '\'' || c == '"')
            .to_string();
        map.insert(key.trim().to_string(), (i + 1, value));
    }
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_kalibrs_aprilgrid_template() {
        let text = "target_type: 'aprilgrid' #gridtype\ntagCols: 6               #number of apriltags\ntagRows: 6\ntagSize: 0.088           #size of apriltag, edge to edge [m]\ntagSpacing: 0.3          #ratio of space between tags to tagSize\n";
        assert_eq!(
            parse_kalibr_target(text).unwrap(),
            Target::Aprilgrid {
                tag_cols: 6,
                tag_rows: 6,
                tag_m: 0.088,
                spacing_ratio: 0.3,
                first_id: 0
            }
        );
        assert_eq!(
            parse_kalibr_target(text).unwrap().to_spec(),
            "aprilgrid:6x6:88mm:0.3"
        );
    }

    #[test]
    fn reads_kalibrs_checkerboard_template() {
        let text = "target_type: 'checkerboard' #gridtype\ntargetCols: 6\ntargetRows: 7\nrowSpacingMeters: 0.06\ncolSpacingMeters: 0.06\n";
        assert_eq!(
            parse_kalibr_target(text).unwrap().to_spec(),
            "chessboard:6x7:60mm"
        );
    }

    #[test]
    fn bad_files_say_what_is_wrong() {
        let e = |t: &str| parse_kalibr_target(t).unwrap_err().to_string();
        assert!(
            e("target_type: circlegrid\n").contains("target_type 'circlegrid' is not supported")
        );
        assert!(e("target_type: aprilgrid\ntagCols: 6\n").contains("missing key 'tagRows'"));
        assert!(e(
            "target_type: aprilgrid\ntagCols: six\ntagRows: 6\ntagSize: 0.1\ntagSpacing: 0.3\n"
        )
        .contains("'tagCols' must be a whole number, got 'six'"));
        assert!(e("target_type: checkerboard\ntargetCols: 6\ntargetRows: 7\nrowSpacingMeters: 0.06\ncolSpacingMeters: 0.05\n")
            .contains("need square squares"));
        assert!(e("cam0:\n  camera_model: pinhole\n").contains("nested"));
    }
}
