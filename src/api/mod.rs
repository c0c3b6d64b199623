//! The request/report layer: one file per capability, each with its request
//! (serde), its report and one function from the one to the other. The
//! wasm boundary (`src/wasm.rs`), the npm package and every CLI command
//! call these functions, so the page, node and the command line run the
//! same code path; a CLI command is arguments -> request -> api -> files.
//!
//! - [`camera`]: one camera's intrinsics (`calibrate_camera`, `robocal
//!   intrinsics`);
//! - [`stereo`]: a stereo pair (`calibrate_stereo`, `robocal stereo`);
//! - [`rig`]: a camera rig (`calibrate_rig`, `robocal rig`);
//! - [`handeye`]: hand-eye from poses or image points (`solve_handeye`,
//!   `rank_pose_conventions`, `robocal handeye`);
//! - [`rig_handeye`]: a rig on a robot (`calibrate_rig_handeye`, `robocal
//!   rig --setup`);
//! - [`poses`]: robot pose files (`read_robot_poses`, `read_robot_pose_files`);
//! - [`planar`]: the planar workflow (`planar_fit`, `planar_solve`,
//!   `robocal planar`);
//! - [`xytable`]: the XY-table and known-motion workflows (`xytable_solve`,
//!   `known_motion_solve`, `robocal xytable`);
//! - [`detect`]: which target to find and how (`detect_target`,
//!   `detect_boards`, `robocal detect`, the images of `robocal intrinsics`);
//! - [`export`]: a report in another format (`export_report`,
//!   `export_report_files`, `robocal export`);
//! - [`check`]: a saved calibration against new images, and the projection
//!   difference of two calibrations (`check_camera`, `diff_cameras`,
//!   `robocal check`, `robocal diff`);
//! - [`plan`]: a pose plan for hand-eye (`robocal plan`); [`handeye_field`]:
//!   the hand-eye's error at the work point, held-out poses and the touch
//!   test (`robocal handeye --tcp/--holdout/--touch`);
//! - [`laser`]: the laser plane of a laser-line sensor and its profiles as
//!   points (`robocal laser plane`, `robocal laser points`); [`laser_json`]
//!   their JSON requests (`laser_plane`, `laser_points`, `laser_stripe`).
//!
//! Every report says what it is in `kind` ([`crate::report_kind::ReportKind`])
//! and which robocal wrote it in `robocal_version`; `robocal export` and
//! `export_report` dispatch on `kind` (docs/report-json.md).

pub mod camera;
#[cfg(test)]
pub(crate) mod camera_tests;
mod camera_views;
pub mod check;
mod choices;
pub mod detect;
pub mod export;
pub mod handeye;
pub mod handeye_field;
#[cfg(test)]
mod handeye_tests;
pub mod laser;
pub mod laser_json;
pub mod laser_sphere;
pub mod plan;
pub mod planar;
pub mod poses;
pub mod rig;
pub mod rig_handeye;
pub mod stereo;
pub mod xytable;

pub use crate::report_kind::ReportKind;

use crate::error::Error;

/// The fields of a request whose values are choices read by serde
/// ([`camera::LensModel`], [`camera::MethodChoice`]).
const CHOICES: [&str; 2] = ["model", "method"];

/// The error of a request that did not deserialize. A choice's own error
/// keeps its plain text (`model: unknown model 'x' (expected one of ...)`,
/// as when the names were read after parsing); any other error says where
/// in the text it is and names the request (`what`).
pub(crate) fn request_error(what: &str, e: serde_json::Error) -> Error {
    let text = e.to_string();
    let location = format!(" at line {} column {}", e.line(), e.column());
    let message = text.strip_suffix(location.as_str()).unwrap_or(&text);
    for field in CHOICES {
        if let Some(rest) = message.strip_prefix(&format!("{field}: ")) {
            if rest.starts_with(&format!("unknown {field} '")) {
                return Error::invalid(field, rest);
            }
        }
    }
    Error::parse(e.line(), e.column(), format!("{what}: {e}"))
}
