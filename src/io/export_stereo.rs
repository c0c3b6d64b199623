//! Stereo exports: a stereo report (`robocal stereo`: `left`, `right` camera
//! reports and `right_from_left`) written as OpenCV, ROS and Kalibr users
//! keep a calibrated pair.
//!
//! `right_from_left` is OpenCV's `R`, `T` of `cv2.stereoCalibrate`:
//! `x_right = R x_left + T` (metres). What each format holds:
//! - `opencv-yaml`: one FileStorage file with the keys of OpenCV's stereo
//!   samples, `image_width`, `image_height`, `K1`, `D1`, `K2`, `D2`, `R`,
//!   `T`, `E` (`[T]x R`), `F` (`K2^-T E K1^-1`) and the rectification
//!   `R1`, `R2`, `P1`, `P2`, `Q` of [`crate::calib::multi::stereo_rectify::rectify`]
//!   (`cv2.stereoRectify` with `CALIB_ZERO_DISPARITY`, `alpha = -1`).
//! - `ros`: `left.yaml` and `right.yaml`, the camera_info files ROS's
//!   `camera_calibration` writes for a stereo pair: each camera's K and D,
//!   `rectification_matrix` R1 / R2 and `projection_matrix` P1 / P2 (P2's
//!   `Tx = -fx' * baseline` in its fourth column), from the same
//!   rectification.
//! - `kalibr`: a camchain with `cam0` (left) and `cam1` (right), cam1's
//!   `T_cn_cnm1` = right_from_left as a 4x4 matrix.
//!
//! The cameras are named `left` and `right` (ROS `camera_name`, Kalibr's
//! `/left/image_raw`) unless `--frame left=NAME` / `--frame right=NAME`
//! rename them.

use super::export::ExportFile;
use super::export_camera::{
    float, k_row_major, opencv_distortion, ros_camera_info, yaml_matrix, CameraExportInfo,
};
use super::export_camera_tools::kalibr_camera;
use super::import_camera::import_camera;
use crate::calib::multi::stereo_rectify::{essential_matrix, fundamental_matrix, rectify};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::Pose;
use nalgebra::DMatrix;

/// The formats a stereo report exports to as a pair (besides `report` and
/// every transform format, which write `right_from_left`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StereoFormat {
    /// One OpenCV FileStorage YAML: K1 D1 K2 D2 R T E F R1 R2 P1 P2 Q.
    OpencvYaml,
    /// ROS camera_info YAMLs `left.yaml` and `right.yaml`, rectified.
    Ros,
    /// Kalibr camchain with `cam0`, `cam1` and cam1's `T_cn_cnm1`.
    Kalibr,
}

impl StereoFormat {
    /// Every stereo format, in menu order.
    pub const ALL: [StereoFormat; 3] = [
        StereoFormat::OpencvYaml,
        StereoFormat::Ros,
        StereoFormat::Kalibr,
    ];

    /// The name used by the CLI, node and the page.
    pub fn name(self) -> &'static str {
        match self {
            StereoFormat::OpencvYaml => "opencv-yaml",
            StereoFormat::Ros => "ros",
            StereoFormat::Kalibr => "kalibr",
        }
    }

    /// The format of a name, `None` for any other name.
    pub fn from_name(name: &str) -> Option<StereoFormat> {
        StereoFormat::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// The stereo format names, in menu order.
pub fn stereo_format_names() -> Vec<&'static str> {
    StereoFormat::ALL.iter().map(|f| f.name()).collect()
}

/// Whether a report is a stereo report (objects `left` and `right`, and
/// `right_from_left`).
pub fn is_stereo_report(report: &serde_json::Value) -> bool {
    report.get("left").is_some_and(|v| v.is_object())
        && report.get("right").is_some_and(|v| v.is_object())
        && report.get("right_from_left").is_some()
}

/// The error for a format a stereo pair cannot be written in as a pair.
pub fn not_a_stereo_format(format: &str) -> Error {
    Error::invalid(
        "format",
        format!(
            "format '{format}' cannot hold a stereo pair: a stereo report exports as {} (both cameras), as a transform format (right_from_left, e.g. matrix4) or as report",
            stereo_format_names().join(", ")
        ),
    )
}

