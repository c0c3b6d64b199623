//! Rig exports: a [`RigCalibration`] (N cameras and their `camera_from_rig`)
//! written as Kalibr, OpenCV, ROS, URDF and mrcal expect a multi-camera
//! system. The per-camera parts are the single-camera writers'.
//!
//! Which transform each format holds (our `camera_from_rig` maps rig
//! coordinates into the camera; the rig frame is camera `rig_frame`'s):
//! - `kalibr`: `T_cn_cnm1` = camera n from camera n-1, for n >= 1 (Kalibr's
//!   chain), and `cam_overlaps` = the cameras that saw the board together
//!   with camera n in at least one frame.
//! - `opencv-yaml`: `R_k`, `T_k` = camera k from rig (`p_k = R_k p_rig + T_k`,
//!   as `cv2.stereoCalibrate`'s R, T map camera 1 into camera 2).
//! - `ros`, `urdf`: the pose of each camera in the frame `rig` (the child's
//!   pose in the parent, `rig_from_camera`); the rig camera's is the identity.
//! - `mrcal`: `extrinsics` = `rt_cam_ref` with the rig as reference
//!   (rotation vector, then translation: `p_cam = R p_rig + t`).
//!
//! `ros` and `mrcal` are several files ([`ExportFile`]); the one-string
//! entry ([`super::export::export`]) joins them with a `# ==> NAME <==` line
//! before each.

use super::export_camera::{
    export_camera, float, k_row_major, opencv_distortion, yaml_matrix, CameraExportInfo,
    CameraFormat,
};
use super::export_camera_tools::{kalibr_camera, mrcal_model};
use super::export_ros::{ros1_args, ros1_launch_nodes, ros2_args, ros2_launch_nodes, urdf_joint};
use super::export_transform::FrameNames;
use crate::calib::multi::rig_report::RigCalibration;
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{rotvec_from_rotation, Pose};

/// The formats a rig report exports to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RigFormat {
    /// Kalibr camchain YAML (`cam0`, `cam1`, ... with `T_cn_cnm1`).
    Kalibr,
    /// One OpenCV FileStorage YAML: per camera k `camera_matrix_k`,
    /// `distortion_coefficients_k`, `R_k`, `T_k`, `image_width_k`, `image_height_k`.
    OpencvYaml,
    /// One ROS camera_info YAML per camera and the static transforms as
    /// ROS 1 and ROS 2 launch files.
    Ros,
    /// One URDF file: the link `rig`, a link per camera, fixed joints.
    Urdf,
    /// One mrcal `.cameramodel` per camera, with its extrinsics.
    Mrcal,
}

impl RigFormat {
    /// Every rig format, in menu order.
    pub const ALL: [RigFormat; 5] = [
        RigFormat::Kalibr,
        RigFormat::OpencvYaml,
        RigFormat::Ros,
        RigFormat::Urdf,
        RigFormat::Mrcal,
    ];

    /// The name used by the CLI, node and the page.
    pub fn name(self) -> &'static str {
        match self {
            RigFormat::Kalibr => "kalibr",
            RigFormat::OpencvYaml => "opencv-yaml",
            RigFormat::Ros => "ros",
            RigFormat::Urdf => "urdf",
            RigFormat::Mrcal => "mrcal",
        }
    }

    /// Parse a format name; any other name lists the rig formats.
    pub fn from_name(name: &str) -> Result<RigFormat> {
        RigFormat::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| {
                Error::invalid(
                    "format",
                    format!(
                        "format '{name}' is not a rig format: a rig report exports as {} (or report)",
                        rig_format_names().join(", ")
                    ),
                )
            })
    }
}

/// The rig format names, in menu order.
pub fn rig_format_names() -> Vec<&'static str> {
    RigFormat::ALL.iter().map(|f| f.name()).collect()
}

/// One file of an export.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct ExportFile {
    /// A file name (no directory) for it.
    pub name: String,
    /// Its text.
    pub text: String,
}

/// Whether a report is a rig report (it has `cameras` and `co_observation`).
pub fn is_rig_report(report: &serde_json::Value) -> bool {
    report.get("cameras").is_some_and(|c| c.is_array()) && report.get("co_observation").is_some()
}

/// One camera of the rig, read for writing.
struct RigEntry<'a> {
    name: &'a str,
    camera: &'a Camera,
    camera_from_rig: Pose,
    rms_px: f64,
}

fn entries(rig: &RigCalibration) -> Result<Vec<RigEntry<'_>>> {
    if rig.cameras.is_empty() {
        return Err(Error::invalid("cameras", "the rig report has no cameras"));
    }
    super::export::check_one_line("rig_frame", "rig frame name", &rig.rig_frame)?;
    for (k, c) in rig.cameras.iter().enumerate() {
        super::export::check_one_line(&format!("cameras[{k}].name"), "camera name", &c.name)?;
    }
    rig.cameras
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let camera_from_rig = c.camera_from_rig.to_pose().map_err(|e| {
                Error::invalid(format!("cameras[{k}].camera_from_rig"), e.to_string())
            })?;
            Ok(RigEntry {
                name: &c.name,
                camera: &c.calibration.camera,
                camera_from_rig,
                rms_px: c.rms_px,
            })
        })
        .collect()
}

