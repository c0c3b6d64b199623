//! `robocal export`: convert a report into any export format.

use super::args::{Args, Spec};
use super::{read_text, write_output, CliError};

pub const HELP: &str = "robocal export - convert a calibration report into another format

Usage: robocal export REPORT.json --format NAME [--transform NAME] [-o FILE]

REPORT.json is the output of 'robocal intrinsics' (a camera) or
'robocal handeye' (transforms), or any JSON with the same keys.

Camera formats:
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
  robocal export handeye.json --format euler-extrinsic-xyz-deg";

pub fn run(raw: &[String]) -> Result<(), CliError> {
    let spec = Spec {
        command: "export",
        valued: &["format", "transform", "output"],
        switches: &[],
    };
    let args = Args::parse(raw, &spec)?;
    let [report] = args.positionals.as_slice() else {
        return Err(CliError::usage("export", "give exactly one REPORT.json"));
    };
    let format = args
        .value("format")
        .ok_or_else(|| CliError::usage("export", "--format is required"))?;
    let text = read_text(report)?;
    let out = robocal::io::export::export(&text, format, args.value("transform"))?;
    write_output(args.value("output"), &out)
}
