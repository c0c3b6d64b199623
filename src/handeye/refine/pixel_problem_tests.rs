//! Reprojection refinement on a seeded scene whose camera looks at a 9x6
//! grid (0.03 m pitch) from about 0.6 m.

use crate::calib::View;
use crate::camera::Camera;
use crate::handeye::closed_form::solve_method;
use crate::handeye::quality::residuals::pose_difference;
use crate::handeye::refine::pixel_problem::{refine, RefineOptions, RobotNoise};
use crate::handeye::{Chain, HandEyeMethod, MotionPairs, Pose, Setup};
use crate::rng::Rng;
use crate::synth::handeye::{project_grid, HandEyeScene};
use nalgebra::{Translation3, UnitQuaternion, Vector3};
use wasm_bindgen_test::wasm_bindgen_test;

pub(crate) fn looking_scene(setup: Setup, views: usize, seed: u64) -> HandEyeScene {
    let mut rng = Rng::new(seed);
    let x = Pose::from_parts(
        Translation3::new(0.03, -0.05, 0.1),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.2, -0.3, 1.0)),
    );
    let y = Pose::from_parts(
        Translation3::new(0.6, 0.2, -0.1),
        UnitQuaternion::from_scaled_axis(Vector3::new(3.0, 0.2, -0.1)),
    );
    let mut cams = Vec::new();
    let mut robots = Vec::new();
    for _ in 0..views {
        let r = UnitQuaternion::from_scaled_axis(Vector3::new(
            rng.range(-0.4, 0.4),
            rng.range(-0.4, 0.4),
            rng.range(-1.0, 1.0),
        ));
        // Grid centre (0.12, 0.075) in front of the camera at 0.5-0.7 m.
        let centre = Vector3::new(
            rng.range(-0.05, 0.05),
            rng.range(-0.05, 0.05),
            rng.range(0.5, 0.7),
        );
        let t = centre - r * Vector3::new(0.12, 0.075, 0.0);
        let cft = Pose::from_parts(Translation3::from(t), r);
        let bfg = match setup {
            Setup::EyeInHand => y * cft.inverse() * x.inverse(),
            Setup::EyeToHand => x * cft * y.inverse(),
        };
        cams.push(cft);
        robots.push(bfg);
    }
    HandEyeScene {
        setup,
        x_true: x,
        y_true: y,
        base_from_gripper: robots.clone(),
        camera_from_target: cams.clone(),
        base_from_gripper_true: robots,
        camera_from_target_true: cams,
    }
}

pub(crate) fn camera() -> Camera {
    Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480)
}

