//! The hand-eye error where the robot works (issue 39, part 2 and 3), on
//! seeded scenes: the work-point 95 % bound covers the true error, held-out
//! poses show the noise level, the result does not depend on the order of
//! the poses, and a planned pose set reaches its predicted error and beats
//! a random one.
//!
//! The plan's Monte Carlo projects the board corners with the camera and
//! adds pixel noise (the renderer's corner noise without the image), then
//! solves through the image path (PnP, pose refinement with each view's PnP
//! covariance).

use nalgebra::{Point2, Point3, Translation3, UnitQuaternion, Vector3};
use robocal::api::handeye::{solve_handeye, ImagePoints};
use robocal::api::handeye_field::{solve_handeye_field, FieldRequest};
use robocal::calib::View;
use robocal::camera::Camera;
use robocal::handeye::plan::{candidate, plan, view_frame, PlanInput, PlanLimits, PlanNoise};
use robocal::handeye::refine::over_pixels::RefineMode;
use robocal::handeye::report::HandEyeReport;
use robocal::handeye::{calibrate, HandEyeInput, HandEyeOptions, Pose, Setup};
use robocal::rng::Rng;
use robocal::synth::handeye::{handeye_scene, HandEyeSceneConfig};

fn quick() -> HandEyeOptions {
    HandEyeOptions {
        bootstrap_samples: 0,
        ..Default::default()
    }
}

fn x_of(report: &HandEyeReport) -> Pose {
    match report.setup {
        Setup::EyeInHand => report
            .gripper_from_camera
            .as_ref()
            .unwrap()
            .to_pose()
            .unwrap(),
        Setup::EyeToHand => report.base_from_camera.as_ref().unwrap().to_pose().unwrap(),
    }
}

/// The error at a camera-frame point between two camera transforms (mm).
fn point_error_mm(x: &Pose, truth: &Pose, q_camera: &[f64; 3]) -> f64 {
    let q = Point3::from(*q_camera);
    (x * q - truth * q).norm() * 1e3
}

#[test]
fn the_work_point_bound_covers_the_true_error_in_monte_carlo() {
    let seeds = 50;
    let mut covered = 0;
    for seed in 0..seeds {
        let config = HandEyeSceneConfig {
            robot_rotation_sigma_rad: 0.0005,
            robot_translation_sigma_m: 0.0005,
            camera_rotation_sigma_rad: 0.001,
            camera_translation_sigma_m: 0.001,
            ..HandEyeSceneConfig::noise_free(Setup::EyeInHand, 15)
        };
        let s = handeye_scene(&config, 100 + seed);
        let input = HandEyeInput {
            setup: s.setup,
            base_from_gripper: s.base_from_gripper.clone(),
            camera_from_target: s.camera_from_target.clone(),
        };
        let result = calibrate(&input, &quick()).unwrap();
        let report = HandEyeReport::new(&result);
        let w = report.work_point_error.expect("work_point_error");
        assert_eq!(w.frame, "gripper");
        assert!(
            w.verdict
                .starts_with("hand-eye error at the target centre: within "),
            "{}",
            w.verdict
        );
        assert!(!w.shrink_by.is_empty());
        let e = point_error_mm(&result.x, &s.x_true, &w.point_camera_m);
        if e <= w.bound95_mm {
            covered += 1;
        }
    }
    eprintln!("work-point bound coverage: {covered} of {seeds}");
    assert!(covered * 100 >= 90 * seeds, "{covered} of {seeds}");
}

#[test]
fn held_out_poses_show_the_noise_level() {
    let config = HandEyeSceneConfig {
        robot_rotation_sigma_rad: 0.0005,
        robot_translation_sigma_m: 0.0005,
        camera_rotation_sigma_rad: 0.001,
        camera_translation_sigma_m: 0.001,
        ..HandEyeSceneConfig::noise_free(Setup::EyeInHand, 40)
    };
    let s = handeye_scene(&config, 7);
    let input = HandEyeInput {
        setup: s.setup,
        base_from_gripper: s.base_from_gripper.clone(),
        camera_from_target: s.camera_from_target.clone(),
    };
    let field = FieldRequest {
        holdout: 10,
        tcp_m: Some([0.0, 0.0, 0.15]),
        ..FieldRequest::default()
    };
    let report = solve_handeye_field(&input, &quick(), None, Vec::new(), &field).unwrap();
    let h = report.holdout.as_ref().unwrap();
    assert_eq!(h.per_pose.len(), 10);
    assert_eq!(h.per_pose[0].view, 30);
    // The same error with the true transforms: the noise alone.
    let truth: Vec<f64> = (30..40)
        .map(|i| {
            let predicted = s.x_true.inverse() * s.base_from_gripper[i].inverse() * s.y_true;
            (predicted.translation.vector - s.camera_from_target[i].translation.vector).norm() * 1e3
        })
        .collect();
    let truth_rms = (truth.iter().map(|v| v * v).sum::<f64>() / 10.0).sqrt();
    eprintln!(
        "holdout RMS {:.3} mm, with the true transforms {truth_rms:.3} mm, expected {:.3} mm",
        h.rms_mm, h.expected_rms_mm
    );
    assert!(
        h.rms_mm > 0.8 * truth_rms && h.rms_mm < 1.3 * truth_rms,
        "{h:?} vs {truth_rms}"
    );
    assert!(
        h.rms_mm < 2.0 * h.expected_rms_mm && h.rms_mm > 0.5 * h.expected_rms_mm,
        "{h:?}"
    );
    assert!(
        h.verdict
            .starts_with("the 10 held-out poses agree with the fit"),
        "{}",
        h.verdict
    );
    let tcp = report.tcp_error.as_ref().unwrap();
    assert_eq!(tcp.point_m, [0.0, 0.0, 0.15]);
    // Too many held out.
    let err = solve_handeye_field(
        &input,
        &quick(),
        None,
        Vec::new(),
        &FieldRequest {
            holdout: 38,
            ..FieldRequest::default()
        },
    )
    .unwrap_err();
    assert!(
        err.to_string()
            .starts_with("holdout: 38 pose pairs held out of 40"),
        "{err}"
    );
}

