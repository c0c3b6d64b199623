//! `robocal render --laser-plane nx,ny,nz,d`: each view rendered twice, the
//! board with the laser off (`view_000.png`) and the stripe image with it on
//! (`view_000_laser.png`), the true plane and stripe in truth.json.

use super::CliError;
use robocal::laser::{plane_in_camera, LaserPlane};
use robocal::synth::laser::{stripe_truth, LaserStripe};
use robocal::synth::Projection;

/// The laser stripe flags of `robocal render`.
#[derive(clap::Args)]
#[command(next_help_heading = "Laser stripe (with --laser-plane)")]
pub struct LaserArgs {
    /// Draw a laser stripe: the plane nx,ny,nz,d (n . X = d in the camera
    /// frame, metres; the normal is normalised); writes view_NNN_laser.png
    /// beside each view_NNN.png (laser off)
    #[arg(long, value_name = "NX,NY,NZ,D", allow_hyphen_values = true)]
    pub laser_plane: Option<String>,
    /// Full width at half maximum of the stripe's cross-profile, pixels
    #[arg(
        long,
        value_name = "PX",
        default_value_t = 5.0,
        requires = "laser_plane"
    )]
    pub laser_width: f64,
    /// Peak grey level of the stripe on white print before clipping (above
    /// 255 - the scene saturates)
    #[arg(
        long,
        value_name = "GREY",
        default_value_t = 400.0,
        requires = "laser_plane"
    )]
    pub laser_peak: f64,
    /// Speckle: relative RMS of the multiplicative noise along the line
    #[arg(
        long,
        value_name = "RMS",
        default_value_t = 0.2,
        requires = "laser_plane"
    )]
    pub laser_speckle: f64,
    /// Scale of the scene's own light in the stripe image (1: as the
    /// laser-off image; 0.1: a dark, filtered laser image)
    #[arg(
        long,
        value_name = "F",
        default_value_t = 1.0,
        requires = "laser_plane"
    )]
    pub laser_ambient: f64,
}

/// The stripe the flags ask for, `None` without `--laser-plane`.
pub fn laser_of(a: &LaserArgs, seed: u64) -> Result<Option<LaserStripe>, CliError> {
    let Some(text) = a.laser_plane.as_deref() else {
        return Ok(None);
    };
    let v: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            CliError::usage(
                "render",
                format!("--laser-plane must be four numbers nx,ny,nz,d, got '{text}'"),
            )
        })?;
    let [nx, ny, nz, d] = v[..] else {
        return Err(CliError::usage(
            "render",
            format!("--laser-plane must be four numbers nx,ny,nz,d, got '{text}'"),
        ));
    };
    let plane = plane_in_camera(nalgebra::Vector3::new(nx, ny, nz), d)
        .map_err(|e| CliError::usage("render", e.to_string()))?;
    for (flag, value) in [
        ("--laser-width", a.laser_width),
        ("--laser-peak", a.laser_peak),
        ("--laser-speckle", a.laser_speckle),
        ("--laser-ambient", a.laser_ambient),
    ] {
        if !(value.is_finite() && value >= 0.0) || (flag == "--laser-width" && value < 0.5) {
            return Err(CliError::usage(
                "render",
                format!(
                    "{flag} must be a number >= {}, got {value}",
                    if flag == "--laser-width" { "0.5" } else { "0" }
                ),
            ));
        }
    }
    Ok(Some(LaserStripe {
        peak: a.laser_peak,
        width_px: a.laser_width,
        speckle: a.laser_speckle,
        ambient: a.laser_ambient,
        seed,
        ..LaserStripe::new(plane)
    }))
}

/// The truth of one view's stripe: its axis and the exact centre in every
/// column (row) where it is imaged.
pub fn stripe_truth_json(
    camera: &dyn Projection,
    pose: &nalgebra::Isometry3<f64>,
    plane: &LaserPlane,
) -> serde_json::Value {
    let cols = stripe_truth(camera, pose, plane, true);
    let rows = stripe_truth(camera, pose, plane, false);
    let (axis, centres): (&str, Vec<[f64; 2]>) = if cols.len() >= rows.len() {
        (
            "columns",
            cols.iter().map(|(i, v)| [*i as f64, *v]).collect(),
        )
    } else {
        ("rows", rows.iter().map(|(i, v)| [*v, *i as f64]).collect())
    };
    serde_json::json!({ "stripe_axis": axis, "stripe_px": centres })
}
