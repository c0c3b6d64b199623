//! The asymmetric circle grids of tests/detect/detect_circles_asym.rs
//! (7x11 and 11x7 at 15 mm, either print; 56-64 degrees of tilt, 0.3 m
//! away; the pinhole and the strongly distorted example cameras), rendered
//! with their truth for OpenCV (benches/steep_asym_opencv.py) and detected
//! by robocal in this process.
//!
//! Usage: cargo run --release --example steep_asym_set -- [OUT_DIR]
//! (default benches/out/steep_asym). Writes OUT_DIR/NN.png and
//! OUT_DIR/truth.json: `[{"file", "target", "camera", "tilt_deg",
//! "opencv_pattern": [cols, rows], "light_on_dark", "points": [[x_px,
//! y_px], ...] in id order}]` for the views with every circle whole in the
//! image (30 of 36), and prints robocal's result per view and in total: views found,
//! mean / max distance to the truth, px.

use robocal::camera::Camera;
use robocal::detect::{detect, DetectOptions};
use robocal::synth::{steep_view, STEEP_VIEWS_DEG};
use robocal::target::Target;
use serde_json::json;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::path::PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "benches/out/steep_asym".into()),
    );
    std::fs::create_dir_all(&out)?;
    let cams = [
        ("pinhole", Camera::example_pinhole()),
        ("brown", Camera::example_brown()),
    ];
    let mut truth = Vec::new();
    let (mut found, mut errors) = (0, Vec::new());
    for spec in [
        "circles:7x11:15mm:asymmetric",
        "circles:11x7:15mm:asymmetric",
        "circles:7x11:15mm:asymmetric:light-on-dark",
    ] {
        let target = Target::parse_spec(spec)?;
        let Target::CircleGrid { cols, rows, .. } = target else {
            return Err(format!("{spec} is not a circle grid").into());
        };
        for (name, cam) in &cams {
            for (k, &(tilt, _, _)) in STEEP_VIEWS_DEG.iter().enumerate() {
                let Some(r) = steep_view(&target, cam, k) else {
                    continue;
                };
                let file = out.join(format!("{:02}.png", truth.len()));
                std::fs::write(&file, robocal::image::encode_png(&r.image)?)?;
                let what = format!("{spec} {name} view {k} ({tilt} deg)");
                match detect(&r.image, &target, &DetectOptions::default()) {
                    Ok(det) => {
                        let d: Vec<f64> = det
                            .points
                            .iter()
                            .zip(&r.points)
                            .map(|(d, t)| (d.x_px - t.x_px).hypot(d.y_px - t.y_px))
                            .collect();
                        let worst = d.iter().copied().fold(0.0, f64::max);
                        println!("{what}: found, worst {worst:.4} px");
                        found += 1;
                        errors.extend(d);
                    }
                    Err(e) => println!("{what}: {e}"),
                }
                truth.push(json!({
                    "file": file.to_string_lossy(),
                    "target": spec,
                    "camera": name,
                    "tilt_deg": tilt,
                    "opencv_pattern": [cols, rows],
                    "light_on_dark": spec.ends_with(":light-on-dark"),
                    "points": r.points.iter().map(|p| [p.x_px, p.y_px]).collect::<Vec<_>>(),
                }));
            }
        }
    }
    std::fs::write(
        out.join("truth.json"),
        serde_json::to_string_pretty(&truth)?,
    )?;
    let mean = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
    let max = errors.iter().copied().fold(0.0, f64::max);
    println!(
        "robocal: {found} of {} views found, mean / max {mean:.4} / {max:.4} px",
        truth.len()
    );
    Ok(())
}