#[test]
fn the_result_does_not_depend_on_the_order_of_the_poses() {
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        let s = handeye_scene(&HandEyeSceneConfig::opencv_noise(setup, 14), 21);
        let solve = |order: &[usize]| {
            let input = HandEyeInput {
                setup,
                base_from_gripper: order.iter().map(|&i| s.base_from_gripper[i]).collect(),
                camera_from_target: order.iter().map(|&i| s.camera_from_target[i]).collect(),
            };
            calibrate(&input, &quick()).unwrap()
        };
        let forward: Vec<usize> = (0..14).collect();
        let a = solve(&forward);
        for perm_seed in 0..3u64 {
            let mut order = forward.clone();
            let mut rng = Rng::new(perm_seed);
            for i in (1..order.len()).rev() {
                order.swap(i, rng.below(i + 1));
            }
            let b = solve(&order);
            let dt = (a.x.translation.vector - b.x.translation.vector).norm();
            let dr = (a.x.rotation.inverse() * b.x.rotation).angle();
            let dy = (a.y.translation.vector - b.y.translation.vector).norm();
            assert!(
                dt <= 1e-9 * a.x.translation.vector.norm(),
                "{setup:?} {order:?}: x moved {dt} m"
            );
            assert!(dr <= 1e-9, "{setup:?} {order:?}: x turned {dr} rad");
            assert!(
                dy <= 1e-9 * a.y.translation.vector.norm(),
                "{setup:?} {order:?}: y moved {dy} m"
            );
        }
    }
}

/// The plan's cell: a 9 x 6 board of 30 mm squares at 0.5 m, a 1280 x 960
/// camera 0.1 m in front of the flange (the truth, also the plan's guess).
fn cell() -> PlanInput {
    let camera = Camera::pinhole(1000.0, 1000.0, 640.0, 480.0, 1280, 960);
    let board_m: Vec<Point3<f64>> = (0..6)
        .flat_map(|r| (0..9).map(move |c| Point3::new(c as f64 * 0.03, r as f64 * 0.03, 0.0)))
        .collect();
    PlanInput {
        setup: Setup::EyeInHand,
        base_from_gripper: Pose::from_parts(
            Translation3::new(0.5, 0.1, 0.8),
            UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.2),
        ),
        camera_from_target: Pose::from_parts(
            Translation3::new(-0.12, -0.075, 0.5),
            UnitQuaternion::identity(),
        ),
        camera,
        board_m,
        guess: Pose::from_parts(
            Translation3::new(0.03, -0.02, 0.1),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 0.3),
        ),
    }
}

fn left_noise(rng: &mut Rng, p: &Pose, sr: f64, st: f64) -> Pose {
    let w = Vector3::new(rng.gaussian(sr), rng.gaussian(sr), rng.gaussian(sr));
    let v = Vector3::new(rng.gaussian(st), rng.gaussian(st), rng.gaussian(st));
    Pose::from_parts(
        (p.translation.vector + v).into(),
        UnitQuaternion::from_scaled_axis(w) * p.rotation,
    )
}

