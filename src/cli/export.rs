//! `robocal export`: convert a report into any export format.

use super::{read_text, write_output, CliError};
use robocal::api::export::ExportRequest;

#[derive(clap::Args)]
#[command(
    about = "convert a calibration report into OpenCV, ROS, Kalibr, mrcal, Halcon, MATLAB, URDF, robot-controller and other formats",
    long_about = "convert a calibration report into another format

REPORT.json is the output of 'robocal intrinsics' (a camera),
'robocal handeye' (transforms), 'robocal stereo' (a stereo pair) or
'robocal rig' (a camera rig), or any JSON with the same keys.",
    after_help = "Camera formats:
  json          robocal's camera JSON (schema robocal.camera.v1)
  opencv-yaml   OpenCV FileStorage YAML (cv2.FileStorage, camera_matrix, distortion_coefficients)
  opencv-xml    OpenCV FileStorage XML
  ros-yaml      ROS camera_info YAML
  kalibr        Kalibr camchain YAML
  mrcal         mrcal .cameramodel
  halcon        Halcon camera parameter tuple (metric, nominal 5 um pixels)
  matlab        MATLAB cameraIntrinsics script (1-based principal point)
  text          the 3x3 camera matrix, then '# image_size_px: W H' (read back by --camera)
  report        the report itself, pretty-printed
  remap         a dense undistortion map for cv2.remap, any lens model (splined
                included): OpenCV FileStorage YAML with mapx, mapy (rows =
                height, cols = width) onto the distortion-free camera_matrix
                (about 20 MB at 1280x960)

Transform formats (of gripper_from_camera, base_from_camera, right_from_left
or base_from_target, the first present; choose with --transform):
  matrix4, xyz-quat-xyzw, xyz-quat-wxyz, urdf (the joint), urdf-robot (a whole
  .urdf file), ros2-static-tf, ros1-static-tf, ros1-launch (XML), ros2-launch
  (Python), ur, kuka, abb-tooldata, abb-wobjdata, fanuc, and
  euler-<intrinsic|extrinsic>-<order>-<deg|rad>
  with order one of xyz xzy yxz yzx zxy zyx xyx xzx yxy yzy zxz zyz.

Frame names: a transform a_from_b is written with parent frame a and child
frame b (gripper_from_camera: gripper, camera). --frame ROLE=NAME renames a
role in the output, e.g. --frame gripper=tool0 --frame camera=camera_optical_frame
--frame base=base_link; a report's \"frame_names\" object does the same
({\"gripper\": \"tool0\"}), --frame wins. robocal's camera frame is the optical
frame (z forward, x right, y down): in ROS that is a *_optical_frame, not
camera_link (x forward).

Rig reports (robocal rig): --format kalibr (camchain, T_cn_cnm1 = camera n
from camera n-1), opencv-yaml (one FileStorage: camera_matrix_k,
distortion_coefficients_k, R_k, T_k = camera k from rig), ros (a camera_info
YAML per camera and rig_tf.launch / rig_tf.launch.py placing each camera in
the frame 'rig'), urdf (link rig, fixed joints rig -> each camera), mrcal (a
.cameramodel per camera, extrinsics = rt_cam_ref with the rig as reference).
Frames: --frame rig=NAME, --frame CAMERA=NAME.

Stereo reports (robocal stereo; right_from_left is OpenCV's R, T:
x_right = R x_left + T): --format opencv-yaml (one FileStorage as OpenCV's
stereo samples keep it: image_width, image_height, K1 D1 K2 D2 R T, E = [T]x R,
F = K2^-T E K1^-1, and R1 R2 P1 P2 Q of cv2.stereoRectify with
CALIB_ZERO_DISPARITY and alpha -1), ros (left.yaml and right.yaml, the
camera_info files of ROS camera_calibration's stereo: rectification_matrix
R1/R2, projection_matrix P1/P2), kalibr (cam0 = left, cam1 = right with
T_cn_cnm1 = right_from_left), or a transform format (right_from_left).
Frames: --frame left=NAME, --frame right=NAME (ROS camera_name, Kalibr topic).

Output goes to FILE with -o, else to stdout. Formats of several files (a
rig's ros and mrcal, a stereo pair's ros) go into the folder DIR with -o DIR, else to stdout
each after a line '# ==> NAME <=='.

Examples:
  robocal export camera.json --format opencv-yaml -o camera.yaml
  robocal export handeye.json --format urdf --transform gripper_from_camera
  robocal export handeye.json --format euler-extrinsic-xyz-deg
  robocal export handeye.json --format ros1-launch --frame gripper=tool0 --frame camera=camera_optical_frame
  robocal export rig.json --format kalibr -o camchain.yaml
  robocal export rig.json --format ros -o rig_ros/
  robocal export stereo.json --format opencv-yaml -o stereo.yaml",
    args_override_self = true
)]
pub struct ExportArgs {
    /// The report: robocal's camera JSON, an intrinsics, handeye or stereo report
    #[arg(value_name = "REPORT.json")]
    reports: Vec<String>,
    /// The output format (see the lists below)
    #[arg(long, value_name = "NAME")]
    format: Option<String>,
    /// Which transform of the report to export (default: the first present)
    #[arg(long, value_name = "NAME")]
    transform: Option<String>,
    /// Name a frame in the output: ROLE=NAME, e.g. gripper=tool0 (repeatable)
    #[arg(long = "frame", value_name = "ROLE=NAME")]
    frames: Vec<String>,
    /// Write the export there (default: standard output); a folder for formats of several files
    #[arg(short = 'o', long, value_name = "FILE|DIR")]
    output: Option<String>,
}

pub fn run(args: ExportArgs) -> Result<(), CliError> {
    let [report] = args.reports.as_slice() else {
        return Err(CliError::usage("export", "give exactly one REPORT.json"));
    };
    let format = args
        .format
        .as_deref()
        .ok_or_else(|| CliError::usage("export", "--format is required"))?;
    let request = ExportRequest {
        format: format.to_string(),
        transform: args.transform.clone(),
        frames: Default::default(),
    }
    .with_frame_args(&args.frames)
    .map_err(|e| match e {
        robocal::Error::Invalid { message, .. } => CliError::usage("export", message),
        other => other.into(),
    })?;
    let text = read_text(report)?;
    let files = robocal::api::export::export(&text, &request)?;
    match (files.as_slice(), args.output.as_deref()) {
        ([one], path) => write_output(path, &one.text),
        (_, None | Some("-")) => write_output(None, &robocal::io::export::join_files(&files)),
        (_, Some(dir)) => write_files(dir, &files),
    }
}

/// Several files (a rig's ros and mrcal) into the folder `dir`, created if
/// missing; their names are listed on stderr.
fn write_files(dir: &str, files: &[robocal::io::export::ExportFile]) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::Io(format!("cannot create the folder '{dir}': {e}")))?;
    for f in files {
        let path = std::path::Path::new(dir).join(&f.name);
        super::output::write_file(&path, f.text.as_bytes())?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
