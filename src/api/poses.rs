//! JSON in, JSON out for robot pose files (used by the wasm boundary and the
//! web app's robot step): one call that either reads the file or, when its
//! layout is ambiguous, returns every plausible reading ranked.

use crate::error::{Error, Result};
use crate::io::{
    parse_pose_candidates, parse_pose_file_candidates, parse_pose_files, parse_poses, Candidate,
    ParsedPoses, PoseFileOptions, PoseFileText,
};
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
    let reading = read_poses(text, &options_from_json(options_json)?)?;
    serde_json::to_string(&reading).map_err(|e| Error::invalid("poses", e.to_string()))
}

fn options_from_json(options_json: &str) -> Result<PoseFileOptions> {
    if options_json.trim().is_empty() {
        return Ok(PoseFileOptions::default());
    }
    serde_json::from_str(options_json)
        .map_err(|e| Error::invalid("options", format!("not valid pose-file options: {e}")))
}

/// Read one pose per file: `files_json` is `[{"name": "pose_01.yaml",
/// "text": "..."}, ...]` (any order: read in numeric order of the names,
/// each pose named by its file's stem), `options_json` as for
/// [`read_poses_json`]. The same answer as [`read_poses_json`]; errors name
/// the file.
pub fn read_pose_files_json(files_json: &str, options_json: &str) -> Result<String> {
    let files: Vec<PoseFileText> = serde_json::from_str(files_json).map_err(|e| {
        Error::invalid(
            "files",
            format!("expected [{{\"name\", \"text\"}}, ...]: {e}"),
        )
    })?;
    let options = options_from_json(options_json)?;
    let reading = match parse_pose_files(&files, &options) {
        Ok(parsed) => PoseReading {
            parsed: Some(parsed),
            ambiguity: None,
            candidates: vec![],
        },
        Err(e) if options.format.is_none() => {
            let candidates = parse_pose_file_candidates(&files, &options).map_err(|_| e.clone())?;
            if candidates.is_empty() {
                return Err(e);
            }
            PoseReading {
                parsed: None,
                ambiguity: Some(e.to_string()),
                candidates,
            }
        }
        Err(e) => return Err(e),
    };
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
        let files = r#"[{"name": "b/p10.yaml", "text": "position: {x: 0.1, y: 0, z: 0}\norientation: {x: 0, y: 0, z: 0, w: 1}"},
                        {"name": "b/p9.txt", "text": "1 0 0 0.2\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"}]"#;
        let err = read_pose_files_json(files, "").unwrap_err().to_string();
        assert_eq!(err, "'b/p10.yaml': poses: its values (x y z qx qy qz qw) are not those of 'b/p9.txt' (16 numbers without names): every pose file must have the same layout");
        let files = r#"[{"name": "p10.yaml", "text": "position: {x: 0.1, y: 0, z: 0}\norientation: {x: 0, y: 0, z: 0, w: 1}"},
                        {"name": "p9.yml", "text": "position: {x: 0.2, y: 0, z: 0}\norientation: {x: 0, y: 0, z: 0, w: 1}"}]"#;
        let v: serde_json::Value =
            serde_json::from_str(&read_pose_files_json(files, "").unwrap()).unwrap();
        assert_eq!(v["parsed"]["poses"][0]["name"], "p9");
        assert_eq!(
            v["parsed"]["poses"][0]["base_from_gripper"]["translation_m"][0],
            0.2
        );
        assert_eq!(v["parsed"]["poses"][1]["name"], "p10");
        let err = read_pose_files_json("{}", "").unwrap_err().to_string();
        assert!(
            err.starts_with("files: expected [{\"name\", \"text\"}, ...]: invalid type"),
            "{err}"
        );
        let err = read_poses_json(bare, "{\"format\": 3}")
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("options: not valid pose-file options"),
            "{err}"
        );
    }
}
