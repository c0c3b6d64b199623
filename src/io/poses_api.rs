//! JSON in, JSON out for robot pose files (used by the wasm boundary and the
//! web app's robot step): one call that either reads the file or, when its
//! layout is ambiguous, returns every plausible reading ranked.

use super::{parse_pose_candidates, parse_poses, Candidate, ParsedPoses, PoseFileOptions};
use crate::error::{Error, Result};
use serde::Serialize;

/// What [`read_poses_json`] returns.
#[derive(Debug, Serialize)]
pub struct PoseReading {
    /// The poses when the file's layout was determined (format given, a
    /// header, or a unique value count).
    pub parsed: Option<ParsedPoses>,
    /// Why the layout could not be determined, when it could not.
    pub ambiguity: Option<String>,
    /// Every plausible reading, most plausible first (empty when `parsed`).
    pub candidates: Vec<Candidate>,
}

/// Read a pose file. `options_json` is a [`PoseFileOptions`] object (every
/// field optional: `{"format": "kuka", "length_unit": "mm", "angle_unit":
/// "deg", "direction": "base_from_gripper"}`); `""` means none.
pub fn read_poses_json(text: &str, options_json: &str) -> Result<String> {
    let options: PoseFileOptions = if options_json.trim().is_empty() {
        PoseFileOptions::default()
    } else {
        serde_json::from_str(options_json)
            .map_err(|e| Error::invalid("options", format!("not valid pose-file options: {e}")))?
    };
    let reading = read_poses(text, &options)?;
    serde_json::to_string(&reading).map_err(|e| Error::invalid("poses", e.to_string()))
}

/// [`read_poses_json`] without the JSON.
pub fn read_poses(text: &str, options: &PoseFileOptions) -> Result<PoseReading> {
    match parse_poses(text, options) {
        Ok(parsed) => Ok(PoseReading {
            parsed: Some(parsed),
            ambiguity: None,
            candidates: vec![],
        }),
        Err(e) if options.format.is_none() => {
            let candidates = parse_pose_candidates(text, options).map_err(|_| e.clone())?;
            if candidates.is_empty() {
                return Err(e);
            }
            Ok(PoseReading {
                parsed: None,
                ambiguity: Some(e.to_string()),
                candidates,
            })
        }
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn a_header_decides_and_ambiguous_files_get_ranked_candidates() {
        let kuka = "X,Y,Z,A,B,C\n100,0,500,90,0,0\n";
        let v: serde_json::Value =
            serde_json::from_str(&read_poses_json(kuka, "").unwrap()).unwrap();
        assert_eq!(v["parsed"]["format"], "kuka");
        assert_eq!(
            v["parsed"]["poses"][0]["base_from_gripper"]["translation_m"][0],
            0.1
        );
        let bare = "100 0 500 90 0 0\n200 0 500 0 90 0\n";
        let v: serde_json::Value =
            serde_json::from_str(&read_poses_json(bare, "").unwrap()).unwrap();
        assert!(v["parsed"].is_null());
        assert!(v["candidates"].as_array().unwrap().len() > 1);
        let v: serde_json::Value =
            serde_json::from_str(&read_poses_json(bare, r#"{"format": "kuka"}"#).unwrap()).unwrap();
        assert_eq!(v["parsed"]["poses"].as_array().unwrap().len(), 2);
        let err = read_poses_json("1,2,abc,4,5,6\n", r#"{"format": "kuka"}"#).unwrap_err();
        assert_eq!(err.to_string(), "line 1, column 3: 'abc' is not a number");
        let err = read_poses_json(bare, "{\"format\": 3}")
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("options: not valid pose-file options"),
            "{err}"
        );
    }
}
