//! Calibration, stereo and hand-eye from partial views: every view holds a
//! subset of the 9x6 grid's points, as a marker board gives when it is
//! partly out of the image or occluded: whole rows or columns cut off at one
//! side (the image border), then a random 30-70 % of the rest removed.
//!
//! Tolerances: noise-free scenes are solved to rounding (1e-9 relative on
//! the intrinsics, 1e-9 m / 1e-9 rad on transforms); noisy ones within 4
//! reported standard deviations (the reported std comes from the injected
//! pixel noise through the covariance), with the RMS within 10 % of its
//! expectation `sigma sqrt(2 (1 - p / 2N))`.

use nalgebra::{Point2, Point3, Translation3, Vector3};
use robocal::api::camera::calibrate_input;
use robocal::api::camera::{CalibrationInput, JsonOptions, JsonView, LensModel, MethodChoice};
use robocal::calib::multi::stereo::calibrate_stereo;
use robocal::calib::{calibrate, CalibrationOptions, View};
use robocal::geometry::{rotation_from_rotvec, Pose};
use robocal::synth::handeye_looking::{grid_pixels, looking_scene, LookingConfig};
use robocal::synth::{Rng, Scene};
use robocal::Camera;
use serde_json::{json, Value};

const COLS: usize = 9;
const ROWS: usize = 6;
const PITCH_M: f64 = 0.03;

/// The grid id of a board point (row by row), from its position.
fn grid_id(p: &Point3<f64>) -> usize {
    let (c, r) = ((p.x / PITCH_M).round(), (p.y / PITCH_M).round());
    r as usize * COLS + c as usize
}

/// Which ids of a full grid a partial view keeps: 1 or 2 whole rows or
/// columns cut at one side, then each remaining point kept with a
/// probability drawn in [0.3, 0.7] (30-70 % removed).
fn kept_ids(rng: &mut Rng) -> Vec<usize> {
    let side = rng.below(4);
    let cut = 1 + rng.below(2);
    let keep_rate = rng.range(0.3, 0.7);
    (0..COLS * ROWS)
        .filter(|&id| {
            let (c, r) = (id % COLS, id / COLS);
            let inside = match side {
                0 => c >= cut,
                1 => c < COLS - cut,
                2 => r >= cut,
                _ => r < ROWS - cut,
            };
            inside && rng.uniform() < keep_rate
        })
        .collect()
}

/// `view` restricted to `ids` (grid ids), with the ids kept.
fn restrict(view: &View, ids: &[usize]) -> View {
    let mut out = View::new(view.name.clone(), vec![], vec![]);
    for (o, px) in view.object_m.iter().zip(&view.image_px) {
        let id = grid_id(o);
        if ids.contains(&id) {
            out.object_m.push(*o);
            out.image_px.push(*px);
            out.point_ids.push(id);
        }
    }
    out
}

fn partial_views(views: &[View], seed: u64) -> Vec<View> {
    let mut rng = Rng::new(seed);
    views
        .iter()
        .map(|v| restrict(v, &kept_ids(&mut rng)))
        .collect()
}

fn truth() -> Camera {
    let mut c = Camera::example_brown();
    c.skew = 0.0;
    c
}

fn brown_options() -> CalibrationOptions {
    CalibrationOptions::default()
}

