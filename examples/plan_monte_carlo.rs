//! The pose plan's Monte Carlo on rendered images: does solving with the
//! planned poses reach the error the plan predicts, and beat random poses?
//!
//! Usage: cargo run --example plan_monte_carlo -- [--trials N] [--random N]
//!        [--seed S] [--seeds K] [--pixel-noise PX]
//!
//! The cell and each trial are those of tests/handeye/plan_trials.rs
//! (included here by path): an eye-in-hand 640 x 480 camera over a 9 x 6
//! chessboard, 12 planned poses; per trial every view is rendered
//! (`robocal::synth::render`), detected (`robocal::detect::detect`) and the
//! hand-eye solved through `robocal::api::handeye::solve_handeye`, with
//! robot noise 0.02 deg / 0.1 mm per axis. The plan's pixel noise is
//! measured on the rendered current view (its PnP residual) unless
//! `--pixel-noise` fixes it. `--random N` random plans (default: as many
//! as trials). `--seeds K` repeats the run for seeds S .. S + K - 1. Prints, per seed: the predicted RMS error at the work point,
//! the planned poses' achieved RMS over the trials (vs the truth), their
//! ratio, random plans' RMS, and the detector's corner RMS.

#[path = "../tests/handeye/plan_trials.rs"]
mod plan_trials;

use robocal::handeye::plan::PlanNoise;

fn value<T: std::str::FromStr>(args: &[String], flag: &str) -> Option<T> {
    let at = args.iter().position(|a| a == flag)?;
    args.get(at + 1)?.parse().ok()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let trials: usize = value(&args, "--trials").unwrap_or(40);
    let random: usize = value(&args, "--random").unwrap_or(trials);
    let seed: u64 = value(&args, "--seed").unwrap_or(1);
    let seeds: u64 = value(&args, "--seeds").unwrap_or(1);
    let fixed: Option<f64> = value(&args, "--pixel-noise");
    let noise = PlanNoise {
        pixel_sigma_px: fixed.unwrap_or(PlanNoise::default().pixel_sigma_px),
        ..PlanNoise::default()
    };
    println!(
        "seed  trials  random  sigma_px(assumed)  corner_rms_px  predicted_mm  planned_mm  ratio  random_mm"
    );
    for s in seed..seed + seeds {
        match plan_trials::run((trials, random), s, noise, fixed.is_none()) {
            Ok(r) => println!(
                "{s:4}  {:6}  {:6}  {:17.4}  {:13.4}  {:12.4}  {:10.4}  {:5.3}  {:9.4}",
                r.trials,
                r.random_trials,
                r.assumed_sigma_px,
                r.corner_rms_px,
                r.predicted_mm,
                r.planned_mm,
                r.planned_mm / r.predicted_mm,
                r.random_mm
            ),
            Err(e) => {
                eprintln!("seed {s}: {e}");
                std::process::exit(1);
            }
        }
    }
}
