//! Does the hand-eye report's uncertainty cover the truth when the model is
//! not exactly right? A seeded Monte-Carlo over scenes of a camera looking
//! at a 9x6 board (30 mm) at 0.5 m, 1280x960 at f = 1100 px, through the
//! image path of `robocal handeye` (PnP with its covariance per view, the
//! closed forms, the pose refinement, its leave-one-out repeatability and
//! the checks of `handeye::quality::trust` and `handeye::quality::focal`).
//!
//! Each cell: eye-in-hand, pixel noise 0.2 px, robot noise 0.1 mm / 0.02 deg
//! per axis, plus the misspecification named by the row. Columns: trials
//! whose true `gripper_from_camera` lies within 3 reported std on every one
//! of its six components (rotation about x, y, z in the left frame and the
//! translation x, y, z), trials that are not covered and carry no
//! warning (silent wrong answers), trials whose std was widened to the
//! leave-one-out spread, trials warned that this spread is over 2x the
//! model's, trials warned that the focal length disagrees with the robot's
//! motion, and the coverage and silent share of the same trials without
//! that focal check (the pose refinement alone, as before it).
//!
//! `cargo run --release --example handeye_coverage -- [TRIALS] [CELL]`
//! (default 100 trials, every cell; `CELL`: only the cells whose name
//! contains it). Also printed: the 95 % (Wilson) interval of the covered
//! share, and the mean over trials and components of |error| / reported
//! std (about 0.8 for a right Gaussian std, lower when it is too wide).

use robocal::camera::Camera;
use robocal::handeye::refine::over_poses::camera_noise_from_views;
use robocal::handeye::solve::{apply_pose_refinement, apply_pose_refinement_from_views};
use robocal::handeye::{calibrate, HandEyeOptions, HandEyeResult, MotionPairs, Setup};
use robocal::optim::wilson::wilson_interval_95;
use robocal::synth::handeye_looking::{
    looking_scene, looking_scene_one_height, observe_scene, LookingConfig, LookingNoise,
};

struct Cell {
    name: &'static str,
    views: usize,
    max_tilt_deg: f64,
    max_roll_deg: f64,
    /// Robot kinematic error amplitude: translation (mm), rotation (deg),
    /// a smooth function of the pose (the same pose, the same error).
    kinematic: (f64, f64),
    /// Relative focal-length error of the camera used for PnP.
    focal_error: f64,
    /// Every camera at one height above the board (the flange on one plane).
    one_height: bool,
    /// The std of the camera's fx (px) given with it, as a camera JSON from
    /// `robocal intrinsics` holds it; none: a camera without its std.
    fx_std: Option<f64>,
}

/// One trial's outcome.
struct Outcome {
    /// The truth within 3 reported std on every component.
    covered: bool,
    /// ... within 3 of the model's std (before any widening).
    covered_before: bool,
    /// The truth within 4 reported std on every component (a right
    /// Gaussian std leaves 0.04 % of six components outside by chance).
    covered_4: bool,
    /// Any warning.
    warned: bool,
    /// The std widened to the leave-one-out spread.
    widened: bool,
    /// Warned of a leave-one-out spread over 2x the model's.
    spread_named: bool,
    /// Warned that the focal length disagrees with the robot.
    focal_named: bool,
    /// Without the focal check: covered, and any warning.
    without_focal_check: (bool, bool),
    /// Mean over the six components of |error| / reported std.
    mean_ratio: f64,
}

fn trial(cell: &Cell, seed: u64) -> Option<Outcome> {
    let camera = Camera::pinhole(1100.0, 1100.0, 639.5, 479.5, 1280, 960);
    let config = LookingConfig {
        setup: Setup::EyeInHand,
        views: cell.views,
        distance_m: 0.5,
        grid: (9, 6, 0.03),
        max_tilt_deg: cell.max_tilt_deg,
        max_roll_deg: cell.max_roll_deg,
    };
    let measured = LookingNoise {
        pixel_sigma: 0.2,
        robot_sigma: (0.02f64.to_radians(), 0.1e-3),
        kinematic: Some(cell.kinematic),
    };
    let scene = if cell.one_height {
        looking_scene_one_height(&config, seed)
    } else {
        looking_scene(&config, seed)
    };
    let seen = observe_scene(scene, &camera, &measured, seed ^ 0xc0ffee);
    let scene = &seen.scene;
    let f = 1100.0 * (1.0 + cell.focal_error);
    let used_camera = Camera::pinhole(f, f, 639.5, 479.5, 1280, 960);
    let input = seen.handeye_input(&used_camera).ok()?;
    let options = HandEyeOptions {
        bootstrap_samples: 1,
        refine_poses: false,
        strict_checks: false,
        ..Default::default()
    };
    let mut result = calibrate(&input, &options).ok()?;
    // The same pose refinement without the focal check (as before it).
    let mut held = result.clone();
    let (noise, _) = camera_noise_from_views(&input, &seen.views, &used_camera);
    apply_pose_refinement(&mut held, &input, noise, MotionPairs::All).ok()?;
    apply_pose_refinement_from_views(
        &mut result,
        &input,
        &seen.views,
        (&used_camera, cell.fx_std),
        MotionPairs::All,
    )
    .ok()?;
    let covered = |r: &HandEyeResult, scale: f64| -> Option<bool> {
        let std = &r.pose_refinement.as_ref()?.camera_transform_std;
        let dt = (r.x.translation.vector - scene.x_true.translation.vector) * 1e3;
        let dr = (r.x.rotation * scene.x_true.rotation.inverse()).scaled_axis();
        Some((0..3).all(|k| {
            dt[k].abs() <= 3.0 * scale * std.translation_mm[k]
                && dr[k].to_degrees().abs() <= 3.0 * scale * std.rotation_deg[k]
        }))
    };
    let within = |scale: f64| covered(&result, scale).unwrap_or(false);
    let summary = result.pose_refinement.as_ref()?;
    let mean_ratio = {
        let std = &summary.camera_transform_std;
        let dt = (result.x.translation.vector - scene.x_true.translation.vector) * 1e3;
        let dr = (result.x.rotation * scene.x_true.rotation.inverse()).scaled_axis();
        (0..3)
            .map(|k| {
                dt[k].abs() / std.translation_mm[k] + dr[k].to_degrees().abs() / std.rotation_deg[k]
            })
            .sum::<f64>()
            / 6.0
    };
    let widened = summary.std_widened_by;
    let named = |start: &str| result.warnings.iter().any(|w| w.starts_with(start));
    Some(Outcome {
        covered: within(1.0),
        covered_before: within(1.0 / widened.unwrap_or(1.0)),
        covered_4: within(4.0 / 3.0),
        warned: !result.warnings.is_empty(),
        widened: widened.is_some(),
        spread_named: named("uncertainty: the leave-one-out solutions spread"),
        focal_named: named("focal length:"),
        without_focal_check: (covered(&held, 1.0)?, !held.warnings.is_empty()),
        mean_ratio,
    })
}