#[test]
fn partial_views_give_the_exact_intrinsics_without_noise() {
    let truth = truth();
    let scene = Scene::calibration(21, &truth, (COLS, ROWS), PITCH_M, 16, 0.0).expect("scene");
    let views = partial_views(&scene.views, 5);
    let counts: Vec<usize> = views.iter().map(|v| v.object_m.len()).collect();
    assert!(
        counts.iter().all(|&n| (8..=38).contains(&n)),
        "each view keeps 30-70 % of at most 45 points: {counts:?}"
    );
    let report = calibrate(&views, (truth.width, truth.height), &brown_options())
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(report.rms_px < 1e-9, "rms {} px", report.rms_px);
    assert_eq!(report.views.len(), views.len(), "no view left out");
    for ((n, got), want) in report
        .camera
        .param_names()
        .iter()
        .zip(report.camera.params())
        .zip(truth.params())
    {
        assert!(
            (got - want).abs() < 1e-9 * want.abs().max(1.0),
            "{n}: {got} vs {want} (1e-9 relative)"
        );
    }
    for ((pose, view), input) in scene
        .camera_from_target
        .iter()
        .zip(&report.views)
        .zip(&views)
    {
        let t = pose.translation.vector;
        let got = view.camera_from_target.translation_m;
        let err = (t - Vector3::from(got)).norm();
        assert!(err < 1e-9, "{}: pose off by {err} m", view.name);
        // The residuals name the corners they belong to.
        let ids: Vec<Option<usize>> = view.residuals_px.iter().map(|r| r.id).collect();
        let want: Vec<Option<usize>> = input.point_ids.iter().map(|&i| Some(i)).collect();
        assert_eq!(ids, want, "{}", view.name);
    }
}

#[test]
fn partial_views_with_noise_stay_within_the_reported_uncertainty() {
    let truth = truth();
    let sigma = 0.2;
    let scene = Scene::calibration(22, &truth, (COLS, ROWS), PITCH_M, 30, sigma).expect("scene");
    let views = partial_views(&scene.views, 6);
    let report = calibrate(&views, (truth.width, truth.height), &brown_options())
        .unwrap_or_else(|e| panic!("{e}"));
    let n = report.n_points as f64;
    // Parameters: 4 pinhole (skew held) + 5 Brown + 6 per view.
    let p = 9.0 + 6.0 * views.len() as f64;
    let expected = sigma * (2.0 * (1.0 - p / (2.0 * n))).sqrt();
    assert!(
        (report.rms_px / expected - 1.0).abs() < 0.10,
        "rms {} px vs expected {expected} px ({n} points)",
        report.rms_px
    );
    let kept: usize = views.iter().map(|v| v.object_m.len()).sum();
    eprintln!(
        "noisy partial views: {kept} of {} points kept, rms {:.4} px (expected {expected:.4})",
        54 * views.len(),
        report.rms_px
    );
    for ((name, got), want) in report
        .camera
        .param_names()
        .iter()
        .zip(report.camera.params())
        .zip(truth.params())
    {
        let std = report.std.get(*name).copied().unwrap_or(f64::NAN);
        if *name == "skew" {
            continue;
        }
        eprintln!(
            "  {name}: error {:.3e}, std {std:.3e} ({:.2} sigma)",
            got - want,
            (got - want) / std
        );
        assert!(std > 0.0, "{name}: std {std}");
        assert!(
            (got - want).abs() < 4.0 * std,
            "{name}: {got} vs {want}, std {std} (4 sigma)"
        );
    }
}

fn json_view(v: &View) -> JsonView {
    JsonView {
        name: v.name.clone(),
        detection: None,
        object_m: Some(v.object_m.iter().map(|p| [p.x, p.y, p.z]).collect()),
        image_px: Some(v.image_px.iter().map(|p| [p.x, p.y]).collect()),
    }
}

fn input(views: &[View]) -> CalibrationInput {
    CalibrationInput {
        model: LensModel::default(),
        method: MethodChoice::default(),
        options: JsonOptions::default(),
        views: views.iter().map(json_view).collect(),
        image_size_px: Some([1280, 960]),
    }
}

