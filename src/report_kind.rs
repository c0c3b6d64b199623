//! The `kind` key of every report robocal writes: which capability made it,
//! so a reader (export, the page, npm) dispatches on it instead of guessing
//! from the keys. Reports written before the key existed have none; their
//! readers default it (each report type to its own kind) and `export`
//! guesses as it did then (docs/report-json.md, "Migration").

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// What a report is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReportKind {
    /// One camera's calibration (`robocal intrinsics`, `calibrate_camera`).
    Camera,
    /// A stereo pair (`robocal stereo`, `calibrate_stereo`).
    Stereo,
    /// A camera rig (`robocal rig`, `calibrate_rig`).
    Rig,
    /// A hand-eye calibration (`robocal handeye`, `solve_handeye`).
    Handeye,
    /// A rig on a robot: the rig report with `handeye` (`robocal rig
    /// --setup`, `calibrate_rig_handeye`).
    RigHandeye,
    /// A health check of a saved calibration (`robocal check`, `check_camera`).
    Check,
    /// The projection difference of two calibrations (`robocal diff`, `diff_cameras`).
    Diff,
    /// A laser-line sensor's plane in the camera frame (`robocal laser
    /// plane`, `laser_plane`; docs/laser.md).
    LaserPlane,
    /// A stripe image as 3-D points (`robocal laser points`, `laser_points`).
    LaserPoints,
    /// A laser-line sensor on the robot from scans of a sphere: the plane,
    /// the camera's mounting (`robocal laser sphere`, `laser_sphere`).
    LaserSphere,
}

impl ReportKind {
    /// Every kind, in the order of the docs.
    pub const ALL: [ReportKind; 10] = [
        ReportKind::Camera,
        ReportKind::Stereo,
        ReportKind::Rig,
        ReportKind::Handeye,
        ReportKind::RigHandeye,
        ReportKind::Check,
        ReportKind::Diff,
        ReportKind::LaserPlane,
        ReportKind::LaserPoints,
        ReportKind::LaserSphere,
    ];

    /// The name written as `kind`.
    pub fn name(self) -> &'static str {
        match self {
            ReportKind::Camera => "camera",
            ReportKind::Stereo => "stereo",
            ReportKind::Rig => "rig",
            ReportKind::Handeye => "handeye",
            ReportKind::RigHandeye => "rig_handeye",
            ReportKind::Check => "check",
            ReportKind::Diff => "diff",
            ReportKind::LaserPlane => "laser_plane",
            ReportKind::LaserPoints => "laser_points",
            ReportKind::LaserSphere => "laser_sphere",
        }
    }

    /// The kind of a report's `kind` value: `None` when the report has no
    /// `kind` (written before the key existed); an error naming the valid
    /// kinds when it is not one of them.
    pub fn of_report(report: &serde_json::Value) -> Result<Option<ReportKind>> {
        let Some(value) = report.get("kind") else {
            return Ok(None);
        };
        let known = || {
            ReportKind::ALL
                .iter()
                .map(|k| k.name())
                .collect::<Vec<_>>()
                .join(", ")
        };
        match value.as_str() {
            Some(name) => ReportKind::ALL
                .into_iter()
                .find(|k| k.name() == name)
                .map(Some)
                .ok_or_else(|| {
                    Error::invalid(
                        "kind",
                        format!("unknown report kind '{name}' (expected one of {})", known()),
                    )
                }),
            None => Err(Error::invalid(
                "kind",
                format!("should be a string, one of {}, got {value}", known()),
            )),
        }
    }

    // The serde defaults of reports written before `kind` existed.
    pub(crate) fn camera() -> Self {
        ReportKind::Camera
    }
    pub(crate) fn stereo() -> Self {
        ReportKind::Stereo
    }
    pub(crate) fn rig() -> Self {
        ReportKind::Rig
    }
    pub(crate) fn handeye() -> Self {
        ReportKind::Handeye
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_read_back_and_unknown_ones_name_the_valid_ones() {
        for kind in ReportKind::ALL {
            let text = serde_json::to_string(&kind).expect("serialise");
            assert_eq!(text, format!("\"{}\"", kind.name()));
            let report = serde_json::json!({ "kind": kind.name() });
            assert_eq!(ReportKind::of_report(&report).expect("kind"), Some(kind));
        }
        assert_eq!(
            ReportKind::of_report(&serde_json::json!({})).expect("none"),
            None
        );
        assert_eq!(
            ReportKind::of_report(&serde_json::json!({"kind": "mono"}))
                .unwrap_err()
                .to_string(),
            "kind: unknown report kind 'mono' (expected one of camera, stereo, rig, handeye, rig_handeye, check, diff, laser_plane, laser_points, laser_sphere)"
        );
    }
}
