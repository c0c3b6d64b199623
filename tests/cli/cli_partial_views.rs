//! `robocal intrinsics`, `robocal handeye` (image path) and `robocal stereo`
//! fed 'robocal detect' files whose detections hold only part of the 9x6
//! board (rows or columns cut at one side, then 30-70 % of the rest
//! removed, ids kept), as marker boards give. Noise-free scenes: the
//! results match the truth to rounding (1e-9 relative / 1e-9 m); views
//! whose points lie on one line are left out with the documented message.

use crate::support;
use support::{robocal, temp_dir};

use nalgebra::{Point3, Translation3, Vector3};
use robocal::geometry::{rotation_from_rotvec, Pose};
use robocal::handeye::Setup;
use robocal::synth::handeye_looking::{grid_pixels, looking_scene, LookingConfig};
use robocal::synth::{Rng, Scene};
use robocal::Camera;
use serde_json::{json, Value};
use std::path::Path;

const COLS: usize = 9;
const ROWS: usize = 6;
const PITCH_M: f64 = 0.03;
const LINE: &str =
    "its 6 points lie on one line: a homography needs 4 points with no 3 on one line";

fn grid_id(p: &Point3<f64>) -> usize {
    let (c, r) = ((p.x / PITCH_M).round(), (p.y / PITCH_M).round());
    r as usize * COLS + c as usize
}

/// 1-2 rows or columns cut at one side, then 30-70 % of the rest removed.
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

/// Column 4 of the board: 6 points on one line.
fn column() -> Vec<usize> {
    (0..ROWS).map(|r| r * COLS + 4).collect()
}

/// One detection JSON of the points of `ids` (board points and pixels in
/// any order; ids from the board positions), sorted by id.
fn detection(
    size: (u32, u32),
    object: &[Point3<f64>],
    pixels: &[nalgebra::Point2<f64>],
    ids: &[usize],
) -> Value {
    let mut points: Vec<(usize, f64, f64)> = object
        .iter()
        .zip(pixels)
        .map(|(o, p)| (grid_id(o), p.x, p.y))
        .filter(|(id, _, _)| ids.contains(id))
        .collect();
    points.sort_by_key(|p| p.0);
    json!({
        "image_size_px": [size.0, size.1],
        "target": {"kind": "chessboard", "cols": COLS, "rows": ROWS, "square_m": PITCH_M},
        "points": points.iter().map(|(id, x, y)| json!({"id": id, "x_px": x, "y_px": y})).collect::<Vec<_>>(),
    })
}

/// A 'robocal detect' output file of (file name, detection) entries.
fn write_detections(path: &Path, entries: &[(String, Value)]) {
    let images: Vec<Value> = entries
        .iter()
        .map(|(file, d)| json!({"file": file, "detection": d, "detect_ms": 1.0}))
        .collect();
    let doc = json!({"robocal_version": robocal::VERSION, "target": entries[0].1["target"], "images": images});
    std::fs::write(path, doc.to_string()).expect("write detections");
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("report")).expect("json")
}

fn truth() -> Camera {
    let mut c = Camera::example_brown();
    c.skew = 0.0;
    c
}

fn arg(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

#[test]
fn intrinsics_from_partial_detections_is_exact_and_leaves_out_a_line() {
    let dir = temp_dir("cli_partial", "intrinsics");
    let truth = truth();
    let scene = Scene::calibration(41, &truth, (COLS, ROWS), PITCH_M, 14, 0.0).expect("scene");
    let mut rng = Rng::new(3);
    let size = (truth.width, truth.height);
    let entries: Vec<(String, Value)> = scene
        .views
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let ids = if i == 5 { column() } else { kept_ids(&mut rng) };
            (
                format!("view{i:02}.png"),
                detection(size, &v.object_m, &v.image_px, &ids),
            )
        })
        .collect();
    let file = dir.join("detections.json");
    write_detections(&file, &entries);
    let out = dir.join("camera.json");
    let (code, _, stderr) = robocal(&["intrinsics", "--detections", &arg(&file), "-o", &arg(&out)]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains(&format!(
            "robocal intrinsics: warning: view view05.png left out: {LINE}"
        )),
        "{stderr}"
    );
    let report = read_json(&out);
    assert_eq!(report["views"].as_array().map(Vec::len), Some(13));
    let k = &report["camera"];
    for (name, want) in [
        ("fx", truth.fx),
        ("fy", truth.fy),
        ("cx", truth.cx),
        ("cy", truth.cy),
    ] {
        let got = k[name].as_f64().expect(name);
        assert!(
            (got - want).abs() < 1e-9 * want,
            "{name}: {got} vs {want} (1e-9 relative)"
        );
    }
    // The residuals carry the detection's ids.
    let first = &report["views"][0]["residuals_px"];
    let want: Vec<Value> = entries[0].1["points"]
        .as_array()
        .expect("points")
        .iter()
        .map(|p| p["id"].clone())
        .collect();
    let got: Vec<Value> = first
        .as_array()
        .expect("residuals")
        .iter()
        .map(|r| r["id"].clone())
        .collect();
    assert_eq!(got, want);
}