/// One camera of the pair, read for writing.
struct Side {
    role: &'static str,
    name: String,
    camera: Camera,
    rms_px: Option<f64>,
}

/// The pair of a stereo report.
struct Pair {
    left: Side,
    right: Side,
    right_from_left: Pose,
}

fn read_pair(report: &serde_json::Value, frames: &[(String, String)]) -> Result<Pair> {
    let side = |role: &'static str| -> Result<Side> {
        let (camera, _) = import_camera(&report[role].to_string()).map_err(|e| match e {
            Error::Invalid { field, message } => Error::invalid(format!("{role}.{field}"), message),
            other => other,
        })?;
        let name = frames
            .iter()
            .rev()
            .find(|(r, _)| r == role)
            .map_or(role.to_string(), |(_, n)| n.clone());
        if !super::export::is_ros_frame_name(&name) {
            return Err(Error::invalid(
                "frame_names",
                format!("the {role} camera name '{}' is not a ROS name: use letters, digits, _ and / (starting with a letter, _ or /), e.g. --frame {role}=cam0", name.escape_default()),
            ));
        }
        Ok(Side {
            role,
            name,
            camera,
            rms_px: report[role]["rms_px"].as_f64(),
        })
    };
    Ok(Pair {
        left: side("left")?,
        right: side("right")?,
        right_from_left: super::export::pose_from_report(report, "right_from_left")?,
    })
}

/// Write the stereo report `report` in `format`; `frames` renames the
/// cameras (`left`, `right`).
pub fn export_stereo(
    report: &serde_json::Value,
    format: StereoFormat,
    frames: &[(String, String)],
) -> Result<Vec<ExportFile>> {
    let pair = read_pair(report, frames)?;
    let one = |name: &str, text: String| {
        Ok(vec![ExportFile {
            name: name.into(),
            text,
        }])
    };
    match format {
        StereoFormat::OpencvYaml => one("stereo.opencv.yaml", opencv_yaml(&pair, report)?),
        StereoFormat::Ros => ros(&pair),
        StereoFormat::Kalibr => one("camchain.yaml", kalibr(&pair)?),
    }
}

/// A camera's error, named after its side.
fn about(side: &Side, e: Error) -> Error {
    match e {
        Error::Invalid { field, message } => {
            Error::invalid(field, format!("{} camera: {message}", side.role))
        }
        other => other,
    }
}

/// OpenCV and ROS rectify one image size: both cameras must have it.
fn one_size(pair: &Pair, format: &str) -> Result<()> {
    let (l, r) = (&pair.left.camera, &pair.right.camera);
    if (l.width, l.height) == (r.width, r.height) {
        return Ok(());
    }
    Err(Error::invalid(
        "format",
        format!(
            "format '{format}' holds one image size for both cameras (as cv2.stereoRectify takes one), but the left camera is {}x{} and the right {}x{}: export as kalibr, or each camera alone",
            l.width, l.height, r.width, r.height
        ),
    ))
}

fn row_major(m: &DMatrix<f64>) -> Vec<f64> {
    (0..m.nrows())
        .flat_map(|r| (0..m.ncols()).map(move |c| (r, c)))
        .map(|(r, c)| m[(r, c)])
        .collect()
}

fn matrix<R: nalgebra::Dim, C: nalgebra::Dim, S: nalgebra::RawStorage<f64, R, C>>(
    name: &str,
    m: &nalgebra::Matrix<f64, R, C, S>,
) -> String {
    let d = DMatrix::from_fn(m.nrows(), m.ncols(), |r, c| m[(r, c)]);
    yaml_matrix(name, m.nrows(), m.ncols(), &row_major(&d))
}

