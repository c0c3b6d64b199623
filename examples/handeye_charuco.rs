//! Render seeded ChArUco hand-eye image sets (eye-in-hand and eye-to-hand)
//! for benches/compare_handeye_charuco.py: robocal's image path against
//! OpenCV's ChArUco detector, PnP and hand-eye methods on the same images.
//!
//! Usage: cargo run --release --example handeye_charuco -- OUT_DIR
//!        [--trials N] [--views N] [--seed N]
//!
//! Per setup and trial (seed = --seed + trial): a scene whose camera looks at
//! the board from about 0.45 m ([`robocal::synth::handeye_looking`]), every
//! fourth view shifted sideways so that a third to a half of the board is
//! out of the image (a partial view), rendered at 1280x960 (pinhole,
//! f = 1100 px, blur 0.7 px, noise sigma 2 grey levels). The robot poses
//! get Gaussian noise of 0.02 deg per rotation axis and 0.1 mm per
//! translation axis (left perturbation in the base frame).
//!
//! Writes OUT_DIR/<setup>/trial_NN/: view_MM.png, poses.txt (noisy
//! base_from_gripper, one row-major 4x4 per line, metres), camera.json
//! (robocal's camera JSON) and truth.json {"setup", "target", "x_true"
//! (row-major 4x4: gripper_from_camera or base_from_camera), "partial_views"}.

use nalgebra::Vector3;
use robocal::camera::Camera;
use robocal::handeye::{Pose, Setup};
use robocal::synth::handeye_looking::{looking_scene, perturbed, shift_view, LookingConfig};
use robocal::synth::{render, RenderOptions, Rng};
use robocal::target::Target;
use serde_json::json;
use std::path::Path;

/// The board: OpenCV's usual 12x9 ChArUco with 20 mm squares.
const SPEC: &str = "charuco:12x9:20mm:15mm:DICT_5X5_100";
/// Robot pose noise per axis.
const ROBOT_ROT_DEG: f64 = 0.02;
const ROBOT_T_MM: f64 = 0.1;

fn camera() -> Camera {
    Camera::pinhole(1100.0, 1100.0, 641.3, 478.2, 1280, 960)
}

fn rows(p: &Pose) -> Vec<Vec<f64>> {
    let m = p.to_homogeneous();
    (0..4)
        .map(|r| (0..4).map(|c| m[(r, c)]).collect())
        .collect()
}

fn line(p: &Pose) -> String {
    let m = p.to_homogeneous();
    let v: Vec<String> = (0..4)
        .flat_map(|r| (0..4).map(move |c| (r, c)))
        .map(|(r, c)| format!("{:.17e}", m[(r, c)]))
        .collect();
    v.join(" ")
}

/// Shift every fourth view so that the board centre lands 75-100 % of the
/// way to a random image edge.
fn make_partial(
    scene: &mut robocal::synth::handeye_looking::LookingScene,
    rng: &mut Rng,
    cam: &Camera,
) -> Vec<usize> {
    let mut partial = Vec::new();
    for k in (3..scene.camera_from_target.len()).step_by(4) {
        let z = scene.camera_from_target[k].translation.vector.z;
        let (hx, hy) = (cam.width as f64 / 2.0, cam.height as f64 / 2.0);
        let along = rng.range(-0.3, 0.3);
        let far = rng.range(0.75, 1.0);
        let px = match rng.below(4) {
            0 => Vector3::new(hx * far, hy * along, 0.0),
            1 => Vector3::new(-hx * far, hy * along, 0.0),
            2 => Vector3::new(hx * along, hy * far, 0.0),
            _ => Vector3::new(hx * along, -hy * far, 0.0),
        };
        // The board moves by -f * d / z pixels when the camera moves by d.
        shift_view(scene, k, -px * z / 1100.0);
        partial.push(k);
    }
    partial
}

fn write(path: &Path, text: String) {
    std::fs::write(path, text).unwrap_or_else(|e| panic!("write {}: {e}", path.display()));
}

fn main() {
    let mut args = std::env::args().skip(1);
    let (mut out, mut trials, mut views, mut seed) = (None, 20u64, 12usize, 1u64);
    while let Some(a) = args.next() {
        let mut number = |name: &str| -> u64 {
            args.next()
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| panic!("{name} needs a number"))
        };
        match a.as_str() {
            "--trials" => trials = number("--trials"),
            "--views" => views = number("--views") as usize,
            "--seed" => seed = number("--seed"),
            _ => out = Some(a),
        }
    }
    let out = out.expect("usage: handeye_charuco OUT_DIR [--trials N] [--views N] [--seed N]");
    let cam = camera();
    let target = Target::parse_spec(SPEC).expect("spec");
    let (sr, st) = (ROBOT_ROT_DEG.to_radians(), ROBOT_T_MM * 1e-3);
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        for trial in 0..trials {
            let dir = Path::new(&out)
                .join(setup.name())
                .join(format!("trial_{trial:02}"));
            std::fs::create_dir_all(&dir).expect("mkdir");
            let config = LookingConfig {
                setup,
                views,
                distance_m: 0.45,
                grid: (11, 8, 0.02),
                max_tilt_deg: 35.0,
                max_roll_deg: 60.0,
            };
            let mut scene = looking_scene(&config, seed + trial);
            let mut rng = Rng::new(1000 + seed + trial);
            let partial = make_partial(&mut scene, &mut rng, &cam);
            let mut poses = String::new();
            for (k, pose) in scene.camera_from_target.iter().enumerate() {
                let options = RenderOptions {
                    seed: (seed + trial) * 1000 + k as u64,
                    ..RenderOptions::default()
                };
                let image = render(&cam, &target, pose, &options).expect("render").image;
                let png = robocal::image::encode_png(&image).expect("png");
                std::fs::write(dir.join(format!("view_{k:02}.png")), png).expect("write png");
                let noisy = perturbed(&mut rng, &scene.base_from_gripper[k], [sr; 3], [st; 3]);
                poses += &(line(&noisy) + "\n");
            }
            write(&dir.join("poses.txt"), poses);
            write(
                &dir.join("camera.json"),
                serde_json::to_string_pretty(&cam).expect("camera json"),
            );
            let truth = json!({
                "setup": setup.name(),
                "target": SPEC,
                "x_true": rows(&scene.x_true),
                "partial_views": partial,
                "robot_noise": {"rotation_deg": ROBOT_ROT_DEG, "translation_mm": ROBOT_T_MM},
            });
            write(&dir.join("truth.json"), truth.to_string());
            eprintln!(
                "{} trial {trial}: {views} views ({} partial)",
                setup.name(),
                partial.len()
            );
        }
    }
}
