//! `robocal laser sphere`: the laser plane and the camera's mounting on the
//! flange from laser images of a sphere of known radius scanned at several
//! robot poses (docs/laser.md).

use super::laser::{read_camera, read_pose, stripe_options, ScanArgs};
use super::{read_text, CliError};
use robocal::api::laser::plane_from_json;
use robocal::api::laser_sphere::{laser_sphere, SphereScanImage};

#[derive(clap::Args)]
pub(super) struct SphereArgs {
    /// The calibrated camera
    #[arg(long, value_name = "FILE")]
    camera: String,
    /// Start value of the laser plane (a `robocal laser plane` report, or
    /// {"normal_camera", "distance_m"} from the design)
    #[arg(long, value_name = "FILE")]
    plane: String,
    /// Start value of the camera's mounting: a JSON pose or a hand-eye
    /// report's gripper_from_camera
    #[arg(long, value_name = "FILE")]
    gripper_from_camera: String,
    /// The sphere's radius, millimetres
    #[arg(long, value_name = "MM")]
    radius_mm: f64,
    /// The robot's flange pose of each image, in the images' order (JSON
    /// pose files; repeat once per image)
    #[arg(long, value_name = "FILE", required = true)]
    base_from_gripper: Vec<String>,
    /// The images come in pairs: laser off, then laser on (the off image
    /// is subtracted before extraction)
    #[arg(long)]
    pairs: bool,
    #[command(flatten)]
    scans: ScanArgs,
}

pub(super) fn run_sphere(a: SphereArgs) -> Result<(), CliError> {
    let step = if a.pairs { 2 } else { 1 };
    let images = &a.scans.images;
    if images.len() % step != 0 || images.len() / step != a.base_from_gripper.len() {
        return Err(CliError::usage(
            "laser",
            format!(
                "sphere needs one --base-from-gripper per scan: {} poses for {} images{}",
                a.base_from_gripper.len(),
                images.len(),
                if a.pairs { " (in pairs: off, on)" } else { "" }
            ),
        ));
    }
    let camera = read_camera(&a.camera)?;
    let (plane, _) =
        plane_from_json(&read_text(&a.plane)?).map_err(|e| CliError::from(e).in_file(&a.plane))?;
    let mount = read_pose(&a.gripper_from_camera, "gripper_from_camera")?;
    let mut scans = Vec::new();
    for ((name, first, second), pose) in a.scans.read(step)?.into_iter().zip(&a.base_from_gripper) {
        // With --pairs a chunk is (off, on), else (on): the last is the laser image.
        let (image, off) = match second {
            Some(on) => (on, Some(first)),
            None => (first, None),
        };
        scans.push(SphereScanImage {
            name,
            image,
            off,
            base_from_gripper: read_pose(pose, "base_from_gripper")?,
        });
    }
    let report = laser_sphere(
        &camera,
        &scans,
        a.radius_mm * 1e-3,
        &plane,
        &mount,
        &stripe_options(&a.scans.stripe)?,
    )?;
    for w in &report.warnings {
        eprintln!("robocal laser sphere: warning: {w}");
    }
    let text =
        serde_json::to_string_pretty(&report).map_err(|e| CliError::Io(e.to_string()))? + "\n";
    super::write_output(a.scans.output.as_deref(), &text)
}
