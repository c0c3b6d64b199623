//! `robocal laser`: the laser plane of a laser-line sensor from board
//! images, and stripe images to 3-D points (docs/laser.md).

use super::{read_text, CliError, ImageLimits};
use robocal::api::laser::{
    laser_plane, laser_plane_refining_camera, laser_points, plane_from_json, LaserPlaneSettings,
    LaserView,
};
use robocal::camera::Camera;
use robocal::geometry::{Pose, PoseJson};
use robocal::image::GrayImage;
use robocal::io::export_laser::{export_plane_frame, export_plane_halcon};
use robocal::io::export_transform::TransformFormat;
use robocal::laser::{PlaneResidual, ScanAxis, StripeMethod, StripeOptions};

#[derive(clap::Args)]
#[command(
    about = "laser-line sensors: the laser plane from board images, stripe images to 3-D points",
    long_about = "laser-line sensors: the laser plane from board images, stripe images to 3-D points

  robocal laser plane --camera FILE --target SPEC [--pairs] IMAGES... [-o FILE]
  robocal laser points --camera FILE --plane FILE [--off FILE] IMAGE [-o FILE]
  robocal laser sphere --camera FILE --plane FILE --gripper-from-camera FILE --radius-mm R
      --base-from-gripper POSE... IMAGES... [-o FILE]

plane: per board pose, the board is detected and its pose found with the
calibrated camera, the stripe's centre is extracted in every column (or
row) on the board and met with the board's plane; the plane is fitted to
those points at two or more poses. The JSON report holds
laser_plane.normal_camera (unit vector), laser_plane.distance_m and
laser_plane.covariance (4x4 over nx, ny, nz, d), per-image residuals and
warnings when the poses do not constrain the plane. --refine-intrinsics
refines the camera with the plane (the boards' corners and the stripe in one
least squares) and adds refined_camera.

points: the stripe of one image met with the plane: 3-D points in the camera
frame (and the flange and base frames with --gripper-from-camera and
--base-from-gripper).