#[test]
fn a_view_on_one_line_is_left_out_with_a_warning() {
    let truth = truth();
    let scene = Scene::calibration(23, &truth, (COLS, ROWS), PITCH_M, 8, 0.0).expect("scene");
    let mut views = partial_views(&scene.views, 7);
    let row: Vec<usize> = (2 * COLS..3 * COLS).collect();
    let mut line = restrict(&scene.views[0], &row);
    line.name = "row_only".into();
    let mut three = restrict(&scene.views[1], &[0, 1, COLS]);
    three.name = "three_corners".into();
    let mut corner = restrict(&scene.views[2], &[0, 1, 2, 3, COLS + 2]);
    corner.name = "row_and_one".into();
    views.insert(2, line.clone());
    views.push(three.clone());
    views.push(corner.clone());
    let out = calibrate_input(&input(&views)).unwrap_or_else(|e| panic!("{e}"));
    let report = &out.report;
    assert_eq!(report.views.len(), 8, "the three views are left out");
    assert!(report.rms_px < 1e-9, "rms {} px", report.rms_px);
    let left_out: Vec<&String> = report
        .warnings
        .iter()
        .filter(|w| w.contains("left out"))
        .collect();
    assert_eq!(
        left_out,
        [
            "view row_only left out: its 9 points lie on one line: a homography needs 4 points \
             with no 3 on one line",
            "view three_corners left out: 3 points: a homography needs at least 4",
            "view row_and_one left out: 4 of its 5 points lie on one line: a homography needs 4 \
             points with no 3 on one line",
        ]
    );
    // Too few usable views: the error names the views left out and why.
    let few = vec![views[0].clone(), line, three];
    let e = calibrate_input(&input(&few))
        .map(|_| ())
        .map_err(|e| e.to_string());
    assert_eq!(
        e,
        Err(
            "views: 1 view whose points fix a homography, a calibration needs at least 3 (10 or \
             more from varied angles are recommended); left out: view row_only (its 9 points lie \
             on one line: a homography needs 4 points with no 3 on one line), view three_corners \
             (3 points: a homography needs at least 4): add images in which more of the target \
             is found"
                .to_string()
        )
    );
    // The library call says the same, in its own words.
    let e = calibrate(&few, (1280, 960), &brown_options())
        .map(|_| ())
        .map_err(|e| e.to_string());
    assert_eq!(
        e,
        Err(
            "views: requires at least 2 views whose points fix a homography, got 1; left out: \
             view row_only (its 9 points lie on one line: a homography needs 4 points with no 3 \
             on one line), view three_corners (3 points: a homography needs at least 4)"
                .to_string()
        )
    );
}

#[test]
fn stereo_with_partial_views_on_both_sides_recovers_the_pair() {
    let left_camera = truth();
    let mut right_camera = truth();
    right_camera.fx *= 1.02;
    right_camera.cx += 12.0;
    let right_from_left = Pose::from_parts(
        Translation3::new(-0.12, 0.002, 0.004),
        rotation_from_rotvec(&Vector3::new(0.01, -0.05, 0.004)),
    );
    let scene =
        Scene::calibration(24, &left_camera, (COLS, ROWS), PITCH_M, 14, 0.0).expect("scene");
    let right_full: Vec<View> = scene
        .views
        .iter()
        .zip(&scene.camera_from_target)
        .map(|(v, pose)| {
            let image_px = v
                .object_m
                .iter()
                .map(|p| {
                    right_camera
                        .project(&(right_from_left * pose * p))
                        .unwrap_or(Point2::new(f64::NAN, f64::NAN))
                })
                .collect();
            View::new(format!("right_{}", v.name), v.object_m.clone(), image_px)
        })
        .collect();
    // Each side loses its own points (different seeds).
    let left = partial_views(&scene.views, 8);
    let mut right = partial_views(&right_full, 9);
    // One pair's right side sees only a column: that pair is left out.
    let column: Vec<usize> = (0..ROWS).map(|r| r * COLS + 4).collect();
    right[3] = restrict(&right_full[3], &column);
    let (w, h) = (left_camera.width, left_camera.height);
    let report = calibrate_stereo(&left, &right, (w, h), (w, h), &brown_options())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        report.warnings,
        [
            "pair 3 left out: right right_view_003: its 6 points lie on one line: a homography \
          needs 4 points with no 3 on one line"
        ]
    );
    assert_eq!(report.left.views.len(), 13);
    assert!(report.rms_px < 1e-9, "rms {} px", report.rms_px);
    let got = report.right_from_left.to_pose().expect("pose");
    let dt = (got.translation.vector - right_from_left.translation.vector).norm();
    let dr = (got.rotation * right_from_left.rotation.inverse()).angle();
    assert!(
        dt < 1e-9 && dr < 1e-9,
        "right_from_left off by {dt} m, {dr} rad"
    );
    for (cam, rep) in [(&left_camera, &report.left), (&right_camera, &report.right)] {
        for (got, want) in rep.camera.params().iter().zip(cam.params()) {
            assert!(
                (got - want).abs() < 1e-9 * want.abs().max(1.0),
                "{got} vs {want}"
            );
        }
    }
}

