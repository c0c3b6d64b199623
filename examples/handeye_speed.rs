//! Wall time of the default hand-eye output from poses (every closed form,
//! the maximum-likelihood pose refinement, leave-one-out and the seeded
//! bootstrap of 100 resamples: `robocal handeye --poses ... --camera-poses
//! ...` without options) at 20, 100 and 1,000 poses, and the uncertainty it
//! reports (so that a faster path can be compared number for number).
//!
//! Usage: cargo run --release --example handeye_speed -- [--poses N]... [--runs N]
//!        [--write DIR]
//!
//! Scene: `synth::handeye_looking`, eye-in-hand, the camera 0.5 m from a
//! 9x6 grid (30 mm), tilts up to 30 deg, rolls up to 60 deg, seed 21;
//! robot noise 0.02 deg / 0.1 mm per axis, camera pose noise 0.05 deg
//! (0.01 deg about the optical axis) and 0.05 / 0.3 mm (x, y / depth), as
//! `examples/handeye_time.rs`. `--write DIR` also writes each scene as
//! `DIR/robot_N.txt` and `DIR/camera_N.txt` (one row-major 4x4 a line,
//! metres) for timing the whole `robocal handeye` process.

use robocal::handeye::solve::{calibrate, HandEyeInput, HandEyeOptions};
use robocal::handeye::{Pose, Setup};
use robocal::synth::handeye_looking::{looking_scene, noisy_input, LookingConfig, LookingScene};
use std::time::Instant;

fn args_of(name: &str) -> Vec<String> {
    let args: Vec<String> = std::env::args().collect();
    args.windows(2)
        .filter(|w| w[0] == name)
        .map(|w| w[1].clone())
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn scene_input(poses: usize) -> (LookingScene, HandEyeInput) {
    let scene = looking_scene(&LookingConfig::half_metre(Setup::EyeInHand, poses), 21);
    let input = noisy_input(&scene, 3);
    (scene, input)
}

fn matrix_lines(poses: &[Pose]) -> String {
    poses
        .iter()
        .map(|p| {
            let m = p.to_homogeneous();
            let row: Vec<String> = (0..4)
                .flat_map(|r| (0..4).map(move |c| (r, c)))
                .map(|(r, c)| format!("{:e}", m[(r, c)]))
                .collect();
            row.join(" ") + "\n"
        })
        .collect()
}

fn main() {
    let mut poses: Vec<usize> = args_of("--poses")
        .iter()
        .map(|v| v.parse().expect("--poses takes a whole number"))
        .collect();
    if poses.is_empty() {
        poses = vec![20, 100, 1000];
    }
    let runs: usize = args_of("--runs")
        .first()
        .map(|v| v.parse().expect("--runs takes a whole number"))
        .unwrap_or(3);
    let write = args_of("--write").first().cloned();
    if let Some(dir) = &write {
        std::fs::create_dir_all(dir).expect("creating the --write folder");
    }
    for &n in &poses {
        let (scene, input) = scene_input(n);
        if let Some(dir) = &write {
            std::fs::write(
                format!("{dir}/robot_{n}.txt"),
                matrix_lines(&input.base_from_gripper),
            )
            .expect("writing the robot poses");
            std::fs::write(
                format!("{dir}/camera_{n}.txt"),
                matrix_lines(&input.camera_from_target),
            )
            .expect("writing the camera poses");
        }
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..runs {
            let start = Instant::now();
            let result = calibrate(&input, &HandEyeOptions::default()).expect("the solve");
            times.push(start.elapsed().as_secs_f64());
            last = Some(result);
        }
        let Some(result) = last else { continue };
        let t_mm = (result.x.translation.vector - scene.x_true.translation.vector) * 1e3;
        println!(
            "{n} poses: median of {runs} {:.4} s (runs {:?}); {}; X off by [{:.4}, {:.4}, {:.4}] mm",
            median(times.clone()),
            times.iter().map(|t| (t * 1e4).round() / 1e4).collect::<Vec<_>>(),
            result.method,
            t_mm.x,
            t_mm.y,
            t_mm.z
        );
        let r_deg = (scene.x_true.rotation.inverse() * result.x.rotation)
            .scaled_axis()
            .map(f64::to_degrees);
        println!(
            "  X off by [{:.6}, {:.6}, {:.6}] mm, rotation [{:.7}, {:.7}, {:.7}] deg",
            t_mm.x, t_mm.y, t_mm.z, r_deg.x, r_deg.y, r_deg.z
        );
        if let Some(s) = &result.pose_refinement {
            println!(
                "  std: rotation {:.5?} deg, translation {:.4?} mm; widened by {:?}; work point {:.4?} mm",
                s.camera_transform_std.rotation_deg,
                s.camera_transform_std.translation_mm,
                s.std_widened_by,
                s.work_point_std_mm
            );
        }
        if let Some(r) = &result.repeatability {
            for (name, stats) in [
                ("leave-one-out", &r.leave_one_out),
                ("bootstrap", &r.bootstrap),
            ] {
                println!(
                    "  {name} ({}, {} runs, {} failed): rotation {:.5?} deg, translation {:.4?} mm",
                    r.method,
                    stats.runs,
                    stats.failed,
                    stats.camera_std.rotation_deg,
                    stats.camera_std.translation_mm
                );
            }
        }
        for w in &result.warnings {
            println!("  warning: {w}");
        }
    }
}