sphere: the sensor on the robot from laser images of a sphere of known
radius at several robot poses (one --base-from-gripper per image): the
laser plane, the camera's mounting gripper_from_camera and the sphere's
centre refined together from start values (a plane and a mounting within a
few mm and degrees), with their covariance; the plane also in the flange
frame.",
    after_help = "Examples:
  robocal render --out scans --views 4 --laser-plane 0,-0.98,0.196,0.098
  robocal laser plane --camera camera.json --target chessboard:9x6:30mm --pairs \\
      scans/view_000.png scans/view_000_laser.png scans/view_001.png scans/view_001_laser.png -o plane.json
  robocal laser plane --camera camera.json --target chessboard:9x6:30mm --pairs --format halcon scans/*.png
  robocal laser points --camera camera.json --plane plane.json --off scans/view_002.png scans/view_002_laser.png"
)]
pub struct LaserArgs {
    #[command(subcommand)]
    command: LaserCommand,
}

#[derive(clap::Subcommand)]
enum LaserCommand {
    /// The laser plane in the camera frame from images of a board with the stripe
    Plane(PlaneArgs),
    /// A stripe image to 3-D points with a known laser plane
    Points(PointsArgs),
    /// The plane and the camera on the robot's flange from scans of a sphere
    Sphere(super::laser_sphere::SphereArgs),
}

/// Stripe extraction flags shared by the subcommands.
#[derive(clap::Args)]
pub(super) struct StripeArgs {
    /// Stripe extractor: cog (centre of gravity over a thresholded window)
    /// or ridge (Steger's ridge detector)
    #[arg(long, value_name = "NAME", default_value = "cog")]
    extractor: String,
    /// Scan axis: auto, columns (a horizontal stripe) or rows
    #[arg(long, value_name = "AXIS", default_value = "auto")]
    axis: String,
    /// Smallest peak contrast above the local background, grey levels
    #[arg(long, value_name = "GREY", default_value_t = 20.0)]
    min_contrast: f64,
    /// Widest stripe expected, pixels
    #[arg(long, value_name = "PX", default_value_t = 24.0)]
    max_width: f64,
}

/// The arguments every multi-image laser command shares (`plane`,
/// `sphere`): the stripe extraction, the image limits, the output and the
/// images (one per pose, or pairs with --pairs: the laser off first).
#[derive(clap::Args)]
pub(super) struct ScanArgs {
    #[command(flatten)]
    pub(super) stripe: StripeArgs,
    #[command(flatten)]
    pub(super) limits: ImageLimits,
    /// Output file (default: standard output)
    #[arg(short, long, value_name = "FILE")]
    pub(super) output: Option<String>,
    /// The images, one per pose (plane: showing board and stripe; sphere:
    /// the laser image), or pairs with --pairs: the laser off, then on
    #[arg(value_name = "IMAGES", required = true)]
    pub(super) images: Vec<String>,
}

impl ScanArgs {
    /// The images read in chunks of `step` (1, or 2 with --pairs): each
    /// chunk's last path (the view's name), its first image and its second
    /// when there is one.
    pub(super) fn read(
        &self,
        step: usize,
    ) -> Result<Vec<(String, GrayImage, Option<GrayImage>)>, CliError> {
        let mut out = Vec::new();
        for chunk in self.images.chunks(step) {
            let first = read_gray(&chunk[0], &self.limits)?;
            let second = match chunk.get(1) {
                Some(p) => Some(read_gray(p, &self.limits)?),
                None => None,
            };
            out.push((chunk.last().cloned().unwrap_or_default(), first, second));
        }
        Ok(out)
    }
}

#[derive(clap::Args)]
struct PlaneArgs {
    /// The calibrated camera (robocal/OpenCV/ROS camera file)
    #[arg(long, value_name = "FILE")]
    camera: String,
    /// The board: chessboard:9x6:30mm, ... (robocal target --help)
    #[arg(long, value_name = "SPEC")]
    target: String,
    /// The images come in pairs: the board with the laser off, then the
    /// stripe image with it on
    #[arg(long)]
    pairs: bool,
    /// Residual: image_px (default: pixels along the scan, weighted by each
    /// centre's std) or point_to_plane (metres)
    #[arg(long, value_name = "NAME", default_value = "image_px")]
    residual: String,
    /// Refine the camera jointly with the plane and the board poses from
    /// the boards' corners and the stripe (3 or more poses; coefficients at
    /// 0 stay 0; a tilted camera's tilt, principal point and p1, p2 are
    /// held, with a warning); the JSON report gains refined_camera
    #[arg(long)]
    refine_intrinsics: bool,
    /// Output: json (the report), halcon (a sheet-of-light parameter list)
    /// or a transform format of the plane frame (urdf, ros2, ros1, matrix, ...)
    #[arg(long, value_name = "FORMAT", default_value = "json")]
    format: String,
    #[command(flatten)]
    scans: ScanArgs,
}

#[derive(clap::Args)]
struct PointsArgs {
    /// The calibrated camera
    #[arg(long, value_name = "FILE")]
    camera: String,
    /// The laser plane (a `robocal laser plane` report)
    #[arg(long, value_name = "FILE")]
    plane: String,
    /// The same view with the laser off, subtracted before extraction
    #[arg(long, value_name = "FILE")]
    off: Option<String>,
    /// The camera's mounting: a JSON pose (matrix_row_major) or a hand-eye
    /// report's gripper_from_camera; adds flange_m to every point
    #[arg(long, value_name = "FILE")]
    gripper_from_camera: Option<String>,
    /// The robot's flange pose for this image (JSON pose); adds base_m
    #[arg(long, value_name = "FILE", requires = "gripper_from_camera")]
    base_from_gripper: Option<String>,
    #[command(flatten)]
    stripe: StripeArgs,
    #[command(flatten)]
    limits: ImageLimits,
    /// Output file (default: standard output)
    #[arg(short, long, value_name = "FILE")]
    output: Option<String>,
    /// The stripe image
    #[arg(value_name = "IMAGE")]
    image: String,
}

pub fn run(args: LaserArgs) -> Result<(), CliError> {
    match args.command {
        LaserCommand::Plane(a) => run_plane(a),
        LaserCommand::Points(a) => run_points(a),
        LaserCommand::Sphere(a) => super::laser_sphere::run_sphere(a),
    }
}

pub(super) fn stripe_options(a: &StripeArgs) -> Result<StripeOptions, CliError> {
    let method = StripeMethod::from_name(&a.extractor)
        .map_err(|e| CliError::usage("laser", e.to_string()))?;
    let axis = match a.axis.as_str() {
        "auto" => None,
        "columns" => Some(ScanAxis::Columns),
        "rows" => Some(ScanAxis::Rows),
        other => {
            return Err(CliError::usage(
                "laser",
                format!("--axis must be auto, columns or rows, got '{other}'"),
            ))
        }
    };
    Ok(StripeOptions {
        method,
        axis,
        min_contrast: a.min_contrast,
        max_width_px: a.max_width,
        ..StripeOptions::default()
    })
}

pub(super) fn read_camera(path: &str) -> Result<Camera, CliError> {
    Ok(robocal::io::import_camera::import_camera(&read_text(path)?)
        .map_err(|e| CliError::from(e).in_file(path))?
        .0)
}

pub(super) fn read_gray(path: &str, limits: &ImageLimits) -> Result<GrayImage, CliError> {
    let bytes = super::image_file::read_image(path, &limits.decode_options())?;
    robocal::image::decode_gray(&bytes).map_err(|e| CliError::from(e).in_file(path))
}

fn run_plane(a: PlaneArgs) -> Result<(), CliError> {
    let camera = read_camera(&a.camera)?;
    let (target, _) = super::parse_target_print("laser", &a.target)?;
    let residual = PlaneResidual::from_name(&a.residual)
        .map_err(|e| CliError::usage("laser", e.to_string()))?;
    let format = a.format.as_str();
    let transform = match format {
        "json" | "halcon" => None,
        other => Some(TransformFormat::from_name(other).map_err(|_| {
            CliError::usage(
                "laser",
                format!(
                    "--format must be json, halcon or a transform format ({}), got '{other}'",
                    TransformFormat::names().join(", ")
                ),
            )
        })?),
    };
    if a.pairs && a.scans.images.len() % 2 != 0 {
        return Err(CliError::usage(
            "laser",
            format!(
                "--pairs needs an even number of images (board, stripe, board, stripe, ...), got {}",
                a.scans.images.len()
            ),
        ));
    }
    let views: Vec<LaserView> = a
        .scans
        .read(if a.pairs { 2 } else { 1 })?
        .into_iter()
        .map(|(name, board, stripe)| LaserView {
            name,
            board,
            stripe,
        })
        .collect();
    let settings = LaserPlaneSettings {
        residual,
        stripe: stripe_options(&a.scans.stripe)?,
        detect: super::detect_options_of(Some(&a.target)),
    };
    let (report, refined) = if a.refine_intrinsics {
        let (report, camera) = laser_plane_refining_camera(&camera, &target, &views, &settings)?;
        (report, Some(camera))
    } else {
        (laser_plane(&camera, &target, &views, &settings)?, None)
    };
    for w in &report.warnings {
        eprintln!("robocal laser plane: warning: {w}");
    }
    let (plane, cov) =
        plane_from_json(&serde_json::to_string(&report).map_err(|e| CliError::Io(e.to_string()))?)?;
    let text = match (format, transform) {
        ("halcon", _) => export_plane_halcon(&plane, &cov),
        (_, Some(t)) => export_plane_frame(&plane, t)?,
        _ => match &refined {
            // The report's own key order, refined_camera after it.
            Some(c) => {
                #[derive(serde::Serialize)]
                struct WithCamera<'a> {
                    #[serde(flatten)]
                    report: &'a robocal::api::laser::LaserPlaneReport,
                    refined_camera: &'a Camera,
                }
                let both = WithCamera {
                    report: &report,
                    refined_camera: c,
                };
                serde_json::to_string_pretty(&both).map_err(|e| CliError::Io(e.to_string()))? + "\n"
            }
            None => {
                serde_json::to_string_pretty(&report).map_err(|e| CliError::Io(e.to_string()))?
                    + "\n"
            }
        },
    };
    super::write_output(a.scans.output.as_deref(), &text)
}

/// A pose from a JSON file: a pose object, or the value of `key` in it.
pub(super) fn read_pose(path: &str, key: &str) -> Result<Pose, CliError> {
    let value: serde_json::Value = serde_json::from_str(&read_text(path)?)
        .map_err(|e| CliError::Io(format!("'{path}': {e}")))?;
    let found = value
        .get(key)
        .or_else(|| value.get("handeye").and_then(|h| h.get(key)));
    let pose: PoseJson = serde_json::from_value(found.unwrap_or(&value).clone()).map_err(|e| {
        CliError::Io(format!(
            "'{path}': expected a pose {{\"matrix_row_major\", \"translation_m\", \"quaternion_xyzw\"}} or \"{key}\": {e}"
        ))
    })?;
    pose.to_pose().map_err(|e| CliError::from(e).in_file(path))
}

fn run_points(a: PointsArgs) -> Result<(), CliError> {
    let camera = read_camera(&a.camera)?;
    let (plane, _) =
        plane_from_json(&read_text(&a.plane)?).map_err(|e| CliError::from(e).in_file(&a.plane))?;
    let image = read_gray(&a.image, &a.limits)?;
    let off = match a.off.as_deref() {
        Some(p) => Some(read_gray(p, &a.limits)?),
        None => None,
    };
    let mount = match a.gripper_from_camera.as_deref() {
        Some(p) => Some(read_pose(p, "gripper_from_camera")?),
        None => None,
    };
    let robot = match a.base_from_gripper.as_deref() {
        Some(p) => Some(read_pose(p, "base_from_gripper")?),
        None => None,
    };
    let report = laser_points(
        &camera,
        &plane,
        &image,
        off.as_ref(),
        &stripe_options(&a.stripe)?,
        mount.as_ref(),
        robot.as_ref(),
    )?;
    let text =
        serde_json::to_string_pretty(&report).map_err(|e| CliError::Io(e.to_string()))? + "\n";
    super::write_output(a.output.as_deref(), &text)
}
