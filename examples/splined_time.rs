//! Native time of the splined fit that `benches/wasm_splined.mjs` times in
//! wasm (issue 41), on the same input.
//!
//! Usage: `node benches/wasm_splined.mjs --dump IN.json`, then
//! `cargo run --release --example splined_time -- IN.json [--runs N]`.
//! Runs `robocal::api::camera::calibrate_json` (the parametric pre-fits
//! and the model advice included, as the page's call); prints every run's
//! wall time, the rms and the median.

use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.iter().find(|a| !a.starts_with("--")) else {
        eprintln!("usage: splined_time IN.json [--runs N]");
        std::process::exit(2);
    };
    let runs: usize = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(1);
    let input = match std::fs::read_to_string(path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cannot read {path}: {e}");
            std::process::exit(1);
        }
    };
    let mut times = Vec::new();
    for run in 0..runs {
        let t0 = Instant::now();
        let out = match robocal::api::camera::calibrate_json(&input) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("calibration failed: {e}");
                std::process::exit(1);
            }
        };
        let secs = t0.elapsed().as_secs_f64();
        let value: serde_json::Value = serde_json::from_str(&out).unwrap_or_default();
        let rms = value["report"]["rms_px"].as_f64().unwrap_or(f64::NAN);
        println!("run {}: {secs:.2} s, rms {rms:.4} px", run + 1);
        times.push(secs);
    }
    times.sort_by(f64::total_cmp);
    println!("median {:.2} s over {runs} runs", times[times.len() / 2]);
}
