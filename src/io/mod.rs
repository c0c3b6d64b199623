//! Text formats at the edge of the core: parsers take `&str`/`&[u8]`,
//! writers return `String`. No filesystem here.
//!
//! Robot poses: [`parse_poses`] (format named, from a header, or unique by
//! value count), [`parse_pose_candidates`] (every plausible reading, ranked),
//! [`format_poses`] (the inverse); one pose per file (a folder of YAML, JSON
//! or text files): [`parse_pose_files`], [`parse_pose_file_candidates`]. See [`PoseFormat`] for each vendor's
//! convention and formula. Camera poses as plain text (`--camera-poses`,
//! camera_from_target per view): [`pose_text`].

pub mod csv_table;
pub mod export;
pub mod export_camera;
mod export_camera_tools;
pub mod export_laser;
mod export_mrcal_splined;
pub mod export_remap;
pub mod export_rig;
pub mod export_ros;
pub mod export_stereo;
pub mod export_transform;
pub mod import_camera;
pub mod import_camera_halcon;
pub mod import_camera_matlab;
mod import_camera_tools;
pub mod kalibr_target;
pub mod move_lists;
pub mod pairing;
mod pose_candidates;
mod pose_files;
mod pose_formats;
mod pose_json;
mod pose_krl;
pub mod pose_pairing;
mod pose_table;
pub mod pose_text;
mod pose_writer;
mod pose_yaml;
mod poses;
pub mod video_frames;
pub mod video_timestamps;
pub mod workflow_csv;

#[cfg(test)]
mod export_rig_tests;
#[cfg(test)]
mod export_tests;
#[cfg(test)]
mod import_camera_tests;
#[cfg(test)]
mod pose_tests;

/// The pretty-printed JSON text of `value` (two-space indent). Printing a
/// `Value` to a `String` cannot fail (its keys are strings, its numbers
/// finite), so the text of the error-free path is all there is.
pub(crate) fn to_string_pretty(value: &serde_json::Value) -> String {
    serde_json::to_string_pretty(value).unwrap_or_else(|_| value.to_string())
}
pub use kalibr_target::parse_kalibr_target;
pub use pose_candidates::{parse_pose_candidates, Candidate};
pub use pose_files::{parse_pose_file_candidates, parse_pose_files, PoseFileText};
pub use pose_formats::{AngleUnit, LengthUnit, PoseFormat, QUATERNION_NORM_TOLERANCE};
pub use pose_writer::format_poses;
pub use poses::{
    parse_poses, radians_read_as_degrees, ParsedPoses, PoseDirection, PoseFileOptions, RobotPose,
    RADIANS_AS_DEGREES_MAX_DEG,
};

/// The numbers of a JSON matrix given as rows of numbers (`[[..], [..]]`)
/// or as one flat list, row-major; `None` if anything is not a number.
pub(crate) fn json_matrix_numbers(value: &serde_json::Value) -> Option<Vec<f64>> {
    let items = value.as_array()?;
    items
        .iter()
        .flat_map(|x| x.as_array().cloned().unwrap_or_else(|| vec![x.clone()]))
        .map(|x| x.as_f64())
        .collect()
}
