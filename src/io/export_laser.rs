//! Exports of a laser plane: the plane as a frame (z along the normal) in
//! the transform formats ([`crate::io::export_transform`]: URDF, ROS static
//! TF, ...), and a HALCON-style sheet-of-light parameter list; and the
//! plane of a `laser_plane` report read back for `robocal export`.

use crate::error::{Error, Result};
use crate::io::export_camera::float;
use crate::io::export_transform::{export_transform, FrameNames, TransformFormat};
use crate::laser::LaserPlane;
use nalgebra::Matrix4;
use serde::Deserialize;

/// The one transform of a laser plane report: the plane as a frame.
pub const PLANE_FRAME: &str = "camera_from_laser_plane";

/// The format that writes the HALCON-style sheet-of-light parameter list.
pub const HALCON_FORMAT: &str = "halcon";

/// `laser_plane` of a report, as the report writes it.
#[derive(Deserialize)]
struct PlaneJson {
    normal_camera: [f64; 3],
    distance_m: f64,
    #[serde(default)]
    covariance: Option<[[f64; 4]; 4]>,
}

#[derive(Deserialize)]
struct PlaneReportJson {
    laser_plane: PlaneJson,
}

/// The plane and its covariance (zero when the report has none) of a
/// laser report (`{"laser_plane": {"normal_camera", "distance_m",
/// "covariance"}, ...}`).
pub fn read_plane_report(report: &serde_json::Value) -> Result<(LaserPlane, Matrix4<f64>)> {
    let read = PlaneReportJson::deserialize(report).map_err(|e| {
        Error::invalid(
            "laser_plane",
            format!("expected {{\"laser_plane\": {{\"normal_camera\": [nx, ny, nz], \"distance_m\": d, \"covariance\": 4 rows of 4}}}}: {e}"),
        )
    })?;
    let p = read.laser_plane;
    let plane = LaserPlane::new(nalgebra::Vector3::from(p.normal_camera), p.distance_m)?;
    let rows = p.covariance.unwrap_or([[0.0; 4]; 4]);
    Ok((plane, Matrix4::from_fn(|r, k| rows[r][k])))
}

/// The plane in a transform format, as the frame `camera_from_laser_plane`.
pub fn export_plane_frame(plane: &LaserPlane, format: TransformFormat) -> Result<String> {
    let names = FrameNames::from_transform_name("camera_from_laser_plane")?;
    Ok(export_transform(&plane.a_from_plane(), &names, format))
}