fn main() {
    let trials: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(100);
    let only = std::env::args().nth(2).unwrap_or_default();
    let cells = [
        Cell {
            name: "20 poses, model right, the camera's fx std given (0.5 px)",
            views: 20,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.0, 0.0),
            focal_error: 0.0,
            one_height: false,
            fx_std: Some(0.5),
        },
        Cell {
            name: "20 poses, tilts to 30 deg (model right)",
            views: 20,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.0, 0.0),
            focal_error: 0.0,
            one_height: false,
            fx_std: None,
        },
        Cell {
            name: "20 poses, robot kinematic error 0.3 mm / 0.02 deg",
            views: 20,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.0,
            one_height: false,
            fx_std: None,
        },
        Cell {
            name: "20 poses, focal length 1 % off",
            views: 20,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.0, 0.0),
            focal_error: 0.01,
            one_height: false,
            fx_std: None,
        },
        Cell {
            name: "4 poses, kinematic error",
            views: 4,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.0,
            one_height: false,
            fx_std: None,
        },
        Cell {
            name: "8 poses, kinematic error",
            views: 8,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.0,
            one_height: false,
            fx_std: None,
        },
        Cell {
            name: "30 poses, kinematic error + focal 1 %",
            views: 30,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.01,
            one_height: false,
            fx_std: None,
        },
        Cell {
            name: "12 poses, tilts and rolls to 8 deg, kinematic error",
            views: 12,
            max_tilt_deg: 8.0,
            max_roll_deg: 8.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.0,
            one_height: false,
            fx_std: None,
        },
        Cell {
            name: "20 poses at one height, tilts to 10 deg, kinematic error",
            views: 20,
            max_tilt_deg: 10.0,
            max_roll_deg: 60.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.0,
            one_height: true,
            fx_std: None,
        },
        Cell {
            name: "5 poses at one height, tilts to 10 deg, kinematic error",
            views: 5,
            max_tilt_deg: 10.0,
            max_roll_deg: 60.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.0,
            one_height: true,
            fx_std: None,
        },
    ];
    println!(
        "| scene | trials | truth within 3 std (the model's std) | truth within 3 std (reported) \
         | its 95 % interval | mean abs(error) / std | wrong without a warning | std widened \
         | spread over 2x named | focal length named \
         | without the focal check: covered, wrong without a warning \
         | beyond 4 std without a warning |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for cell in cells.iter().filter(|c| c.name.contains(only.as_str())) {
        let (mut n, mut covered, mut before, mut silent, mut widened) = (0, 0, 0, 0, 0);
        let (mut named, mut focal, mut held_covered, mut held_silent) = (0, 0, 0, 0);
        let mut ratio_sum = 0.0;
        let mut silent_4 = 0;
        for t in 0..trials {
            if let Some(o) = trial(cell, 9000 + t) {
                n += 1;
                covered += usize::from(o.covered);
                before += usize::from(o.covered_before);
                silent += usize::from(!o.covered && !o.warned);
                silent_4 += usize::from(!o.covered_4 && !o.warned);
                widened += usize::from(o.widened);
                named += usize::from(o.spread_named);
                focal += usize::from(o.focal_named);
                let (c, warned) = o.without_focal_check;
                held_covered += usize::from(c);
                held_silent += usize::from(!c && !warned);
                ratio_sum += o.mean_ratio;
            }
        }
        let pct = |k: usize| 100.0 * k as f64 / n.max(1) as f64;
        let (low, high) = wilson_interval_95(covered, n);
        println!(
            "| {} | {n} | {:.1} % | {:.1} % | {:.1}-{:.1} % | {:.2} | {:.1} % | {:.1} % | {:.1} % \
             | {:.1} % | {:.1} %, {:.1} % | {:.1} % |",
            cell.name,
            pct(before),
            pct(covered),
            100.0 * low,
            100.0 * high,
            ratio_sum / n.max(1) as f64,
            pct(silent),
            pct(widened),
            pct(named),
            pct(focal),
            pct(held_covered),
            pct(held_silent),
            pct(silent_4)
        );
    }
}