/// Write `rig` in `format`. `frames` renames frames for `ros` and `urdf`
/// by role: `rig` (default name `rig`) and each camera's name.
pub fn export_rig(
    rig: &RigCalibration,
    format: RigFormat,
    frames: &[(String, String)],
) -> Result<Vec<ExportFile>> {
    let cameras = entries(rig)?;
    let one = |name: String, text: String| Ok(vec![ExportFile { name, text }]);
    match format {
        RigFormat::Kalibr => one("camchain.yaml".into(), kalibr(rig, &cameras)?),
        RigFormat::OpencvYaml => one("rig.opencv.yaml".into(), opencv_yaml(rig, &cameras)?),
        RigFormat::Urdf => one("rig.urdf".into(), urdf(&cameras, frames)?),
        RigFormat::Ros => ros(&cameras, frames),
        RigFormat::Mrcal => cameras
            .iter()
            .map(|c| {
                let r = rotvec_from_rotation(&c.camera_from_rig.rotation);
                let t = c.camera_from_rig.translation.vector;
                let text = mrcal_model(c.camera, Some([r.x, r.y, r.z, t.x, t.y, t.z]))
                    .map_err(|e| about_camera(c.name, e))?;
                Ok(ExportFile {
                    name: format!("{}.cameramodel", file_stem(c.name)),
                    text,
                })
            })
            .collect(),
    }
}

/// The files as one text: the file itself when there is one, else each
/// after a line `# ==> NAME <==`.
pub fn join_files(files: &[ExportFile]) -> String {
    match files {
        [one] => one.text.clone(),
        _ => files
            .iter()
            .map(|f| format!("# ==> {} <==\n{}", f.name, f.text))
            .collect(),
    }
}

/// A camera's error, named after the camera.
fn about_camera(name: &str, e: Error) -> Error {
    match e {
        Error::Invalid { field, message } => {
            Error::invalid(field, format!("camera '{name}': {message}"))
        }
        other => other,
    }
}

