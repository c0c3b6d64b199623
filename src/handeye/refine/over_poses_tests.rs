//! The maximum-likelihood pose refinement on seeded scenes: exact without
//! noise, at the Cramér-Rao bound with noise (tolerances from the number of
//! trials), honest reported std, outliers flagged, eye-to-hand, SCARA, and
//! the flag that turns it off.

use crate::handeye::quality::residuals::pose_difference;
use crate::handeye::refine::over_poses::measurements;
use crate::handeye::refine::pose_noise::{CameraNoise, NoiseModel};
use crate::handeye::refine::pose_problem::fisher_information;
use crate::handeye::refine::pose_residual::difference;
use crate::handeye::solve::{calibrate, HandEyeInput, HandEyeOptions};
use crate::handeye::{Pose, Setup};
use crate::rng::Rng;
use crate::synth::handeye_looking::{looking_scene, perturbed, LookingConfig, LookingScene};
use nalgebra::{SMatrix, Translation3, UnitQuaternion, Vector3};
use wasm_bindgen_test::wasm_bindgen_test;

fn config(setup: Setup, views: usize) -> LookingConfig {
    LookingConfig {
        setup,
        views,
        distance_m: 0.5,
        grid: (9, 6, 0.03),
        max_tilt_deg: 30.0,
        max_roll_deg: 60.0,
    }
}

fn options() -> HandEyeOptions {
    HandEyeOptions {
        bootstrap_samples: 0,
        ..Default::default()
    }
}

/// Injected noise: robot 0.1 mm / 0.02 deg; camera as PnP at 0.5 m gives it
/// (tilts 10x the roll, depth 8x the lateral translation).
const ROBOT: (f64, f64) = (0.02, 0.1e-3);
const CAMERA_ROT_DEG: [f64; 3] = [0.05, 0.05, 0.005];
const CAMERA_T_M: [f64; 3] = [0.05e-3, 0.05e-3, 0.4e-3];

/// The grid centre (target frame), where the test camera looks: PnP-like
/// noise tilts the board about it.
const CENTRE: Vector3<f64> = Vector3::new(0.12, 0.075, 0.0);

/// A camera pose with noise rotating the board about its centre.
fn pnp_like(rng: &mut Rng, p: &Pose) -> Pose {
    let noisy = perturbed(rng, p, CAMERA_ROT_DEG.map(f64::to_radians), CAMERA_T_M);
    let d = difference(p, &noisy);
    let w = Vector3::new(d[0], d[1], d[2]);
    let lever = p.rotation * CENTRE;
    let mut pivoted = d;
    pivoted
        .fixed_rows_mut::<3>(3)
        .copy_from(&(d.fixed_rows::<3>(3) + lever.cross(&w)));
    crate::handeye::refine::pose_residual::perturb(p, &pivoted)
}

fn noisy_input(scene: &LookingScene, rng: &mut Rng) -> HandEyeInput {
    let r = ROBOT.0.to_radians();
    HandEyeInput {
        setup: scene.setup,
        base_from_gripper: scene
            .base_from_gripper
            .iter()
            .map(|p| perturbed(rng, p, [r; 3], [ROBOT.1; 3]))
            .collect(),
        camera_from_target: scene
            .camera_from_target
            .iter()
            .map(|p| pnp_like(rng, p))
            .collect(),
    }
}

fn true_model(scene: &LookingScene) -> NoiseModel {
    let mut m = NoiseModel::new(CameraNoise::Diagonal);
    m.pivot_levers = scene
        .camera_from_target
        .iter()
        .map(|c| c.rotation * CENTRE)
        .collect();
    m.variances = vec![ROBOT.0.to_radians().powi(2), ROBOT.1.powi(2)];
    m.variances
        .extend(CAMERA_ROT_DEG.iter().map(|d| d.to_radians().powi(2)));
    m.variances.extend(CAMERA_T_M.iter().map(|t| t * t));
    m
}

fn truth_input(scene: &LookingScene) -> HandEyeInput {
    HandEyeInput {
        setup: scene.setup,
        base_from_gripper: scene.base_from_gripper.clone(),
        camera_from_target: scene.camera_from_target.clone(),
    }
}

/// The 12-vector error `[x, y]` of an estimate.
fn error12(x: &Pose, y: &Pose, scene: &LookingScene) -> SMatrix<f64, 12, 1> {
    let mut e = SMatrix::<f64, 12, 1>::zeros();
    e.fixed_rows_mut::<6>(0)
        .copy_from(&difference(&scene.x_true, x));
    e.fixed_rows_mut::<6>(6)
        .copy_from(&difference(&scene.y_true, y));
    e
}

