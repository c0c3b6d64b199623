//! `robocal handeye` from images: the demo session rendered by `robocal
//! render --demo` (exact truth, grey noise sigma 2: corners within ~0.05 px)
//! and RWHE-Calib's CS_synthetic_1 (ground truth X = diag(1, -1, -1), t = 0).

use crate::support;
use support::dataset;

use std::path::{Path, PathBuf};
use std::process::Command;

fn robocal(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(out: &std::process::Output) {
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn matrix(v: &serde_json::Value) -> [[f64; 4]; 4] {
    serde_json::from_value(v["matrix_row_major"].clone()).unwrap()
}

/// Translation (mm) and rotation (degrees) between two row-major 4x4 poses.
fn distance(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> (f64, f64) {
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

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
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
    let camera = tmp.join("camera.json");
    std::fs::write(
        &camera,
        r#"{"fx":1078.88,"fy":1078.88,"cx":959.45,"cy":539.32,"skew":0.0,
            "width":1920,"height":1080,"distortion":{"model":"none"}}"#,
    )
    .unwrap();
    let out_path = tmp.join("handeye.json");
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
        "joint_intrinsics",
        "--bootstrap",
        "0",
        "-o",
        out_path.to_str().unwrap(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for k in 1..=15 {
        args.push(
            dir.join(format!("im_{k:02}.png"))
                .to_str()
                .unwrap()
                .to_string(),
        );
    }
    let arg_refs: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&robocal(&arg_refs));
    let report = read_json(&out_path);
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
    use robocal::synth::handeye_looking::{looking_scene, perturbed, LookingConfig};
    use robocal::synth::Rng;
    let scene = looking_scene(
        &LookingConfig {
            setup: robocal::handeye::Setup::EyeInHand,
            views: 15,
            distance_m: 0.5,
            grid: (9, 6, 0.03),
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
        },
        21,
    );
    // Robot 0.1 mm / 0.02 deg, camera 0.05 deg and 0.05 / 0.3 mm (x, y / depth).
    let mut rng = Rng::new(3);
    let r = 0.02f64.to_radians();
    let line = |p: &robocal::handeye::Pose| {
        let m = p.to_homogeneous();
        (0..4)
            .flat_map(|i| (0..4).map(move |j| format!("{:.17e}", m[(i, j)])))
            .collect::<Vec<_>>()
            .join(" ")
            + "\n"
    };
    let robot: String = scene
        .base_from_gripper
        .iter()
        .map(|p| line(&perturbed(&mut rng, p, [r; 3], [1e-4; 3])))
        .collect();
    let camera: String = scene
        .camera_from_target
        .iter()
        .map(|p| {
            let c = 0.05f64.to_radians();
            line(&perturbed(&mut rng, p, [c, c, c / 5.0], [5e-5, 5e-5, 3e-4]))
        })
        .collect();
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

/// The demo's poses and images as a user's cell has them: unpadded numbers
/// (`img_0.png` ... `img_11.png`), listed in the shell's order (0, 1, 10,
/// 11, 2, ...), the pose file's image column holding the path as typed.
struct Cell {
    dir: PathBuf,
    /// Image paths in the shell's (lexicographic) order.
    images: Vec<String>,
    /// The demo's pose rows without the image column, in pose order.
    rows: Vec<String>,
}

fn cell(name: &str) -> Cell {
    let dir = std::env::temp_dir().join(format!("robocal-pairing-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.to_str().unwrap();
    ok(&robocal(&["render", "--out", d, "--demo"]));
    std::fs::create_dir_all(dir.join("images")).unwrap();
    for i in 0..12 {
        std::fs::rename(
            dir.join(format!("demo_{i:02}.png")),
            dir.join(format!("images/img_{i}.png")),
        )
        .unwrap();
    }
    let mut images: Vec<String> = (0..12)
        .map(|i| {
            dir.join(format!("images/img_{i}.png"))
                .to_str()
                .unwrap()
                .to_string()
        })
        .collect();
    images.sort();
    let text = std::fs::read_to_string(dir.join("poses.csv")).unwrap();
    assert!(text.starts_with("name,"), "{text}");
    let rows = text
        .lines()
        .skip(1)
        .map(|l| l.split_once(',').unwrap().1.to_string())
        .collect();
    Cell { dir, images, rows }
}

impl Cell {
    /// Run `robocal handeye` on a pose file holding `poses` (with `header`).
    fn run(&self, header: &str, poses: &[String], extra: &[&str]) -> std::process::Output {
        let file = self.dir.join("poses_user.csv");
        std::fs::write(&file, format!("{header}\n{}\n", poses.join("\n"))).unwrap();
        let mut args: Vec<String> = [
            "handeye",
            "--setup",
            "eye-in-hand",
            "--poses",
            file.to_str().unwrap(),
            "--camera",
            self.dir.join("truth.json").to_str().unwrap(),
            "--target",
            "chessboard:9x6:30mm",
            "--bootstrap",
            "0",
            "--threads",
            "2",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        args.extend(extra.iter().map(|s| s.to_string()));
        args.extend(self.images.iter().cloned());
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        robocal(&refs)
    }
}

fn solved_right(out: &std::process::Output, cell: &Cell) -> serde_json::Value {
    ok(out);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let truth = read_json(&cell.dir.join("truth.json"));
    let (t, r) = distance(
        &matrix(&report["gripper_from_camera"]),
        &matrix(&truth["gripper_from_camera"]),
    );
    assert!(t < 0.1 && r < 0.01, "{t} mm, {r} deg");
    report
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn poses_pair_by_path_suffix_and_numeric_order_and_wrong_pairings_are_named() {
    let c = cell("rules");
    let header = "x,y,z,rx,ry,rz";
    // 1. No image column: pose i with the i-th image in numeric order,
    // although the shell listed img_10.png before img_2.png.
    let report = solved_right(&c.run(header, &c.rows, &[]), &c);
    let pairs = report["pairs"].as_array().unwrap();
    for (i, p) in pairs.iter().enumerate() {
        let image = p["image"].as_str().unwrap();
        assert!(
            image.ends_with(&format!("/img_{i}.png")),
            "pose {i}: {image}"
        );
    }
    // 2. The image column as the user typed the paths (relative, with the
    // folder), absolute, or stems: matched by path suffix, path, stem.
    let dir = c.dir.to_str().unwrap();
    let namers: [fn(usize, &str) -> String; 3] = [
        |i, _| format!("images/img_{i}.png"),
        |i, d| format!("{d}/images/img_{i}.png"),
        |i, _| format!("img_{i}"),
    ];
    for name in namers {
        let named: Vec<String> = (0..12)
            .map(|i| format!("{},{}", name(i, dir), c.rows[i]))
            .collect();
        solved_right(&c.run(&format!("image,{header}"), &named, &[]), &c);
    }
    // 3. Paired in the shell's order on request: the data say numeric order.
    let out = c.run(header, &c.rows, &["--pair-by", "lexicographic"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(
        e.starts_with(
            "robocal: pairing: the poses fit the images only when paired in numeric order of \
             the file names: the rotation angles of the robot and camera motions agree to 0.0"
        ) && e
            .contains("as paired in lexicographic order of the file names: pass --pair-by numeric"),
        "{e}"
    );
    // 4. Two rows naming one image, and a row naming no image: errors naming them.
    let mut named: Vec<String> = (0..12)
        .map(|i| format!("images/img_{i}.png,{}", c.rows[i]))
        .collect();
    named[5] = format!("images/img_4.png,{}", c.rows[5]);
    let out = c.run(&format!("image,{header}"), &named, &[]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("pairing: two poses name the same image: rows 6, 7 all name '"),
        "{}",
        stderr(&out)
    );
    named[5] = format!("images/img_44.png,{}", c.rows[5]);
    let out = c.run(&format!("image,{header}"), &named, &[]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains(
            "pairing: 1 of 12 poses name no image that was given: row 7 'images/img_44.png': \
             give those images, or remove their rows from the pose file"
        ),
        "{}",
        stderr(&out)
    );
    // 5. --pair-by with an unknown rule.
    let out = c.run(header, &c.rows, &["--pair-by", "name"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).trim_end(),
        "robocal: handeye: --pair-by: unknown rule 'name' (valid: auto, numeric, \
         lexicographic, given) (see 'robocal handeye --help')"
    );
    let _ = std::fs::remove_dir_all(&c.dir);
}

/// The demo's pose rows (UR: m, rotation vector) as (translation m,
/// rotation).
fn demo_poses(c: &Cell) -> Vec<([f64; 3], robocal::geometry::Rotation)> {
    c.rows
        .iter()
        .map(|row| {
            let v: Vec<f64> = row.split(',').map(|f| f.parse().unwrap()).collect();
            let r =
                robocal::geometry::rotation_from_rotvec(&nalgebra::Vector3::new(v[3], v[4], v[5]));
            ([v[0], v[1], v[2]], r)
        })
        .collect()
}

impl Cell {
    /// `robocal handeye` with `--poses` given as `poses` (a folder or files).
    fn run_poses(
        &self,
        poses: &[String],
        images: &[String],
        extra: &[&str],
    ) -> std::process::Output {
        let mut args: Vec<String> = vec![
            "handeye".into(),
            "--setup".into(),
            "eye-in-hand".into(),
            "--poses".into(),
        ];
        args.extend(poses.iter().cloned());
        for a in [
            "--camera",
            self.dir.join("truth.json").to_str().unwrap(),
            "--target",
            "chessboard:9x6:30mm",
            "--bootstrap",
            "0",
            "--threads",
            "2",
        ] {
            args.push(a.into());
        }
        args.extend(extra.iter().map(|s| s.to_string()));
        args.extend(images.iter().cloned());
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        robocal(&refs)
    }
}

#[test]
fn one_pose_per_file_folders_and_lists_pair_by_stem() {
    let c = cell("files");
    let poses = demo_poses(&c);
    let folder = c.dir.join("poses");
    std::fs::create_dir_all(&folder).unwrap();
    // 1. A folder of ROS Pose YAML (block and flow alike) and JSON, one per
    // image, named by the image stems; a README in the folder is not read.
    for (i, (t, r)) in poses.iter().enumerate() {
        let q = robocal::geometry::quaternion_xyzw_from_rotation(r);
        let (name, text) = match i % 3 {
            0 => (format!("img_{i}.yaml"), format!(
                "header:\n  frame_id: base_link\npose:\n  position:\n    x: {}\n    y: {}\n    z: {}\n  orientation:\n    x: {}\n    y: {}\n    z: {}\n    w: {}\n",
                t[0], t[1], t[2], q[0], q[1], q[2], q[3])),
            1 => (format!("img_{i}.yml"), format!(
                "position: {{x: {}, y: {}, z: {}}}\norientation: {{x: {}, y: {}, z: {}, w: {}}}\n",
                t[0], t[1], t[2], q[0], q[1], q[2], q[3])),
            _ => (format!("img_{i}.json"), format!(
                r#"{{"position": {{"x": {}, "y": {}, "z": {}}}, "orientation": {{"x": {}, "y": {}, "z": {}, "w": {}}}}}"#,
                t[0], t[1], t[2], q[0], q[1], q[2], q[3])),
        };
        std::fs::write(folder.join(name), text).unwrap();
    }
    std::fs::write(folder.join("README.md"), "poses of the cell\n").unwrap();
    let report = solved_right(
        &c.run_poses(&[folder.to_str().unwrap().into()], &c.images, &[]),
        &c,
    );
    for p in report["pairs"].as_array().unwrap() {
        let i = p["pose_index"].as_u64().unwrap();
        let image = p["image"].as_str().unwrap();
        assert!(
            image.ends_with(&format!("/img_{i}.png")),
            "pose {i}: {image}"
        );
    }
    // 2. Several files: 4x4 matrices as text, millimetres by --pose-units.
    let mats = c.dir.join("mats");
    std::fs::create_dir_all(&mats).unwrap();
    let mut listed = Vec::new();
    for (i, (t, r)) in poses.iter().enumerate() {
        let m = r.to_rotation_matrix().into_inner();
        let text: String = (0..3)
            .map(|k| format!("{} {} {} {}\n", m[(k, 0)], m[(k, 1)], m[(k, 2)], t[k] * 1e3))
            .chain(["0 0 0 1\n".to_string()])
            .collect();
        let path = mats.join(format!("img_{i}.txt"));
        std::fs::write(&path, text).unwrap();
        listed.push(path.to_str().unwrap().to_string());
    }
    listed.reverse();
    solved_right(
        &c.run_poses(&listed, &c.images, &["--pose-units", "mm"]),
        &c,
    );
    // 3. A table with units and Euler angles in degrees in its header.
    let rows: Vec<String> = poses
        .iter()
        .map(|(t, r)| {
            let e = robocal::geometry::euler_from_rotation(
                r,
                robocal::geometry::EulerOrder::XYZ,
                robocal::geometry::EulerKind::Extrinsic,
            );
            format!(
                "{},{},{},{},{},{}",
                t[0] * 1e3,
                t[1] * 1e3,
                t[2] * 1e3,
                e[0].to_degrees(),
                e[1].to_degrees(),
                e[2].to_degrees()
            )
        })
        .collect();
    solved_right(
        &c.run("x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg", &rows, &[]),
        &c,
    );
    // Radians under a _deg header: read as the header says (tiny rotations),
    // caught by the plausibility checks, not solved silently.
    let radians: Vec<String> = poses
        .iter()
        .map(|(t, r)| {
            let e = robocal::geometry::euler_from_rotation(
                r,
                robocal::geometry::EulerOrder::XYZ,
                robocal::geometry::EulerKind::Extrinsic,
            );
            format!(
                "{},{},{},{},{},{}",
                t[0] * 1e3,
                t[1] * 1e3,
                t[2] * 1e3,
                e[0],
                e[1],
                e[2]
            )
        })
        .collect();
    let out = c.run("x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg", &radians, &[]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let e = stderr(&out);
    let file = c.dir.join("poses_user.csv");
    let first = e.lines().next().unwrap_or_default();
    assert!(
        first.starts_with(&format!(
            "warning: '{}': every pose is within ",
            file.display()
        )) && first.ends_with(
            " deg of the base orientation with the angles read as degrees: radians read as \
                 degrees? If the file holds radians, say so (a _rad header, --pose-units rad, or \
                 Angles: radians on the page)"
        ),
        "{e}"
    );
    assert!(e.contains("robocal: robot poses: the robot translations fit the camera motion only when scaled by"), "{e}");
    // Said in radians, the same numbers solve.
    solved_right(
        &c.run(
            "x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg",
            &radians,
            &["--pose-units", "rad"],
        ),
        &c,
    );
    // 4. A bad file is named with its line, before any image is read (the
    // images given do not exist).
    std::fs::write(
        folder.join("img_4.yml"),
        "position: {x: 0.1, y: 0.2, z: 0.3}\norientation:\n  {x: 0, y: 0, z: 0, w: 2}\n",
    )
    .unwrap();
    let missing = vec![c.dir.join("nothing.png").to_str().unwrap().to_string()];
    let out = c.run_poses(&[folder.to_str().unwrap().into()], &missing, &[]);
    assert_eq!(out.status.code(), Some(1));
    let bad = folder.join("img_4.yml");
    assert_eq!(
        stderr(&out).trim_end(),
        format!(
            "robocal: '{}': line 3: quaternion has norm 2: not a rotation",
            bad.display()
        )
    );
    // 5. An empty folder, and --pose-format names only pose-file formats.
    let empty = c.dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let out = c.run_poses(&[empty.to_str().unwrap().into()], &missing, &[]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr(&out).trim_end(),
        format!(
            "robocal: '{}': no pose files in the folder (files ending .yaml, .yml, .json, .txt, .csv, .tsv, .dat)",
            empty.display()
        )
    );
    let _ = std::fs::remove_dir_all(&c.dir);
}