/// Partial views of a hand-eye scene, as detection JSON objects (ids kept),
/// plus one view whose points lie on one line.
fn handeye_input(setup: &str, scene_setup: robocal::handeye::Setup, seed: u64) -> (Value, Pose) {
    let camera = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
    let scene = looking_scene(
        &LookingConfig {
            setup: scene_setup,
            views: 10,
            distance_m: 0.6,
            grid: (COLS, ROWS, PITCH_M),
            max_tilt_deg: 35.0,
            max_roll_deg: 60.0,
        },
        seed,
    );
    let mut rng = Rng::new(seed);
    let pixels = grid_pixels(&scene, &camera, 0.0, &mut rng);
    let mut detections = Vec::new();
    for (i, v) in pixels.iter().enumerate() {
        let ids = if i == 4 {
            (0..ROWS).map(|r| r * COLS + 2).collect()
        } else {
            kept_ids(&mut rng)
        };
        let points: Vec<Value> = v
            .object_m
            .iter()
            .zip(&v.image_px)
            .filter(|(o, _)| ids.contains(&grid_id(o)))
            .map(|(o, px)| json!({"id": grid_id(o), "x_px": px.x, "y_px": px.y}))
            .collect();
        detections.push(json!({
            "image_size_px": [640, 480],
            "target": {"kind": "chessboard", "cols": COLS, "rows": ROWS, "square_m": PITCH_M},
            "points": points,
        }));
    }
    let pose = |p: &Pose| json!({"matrix_row_major": (0..4).map(|r| (0..4).map(|c| p.to_homogeneous()[(r, c)]).collect::<Vec<f64>>()).collect::<Vec<_>>()});
    let input = json!({
        "setup": setup,
        "base_from_gripper": scene.base_from_gripper.iter().map(pose).collect::<Vec<_>>(),
        "camera": serde_json::to_value(&camera).expect("camera"),
        "detections": detections,
        "bootstrap_samples": 0,
    });
    (input, scene.x_true)
}

#[test]
fn handeye_from_partial_views_recovers_x_exactly_in_both_setups() {
    for (name, setup) in [
        ("eye-in-hand", robocal::handeye::Setup::EyeInHand),
        ("eye-to-hand", robocal::handeye::Setup::EyeToHand),
    ] {
        let (input, x_true) = handeye_input(name, setup, 31);
        let out = robocal::api::handeye::solve_handeye_json(&input.to_string())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let report: Value = serde_json::from_str(&out).expect("report");
        let key = if name == "eye-in-hand" {
            "gripper_from_camera"
        } else {
            "base_from_camera"
        };
        let m = &report[key]["matrix_row_major"];
        let mut got = nalgebra::Matrix4::zeros();
        for r in 0..4 {
            for c in 0..4 {
                got[(r, c)] = m[r][c].as_f64().expect("number");
            }
        }
        let diff = (got - x_true.to_homogeneous()).amax();
        assert!(
            diff < 1e-9,
            "{name}: X off by {diff} (matrix entries, m and unitless)"
        );
        let warnings: Vec<&str> = report["warnings"]
            .as_array()
            .expect("warnings")
            .iter()
            .filter_map(Value::as_str)
            .collect();
        assert!(
            warnings.contains(
                &"view 4 left out with its robot pose: its 6 points lie on one line: a homography \
                  needs 4 points with no 3 on one line"
            ),
            "{name}: {warnings:?}"
        );
    }
}