/// A file name part from a camera name (anything but letters, digits, `-`
/// and `_` becomes `_`).
fn file_stem(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

fn kalibr(rig: &RigCalibration, cameras: &[RigEntry]) -> Result<String> {
    let graph = &rig.co_observation;
    let index_in_graph = |name: &str| graph.cameras.iter().position(|n| n == name);
    let mut out = format!(
        "# robocal {}: rig of {} cameras, T_cn_cnm1 = camera n from camera n-1\n",
        crate::VERSION,
        cameras.len()
    );
    for (n, c) in cameras.iter().enumerate() {
        if !super::export::is_ros_frame_name(c.name) {
            return Err(Error::invalid(
                "format",
                format!("camera '{}': Kalibr's rostopic /{}/image_raw needs a ROS name (letters, digits, _ and /)", c.name, c.name),
            ));
        }
        out += &format!("cam{n}:\n");
        if n > 0 {
            let cn_from_cnm1 = c.camera_from_rig * cameras[n - 1].camera_from_rig.inverse();
            let m = cn_from_cnm1.to_homogeneous();
            out += "  T_cn_cnm1:\n";
            for r in 0..4 {
                let row: Vec<String> = (0..4).map(|col| float(m[(r, col)])).collect();
                out += &format!("  - [{}]\n", row.join(", "));
            }
        }
        let overlaps: Vec<String> = match index_in_graph(c.name) {
            Some(i) => cameras
                .iter()
                .enumerate()
                .filter(|(m, other)| {
                    *m != n
                        && index_in_graph(other.name)
                            .and_then(|j| graph.frames.get(i).and_then(|row| row.get(j)))
                            .is_some_and(|shared| *shared > 0)
                })
                .map(|(m, _)| m.to_string())
                .collect(),
            None => Vec::new(),
        };
        out += &format!("  cam_overlaps: [{}]\n", overlaps.join(", "));
        out += &kalibr_camera(c.camera, c.name).map_err(|e| about_camera(c.name, e))?;
    }
    Ok(out)
}

/// A double-quoted YAML string (OpenCV's FileStorage reads these).
/// A YAML double-quoted scalar (JSON's escapes, so no character of `s`
/// can end the string or the line).
fn quoted(s: &str) -> String {
    serde_json::Value::String(s.to_string()).to_string()
}

fn opencv_yaml(rig: &RigCalibration, cameras: &[RigEntry]) -> Result<String> {
    let mut out = String::from("%YAML:1.0\n---\n");
    out += &format!(
        "# robocal {}: rig of {} cameras; R_k, T_k map rig coordinates (camera {}) into camera k: p_k = R_k p_rig + T_k (metres)\n",
        crate::VERSION,
        cameras.len(),
        quoted(&rig.rig_frame)
    );
    out += &format!(
        "rig_frame: {}\ncamera_count: {}\n",
        quoted(&rig.rig_frame),
        cameras.len()
    );
    for (k, c) in cameras.iter().enumerate() {
        let (dist, fisheye) = opencv_distortion(c.camera).map_err(|e| about_camera(c.name, e))?;
        let camera = c.camera;
        if fisheye {
            out += &format!("# camera {k}: read with cv2.fisheye\n");
        }
        out += &format!(
            "name_{k}: {}\nmodel_{k}: {}\nimage_width_{k}: {}\nimage_height_{k}: {}\n",
            quoted(c.name),
            quoted(camera.distortion.model_name()),
            camera.width,
            camera.height
        );
        out += &yaml_matrix(&format!("camera_matrix_{k}"), 3, 3, &k_row_major(camera));
        out += &yaml_matrix(
            &format!("distortion_coefficients_{k}"),
            1,
            dist.len(),
            &dist,
        );
        let m = c.camera_from_rig.to_homogeneous();
        let r: Vec<f64> = (0..3)
            .flat_map(|row| (0..3).map(move |col| (row, col)))
            .map(|(row, col)| m[(row, col)])
            .collect();
        let t = c.camera_from_rig.translation.vector;
        out += &yaml_matrix(&format!("R_{k}"), 3, 3, &r);
        out += &yaml_matrix(&format!("T_{k}"), 3, 1, &[t.x, t.y, t.z]);
        out += &format!("rms_px_{k}: {}\n", float(c.rms_px));
    }
    Ok(out)
}

/// The frame names and `rig_from_camera` of every camera, for ROS and URDF.
fn rig_links(cameras: &[RigEntry], frames: &[(String, String)]) -> Result<Vec<(Pose, FrameNames)>> {
    let named = |role: &str| -> Result<String> {
        let name = frames
            .iter()
            .rev()
            .find(|(r, _)| r == role)
            .map(|(_, n)| n.clone())
            .unwrap_or_else(|| role.to_string());
        if super::export::is_ros_frame_name(&name) {
            Ok(name)
        } else {
            Err(Error::invalid(
                "frame_names",
                format!("the {role} frame name '{name}' is not a ROS frame name: use letters, digits, _ and / (starting with a letter, _ or /), or rename it with --frame {role}=NAME"),
            ))
        }
    };
    let parent = named("rig")?;
    cameras
        .iter()
        .map(|c| {
            Ok((
                c.camera_from_rig.inverse(),
                FrameNames {
                    parent: parent.clone(),
                    child: named(c.name)?,
                    key: format!("rig_from_{}", c.name),
                },
            ))
        })
        .collect()
}

fn urdf(cameras: &[RigEntry], frames: &[(String, String)]) -> Result<String> {
    let links = rig_links(cameras, frames)?;
    let mut out = String::from("<?xml version=\"1.0\"?>\n<!-- robocal rig: each joint's origin is the camera's pose in the rig frame (rig_from_camera); camera frames are optical (z forward, x right, y down) -->\n<robot name=\"robocal_rig\">\n");
    if let Some((_, names)) = links.first() {
        out += &format!("  <link name=\"{}\"/>\n", names.parent);
    }
    for (_, names) in &links {
        out += &format!("  <link name=\"{}\"/>\n", names.child);
    }
    for (pose, names) in &links {
        out += &urdf_joint(pose, names)
            .lines()
            .map(|l| format!("  {l}\n"))
            .collect::<String>();
    }
    out += "</robot>\n";
    Ok(out)
}

fn ros(cameras: &[RigEntry], frames: &[(String, String)]) -> Result<Vec<ExportFile>> {
    let links = rig_links(cameras, frames)?;
    let mut files = Vec::with_capacity(cameras.len() + 2);
    for (c, (_, names)) in cameras.iter().zip(&links) {
        let info = CameraExportInfo {
            name: names.child.clone(),
            rms_px: Some(c.rms_px),
            ..CameraExportInfo::default()
        };
        let text = export_camera(c.camera, &info, CameraFormat::RosYaml)
            .map_err(|e| about_camera(c.name, e))?;
        files.push(ExportFile {
            name: format!("{}.yaml", file_stem(c.name)),
            text,
        });
    }
    let label = "rig_from_camera for every camera";
    let ros1: Vec<(String, FrameNames)> = links
        .iter()
        .map(|(pose, names)| (ros1_args(pose, names), names.clone()))
        .collect();
    let ros2: Vec<(String, FrameNames)> = links
        .iter()
        .map(|(pose, names)| (ros2_args(pose, names), names.clone()))
        .collect();
    files.push(ExportFile {
        name: "rig_tf.launch".into(),
        text: ros1_launch_nodes(label, &ros1),
    });
    files.push(ExportFile {
        name: "rig_tf.launch.py".into(),
        text: ros2_launch_nodes(label, &ros2),
    });
    Ok(files)
}
