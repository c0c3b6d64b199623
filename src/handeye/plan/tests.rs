//! Tests of the pose plan on a seeded eye-in-hand and eye-to-hand cell.

use super::*;
use nalgebra::Translation3;
use wasm_bindgen_test::wasm_bindgen_test;

/// A 9 x 6 board of 30 mm squares seen from 0.5 m by a 1280 x 960 camera,
/// the camera 0.1 m in front of the flange.
pub(crate) fn cell(setup: Setup) -> PlanInput {
    let camera = Camera::pinhole(1000.0, 1000.0, 640.0, 480.0, 1280, 960);
    let board_m: Vec<Point3<f64>> = (0..6)
        .flat_map(|r| (0..9).map(move |c| Point3::new(c as f64 * 0.03, r as f64 * 0.03, 0.0)))
        .collect();
    let centre = board_centre(&board_m);
    // The camera 0.5 m above the board centre, looking down at it.
    let camera_from_target = Pose::from_parts(
        Translation3::new(-centre.x, -centre.y, 0.5),
        UnitQuaternion::identity(),
    );
    let guess = Pose::from_parts(
        Translation3::new(0.03, -0.02, 0.1),
        UnitQuaternion::from_euler_angles(0.0, 0.0, 0.3),
    );
    PlanInput {
        setup,
        base_from_gripper: Pose::from_parts(
            Translation3::new(0.5, 0.1, 0.8),
            UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.2),
        ),
        camera_from_target,
        camera,
        board_m,
        guess,
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn a_plan_keeps_the_board_in_view_and_rotates_about_two_axes() {
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        let input = cell(setup);
        let limits = PlanLimits::default();
        let plan = plan(&input, &limits, &PlanNoise::default()).unwrap();
        assert_eq!(plan.poses.len(), 15);
        for p in &plan.poses {
            assert!(in_image(&input, &p.camera_from_target, limits.margin_px));
            // The flange pose makes the camera see what was planned.
            let again = robot_pose_for_view(&input, &p.camera_from_target);
            assert!(
                (again.translation.vector - p.base_from_gripper.translation.vector).norm() < 1e-12
            );
            assert!(p.tilt_deg <= 40.0 + 1e-9);
        }
        assert!(plan.motion.angle_max_deg >= 30.0, "{:?}", plan.motion);
        assert!(plan.motion.axis_spread_deg >= 30.0, "{:?}", plan.motion);
        assert!(
            plan.predicted.bound95_mm > 0.0 && plan.predicted.bound95_mm < 5.0,
            "{:?}",
            plan.predicted
        );
        assert!(
            plan.notes[0].starts_with("joint limits, reachability and collisions are not modelled")
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn a_tight_flange_box_is_refused_with_what_to_widen() {
    let input = cell(Setup::EyeInHand);
    let limits = PlanLimits {
        flange_box_m: Some(([0.0, 0.0, 0.0], [0.01, 0.01, 0.01])),
        ..PlanLimits::default()
    };
    let err = plan(&input, &limits, &PlanNoise::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("only 0 candidate poses keep the whole target in view"),
        "{err}"
    );
}