#[wasm_bindgen_test(unsupported = test)]
fn noise_free_poses_give_x_and_z_exactly_in_both_setups() {
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        let scene = looking_scene(&config(setup, 12), 3);
        let result = calibrate(&truth_input(&scene), &options()).unwrap();
        assert!(
            result.method.starts_with("refined from "),
            "{}",
            result.method
        );
        let e = error12(&result.x, &result.y, &scene);
        // Round-off only: 1e-9 rad and 1e-9 m.
        assert!(e.amax() < 1e-9, "{setup:?}: {e}");
        let summary = result.pose_refinement.as_ref().unwrap();
        assert!(summary.outlier_views.is_empty());
        // Every closed form was scored; the start is the lowest cost.
        let costs: Vec<f64> = result.methods.iter().filter_map(|m| m.pose_cost).collect();
        assert_eq!(costs.len(), 8);
        assert!(costs.iter().all(|c| *c >= summary.closed_form_cost));
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn noisy_poses_reach_the_bound_and_the_reported_std_covers_the_truth() {
    // 40 trials of 20 views each setup. The RMS of a 3-vector error over
    // 40 trials has a relative std of about 1 / sqrt(2 * 120) = 6.5 %: the
    // ratio to the bound must lie in [0.8, 1.25] (3 std and the few
    // percent lost to estimating 8 noise levels from 120 residuals). The
    // Mahalanobis distance of the 12-vector error under the reported
    // covariance is chi-squared(12): its mean over 40 trials is 12 +- 0.8,
    // so [9.5, 16] (estimated covariances run a little small).
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        let mut rng = Rng::new(17);
        let trials = 40;
        let (mut sum_rot, mut sum_t, mut bound_rot, mut bound_t, mut maha) =
            (0.0, 0.0, 0.0, 0.0, 0.0);
        for trial in 0..trials {
            let scene = looking_scene(&config(setup, 20), 100 + trial);
            let input = noisy_input(&scene, &mut rng);
            let result = calibrate(&input, &options()).unwrap();
            let e = error12(&result.x, &result.y, &scene);
            sum_rot += e.fixed_rows::<3>(0).norm_squared();
            sum_t += e.fixed_rows::<3>(3).norm_squared();
            let truth = measurements(&truth_input(&scene));
            let crb = fisher_information(
                setup,
                &truth,
                &true_model(&scene),
                &scene.x_true,
                &scene.y_true,
            )
            .try_inverse()
            .unwrap();
            bound_rot += crb.fixed_view::<3, 3>(0, 0).trace();
            bound_t += crb.fixed_view::<3, 3>(3, 3).trace();
            let s = result.pose_refinement.unwrap();
            let cov = SMatrix::<f64, 12, 12>::from_fn(|r, c| s.covariance[r][c]);
            maha += (e.transpose() * cov.try_inverse().unwrap() * e)[0];
        }
        let ratio_rot = (sum_rot / bound_rot).sqrt();
        let ratio_t = (sum_t / bound_t).sqrt();
        let mean_maha = maha / trials as f64;
        eprintln!("{setup:?}: RMS / bound rotation {ratio_rot:.3}, translation {ratio_t:.3}, mean chi2 {mean_maha:.2}");
        assert!(
            (0.8..1.25).contains(&ratio_rot) && (0.8..1.25).contains(&ratio_t),
            "{setup:?}: RMS / bound rotation {ratio_rot:.3}, translation {ratio_t:.3}"
        );
        assert!(
            (9.5..16.0).contains(&mean_maha),
            "{setup:?}: mean chi2 {mean_maha:.2}"
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn an_outlier_pose_is_flagged_and_does_not_pull_the_estimate() {
    let scene = looking_scene(&config(Setup::EyeInHand, 20), 5);
    let mut rng = Rng::new(9);
    let mut input = noisy_input(&scene, &mut rng);
    // View 7's robot pose is 3 mm and 0.5 deg off (a wrong pose pairing
    // would be worse): about 30 sigma.
    input.base_from_gripper[7] *= Pose::from_parts(
        Translation3::new(0.003, 0.0, 0.0),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.5f64.to_radians(), 0.0)),
    );
    let result = calibrate(&input, &options()).unwrap();
    let s = result.pose_refinement.as_ref().unwrap();
    // View 7 is flagged far above the threshold; a good view may sit just
    // above it (1 % of good views do, by the threshold's definition).
    let norms = &s.whitened_residual_norms;
    assert!(s.outlier_views.contains(&7), "{norms:?}");
    assert!(
        norms[7] > 3.0 * crate::handeye::refine::pose_problem::HUBER_SCALE,
        "{norms:?}"
    );
    for &v in s.outlier_views.iter().filter(|v| **v != 7) {
        assert!(
            norms[v] < 1.2 * crate::handeye::refine::pose_problem::HUBER_SCALE,
            "view {v}: {norms:?}"
        );
    }
    assert!(s.outlier_views.len() <= 2, "{:?}", s.outlier_views);
    assert!(
        result
            .warnings
            .iter()
            .any(|w| w.contains("view(s) 7 ") || w.contains("view(s) 7, ")),
        "{:?}",
        result.warnings
    );
    // The estimate stays within 5 reported std of the truth on every axis.
    let e = error12(&result.x, &result.y, &scene);
    for k in 0..12 {
        let std = s.covariance[k][k].sqrt();
        assert!(
            e[k].abs() < 5.0 * std,
            "axis {k}: error {} vs std {std}",
            e[k]
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn few_poses_use_the_default_levels_and_the_flag_turns_it_off() {
    let scene = looking_scene(&config(Setup::EyeToHand, 6), 8);
    let mut rng = Rng::new(4);
    let input = noisy_input(&scene, &mut rng);
    let result = calibrate(&input, &options()).unwrap();
    let s = result.pose_refinement.as_ref().unwrap();
    assert!(!s.noise_estimated_per_component);
    // One common factor on the defaults: their ratios are kept.
    let n = &s.noise;
    let ratio = n.robot_translation_mm / n.robot_rotation_deg;
    assert!((ratio - 0.1 / 0.02).abs() < 1e-9, "{n:?}");
    let off = calibrate(
        &input,
        &HandEyeOptions {
            refine_poses: false,
            ..options()
        },
    )
    .unwrap();
    assert!(!off.method.starts_with("refined"), "{}", off.method);
    assert!(off.pose_refinement.is_none());
    assert!(off.methods.iter().all(|m| m.pose_cost.is_none()));
}

#[wasm_bindgen_test(unsupported = test)]
fn scara_refines_the_observable_part_and_keeps_the_axis_unobservable() {
    // Every gripper pose rotates about the base z axis only: the camera's
    // height on the gripper (along the axis in the gripper frame) is
    // unobservable, so it stays at the closed form's 0 with zero variance.
    let (x, _, input) = crate::handeye::solver_tests::scara_scene(12, -1.0, 0.2, 0.05, 0.01);
    let result = calibrate(&input, &options()).unwrap();
    assert_eq!(result.method, "refined from scara");
    let axis = result.unobservable_translation[0];
    let d = result.x.translation.vector - x.translation.vector;
    let along = d.dot(&axis);
    assert!(
        (d - axis * along).norm() < 1e-9,
        "observable part off {d:?}"
    );
    assert!(result.x.translation.vector.dot(&axis).abs() < 1e-12);
    let (_, r) = pose_difference(&result.x, &x);
    assert!(r < 1e-7, "rotation off {r} deg");
    let s = result.pose_refinement.unwrap();
    let cov = SMatrix::<f64, 12, 12>::from_fn(|r, c| s.covariance[r][c]);
    let along_var = (axis.transpose() * cov.fixed_view::<3, 3>(3, 3) * axis)[0];
    assert!(
        along_var.abs() < 1e-30,
        "variance along the axis {along_var}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn the_json_option_and_report_keys() {
    let scene = looking_scene(&config(Setup::EyeInHand, 10), 2);
    let pose = |p: &Pose| serde_json::to_value(crate::geometry::PoseJson::from(p)).unwrap();
    let mut input = serde_json::json!({
        "setup": "eye-in-hand",
        "base_from_gripper": scene.base_from_gripper.iter().map(pose).collect::<Vec<_>>(),
        "camera_from_target": scene.camera_from_target.iter().map(pose).collect::<Vec<_>>(),
        "bootstrap_samples": 0,
    });
    let run = |v: &serde_json::Value| -> serde_json::Value {
        serde_json::from_str(&crate::api::handeye::solve_handeye_json(&v.to_string()).unwrap())
            .unwrap()
    };
    let out = run(&input);
    assert!(out["method"].as_str().unwrap().starts_with("refined from "));
    let p = &out["pose_refinement"];
    assert_eq!(p["covariance"].as_array().unwrap().len(), 12);
    // The camera noise model is chosen by likelihood; each name comes with
    // its own keys.
    match p["camera_noise_model"].as_str().unwrap() {
        "diagonal" => assert_eq!(
            p["noise"]["camera_rotation_deg"].as_array().unwrap().len(),
            3
        ),
        "predicted_pnp" => {
            assert!(p["noise"]["camera_covariance_sigma"].is_number());
            assert_eq!(
                p["camera_noise_nominal_target_m"]["half_extent"]
                    .as_array()
                    .unwrap()
                    .len(),
                2
            );
        }
        other => panic!("camera_noise_model {other}"),
    }
    assert_eq!(
        p["camera_transform_std"]["rotation_deg"]
            .as_array()
            .unwrap()
            .len(),
        3
    );
    assert!(out["methods"][0]["pose_cost"].is_number());
    input["refine_poses"] = serde_json::Value::Bool(false);
    let off = run(&input);
    assert!(off["pose_refinement"].is_null());
    assert!(!off["method"].as_str().unwrap().starts_with("refined"));
}
