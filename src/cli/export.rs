//! `robocal export`: convert a report into any export format.

use super::{read_text, write_output, CliError};

#[derive(clap::Args)]
#[command(
    about = "convert a calibration report into OpenCV, ROS, Kalibr, mrcal, Halcon, MATLAB, URDF, robot-controller and other formats",
    long_about = "convert a calibration report into another format

REPORT.json is the output of 'robocal intrinsics' (a camera) or
'robocal handeye' (transforms), or any JSON with the same keys.",
    after_help = "Camera formats:
  json          robocal's camera JSON (schema robocal.camera.v1)
  opencv-yaml   OpenCV FileStorage YAML (cv2.FileStorage, camera_matrix, distortion_coefficients)
  opencv-xml    OpenCV FileStorage XML
  ros-yaml      ROS camera_info YAML
  kalibr        Kalibr camchain YAML
  mrcal         mrcal .cameramodel
  halcon        Halcon camera parameter tuple (metric, nominal 5 um pixels)
  matlab        MATLAB cameraIntrinsics script (1-based principal point)
  text          the 3x3 camera matrix
  report        the report itself, pretty-printed

Transform formats (of gripper_from_camera, base_from_camera, right_from_left
or base_from_target, the first present; choose with --transform):
  matrix4, xyz-quat-xyzw, xyz-quat-wxyz, urdf, ros2-static-tf, ur, kuka,
  abb-tooldata, abb-wobjdata, fanuc, and euler-<intrinsic|extrinsic>-<order>-<deg|rad>
  with order one of xyz xzy yxz yzx zxy zyx xyx xzx yxy yzy zxz zyz.

Output goes to FILE with -o, else to stdout.

Examples:
  robocal export camera.json --format opencv-yaml -o camera.yaml
  robocal export handeye.json --format urdf --transform gripper_from_camera
  robocal export handeye.json --format euler-extrinsic-xyz-deg",
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
    /// Write the export there (default: standard output)
    #[arg(short = 'o', long, value_name = "FILE")]
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
    let text = read_text(report)?;
    let out = robocal::io::export::export(&text, format, args.transform.as_deref())?;
    write_output(args.output.as_deref(), &out)
}
