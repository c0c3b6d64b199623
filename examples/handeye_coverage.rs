//! Does the hand-eye report's uncertainty cover the truth when the model is
//! not exactly right? A seeded Monte-Carlo over scenes of a camera looking
//! at a 9x6 board (30 mm) at 0.5 m, 1280x960 at f = 1100 px, through the
//! image path of `robocal handeye` (PnP with its covariance per view, the
//! closed forms, the pose refinement, its leave-one-out repeatability and
//! the checks of `handeye::quality::trust`).
//!
//! Each cell: eye-in-hand, pixel noise 0.2 px, robot noise 0.1 mm / 0.02 deg
//! per axis, plus the misspecification named by the row. Columns: trials
//! whose true `gripper_from_camera` lies within 3 reported std on every one
//! of its six components (rotation about x, y, z in the left frame and the
//! translation x, y, z), trials that are not covered and carry no
//! warning (silent wrong answers), trials whose std was widened to the
//! leave-one-out spread, and trials warned that this spread is over 2x the
//! model's.
//!
//! `cargo run --release --example handeye_coverage -- [TRIALS]` (default 100).

use robocal::calib::pnp::camera_from_target_with_covariance;
use robocal::calib::View;
use robocal::camera::Camera;
use robocal::handeye::solve::apply_pose_refinement_from_views;
use robocal::handeye::{calibrate, HandEyeInput, HandEyeOptions, MotionPairs, Pose, Setup};
use robocal::synth::handeye_looking::{
    grid_pixels, kinematic_error, looking_scene, perturbed, LookingConfig,
};
use robocal::synth::Rng;

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
}

/// One trial: `(covered, covered by the model's std before widening,
/// warned, widened, warned of a leave-one-out spread over 2x the model's)`.
fn trial(cell: &Cell, seed: u64) -> Option<(bool, bool, bool, bool, bool)> {
    let camera = Camera::pinhole(1100.0, 1100.0, 639.5, 479.5, 1280, 960);
    let config = LookingConfig {
        setup: Setup::EyeInHand,
        views: cell.views,
        distance_m: 0.5,
        grid: (9, 6, 0.03),
        max_tilt_deg: cell.max_tilt_deg,
        max_roll_deg: cell.max_roll_deg,
    };
    let scene = looking_scene(&config, seed);
    let mut rng = Rng::new(seed ^ 0xc0ffee);
    let pixels = grid_pixels(&scene, &camera, 0.2, &mut rng);
    let f = 1100.0 * (1.0 + cell.focal_error);
    let used_camera = Camera::pinhole(f, f, 639.5, 479.5, 1280, 960);
    let mut cams = Vec::new();
    for v in &pixels {
        cams.push(camera_from_target_with_covariance(&used_camera, v).ok()?.0);
    }
    let (sr, st) = (0.02f64.to_radians(), 0.1e-3);
    let robots: Vec<Pose> = scene
        .base_from_gripper
        .iter()
        .map(|p| {
            let k = kinematic_error(p, cell.kinematic.0, cell.kinematic.1);
            perturbed(&mut rng, &k, [sr; 3], [st; 3])
        })
        .collect();
    let input = HandEyeInput {
        setup: Setup::EyeInHand,
        base_from_gripper: robots,
        camera_from_target: cams,
    };
    let options = HandEyeOptions {
        bootstrap_samples: 1,
        refine_poses: false,
        strict_checks: false,
        ..Default::default()
    };
    let mut result = calibrate(&input, &options).ok()?;
    let views: Vec<View> = pixels;
    apply_pose_refinement_from_views(&mut result, &input, &views, &used_camera, MotionPairs::All)
        .ok()?;
    let summary = result.pose_refinement.as_ref()?;
    let std = &summary.camera_transform_std;
    let dt = (result.x.translation.vector - scene.x_true.translation.vector) * 1e3;
    let dr = (result.x.rotation * scene.x_true.rotation.inverse()).scaled_axis();
    let within = |scale: f64| {
        (0..3).all(|k| {
            dt[k].abs() <= 3.0 * scale * std.translation_mm[k]
                && dr[k].to_degrees().abs() <= 3.0 * scale * std.rotation_deg[k]
        })
    };
    let widened = summary.std_widened_by;
    let spread_named = result
        .warnings
        .iter()
        .any(|w| w.starts_with("uncertainty: the leave-one-out solutions spread"));
    Some((
        within(1.0),
        within(1.0 / widened.unwrap_or(1.0)),
        !result.warnings.is_empty(),
        widened.is_some(),
        spread_named,
    ))
}

fn main() {
    let trials: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(100);
    let cells = [
        Cell {
            name: "20 poses, tilts to 30 deg (model right)",
            views: 20,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.0, 0.0),
            focal_error: 0.0,
        },
        Cell {
            name: "20 poses, robot kinematic error 0.3 mm / 0.02 deg",
            views: 20,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.0,
        },
        Cell {
            name: "20 poses, focal length 1 % off",
            views: 20,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.0, 0.0),
            focal_error: 0.01,
        },
        Cell {
            name: "4 poses, kinematic error",
            views: 4,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.0,
        },
        Cell {
            name: "8 poses, kinematic error",
            views: 8,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.0,
        },
        Cell {
            name: "30 poses, kinematic error + focal 1 %",
            views: 30,
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.01,
        },
        Cell {
            name: "12 poses, tilts and rolls to 8 deg, kinematic error",
            views: 12,
            max_tilt_deg: 8.0,
            max_roll_deg: 8.0,
            kinematic: (0.3, 0.02),
            focal_error: 0.0,
        },
    ];
    println!(
        "| scene | trials | truth within 3 std (the model's std) | truth within 3 std (reported) \
         | wrong without a warning | std widened | spread over 2x named |"
    );
    println!("|---|---|---|---|---|---|---|");
    for cell in &cells {
        let (mut n, mut covered, mut before, mut silent, mut widened) = (0, 0, 0, 0, 0);
        let mut named = 0;
        for t in 0..trials {
            if let Some((c, b, warned, w, over)) = trial(cell, 9000 + t) {
                n += 1;
                covered += usize::from(c);
                before += usize::from(b);
                silent += usize::from(!c && !warned);
                widened += usize::from(w);
                named += usize::from(over);
            }
        }
        let pct = |k: usize| 100.0 * k as f64 / n.max(1) as f64;
        println!(
            "| {} | {n} | {:.1} % | {:.1} % | {:.1} % | {:.1} % | {:.1} % |",
            cell.name,
            pct(before),
            pct(covered),
            pct(silent),
            pct(widened),
            pct(named)
        );
    }
}
