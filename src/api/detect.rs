//! The request of target detection, shared by `robocal detect` (and the
//! images of `robocal intrinsics`) and the page's `detect_target` /
//! `detect_boards`: which target (a CLI spec or a target JSON), with which
//! options, and whether the other boards of a marker layout are wanted.
//! The image is decoded by the host (files and budgets in the CLI, bytes in
//! wasm); the detection itself is [`crate::detect`]'s.

use crate::detect::{detect, detect_all, DetectOptions};
use crate::error::{Error, Result};
use crate::image::GrayImage;
use crate::target::{Detection, Target};

/// What to look for in an image.
#[derive(Clone, Debug, PartialEq)]
pub struct DetectRequest {
    /// The target, validated.
    pub target: Target,
    /// The detector's options (the print a spec forces among them).
    pub options: DetectOptions,
    /// Also the other boards of the target's marker layout (ChArUco,
    /// AprilGrid, ArUco grid boards printed with other blocks of ids).
    pub other_boards: bool,
}

impl DetectRequest {
    /// The request of a CLI spec (`chessboard:9x6:30mm`,
    /// `charuco:...:light-on-dark`: the print it forces goes into the
    /// options) or a target JSON object (which forces no print); other
    /// boards are wanted for the marker boards.
    pub fn from_spec_or_json(spec_or_json: &str) -> Result<DetectRequest> {
        let (target, polarity) = if spec_or_json.trim_start().starts_with('{') {
            let target = serde_json::from_str::<Target>(spec_or_json)
                .map_err(|e| Error::invalid("target JSON", e.to_string()))?
                .validated()?;
            (target, None)
        } else {
            Target::parse_spec_print(spec_or_json)?
        };
        Ok(DetectRequest {
            other_boards: has_other_boards(&target),
            target,
            options: DetectOptions {
                polarity,
                ..DetectOptions::default()
            },
        })
    }
}

/// Whether a target's layout may have other boards in view (its markers
/// carry a block of ids): ChArUco boards, AprilGrids and ArUco grid boards.
pub fn has_other_boards(target: &Target) -> bool {
    matches!(
        target,
        Target::Charuco { .. } | Target::Aprilgrid { .. } | Target::ArucoGrid { .. }
    )
}

/// What one image showed: the target's detection (or why it was not
/// found) and the other boards of its layout seen beside it.
#[derive(Debug)]
pub struct Found {
    /// The requested target's board.
    pub detection: Result<Detection>,
    /// Boards of the same layout printed with other blocks of ids (empty
    /// unless [`DetectRequest::other_boards`]).
    pub other_boards: Vec<Detection>,
}

/// The target in `image` and, when the request wants them, the other boards
/// of its layout. With other boards the target's own board is taken from
/// [`detect_all`] when it is among them; otherwise (or without) the
/// failure is [`detect`]'s, whose message names what was seen.
pub fn detect_target(image: &GrayImage, request: &DetectRequest) -> Found {
    let mut other_boards = Vec::new();
    if request.other_boards {
        if let Ok(mut boards) = detect_all(image, &request.target, &request.options) {
            let own = request.target.to_spec();
            if let Some(i) = boards.iter().position(|d| d.target.to_spec() == own) {
                let detection = boards.remove(i);
                return Found {
                    detection: Ok(detection),
                    other_boards: boards,
                };
            }
            other_boards = boards;
        }
    }
    Found {
        detection: detect(image, &request.target, &request.options),
        other_boards,
    }
}

/// Every board of the target's layout in `image`, the target's own first
/// when it is in view ([`detect_all`]).
pub fn detect_boards(image: &GrayImage, request: &DetectRequest) -> Result<Vec<Detection>> {
    detect_all(image, &request.target, &request.options)
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn a_spec_forces_its_print_and_a_json_target_none() {
        let spec = DetectRequest::from_spec_or_json("chessboard:9x6:30mm:light-on-dark").unwrap();
        assert!(spec.options.polarity.is_some());
        assert!(!spec.other_boards);
        let json = serde_json::to_string(&spec.target).unwrap();
        let from_json = DetectRequest::from_spec_or_json(&json).unwrap();
        assert_eq!(from_json.target, spec.target);
        assert_eq!(from_json.options.polarity, None);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn a_bad_target_json_names_itself() {
        let err = DetectRequest::from_spec_or_json(r#"{"kind": "chessboard"}"#).unwrap_err();
        assert!(
            err.to_string().starts_with("target JSON: missing field"),
            "{err}"
        );
    }
}