/// A HALCON-style parameter list: the light plane's pose in the camera
/// frame as a HALCON pose `[tx, ty, tz, alpha, beta, gamma, 0]` (metres,
/// degrees, type 0 = 'Rp+T', 'gba', 'point': R = Rx(alpha) Ry(beta)
/// Rz(gamma)), its z = 0 plane the light plane, plus the plane's normal,
/// distance and their standard deviations.
pub fn export_plane_halcon(plane: &LaserPlane, covariance: &Matrix4<f64>) -> String {
    let pose = plane.a_from_plane();
    let r = pose.rotation.to_rotation_matrix();
    let m = r.matrix();
    let beta = m[(0, 2)].clamp(-1.0, 1.0).asin();
    let alpha = (-m[(1, 2)]).atan2(m[(2, 2)]);
    let gamma = (-m[(0, 1)]).atan2(m[(0, 0)]);
    let t = pose.translation.vector;
    let n = plane.normal;
    let std = |i: usize| covariance[(i, i)].max(0.0).sqrt();
    format!(
        "* robocal laser plane, HALCON-style sheet-of-light parameters\n\
         * LightplanePose: pose of the light plane (its z = 0) in the camera frame,\n\
         * [tx, ty, tz (m), alpha, beta, gamma (deg), type 0 ('Rp+T', 'gba', 'point')]\n\
         LightplanePose := [{}, {}, {}, {}, {}, {}, 0]\n\
         * the plane n . X = d in the camera frame (m) and the standard deviations\n\
         LightplaneNormal := [{}, {}, {}]\n\
         LightplaneDistance := {}\n\
         LightplaneNormalStd := [{}, {}, {}]\n\
         LightplaneDistanceStd := {}\n",
        float(t.x),
        float(t.y),
        float(t.z),
        float(alpha.to_degrees()),
        float(beta.to_degrees()),
        float(gamma.to_degrees()),
        float(n[0]),
        float(n[1]),
        float(n[2]),
        float(plane.distance_m),
        float(std(0)),
        float(std(1)),
        float(std(2)),
        float(std(3)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::export::{export, export_files, ExportOptions};

    /// A `laser_plane` report as `robocal laser plane` writes it (the keys
    /// export reads, plus a few it passes by).
    fn report() -> String {
        serde_json::json!({
            "kind": "laser_plane", "robocal_version": "0",
            "laser_plane": {
                "normal_camera": [0.0, -0.98, 0.19899748742132398], "distance_m": 0.098,
                "covariance": [[1e-8, 0, 0, 0], [0, 4e-10, 2e-9, 0], [0, 2e-9, 1e-8, 0], [0, 0, 0, 1e-8]],
                "normal_std_deg": 0.005, "distance_std_mm": 0.1
            },
            "residual": "image_px", "extractor": "cog", "images": [], "warnings": []
        })
        .to_string()
    }

    #[test]
    fn a_plane_report_exports_as_robocal_laser_plane_writes_it() {
        let text = report();
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        let (plane, cov) = read_plane_report(&value).unwrap();
        assert_eq!(
            export(&text, "halcon", None).unwrap(),
            export_plane_halcon(&plane, &cov)
        );
        for format in ["urdf", "ros2-static-tf", "matrix4"] {
            let t = TransformFormat::from_name(format).unwrap();
            assert_eq!(
                export(&text, format, None).unwrap(),
                export_plane_frame(&plane, t).unwrap(),
                "{format}"
            );
        }
        let files = export_files(&text, "halcon", &ExportOptions::default()).unwrap();
        assert_eq!(files[0].name, "laser_plane_halcon.txt");
        assert!(
            files[0].text.contains("LightplanePose := ["),
            "{}",
            files[0].text
        );
        // Frame names by role, as for any transform.
        let renamed = export_files(
            &text,
            "urdf",
            &ExportOptions {
                frames: vec![("laser_plane".into(), "laser_sheet".into())],
                ..ExportOptions::default()
            },
        )
        .unwrap();
        assert!(
            renamed[0].text.contains("laser_sheet"),
            "{}",
            renamed[0].text
        );
        assert_eq!(
            export(&text, "report", None).unwrap().trim_end(),
            crate::io::to_string_pretty(&value)
        );
    }

    #[test]
    fn what_a_laser_report_cannot_be_is_named() {
        let text = report();
        let err = |t: &str, f: &str, tr: Option<&str>| export(t, f, tr).unwrap_err().to_string();
        assert!(
            err(&text, "opencv-yaml", None).starts_with(
                "format: a laser plane report is written as report, halcon (HALCON-style sheet-of-light parameters) or a transform format of its plane frame camera_from_laser_plane ("
            ),
            "{}",
            err(&text, "opencv-yaml", None)
        );
        assert_eq!(
            err(&text, "urdf", Some("gripper_from_camera")),
            "transform: a laser plane report has one transform, camera_from_laser_plane, not 'gripper_from_camera'"
        );
        let points = r#"{"kind": "laser_points", "laser_plane": {"normal_camera": [0, 0, 1], "distance_m": 1}, "points": []}"#;
        assert_eq!(
            err(points, "halcon", None),
            "kind: a 'laser_points' report holds 3-D points: export it as 'report', or export its laser plane report"
        );
        let no_plane = r#"{"kind": "laser_plane", "robocal_version": "0"}"#;
        assert!(err(no_plane, "halcon", None).starts_with("laser_plane: expected {\"laser_plane\""));
    }
}