/// One simulated calibration from planned views (`(robot, camera_from_target)`
/// truth): the work-point error (mm) at `q_camera`.
fn simulate(
    cell: &PlanInput,
    views: &[(Pose, Pose)],
    noise: &PlanNoise,
    q_camera: &[f64; 3],
    seed: u64,
) -> f64 {
    let mut rng = Rng::new(seed);
    let mut robots = Vec::new();
    let mut image_views = Vec::new();
    for (robot, cft) in views {
        robots.push(left_noise(
            &mut rng,
            robot,
            noise.robot_rotation_deg.to_radians(),
            noise.robot_translation_mm * 1e-3,
        ));
        let pixels: Vec<Point2<f64>> = cell
            .board_m
            .iter()
            .map(|p| {
                let px = cell.camera.project(&(cft * p)).unwrap();
                Point2::new(
                    px.x + rng.gaussian(noise.pixel_sigma_px),
                    px.y + rng.gaussian(noise.pixel_sigma_px),
                )
            })
            .collect();
        image_views.push(View::new("", cell.board_m.clone(), pixels));
    }
    let camera_from_target: Vec<Pose> = image_views
        .iter()
        .map(|v| {
            robocal::calib::pnp::camera_from_target(&cell.camera, v)
                .unwrap()
                .0
        })
        .collect();
    let input = HandEyeInput {
        setup: cell.setup,
        base_from_gripper: robots,
        camera_from_target,
    };
    let points = ImagePoints {
        views: &image_views,
        camera: &cell.camera,
        camera_std: None,
        refine: RefineMode::None,
        pixel_sigma_px: noise.pixel_sigma_px,
        refine_poses: true,
    };
    let mut options = quick();
    options.refine_poses = false;
    let report = solve_handeye(&input, &options, Some(&points), Vec::new()).unwrap();
    point_error_mm(&x_of(&report), &cell.guess, q_camera)
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|a| a * a).sum::<f64>() / v.len() as f64).sqrt()
}

#[test]
fn planned_poses_reach_the_predicted_error_and_beat_a_random_plan() {
    let cell = cell();
    let limits = PlanLimits {
        poses: 12,
        ..PlanLimits::default()
    };
    let noise = PlanNoise::default();
    let planned = plan(&cell, &limits, &noise).unwrap();
    let q = planned.predicted.point_camera_m;
    let views: Vec<(Pose, Pose)> = planned
        .poses
        .iter()
        .map(|p| (p.base_from_gripper, p.camera_from_target))
        .collect();
    let trials = 30;
    let errors: Vec<f64> = (0..trials)
        .map(|t| simulate(&cell, &views, &noise, &q, 1000 + t))
        .collect();
    let achieved = rms(&errors);
    let predicted = planned.predicted.rms_mm;
    // Random plans of the same size within the same limits, one per trial.
    let frame = view_frame(&cell);
    let (d_lo, d_hi) = (0.4, 0.6);
    let mut rng = Rng::new(5);
    let random_errors: Vec<f64> = (0..trials)
        .map(|t| {
            let mut views = Vec::new();
            while views.len() < limits.poses {
                let angles = (
                    rng.range(0.0, 40.0),
                    rng.range(0.0, 360.0),
                    rng.range(-60.0, 60.0),
                );
                if let Some(c) = candidate(&cell, &frame, angles, rng.range(d_lo, d_hi), &limits) {
                    views.push((c.base_from_gripper, c.camera_from_target));
                }
            }
            simulate(&cell, &views, &noise, &q, 2000 + t)
        })
        .collect();
    let random = rms(&random_errors);
    eprintln!(
        "plan: predicted RMS {predicted:.4} mm, achieved {achieved:.4} mm over {trials} trials; \
         random plans {random:.4} mm"
    );
    assert!(
        (achieved / predicted - 1.0).abs() <= 0.2,
        "achieved {achieved} vs predicted {predicted}"
    );
    assert!(
        achieved < random,
        "planned {achieved} mm vs random {random} mm"
    );
}

/// Issue 39, part 3, on rendered images (tests/handeye/plan_trials.rs): the
/// planned poses, rendered, detected and solved through the api, reach the
/// plan's predicted RMS error at the work point within 20 %, and random
/// plans of the same size do worse. The plan's pixel noise is measured on
/// the rendered current view (its PnP residual).
#[test]
fn planned_poses_reach_the_predicted_error_on_rendered_images() {
    // 64 trials: the RMS of an error dominated by one or two directions
    // then has a relative spread of about 7 % (1 / sqrt(2 x 64 x 1.5));
    // 16 trials (12 %) read 1.32 on seed 3 where 40 read 1.20 and seed 4
    // 1.06 (examples/plan_monte_carlo.rs).
    let run = crate::plan_trials::run((64, 6), 11, PlanNoise::default(), true).unwrap();
    eprintln!(
        "rendered plan: assumed {:.3} px (detector {:.3} px), predicted RMS {:.4} mm, \
         achieved {:.4} mm over {} trials; {} random plans {:.4} mm",
        run.assumed_sigma_px,
        run.corner_rms_px,
        run.predicted_mm,
        run.planned_mm,
        run.trials,
        run.random_trials,
        run.random_mm
    );
    assert!(
        (run.planned_mm / run.predicted_mm - 1.0).abs() <= 0.2,
        "achieved {} mm vs predicted {} mm",
        run.planned_mm,
        run.predicted_mm
    );
    assert!(
        run.planned_mm < run.random_mm,
        "planned {} mm vs random {} mm",
        run.planned_mm,
        run.random_mm
    );
}