fn pose_line(p: &Pose) -> String {
    let m = p.to_homogeneous();
    (0..4)
        .flat_map(|r| (0..4).map(move |c| m[(r, c)]))
        .map(|v| format!("{v:.17e}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn matrix(v: &Value) -> nalgebra::Matrix4<f64> {
    let mut m = nalgebra::Matrix4::zeros();
    for r in 0..4 {
        for c in 0..4 {
            m[(r, c)] = v["matrix_row_major"][r][c].as_f64().expect("number");
        }
    }
    m
}

#[test]
fn handeye_from_partial_detections_recovers_x_in_both_setups() {
    for (name, setup, key) in [
        ("eye-in-hand", Setup::EyeInHand, "gripper_from_camera"),
        ("eye-to-hand", Setup::EyeToHand, "base_from_camera"),
    ] {
        let dir = temp_dir("cli_partial", name);
        let camera = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
        let scene = looking_scene(
            &LookingConfig {
                setup,
                views: 10,
                distance_m: 0.6,
                grid: (COLS, ROWS, PITCH_M),
                max_tilt_deg: 35.0,
                max_roll_deg: 60.0,
            },
            51,
        );
        let mut rng = Rng::new(52);
        let views = grid_pixels(&scene, &camera, 0.0, &mut rng);
        let entries: Vec<(String, Value)> = views
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let ids = if i == 4 { column() } else { kept_ids(&mut rng) };
                let d = detection((640, 480), &v.object_m, &v.image_px, &ids);
                (format!("img{i}.png"), d)
            })
            .collect();
        let file = dir.join("detections.json");
        write_detections(&file, &entries);
        let poses = dir.join("robot.txt");
        let lines: Vec<String> = scene.base_from_gripper.iter().map(pose_line).collect();
        std::fs::write(&poses, lines.join("\n") + "\n").expect("poses");
        let cam = dir.join("camera.json");
        std::fs::write(&cam, serde_json::to_string(&camera).expect("camera")).expect("camera");
        let out = dir.join("handeye.json");
        let (code, _, stderr) = robocal(&[
            "handeye",
            "--setup",
            name,
            "--poses",
            &arg(&poses),
            "--pose-format",
            "matrix",
            "--camera",
            &arg(&cam),
            "--detections",
            &arg(&file),
            "--bootstrap",
            "0",
            "-o",
            &arg(&out),
        ]);
        assert_eq!(code, 0, "{name}: {stderr}");
        let report = read_json(&out);
        let diff = (matrix(&report[key]) - scene.x_true.to_homogeneous()).amax();
        assert!(
            diff < 1e-9,
            "{name}: X off by {diff} (matrix entries, m and unitless)"
        );
        let pair = &report["pairs"][4];
        assert_eq!(pair["used"], json!(false), "{name}");
        assert_eq!(
            pair["reason"],
            json!(format!(
                "target pose failed: the view's board points cannot fix a pose: {LINE}"
            )),
            "{name}"
        );
    }
}

#[test]
fn stereo_from_partial_detections_on_both_sides_recovers_the_pair() {
    let dir = temp_dir("cli_partial", "stereo");
    let left_camera = truth();
    let mut right_camera = truth();
    right_camera.fx *= 1.02;
    right_camera.cx += 12.0;
    let right_from_left = Pose::from_parts(
        Translation3::new(-0.12, 0.002, 0.004),
        rotation_from_rotvec(&Vector3::new(0.01, -0.05, 0.004)),
    );
    let scene =
        Scene::calibration(61, &left_camera, (COLS, ROWS), PITCH_M, 12, 0.0).expect("scene");
    let size = (left_camera.width, left_camera.height);
    let mut rng = Rng::new(62);
    let (mut left, mut right) = (Vec::new(), Vec::new());
    for (i, (v, pose)) in scene
        .views
        .iter()
        .zip(&scene.camera_from_target)
        .enumerate()
    {
        let right_px: Vec<nalgebra::Point2<f64>> = v
            .object_m
            .iter()
            .map(|p| {
                right_camera
                    .project(&(right_from_left * pose * p))
                    .expect("in front")
            })
            .collect();
        let (l_ids, r_ids) = (kept_ids(&mut rng), kept_ids(&mut rng));
        let r_ids = if i == 2 { column() } else { r_ids };
        left.push((
            format!("left{i:02}.png"),
            detection(size, &v.object_m, &v.image_px, &l_ids),
        ));
        right.push((
            format!("right{i:02}.png"),
            detection(size, &v.object_m, &right_px, &r_ids),
        ));
    }
    let (lf, rf) = (dir.join("left.json"), dir.join("right.json"));
    write_detections(&lf, &left);
    write_detections(&rf, &right);
    let out = dir.join("stereo.json");
    let (code, _, stderr) = robocal(&[
        "stereo",
        "--left-detections",
        &arg(&lf),
        "--right-detections",
        &arg(&rf),
        "-o",
        &arg(&out),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains(&format!(
            "robocal stereo: warning: pair 2 left out: right right02.png: {LINE}"
        )),
        "{stderr}"
    );
    let report = read_json(&out);
    let diff = (matrix(&report["right_from_left"]) - right_from_left.to_homogeneous()).amax();
    assert!(
        diff < 1e-9,
        "right_from_left off by {diff} (matrix entries)"
    );
    let fx = report["right"]["camera"]["fx"].as_f64().expect("fx");
    assert!(
        (fx - right_camera.fx).abs() < 1e-9 * right_camera.fx,
        "right fx {fx}"
    );
}