fn opencv_yaml(pair: &Pair, report: &serde_json::Value) -> Result<String> {
    one_size(pair, "opencv-yaml")?;
    let (l, r) = (&pair.left, &pair.right);
    let (d1, fisheye1) = opencv_distortion(&l.camera).map_err(|e| about(l, e))?;
    let (d2, fisheye2) = opencv_distortion(&r.camera).map_err(|e| about(r, e))?;
    let rect = rectify(&l.camera, &r.camera, &pair.right_from_left)?;
    let e = essential_matrix(&pair.right_from_left);
    let f = fundamental_matrix(&l.camera, &r.camera, &pair.right_from_left)?;
    let rot = pair
        .right_from_left
        .rotation
        .to_rotation_matrix()
        .into_inner();
    let t = pair.right_from_left.translation.vector;
    let mut out = String::from("%YAML:1.0\n---\n");
    out += &format!(
        "# robocal {}: stereo pair, left {} and right {} model{}\n",
        crate::VERSION,
        l.camera.distortion.model_name(),
        r.camera.distortion.model_name(),
        if fisheye1 || fisheye2 {
            " (read D1, D2 with cv2.fisheye)"
        } else {
            ""
        }
    );
    out += "# R, T map left-camera coordinates into the right camera: x_right = R x_left + T (metres), as cv2.stereoCalibrate returns them\n";
    out += "# E = [T]x R, F = K2^-T E K1^-1; R1 R2 P1 P2 Q as cv2.stereoRectify with CALIB_ZERO_DISPARITY and alpha -1\n";
    out += &format!(
        "image_width: {}\nimage_height: {}\n",
        l.camera.width, l.camera.height
    );
    out += &yaml_matrix("K1", 3, 3, &k_row_major(&l.camera));
    out += &yaml_matrix("D1", 1, d1.len(), &d1);
    out += &yaml_matrix("K2", 3, 3, &k_row_major(&r.camera));
    out += &yaml_matrix("D2", 1, d2.len(), &d2);
    out += &matrix("R", &rot);
    out += &yaml_matrix("T", 3, 1, &[t.x, t.y, t.z]);
    out += &matrix("E", &e);
    out += &matrix("F", &f);
    out += &matrix("R1", &rect.r1);
    out += &matrix("R2", &rect.r2);
    out += &matrix("P1", &rect.p1);
    out += &matrix("P2", &rect.p2);
    out += &matrix("Q", &rect.q);
    if let Some(rms) = report["rms_px"].as_f64() {
        out += &format!("rms_px: {}\n", float(rms));
    }
    Ok(out)
}

fn ros(pair: &Pair) -> Result<Vec<ExportFile>> {
    one_size(pair, "ros")?;
    let rect = rectify(&pair.left.camera, &pair.right.camera, &pair.right_from_left)?;
    [
        (&pair.left, rect.r1, rect.p1),
        (&pair.right, rect.r2, rect.p2),
    ]
    .into_iter()
    .map(|(side, r, p)| {
        let info = CameraExportInfo {
            name: side.name.clone(),
            rms_px: side.rms_px,
            ..CameraExportInfo::default()
        };
        let r: Vec<f64> = (0..9).map(|i| r[(i / 3, i % 3)]).collect();
        let p: Vec<f64> = (0..12).map(|i| p[(i / 4, i % 4)]).collect();
        let text =
            ros_camera_info(&side.camera, &info, Some((&r, &p))).map_err(|e| about(side, e))?;
        Ok(ExportFile {
            name: format!("{}.yaml", side.role),
            text,
        })
    })
    .collect()
}

/// The `T_cn_cnm1` lines of a Kalibr camchain camera (indented two spaces).
pub(super) fn kalibr_transform(cn_from_cnm1: &Pose) -> String {
    let m = cn_from_cnm1.to_homogeneous();
    let mut out = String::from("  T_cn_cnm1:\n");
    for r in 0..4 {
        let row: Vec<String> = (0..4).map(|c| float(m[(r, c)])).collect();
        out += &format!("  - [{}]\n", row.join(", "));
    }
    out
}

fn kalibr(pair: &Pair) -> Result<String> {
    let mut out = format!(
        "# robocal {}: stereo pair, cam0 = left, cam1 = right, T_cn_cnm1 = right_from_left (x_right = T x_left)\n",
        crate::VERSION
    );
    for (n, side) in [&pair.left, &pair.right].into_iter().enumerate() {
        out += &format!("cam{n}:\n");
        if n == 1 {
            out += &kalibr_transform(&pair.right_from_left);
        }
        out += &format!("  cam_overlaps: [{}]\n", 1 - n);
        out += &kalibr_camera(&side.camera, &side.name).map_err(|e| about(side, e))?;
    }
    Ok(out)
}