/// Tsai's method (principal point at the centre, k1 only) and the EKF
/// cannot represent the Brown truth exactly: on partial views each must
/// run and fit about as well as on the full views of the same poses
/// (RMS within 1.5x of the full views' and below 1 px); Zhang's is exact.
#[test]
fn every_planar_method_takes_partial_views() {
    let truth = truth();
    let scene = Scene::calibration(25, &truth, (COLS, ROWS), PITCH_M, 12, 0.0).expect("scene");
    let rows = |views: &[View]| {
        let mut all = input(views);
        all.method = MethodChoice::All;
        let out = calibrate_input(&all).unwrap_or_else(|e| panic!("{e}"));
        out.comparison.expect("rows")
    };
    let partial = rows(&partial_views(&scene.views, 10));
    let full = rows(&scene.views);
    for (p, f) in partial.iter().zip(&full) {
        assert_eq!(p.method, f.method);
        let (Some(rp), Some(rf)) = (p.rms_px, f.rms_px) else {
            panic!("{}: {:?} / {:?}", p.method, p.error, f.error);
        };
        eprintln!("{}: rms {rp:.4} px partial, {rf:.4} px full", p.method);
        if p.method == "zhang" {
            assert!(rp < 1e-9, "zhang rms {rp} px");
        } else {
            assert!(
                rp < 1.0 && rp < 1.5 * rf,
                "{}: rms {rp} px vs {rf} px full",
                p.method
            );
        }
    }
}

#[test]
fn tsai_leaves_out_a_view_of_four_points_with_a_warning() {
    let truth = truth();
    let scene = Scene::calibration(26, &truth, (COLS, ROWS), PITCH_M, 8, 0.0).expect("scene");
    let mut views = partial_views(&scene.views, 11);
    let mut four = restrict(&scene.views[3], &[0, 8, 45, 53]);
    four.name = "four_corners".into();
    views.push(four);
    let report = robocal::calib::calibrate_tsai(&views, (1280, 960), &brown_options())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(report.views.len(), 8);
    assert!(
        report.warnings.contains(
            &"view four_corners left out: 4 points: Tsai's method needs at least 5".to_string()
        ),
        "{:?}",
        report.warnings
    );
    // Zhang's method uses the same view (4 corners of the board fix a homography).
    let zhang = calibrate(&views, (1280, 960), &brown_options()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(zhang.views.len(), 9);
}

#[test]
fn handeye_with_too_few_usable_views_names_the_views_left_out() {
    let (mut input, _) = handeye_input("eye-in-hand", robocal::handeye::Setup::EyeInHand, 32);
    // Keep 4 poses: views 2, 3, 4 (on one line) and 5.
    for key in ["base_from_gripper", "detections"] {
        let list = input[key].as_array().expect("list")[2..6].to_vec();
        input[key] = Value::Array(list);
    }
    let column: Vec<Value> = input["detections"][0]["points"]
        .as_array()
        .expect("points")
        .iter()
        .filter(|p| p["id"].as_u64().is_some_and(|id| id as usize % COLS == 3))
        .cloned()
        .collect();
    input["detections"][0]["points"] = Value::Array(column);
    let n = input["detections"][0]["points"]
        .as_array()
        .map_or(0, Vec::len);
    assert!(n >= 2, "column 3 keeps {n} points");
    let e =
        robocal::api::handeye::solve_handeye_json(&input.to_string()).map_err(|e| e.to_string());
    let reason = |k: usize| {
        if k < 4 {
            format!("{k} points: a homography needs at least 4")
        } else {
            format!(
                "its {k} points lie on one line: a homography needs 4 points with no 3 on one line"
            )
        }
    };
    assert_eq!(
        e,
        Err(format!(
            "views: requires at least 3 pose pairs, got 2; view 0 left out with its robot pose: {}, \
             view 2 left out with its robot pose: its 6 points lie on one line: a homography needs \
             4 points with no 3 on one line",
            reason(n)
        ))
    );
}