#[wasm_bindgen_test(unsupported = test)]
fn refinement_is_exact_without_noise_in_both_setups() {
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        let scene = looking_scene(setup, 8, 3);
        let views = project_grid(&scene, &camera(), (9, 6, 0.03), 0.0, 1);
        assert!(views.iter().all(|v| v.image_px.len() == 54));
        // Start away from the truth (1 cm, ~1 deg).
        let bump = Pose::from_parts(
            Translation3::new(0.01, -0.01, 0.005),
            UnitQuaternion::from_scaled_axis(Vector3::new(0.01, 0.01, -0.01)),
        );
        let r = refine(
            setup,
            &scene.base_from_gripper,
            &views,
            &camera(),
            &(scene.x_true * bump),
            &(scene.y_true * bump),
            &RefineOptions::default(),
        )
        .unwrap();
        let (t, a) = pose_difference(&r.x, &scene.x_true);
        assert!(t < 1e-6 && a < 1e-7, "{}: {t} mm {a} deg", setup.name());
        assert!(r.reprojection_rms_px < 1e-6, "{} px", r.reprojection_rms_px);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn refinement_beats_the_closed_form_on_noisy_data() {
    // Camera poses with OpenCV's noise (0.002 rad, 5 mm) feed the closed
    // form; the refinement sees 0.3 px pixel noise instead, which at 800 px
    // focal length and 0.6 m is ~0.2 mm per point, so it must land closer.
    let setup = Setup::EyeInHand;
    let scene = looking_scene(setup, 10, 5);
    let mut rng = Rng::new(77);
    let noisy_cams: Vec<Pose> = scene
        .camera_from_target
        .iter()
        .map(|c| {
            let rv = c.rotation.scaled_axis()
                + Vector3::new(
                    rng.gaussian(0.002),
                    rng.gaussian(0.002),
                    rng.gaussian(0.002),
                );
            let t = c.translation.vector
                + Vector3::new(
                    rng.gaussian(0.005),
                    rng.gaussian(0.005),
                    rng.gaussian(0.005),
                );
            Pose::from_parts(Translation3::from(t), UnitQuaternion::from_scaled_axis(rv))
        })
        .collect();
    let chain = Chain::new(setup, &scene.base_from_gripper, &noisy_cams).unwrap();
    let (x0, y0, _) = solve_method(HandEyeMethod::Daniilidis, &chain, MotionPairs::All).unwrap();
    let views: Vec<View> = project_grid(&scene, &camera(), (9, 6, 0.03), 0.3, 2);
    for noise in [RobotNoise::Trusted, RobotNoise::Estimate] {
        let options = RefineOptions {
            robot_noise: noise,
            ..Default::default()
        };
        let r = refine(
            setup,
            &scene.base_from_gripper,
            &views,
            &camera(),
            &x0,
            &y0,
            &options,
        )
        .unwrap();
        let (t0, a0) = pose_difference(&x0, &scene.x_true);
        let (t1, a1) = pose_difference(&r.x, &scene.x_true);
        assert!(
            t1 < t0 && a1 < a0,
            "{noise:?}: closed form {t0} mm {a0} deg, refined {t1} mm {a1} deg"
        );
        // 0.3 px per coordinate: the RMS point distance is sqrt(2) * 0.3 = 0.42 px.
        assert!(
            r.reprojection_rms_px > 0.35 && r.reprojection_rms_px < 0.5,
            "{} px",
            r.reprojection_rms_px
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn joint_intrinsics_and_control_points_recover_the_truth() {
    // Seed 003: world = robot base, points with world coordinates; the
    // intrinsics start 2 % off and are solved with the hand-eye transform.
    let setup = Setup::EyeInHand;
    let scene = looking_scene(setup, 8, 9);
    let cam = camera();
    let mut views = project_grid(&scene, &cam, (9, 6, 0.03), 0.0, 1);
    for v in &mut views {
        for p in &mut v.object_m {
            *p = scene.y_true * *p;
        }
    }
    let start = Camera::pinhole(816.0, 784.0, 325.0, 236.0, 640, 480);
    let bump = Pose::from_parts(
        Translation3::new(0.005, 0.0, -0.005),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.01, 0.0)),
    );
    let r = refine(
        setup,
        &scene.base_from_gripper,
        &views,
        &start,
        &(scene.x_true * bump),
        &Pose::identity(),
        &RefineOptions {
            intrinsics: true,
            points_in_world: true,
            ..Default::default()
        },
    )
    .unwrap();
    let (t, a) = pose_difference(&r.x, &scene.x_true);
    assert!(t < 1e-6 && a < 1e-7, "{t} mm {a} deg");
    assert!((r.camera.fx - 800.0).abs() < 1e-6 && (r.camera.cy - 240.0).abs() < 1e-6);
}

#[wasm_bindgen_test(unsupported = test)]
fn robot_correction_jacobian_matches_finite_differences() {
    // u = robot^-1-of-the-chain * q1 under a decoupled base-frame correction
    // of base_from_gripper; central differences with step 1e-6 have an error
    // of order step^2 * |q1| ~ 1e-12, so 1e-8 (m per unit step) is loose.
    use crate::handeye::refine::pixel_problem::{chain_robot_inverse, robot_correction_jacobian};
    use crate::handeye::refine::pose_residual::perturb;
    use nalgebra::Vector6;
    let robot = Pose::from_parts(
        Translation3::new(0.9, -0.4, 0.6),
        UnitQuaternion::from_scaled_axis(Vector3::new(2.0, -0.7, 0.4)),
    );
    let q1 = Vector3::new(0.3, 1.2, -0.5);
    for setup in [Setup::EyeInHand, Setup::EyeToHand] {
        let analytic = robot_correction_jacobian(setup, &robot, &q1);
        let h = 1e-6;
        for k in 0..6 {
            let mut d = Vector6::zeros();
            d[k] = h;
            let plus =
                chain_robot_inverse(setup, &perturb(&robot, &d)) * nalgebra::Point3::from(q1);
            let minus =
                chain_robot_inverse(setup, &perturb(&robot, &(-d))) * nalgebra::Point3::from(q1);
            let numeric = (plus - minus) / (2.0 * h);
            let diff = (numeric - analytic.column(k)).norm();
            assert!(diff < 1e-8, "{} column {k}: {diff} m", setup.name());
        }
    }
}

/// Seed 003's Table 1 (Zhang et al., "Simultaneous camera and hand-eye
/// calibration for laser-vision robot welding", /work/shared/seeds/003_*.txt,
/// section III): six control points, the end points of the laser line on
/// two cubes in a 256x192 image, image x y (px) and world wx wy wz (mm) read
/// from the ABB controller with the torch on each point.
const SEED003_TABLE1: [([f64; 2], [f64; 3]); 6] = [
    ([10.0, 116.0], [612.1, 236.2, 123.7]),
    ([64.0, 116.0], [597.1, 236.7, 123.7]),
    ([94.0, 116.0], [589.6, 237.1, 123.7]),
    ([99.0, 116.0], [587.4, 237.6, 123.7]),
    ([119.0, 116.0], [581.1, 237.9, 123.7]),
    ([174.0, 116.0], [566.1, 238.2, 123.7]),
];

/// Table 1 through the seed-003 solver (`points_in_world`: world = robot
/// base, one view, the robot pose T6 = identity since the paper does not
/// print it, so `x` is the camera's pose in the base).
///
/// What the paper reports that the table can check: its intrinsics and
/// hand-eye matrix (Eq. 9-10) are lost from the text, and its accuracy
/// figure (0.12 mm mean over 20 seam points) uses points it does not list.
/// What the table itself says, reproduced here: its image points lie on one
/// row (y = 116) and its world points on one line (within 0.4 mm), so a
/// central camera maps them by a 1-D projective map (3 numbers), and the six
/// points fit such a map only to about 1.5 px RMS (the third point 2.7 px
/// off, about 0.75 mm at the table's 0.28 mm per pixel). Six points give 12
/// equations, not the paper's 18, for its 17 unknowns: Table 1 alone does
/// not determine the intrinsics, so they are held here (f = 350 px, a
/// nominal centre) and the solver finds the pose.
#[wasm_bindgen_test(unsupported = test)]
fn seed003_table1_control_points_through_the_world_point_solver() {
    use nalgebra::{Matrix3, Point2, Point3, Rotation3};
    let mm = 1e-3;
    let world: Vec<Point3<f64>> = SEED003_TABLE1
        .iter()
        .map(|(_, w)| Point3::new(w[0] * mm, w[1] * mm, w[2] * mm))
        .collect();
    let image: Vec<Point2<f64>> = SEED003_TABLE1
        .iter()
        .map(|(p, _)| Point2::new(p[0], p[1]))
        .collect();
    // The world points lie on one line within 0.4 mm (0.35 mm at most).
    let (a, b) = (world[0], world[5]);
    let u = (b - a).normalize();
    for p in &world {
        let off = (p - a) - u * (p - a).dot(&u);
        assert!(off.norm() < 0.4 * mm, "{} mm off the line", off.norm() / mm);
    }
    // Start: camera 100 mm above the line's middle, looking down (world -z),
    // its x axis along the line (image x grows from point 1 to point 6).
    let z = Vector3::new(0.0, 0.0, -1.0);
    let x_axis = (u - z * u.dot(&z)).normalize();
    let y_axis = z.cross(&x_axis);
    let r = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x_axis, y_axis, z]));
    let middle = Point3::from((a.coords + b.coords) / 2.0);
    let base_from_camera = Pose::from_parts(
        Translation3::from(middle.coords - z * 0.1),
        UnitQuaternion::from_rotation_matrix(&r),
    );
    let camera = Camera::pinhole(350.0, 350.0, 127.5, 95.5, 256, 192);
    let views = vec![View {
        name: "seed003_table1".into(),
        object_m: world.clone(),
        image_px: image.clone(),
        point_ids: Vec::new(),
    }];
    let r = refine(
        Setup::EyeInHand,
        &[Pose::identity()],
        &views,
        &camera,
        &base_from_camera,
        &Pose::identity(),
        &RefineOptions {
            points_in_world: true,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let residuals: Vec<f64> = world
        .iter()
        .zip(&image)
        .map(|(w, p)| {
            let q = camera
                .project(&(r.x.inverse() * w))
                .unwrap_or_else(|e| panic!("{e}"));
            (q - p).norm()
        })
        .collect();
    eprintln!(
        "seed 003 Table 1: rms {:.3} px, per point {residuals:.2?} px",
        r.reprojection_rms_px
    );
    // The least-squares 1-D projective map of the six x coordinates (a
    // separate fit, numpy, x = (a w + b) / (c w + 1) over wx) leaves
    // 1.486 px RMS with the third and fifth points worst (2.67, 2.35 px):
    // the solver lands there (measured 1.485 px).
    assert!(
        r.reprojection_rms_px > 1.45 && r.reprojection_rms_px < 1.52,
        "{} px",
        r.reprojection_rms_px
    );
    let worst = residuals
        .iter()
        .enumerate()
        .fold((0, 0.0), |m, (i, e)| if *e > m.1 { (i, *e) } else { m });
    assert_eq!(worst.0, 2, "the third point is the worst: {residuals:?}");
}
