//! Hand-eye at the Cramér-Rao bound: seeded Monte Carlo of the pose
//! refinement against the bound of the same noise model, every closed form,
//! and (optionally) the image-path refinement, per scenario.
//!
//! Usage: cargo run --release --example handeye_crb -- [--trials N] [--views N]
//!        [--image-path] [--trials-json FILE] [--repeat] [--only TEXT]
//!
//! Per trial: a seeded scene whose camera looks at a grid
//! ([`robocal::synth::handeye_looking`]), pixels with Gaussian noise, camera
//! poses by PnP ([`robocal::calib::pnp`]), robot poses with Gaussian noise
//! (`R <- exp(w) R`, `t <- t + v` in the base frame). The bound is the
//! inverse Fisher information of `(X, Z)` at the truth with the true robot
//! noise and each view's PnP covariance at the true pose times the pixel
//! variance. `--trials-json` writes every trial's poses and truth for
//! benches/handeye_crb_opencv.py (OpenCV 4.14 on the same trials).

use nalgebra::Vector6;
use robocal::calib::pnp::camera_from_target_with_covariance;
use robocal::camera::Camera;
use robocal::handeye::quality::residuals::Errors;
use robocal::handeye::refine::over_pixels::RefineMode;
use robocal::handeye::refine::over_poses::paired;
use robocal::handeye::refine::pose_noise::{CameraNoise, NoiseModel};
use robocal::handeye::refine::pose_problem::fisher_information;
use robocal::handeye::refine::pose_residual::difference;
use robocal::handeye::solve::apply_refinement;
use robocal::handeye::solve::{apply_pose_refinement, apply_pose_refinement_with};
use robocal::handeye::{calibrate, HandEyeInput, HandEyeOptions, MotionPairs, Pose, Setup};
use robocal::synth::handeye_looking::{grid_pixels, looking_scene, perturbed, LookingConfig};
use robocal::synth::Rng;
use std::collections::BTreeMap;

struct Scenario {
    name: String,
    setup: Setup,
    camera: Camera,
    config: LookingConfig,
    pixel_sigma: f64,
    robot_rot_deg: f64,
    robot_t_mm: f64,
}

fn scenarios(views: usize) -> Vec<Scenario> {
    let mut out = Vec::new();
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        for far in [false, true] {
            for (rot, t) in [(0.02, 0.1), (0.1, 0.5)] {
                let (camera, grid, distance, sigma, tilt) = if far {
                    // 75 mm lens on 2.4 um pixels, a 13 x 9 plate at 25 mm (seed 004).
                    (
                        Camera::pinhole(31250.0, 31250.0, 2735.5, 1823.5, 5472, 3648),
                        (13, 9, 0.025),
                        2.3,
                        0.1,
                        20.0,
                    )
                } else {
                    (
                        Camera::pinhole(1100.0, 1100.0, 639.5, 479.5, 1280, 960),
                        (9, 6, 0.03),
                        0.5,
                        0.2,
                        30.0,
                    )
                };
                out.push(Scenario {
                    name: format!(
                        "{} {} m, robot {t} mm/{rot} deg, {sigma} px",
                        setup.name(),
                        distance
                    ),
                    setup,
                    camera,
                    config: LookingConfig {
                        setup,
                        views,
                        distance_m: distance,
                        grid,
                        max_tilt_deg: tilt,
                        max_roll_deg: 60.0,
                    },
                    pixel_sigma: sigma,
                    robot_rot_deg: rot,
                    robot_t_mm: t,
                });
            }
        }
    }
    out
}

/// Rotation (deg) and translation (mm) error of an estimate's X, and its
/// decoupled 6-vector error.
fn x_error(est: &Pose, truth: &Pose) -> (f64, f64, Vector6<f64>) {
    let d = difference(truth, est);
    (
        d.fixed_rows::<3>(0).norm().to_degrees(),
        d.fixed_rows::<3>(3).norm() * 1e3,
        d,
    )
}

#[derive(Default)]
struct Tally {
    sq_rot: f64,
    sq_t: f64,
    sum_rot: f64,
    sum_t: f64,
    n: usize,
}

