//! Wall time of the hand-eye solve on many poses, with and without the
//! maximum-likelihood pose refinement (the pose path's default).
//!
//! Usage: cargo run --release --example handeye_time -- [--poses N] [--runs N]
//!
//! Scene: `synth::handeye_looking`, eye-in-hand, the camera 0.5 m from a
//! 9x6 grid (30 mm), tilts up to 30 deg, rolls up to 60 deg, seed 21;
//! robot noise 0.02 deg / 0.1 mm per axis, camera pose noise 0.05 deg
//! (0.01 deg about the optical axis) and 0.05 / 0.3 mm (x, y / depth).
//! Every closed form on all view pairs, no bootstrap (as `robocal handeye
//! --camera-poses ... --bootstrap 0`). The two variants alternate, `--runs`
//! times each; printed: every run and the medians (seconds).

use robocal::handeye::solve::{calibrate, HandEyeOptions};
use robocal::handeye::Setup;
use robocal::synth::handeye_looking::{looking_scene, noisy_input, LookingConfig};
use std::time::Instant;

fn arg(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .map(|v| v.parse().expect("a whole number"))
        .unwrap_or(default)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let (poses, runs) = (arg("--poses", 1000), arg("--runs", 3));
    let scene = looking_scene(&LookingConfig::half_metre(Setup::EyeInHand, poses), 21);
    let input = noisy_input(&scene, 3);
    let (mut with, mut without) = (Vec::new(), Vec::new());
    for run in 0..runs {
        for refine_poses in [true, false] {
            let options = HandEyeOptions {
                bootstrap_samples: 0,
                refine_poses,
                ..Default::default()
            };
            let start = Instant::now();
            let result = calibrate(&input, &options).expect("the solve");
            let s = start.elapsed().as_secs_f64();
            let t_mm = (result.x.translation.vector - scene.x_true.translation.vector).norm() * 1e3;
            println!(
                "run {run}: refine_poses {refine_poses}: {s:.3} s ({}; X off by {t_mm:.4} mm)",
                result.method
            );
            if refine_poses {
                with.push(s);
            } else {
                without.push(s);
            }
        }
    }
    let (a, b) = (median(with), median(without));
    println!(
        "{poses} poses, median of {runs}: {a:.3} s with the pose refinement, {b:.3} s without \
         (refinement {:.3} s)",
        a - b
    );
}
