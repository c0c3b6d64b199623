//! Does a rig's reported std cover the truth when the frames were not
//! taken at one moment? Seeded Monte Carlo over `synth::rig` scenes (four
//! cameras, 0.3 px noise) with a per-view timing error of free-running
//! cameras and a hand-held board (issue 35's rig row).
//!
//! `cargo run --release --example rig_coverage -- [TRIALS]` prints one row
//! per timing error: the share of trials whose every camera_from_rig
//! component (3 rotation, 3 translation, cameras 1-3) lies within 3
//! reported std, the share warned, the share refused, and the share wrong
//! (some component outside 3 std; beyond 4 std) without a warning that the frames
//! disagree (the grouping check, the intrinsics drift or the leave-frames-out
//! spread).

use robocal::calib::multi::rig::{calibrate_rig, RigCameraViews, RigOptions};
use robocal::calib::CalibrationOptions;
use robocal::geometry::{rotvec_from_rotation, Pose};
use robocal::synth::rig::{rig_scene, RigSceneConfig};

fn errors(got: &Pose, truth: &Pose) -> [f64; 6] {
    let r = rotvec_from_rotation(&(got.rotation * truth.rotation.inverse()));
    let t = got.translation.vector - truth.translation.vector;
    [r.x, r.y, r.z, t.x, t.y, t.z]
}

#[derive(Default)]
struct Row {
    trials: usize,
    covered: usize,
    warned: usize,
    refused: usize,
    silent_wrong: usize,
    silent_beyond_4: usize,
    worst_ratio: f64,
}

fn main() {
    let trials: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(100);
    println!("| timing error (std per view) | trials | covered (3 std) | warned | refused | outside 3 std, no warning | beyond 4 std, no warning | worst error / std |");
    println!("|---|---|---|---|---|---|---|---|");
    for timing_ms in [0.0, 1.0, 5.0, 15.0] {
        let mut row = Row::default();
        for seed in 0..trials {
            let config = RigSceneConfig {
                noise_px: 0.3,
                timing_ms,
                ..RigSceneConfig::default()
            };
            let scene = rig_scene(&config, 7000 + seed);
            let cameras: Vec<RigCameraViews> = (0..scene.names.len())
                .map(|k| RigCameraViews {
                    name: scene.names[k].clone(),
                    image_size_px: (scene.cameras[k].width, scene.cameras[k].height),
                    views: scene.views[k].clone(),
                    camera: None,
                })
                .collect();
            let options = RigOptions {
                calibration: CalibrationOptions::default(),
                rig_frame: None,
                target: "chessboard:11x8:60mm".into(),
                grouping: "number".into(),
            };
            row.trials += 1;
            let rig = match calibrate_rig(&cameras, &scene.frame_keys, &options) {
                Ok(rig) => rig,
                Err(_) => {
                    row.refused += 1;
                    continue;
                }
            };
            let mut covered = true;
            let mut beyond_4 = false;
            for (k, camera) in rig.cameras.iter().enumerate().skip(1) {
                let (Some(got), Some(s)) = (
                    camera.camera_from_rig.to_pose().ok(),
                    camera.camera_from_rig_std.as_ref(),
                ) else {
                    covered = false;
                    continue;
                };
                let e = errors(&got, &scene.camera_from_rig[k]);
                let std = [s.rotation_rad, s.translation_m].concat();
                for (err, sd) in e.iter().zip(&std) {
                    let ratio = err.abs() / sd;
                    row.worst_ratio = row.worst_ratio.max(ratio);
                    covered &= ratio <= 3.0;
                    beyond_4 |= ratio > 4.0;
                }
            }
            // The warnings that speak to frames not taken at one moment:
            // the grouping check's and the intrinsics drift (the scene's
            // other warnings, e.g. partial views, say nothing about it).
            let warned = rig.warnings.iter().any(|w| {
                w.contains("disagree on how the board moved")
                    || w.contains("moved its intrinsics beyond")
                    || w.contains("leaving frames out moves")
            });
            row.covered += usize::from(covered);
            row.warned += usize::from(warned);
            row.silent_wrong += usize::from(!covered && !warned);
            row.silent_beyond_4 += usize::from(beyond_4 && !warned);
        }
        let pct = |n: usize| 100.0 * n as f64 / row.trials as f64;
        println!(
            "| {timing_ms} ms | {} | {:.0} % | {:.0} % | {:.0} % | {:.0} % | {:.0} % | {:.1} |",
            row.trials,
            pct(row.covered),
            pct(row.warned),
            pct(row.refused),
            pct(row.silent_wrong),
            pct(row.silent_beyond_4),
            row.worst_ratio
        );
    }
}
