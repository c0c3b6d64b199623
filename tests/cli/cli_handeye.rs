//! `robocal handeye` from images: the demo session rendered by `robocal
//! render --demo` (exact truth, grey noise sigma 2: corners within ~0.05 px)
//! and RWHE-Calib's CS_synthetic_1 (ground truth X = diag(1, -1, -1), t = 0).

use crate::support;
use support::dataset;

use std::path::{Path, PathBuf};
use std::process::Command;

pub(crate) fn robocal(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(args)
        .output()
        .unwrap()
}

pub(crate) fn ok(out: &std::process::Output) {
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

pub(crate) fn matrix(v: &serde_json::Value) -> [[f64; 4]; 4] {
    serde_json::from_value(v["matrix_row_major"].clone()).unwrap()
}

/// Translation (mm) and rotation (degrees) between two row-major 4x4 poses.
pub(crate) fn distance(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> (f64, f64) {
    let t = (0..3)
        .map(|i| (a[i][3] - b[i][3]).powi(2))
        .sum::<f64>()
        .sqrt()
        * 1e3;
    // trace(Ra^T Rb) = 1 + 2 cos(angle)
    let trace: f64 = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| a[i][j] * b[i][j])
        .sum();
    let angle = ((trace - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees();
    (t, angle)
}

pub(crate) fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// RWHE-Calib CS_synthetic_1's `robocal handeye` report from its 15 images
/// (`dir`: the dataset folder): eye-in-hand, the 9x6 chessboard of 200 mm
/// squares, no bootstrap, `--refine refine`, and a pinhole camera without
/// distortion (fx = fy = `f` px, `principal` = (cx, cy) px) written to
/// `tmp` beside the report (both named after `f` and `refine`).
pub(crate) fn rwhe_report(
    dir: &Path,
    tmp: &Path,
    f: f64,
    principal: [f64; 2],
    refine: &str,
) -> serde_json::Value {
    let [cx, cy] = principal;
    let camera = tmp.join(format!("camera-{f}-{refine}.json"));
    std::fs::write(
        &camera,
        format!(
            r#"{{"fx":{f},"fy":{f},"cx":{cx},"cy":{cy},"skew":0.0,
                "width":1920,"height":1080,"distortion":{{"model":"none"}}}}"#
        ),
    )
    .unwrap();
    let out = tmp.join(format!("handeye-{f}-{refine}.json"));
    let poses = dir.join("RobotPosesVec.txt");
    let mut args: Vec<String> = [
        "handeye",
        "--setup",
        "eye-in-hand",
        "--poses",
        poses.to_str().unwrap(),
        "--camera",
        camera.to_str().unwrap(),
        "--target",
        "chessboard:9x6:200mm",
        "--refine",
        refine,
        "--bootstrap",
        "0",
        "-o",
        out.to_str().unwrap(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for k in 1..=15 {
        args.push(dir.join(format!("im_{k:02}.png")).to_str().unwrap().into());
    }
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&robocal(&refs));
    read_json(&out)
}

#[test]
fn demo_images_recover_the_truth_and_failed_images_are_dropped_with_their_pose() {
    let dir = std::env::temp_dir().join(format!("robocal-handeye-{}", std::process::id()));
    let d = dir.to_str().unwrap();
    ok(&robocal(&["render", "--out", d, "--demo"]));
    // Image 3 unreadable: its pose must be dropped, the others still pair by
    // the image column although the images are given in reverse order.
    std::fs::write(dir.join("demo_03.png"), b"not an image").unwrap();
    let mut images: Vec<PathBuf> = (0..12)
        .map(|i| dir.join(format!("demo_{i:02}.png")))
        .collect();
    images.reverse();
    let out_path = dir.join("handeye.json");
    let mut args = vec![
        "handeye",
        "--setup",
        "eye-in-hand",
        "--poses",
        dir.join("poses.csv").to_str().unwrap().to_string().leak(),
        "--camera",
        dir.join("truth.json").to_str().unwrap().to_string().leak(),
        "--target",
        "chessboard:9x6:30mm",
        "--bootstrap",
        "0",
        "--threads",
        "2",
        "-o",
        out_path.to_str().unwrap().to_string().leak(),
    ];
    for img in &images {
        args.push(img.to_str().unwrap().to_string().leak());
    }
    ok(&robocal(&args));
    let report = read_json(&out_path);
    let truth = read_json(&dir.join("truth.json"));
    let method = report["method"].as_str().unwrap();
    assert!(method.starts_with("refined from "), "{method}");
    // Corner noise ~0.05 px over 11 views of 54 corners: X within 0.1 mm and
    // 0.01 deg (measured 0.01 mm).
    let (t, r) = distance(
        &matrix(&report["gripper_from_camera"]),
        &matrix(&truth["gripper_from_camera"]),
    );
    assert!(t < 0.1 && r < 0.01, "{t} mm, {r} deg");
    // The default with images: the ML over the poses, each view weighted by
    // its PnP covariance; no view of the noise-free robot is an outlier.
    let refinement = &report["pose_refinement"];
    assert_eq!(refinement["camera_noise_model"], "per_view");
    assert_eq!(refinement["outlier_views"].as_array().unwrap().len(), 0);
    // Its reprojection RMS (each view's corners through the refined X, the
    // robot pose and the refined target pose): exact robot poses, so about
    // the corner noise times sqrt(2). The pixel sigma is estimated from 11
    // views' 6-D pose residuals (54 degrees of freedom: about 10 % spread),
    // so the ratio is held to 0.6-1.6.
    let rms = report["errors"]["reprojection_rms_px"].as_f64().unwrap();
    let sigma = refinement["noise"]["camera_covariance_sigma"]
        .as_f64()
        .unwrap();
    assert!(
        (0.6..1.6).contains(&(rms / (sigma * 2f64.sqrt()))) && rms < 0.2,
        "{rms} px, pixel sigma {sigma}"
    );
    assert_eq!(refinement["reprojection_rms_px"].as_f64().unwrap(), rms);
    assert_eq!(
        refinement["per_view_reprojection_rms_px"]
            .as_array()
            .unwrap()
            .len(),
        11
    );
    assert_eq!(report["methods"].as_array().unwrap().len(), 8);
    let pairs = report["pairs"].as_array().unwrap();
    assert_eq!(pairs.len(), 12);
    for (i, p) in pairs.iter().enumerate() {
        assert_eq!(p["pose_index"], i);
        let image = p["image"].as_str().unwrap();
        assert!(image.ends_with(&format!("demo_{i:02}.png")), "{image}");
        assert_eq!(p["used"], i != 3, "pair {i}");
    }
    let reason = pairs[3]["reason"].as_str().unwrap();
    assert!(reason.starts_with("detection failed"), "{reason}");
    assert_eq!(pairs[4]["view"], 3);
    let warnings = report["warnings"].to_string();
    assert!(
        warnings.contains("1 of 12 poses were dropped with their image"),
        "{warnings}"
    );
    // By order, the counts must match.
    let lines: String = std::fs::read_to_string(dir.join("poses.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .take(3)
        .map(|l| l.split_once(',').unwrap().1.to_string() + "\n")
        .collect();
    std::fs::write(dir.join("unnamed.csv"), format!("x,y,z,rx,ry,rz\n{lines}")).unwrap();
    let out = robocal(&[
        "handeye",
        "--setup",
        "eye-in-hand",
        "--poses",
        dir.join("unnamed.csv").to_str().unwrap(),
        "--camera",
        dir.join("truth.json").to_str().unwrap(),
        "--target",
        "chessboard:9x6:30mm",
        images[0].to_str().unwrap(),
        images[1].to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains(
            "unnamed.csv': pairing: 3 robot poses but 2 images: give one image per pose \
             (paired in numeric order of the file names), or add an image column to the pose file"
        ),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn rwhe_cs_synthetic_1_recovers_its_ground_truth_from_the_images() {
    let Some(dir) = dataset("rwhe-calib-cs-synthetic-1") else {
        eprintln!("skipped: ../shared/datasets/rwhe-calib-cs-synthetic-1 is absent");
        return;
    };
    // No intrinsics ship with the dataset: start from SOURCE.md's estimate
    // (fx = fy = 1078.88, cx = 959.45, cy = 539.32, no distortion) and refine
    // them jointly with the hand-eye transform.
    let tmp = std::env::temp_dir().join(format!("robocal-rwhe-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let report = rwhe_report(&dir, &tmp, 1078.88, [959.45, 539.32], "joint_intrinsics");
    let truth = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, -1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    // Rendered images, board 7-8 m away with 0.2 m squares: the closed forms
    // land within ~10 mm (OpenCV's too, SOURCE.md); the joint refinement
    // with intrinsics reaches 0.05 mm, 0.001 deg. Bound: 0.5 mm, 0.01 deg.
    let (t, r) = distance(&matrix(&report["gripper_from_camera"]), &truth);
    assert!(t < 0.5 && r < 0.01, "{t} mm, {r} deg");
    for m in report["methods"].as_array().unwrap() {
        let (t, r) = distance(&matrix(&m["gripper_from_camera"]), &truth);
        assert!(t < 15.0 && r < 0.1, "{}: {t} mm, {r} deg", m["method"]);
    }
    let fx = report["refinement"]["camera"]["fx"].as_f64().unwrap();
    assert!((fx - 1080.0).abs() < 0.5, "fx {fx}");
    assert!(report["pairs"]
        .as_array()
        .unwrap()
        .iter()
        .all(|p| p["used"] == true));
    let _ = std::fs::remove_dir_all(&tmp);
}

#[test]
fn camera_poses_are_refined_by_default_and_no_refine_keeps_the_closed_form() {
    use robocal::synth::handeye_looking::{looking_scene, noisy_input, LookingConfig};
    let scene = looking_scene(
        &LookingConfig::half_metre(robocal::handeye::Setup::EyeInHand, 15),
        21,
    );
    let line = |p: &robocal::handeye::Pose| {
        let m = p.to_homogeneous();
        (0..4)
            .flat_map(|i| (0..4).map(move |j| format!("{:.17e}", m[(i, j)])))
            .collect::<Vec<_>>()
            .join(" ")
            + "\n"
    };
    // Robot 0.1 mm / 0.02 deg, camera 0.05 deg and 0.05 / 0.3 mm (x, y / depth).
    let input = noisy_input(&scene, 3);
    let robot: String = input.base_from_gripper.iter().map(line).collect();
    let camera: String = input.camera_from_target.iter().map(line).collect();
    let dir = std::env::temp_dir().join(format!("robocal-cli-pose-refine-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (robot_path, camera_path) = (dir.join("robot.txt"), dir.join("camera.txt"));
    std::fs::write(&robot_path, robot).unwrap();
    std::fs::write(&camera_path, camera).unwrap();
    let run = |extra: &[&str]| {
        let out_path = dir.join("handeye.json");
        let mut args = vec![
            "handeye",
            "--setup",
            "eye-in-hand",
            "--poses",
            robot_path.to_str().unwrap(),
            "--pose-format",
            "matrix",
            "--camera-poses",
            camera_path.to_str().unwrap(),
            "--bootstrap",
            "0",
            "-o",
            out_path.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        ok(&robocal(&args));
        read_json(&out_path)
    };
    let refined = run(&[]);
    let method = refined["method"].as_str().unwrap();
    assert!(method.starts_with("refined from "), "{method}");
    let p = &refined["pose_refinement"];
    let std_mm = p["camera_transform_std"]["translation_mm"][0]
        .as_f64()
        .unwrap();
    // A 15-pose calibration at this noise: the camera's translation to a
    // fraction of a millimetre, and the truth within 4 reported std.
    assert!(std_mm > 0.01 && std_mm < 1.0, "{std_mm} mm");
    let truth = scene.x_true.to_homogeneous();
    let est = matrix(&refined["gripper_from_camera"]);
    for k in 0..3 {
        let s = p["camera_transform_std"]["translation_mm"][k]
            .as_f64()
            .unwrap();
        let e = (est[k][3] - truth[(k, 3)]).abs() * 1e3;
        assert!(e < 4.0 * s, "axis {k}: {e} mm vs std {s} mm");
    }
    assert!(refined["methods"][0]["pose_cost"].as_f64().is_some());
    let closed = run(&["--no-refine"]);
    let method = closed["method"].as_str().unwrap();
    assert!(!method.starts_with("refined"), "{method}");
    assert!(closed["pose_refinement"].is_null());
    let help = robocal(&["handeye", "--help"]);
    assert!(String::from_utf8_lossy(&help.stdout).contains("--no-refine"));
    std::fs::remove_dir_all(&dir).ok();
}
