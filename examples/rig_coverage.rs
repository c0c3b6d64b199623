//! Does a rig's (or a stereo pair's) reported std cover the truth when the
//! frames were not taken at one moment? Seeded Monte Carlo over
//! `synth::rig` scenes (four cameras, 0.3 px noise) with a per-view timing
//! error of free-running cameras and a hand-held board (issue 35's rig
//! row).
//!
//! `cargo run --release --example rig_coverage -- [TRIALS] [rig|stereo]
//! [MS,MS,...]` prints one row per timing error (default 0, 1, 5, 15 ms):
//! the share of trials whose every camera_from_rig component (3 rotation,
//! 3 translation, cameras 1-3; for `stereo`, right_from_left of cam0 and
//! cam1 over the frames both see, 12 pairs) lies within 3 reported std
//! with its 95 % (Wilson) interval, the share warned, the share refused,
//! the share wrong (some component outside 3 std; beyond 4 std) without a
//! warning that the frames disagree (the grouping check, the intrinsics
//! drift or the leave-frames-out spread), the mean over trials and
//! components of |error| / std (about 0.8 for a right std) and the worst.

use robocal::calib::multi::rig::calibrate_rig;
use robocal::calib::multi::stereo::calibrate_stereo;
use robocal::calib::CalibrationOptions;
use robocal::geometry::{rotvec_from_rotation, Pose};
use robocal::optim::wilson::wilson_interval_95;
use robocal::synth::rig::{rig_scene, RigScene, RigSceneConfig};

fn errors(got: &Pose, truth: &Pose) -> [f64; 6] {
    let r = rotvec_from_rotation(&(got.rotation * truth.rotation.inverse()));
    let t = got.translation.vector - truth.translation.vector;
    [r.x, r.y, r.z, t.x, t.y, t.z]
}

/// One solved trial: its |error| / std per component, and whether a
/// warning named frames that disagree.
struct Trial {
    ratios: Vec<f64>,
    warned: bool,
}

/// The warnings that speak to frames not taken at one moment: the grouping
/// check's, the intrinsics drift and the leave-frames-out spread (the
/// scene's other warnings, e.g. partial views, say nothing about it).
fn names_timing(w: &str) -> bool {
    w.contains("disagree on how the board moved")
        || w.contains("moved its intrinsics beyond")
        || w.contains("leaving frames out moves")
        || w.contains("leaving pairs out moves")
}

fn rig_trial(scene: &RigScene) -> Option<Trial> {
    let rig = calibrate_rig(
        &scene.camera_views(&[]),
        &scene.frame_keys,
        &RigScene::rig_options(None),
    )
    .ok()?;
    let mut ratios = Vec::new();
    for (k, camera) in rig.cameras.iter().enumerate().skip(1) {
        let (Some(got), Some(s)) = (
            camera.camera_from_rig.to_pose().ok(),
            camera.camera_from_rig_std.as_ref(),
        ) else {
            ratios.push(f64::INFINITY);
            continue;
        };
        let e = errors(&got, &scene.camera_from_rig[k]);
        let std = [s.rotation_rad, s.translation_m].concat();
        ratios.extend(e.iter().zip(&std).map(|(err, sd)| err.abs() / sd));
    }
    let warned = rig.warnings.iter().any(|w| names_timing(w));
    Some(Trial { ratios, warned })
}

/// cam0 (left) and cam1 (right) over the frames both see.
fn stereo_trial(scene: &RigScene) -> Option<Trial> {
    let (mut left, mut right) = (Vec::new(), Vec::new());
    for (f, v) in &scene.views[0] {
        if let Some((_, r)) = scene.views[1].iter().find(|(g, _)| g == f) {
            left.push(v.clone());
            right.push(r.clone());
        }
    }
    let size = |k: usize| (scene.cameras[k].width, scene.cameras[k].height);
    let options = CalibrationOptions::default();
    let pair = calibrate_stereo(&left, &right, size(0), size(1), &options).ok()?;
    let got = pair.right_from_left.to_pose().ok()?;
    let s = pair.right_from_left_std.as_ref()?;
    // cam0 is the rig frame: right_from_left is cam1's camera_from_rig.
    let e = errors(&got, &scene.camera_from_rig[1]);
    let std = [s.rotation_rad, s.translation_m].concat();
    let ratios = e.iter().zip(&std).map(|(err, sd)| err.abs() / sd).collect();
    let warned = pair.warnings.iter().any(|w| names_timing(w));
    Some(Trial { ratios, warned })
}

#[derive(Default)]
struct Row {
    trials: usize,
    covered: usize,
    warned: usize,
    refused: usize,
    silent_wrong: usize,
    silent_beyond_4: usize,
    ratio_sum: f64,
    ratio_count: usize,
    worst_ratio: f64,
}

fn main() {
    let mut args = std::env::args().skip(1);
    let trials: u64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(100);
    let stereo = args.next().is_some_and(|a| a == "stereo");
    let timings: Vec<f64> = args
        .next()
        .map(|a| a.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or_else(|| vec![0.0, 1.0, 5.0, 15.0]);
    println!("| timing error (std per view) | trials | covered (3 std) | its 95 % interval | warned | refused | outside 3 std, no warning | beyond 4 std, no warning | mean abs(error) / std | worst error / std |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for timing_ms in timings {
        let mut row = Row::default();
        for seed in 0..trials {
            let config = RigSceneConfig {
                noise_px: 0.3,
                timing_ms,
                pair_frames: if stereo { 12 } else { 8 },
                ..RigSceneConfig::default()
            };
            let scene = rig_scene(&config, 7000 + seed);
            row.trials += 1;
            let trial = if stereo {
                stereo_trial(&scene)
            } else {
                rig_trial(&scene)
            };
            let Some(trial) = trial else {
                row.refused += 1;
                continue;
            };
            let covered = trial.ratios.iter().all(|r| *r <= 3.0);
            let beyond_4 = trial.ratios.iter().any(|r| *r > 4.0);
            for r in &trial.ratios {
                row.worst_ratio = row.worst_ratio.max(*r);
                row.ratio_sum += r;
                row.ratio_count += 1;
            }
            row.covered += usize::from(covered);
            row.warned += usize::from(trial.warned);
            row.silent_wrong += usize::from(!covered && !trial.warned);
            row.silent_beyond_4 += usize::from(beyond_4 && !trial.warned);
        }
        let pct = |n: usize| 100.0 * n as f64 / row.trials as f64;
        let (low, high) = wilson_interval_95(row.covered, row.trials);
        println!(
            "| {timing_ms} ms | {} | {:.1} % | {:.1}-{:.1} % | {:.0} % | {:.0} % | {:.1} % | {:.1} % | {:.2} | {:.1} |",
            row.trials,
            pct(row.covered),
            100.0 * low,
            100.0 * high,
            pct(row.warned),
            pct(row.refused),
            pct(row.silent_wrong),
            pct(row.silent_beyond_4),
            row.ratio_sum / row.ratio_count.max(1) as f64,
            row.worst_ratio
        );
    }
}