impl Tally {
    fn add(&mut self, rot: f64, t: f64) {
        self.sq_rot += rot * rot;
        self.sq_t += t * t;
        self.sum_rot += rot;
        self.sum_t += t;
        self.n += 1;
    }
    fn rms(&self) -> (f64, f64) {
        let n = self.n.max(1) as f64;
        ((self.sq_rot / n).sqrt(), (self.sq_t / n).sqrt())
    }
    fn mean(&self) -> (f64, f64) {
        let n = self.n.max(1) as f64;
        (self.sum_rot / n, self.sum_t / n)
    }
}

/// One run's summary errors (closure residuals) and X error, for the
/// repeatability table.
struct RunErrors {
    errors: Errors,
    rot_deg: f64,
    t_mm: f64,
}

fn quartiles(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    let q = |p: f64| {
        let k = p * (v.len() - 1) as f64;
        let (lo, hi) = (k.floor() as usize, k.ceil() as usize);
        v[lo] + (v[hi] - v[lo]) * (k - lo as f64)
    };
    (q(0.5), q(0.75) - q(0.25))
}

fn pose_rows(p: &Pose) -> Vec<Vec<f64>> {
    let m = p.to_homogeneous();
    (0..4)
        .map(|r| (0..4).map(|c| m[(r, c)]).collect())
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let trials: usize = value("--trials")
        .and_then(|v| v.parse().ok())
        .unwrap_or(200);
    let views: usize = value("--views").and_then(|v| v.parse().ok()).unwrap_or(15);
    let image_path = args.iter().any(|a| a == "--image-path");
    let repeat = args.iter().any(|a| a == "--repeat");
    let json_path = value("--trials-json");
    // Run only the scenarios whose name contains this text (quick checks).
    let only = value("--only");
    let options = HandEyeOptions {
        bootstrap_samples: 0,
        strict_checks: false,
        ..Default::default()
    };
    let closed_only = HandEyeOptions {
        refine_poses: false,
        ..options.clone()
    };
    let mut json_scenarios = Vec::new();
    println!("{trials} trials per scenario, {views} views each; X errors (rotation deg, translation mm)\n");
    println!("| scenario | bound rot / t | refined (diag) RMS | ratio rot / t | refined (per-view PnP cov) RMS | ratio rot / t | coverage 3 std diag / per-view |{}", if image_path { " image path RMS | ratio |" } else { "" });
    println!(
        "|---|---|---|---|---|---|---|{}",
        if image_path { "---|---|" } else { "" }
    );
    let mut mean_rows = Vec::new();
    let mut repeat_rows = Vec::new();
    let mut model_rows = Vec::new();
    for (si, sc) in scenarios(views).iter().enumerate() {
        if only.as_ref().is_some_and(|o| !sc.name.contains(o.as_str())) {
            continue;
        }
        let (mut bound, mut diag, mut perview, mut image) = (
            Tally::default(),
            Tally::default(),
            Tally::default(),
            Tally::default(),
        );
        let mut closed: BTreeMap<String, Tally> = BTreeMap::new();
        let mut fixed_rule = Tally::default();
        let (mut covered, mut covered_pv, mut axes) = (0usize, 0usize, 0usize);
        let (mut diag_old, mut covered_old) = (Tally::default(), 0usize);
        let mut models: BTreeMap<String, usize> = BTreeMap::new();
        let mut json_trials = Vec::new();
        let mut runs: BTreeMap<&str, Vec<RunErrors>> = BTreeMap::new();
        for trial in 0..trials {
            let seed = 1000 * si as u64 + trial as u64 + 1;
            let scene = looking_scene(&sc.config, seed);
            let mut rng = Rng::new(seed ^ 0x5eed);
            let pixels = grid_pixels(&scene, &sc.camera, sc.pixel_sigma, &mut rng);
            let exact = grid_pixels(&scene, &sc.camera, 0.0, &mut Rng::new(1));
            let mut cams = Vec::new();
            let mut covs = Vec::new();
            let mut true_covs = Vec::new();
            for (view, clean) in pixels.iter().zip(&exact) {
                let (pose, _, cov) =
                    camera_from_target_with_covariance(&sc.camera, view).expect("pnp");
                let (_, _, cov_true) =
                    camera_from_target_with_covariance(&sc.camera, clean).expect("pnp");
                cams.push(pose);
                covs.push(cov);
                true_covs.push(cov_true);
            }
            let (sr, st) = (sc.robot_rot_deg.to_radians(), sc.robot_t_mm * 1e-3);
            let robots: Vec<Pose> = scene
                .base_from_gripper
                .iter()
                .map(|p| perturbed(&mut rng, p, [sr; 3], [st; 3]))
                .collect();
            let input = HandEyeInput {
                setup: sc.setup,
                base_from_gripper: robots,
                camera_from_target: cams,
            };
            // The bound at the truth.
            let truth_views = paired(&scene.base_from_gripper, &scene.camera_from_target);
            let mut model = NoiseModel::new(CameraNoise::PerView(true_covs));
            model.variances = vec![sr * sr, st * st, sc.pixel_sigma.powi(2)];
            let crb =
                fisher_information(sc.setup, &truth_views, &model, &scene.x_true, &scene.y_true)
                    .try_inverse()
                    .expect("information");
            bound.sq_rot += crb
                .fixed_view::<3, 3>(0, 0)
                .trace()
                .to_degrees()
                .to_degrees();
            bound.sq_t += crb.fixed_view::<3, 3>(3, 3).trace() * 1e6;
            bound.n += 1;
            // Pose path, default (diagonal camera noise estimated).
            let result = calibrate(&input, &options).expect("calibrate");
            let (r, t, d) = x_error(&result.x, &scene.x_true);
            let refined_error = [r, t];
            diag.add(r, t);
            if let Some(s) = &result.pose_refinement {
                *models.entry(s.camera_noise_model.clone()).or_default() += 1;
                for k in 0..6 {
                    axes += 1;
                    covered += usize::from(d[k].abs() <= 3.0 * s.covariance[k][k].sqrt());
                }
            }
            if trial < 12 {
                runs.entry("refined (diag)").or_default().push(RunErrors {
                    errors: result.errors.clone(),
                    rot_deg: r,
                    t_mm: t,
                });
            }
            for m in &result.methods {
                if let Ok((x, _, _)) = &m.outcome {
                    let (r, t, _) = x_error(x, &scene.x_true);
                    closed
                        .entry(m.method.name().to_string())
                        .or_default()
                        .add(r, t);
                }
            }
            // Closed form by the fixed rule, then the per-view PnP covariance model.
            let mut result = calibrate(&input, &closed_only).expect("calibrate");
            let (r, t, _) = x_error(&result.x, &scene.x_true);
            fixed_rule.add(r, t);
            if trial < 12 {
                runs.entry("closed form (fixed rule)")
                    .or_default()
                    .push(RunErrors {
                        errors: result.errors.clone(),
                        rot_deg: r,
                        t_mm: t,
                    });
            }
            let base = result.clone();
            let mut diag_only = result.clone();
            apply_pose_refinement_with(
                &mut diag_only,
                &input,
                CameraNoise::Diagonal,
                MotionPairs::All,
                false,
            )
            .expect("refine");
            let (r, t, d) = x_error(&diag_only.x, &scene.x_true);
            diag_old.add(r, t);
            if let Some(s) = &diag_only.pose_refinement {
                for k in 0..6 {
                    covered_old += usize::from(d[k].abs() <= 3.0 * s.covariance[k][k].sqrt());
                }
            }
            apply_pose_refinement(
                &mut result,
                &input,
                CameraNoise::PerView(covs),
                MotionPairs::All,
            )
            .expect("refine");
            let (r, t, d) = x_error(&result.x, &scene.x_true);
            perview.add(r, t);
            if let Some(s) = &result.pose_refinement {
                for k in 0..6 {
                    covered_pv += usize::from(d[k].abs() <= 3.0 * s.covariance[k][k].sqrt());
                }
            }
            if trial < 12 {
                runs.entry("refined (per-view)")
                    .or_default()
                    .push(RunErrors {
                        errors: result.errors.clone(),
                        rot_deg: r,
                        t_mm: t,
                    });
            }
            if image_path || (repeat && trial < 12) {
                let mut img = base;
                apply_refinement(
                    &mut img,
                    &input,
                    &pixels,
                    &sc.camera,
                    RefineMode::Stochastic,
                    MotionPairs::All,
                    sc.pixel_sigma,
                )
                .expect("image refinement");
                let (r, t, _) = x_error(&img.x, &scene.x_true);
                image.add(r, t);
                if trial < 12 {
                    runs.entry("image path (stochastic)")
                        .or_default()
                        .push(RunErrors {
                            errors: img.errors.clone(),
                            rot_deg: r,
                            t_mm: t,
                        });
                }
            }
            if json_path.is_some() {
                json_trials.push(serde_json::json!({
                    "x_true": pose_rows(&scene.x_true),
                    "base_from_gripper": input.base_from_gripper.iter().map(pose_rows).collect::<Vec<_>>(),
                    "camera_from_target": input.camera_from_target.iter().map(pose_rows).collect::<Vec<_>>(),
                    "refined_error": refined_error,
                }));
            }
        }
        let (br, bt) = bound.rms();
        let (dr, dt) = diag.rms();
        let (pr, pt) = perview.rms();
        let mut line = format!(
            "| {} | {br:.4} / {bt:.3} | {dr:.4} / {dt:.3} | {:.2} / {:.2} | {pr:.4} / {pt:.3} | {:.2} / {:.2} | {:.1} % / {:.1} % |",
            sc.name,
            dr / br,
            dt / bt,
            pr / br,
            pt / bt,
            100.0 * covered as f64 / axes.max(1) as f64,
            100.0 * covered_pv as f64 / axes.max(1) as f64,
        );
        if image_path {
            let (ir, it) = image.rms();
            line += &format!(" {ir:.4} / {it:.3} | {:.2} / {:.2} |", ir / br, it / bt);
        }
        println!("{line}");
        let (or, ot) = diag_old.rms();
        model_rows.push(format!(
            "| {} | {or:.4} / {ot:.3} | {:.2} / {:.2} | {:.1} % | {} |",
            sc.name,
            or / br,
            ot / bt,
            100.0 * covered_old as f64 / axes.max(1) as f64,
            models
                .iter()
                .map(|(k, v)| format!("{k} {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        let (mr, mt) = diag.mean();
        let (mpr, mpt) = perview.mean();
        let (fr, ft) = fixed_rule.mean();
        let mut cells = format!(
            "| {} | {mr:.4} / {mt:.3} | {mpr:.4} / {mpt:.3} | {fr:.4} / {ft:.3} |",
            sc.name
        );
        for tally in closed.values() {
            let (r, t) = tally.mean();
            cells += &format!(" {r:.4} / {t:.3} |");
        }
        mean_rows.push((closed.keys().cloned().collect::<Vec<_>>(), cells));
        if repeat && si == 2 {
            repeat_rows.push((sc.name.clone(), runs));
        }
        if json_path.is_some() {
            json_scenarios.push(serde_json::json!({
                "name": sc.name, "setup": sc.setup.name(), "trials": json_trials,
                "refined_mean": [mr, mt], "closed_form_mean": closed.iter().map(|(k, v)| (k.clone(), v.mean())).collect::<BTreeMap<_, _>>(),
            }));
        }
    }
    println!("\nThe default's camera noise model chosen per trial, and the diagonal model alone\n");
    println!("| scenario | diagonal alone RMS | ratio rot / t | coverage 3 std | default's model (trials) |");
    println!("|---|---|---|---|---|");
    for row in &model_rows {
        println!("{row}");
    }
    if let Some((names, _)) = mean_rows.first() {
        println!("\nMean X error (rotation deg / translation mm)\n");
        println!(
            "| scenario | refined (diag) | refined (per-view) | fixed-rule closed form |{}",
            names.iter().map(|n| format!(" {n} |")).collect::<String>()
        );
        println!("|---|---|---|---|{}", "---|".repeat(names.len()));
        for (_, row) in &mean_rows {
            println!("{row}");
        }
    }
    for (name, runs) in repeat_rows {
        println!("\nRepeatability, 12 runs of {name}: median (IQR)\n");
        println!("| estimate | translation RMS mm | translation max mm | rotation RMS deg | rotation max deg | X error mm | X error deg |");
        println!("|---|---|---|---|---|---|---|");
        for (estimate, list) in runs {
            let col = |f: &dyn Fn(&RunErrors) -> f64| {
                let (m, iqr) = quartiles(list.iter().map(f).collect());
                format!("{m:.4} ({iqr:.4})")
            };
            println!(
                "| {estimate} | {} | {} | {} | {} | {} | {} |",
                col(&|r| r.errors.translation_rms_mm),
                col(&|r| r.errors.translation_max_mm),
                col(&|r| r.errors.rotation_rms_deg),
                col(&|r| r.errors.rotation_max_deg),
                col(&|r| r.t_mm),
                col(&|r| r.rot_deg),
            );
        }
    }
    if let Some(path) = json_path {
        std::fs::write(&path, serde_json::to_string(&json_scenarios).expect("json"))
            .expect("write trials");
        eprintln!("trials written to {path}");
    }
}
