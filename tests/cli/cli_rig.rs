//! `robocal rig` through the real binary on rendered images of the seeded
//! four-camera rig (`robocal::synth::rig`: two pairs facing each other,
//! linked only by side frames seen by cam1 and cam2): the extrinsics, the
//! rig file input, held intrinsics, and the exact errors for cameras no
//! frame connects and for bad flags.

use crate::support;
use support::{robocal, temp_dir};

use robocal::calib::View;
use robocal::camera::Camera;
use robocal::geometry::{rotvec_from_rotation, Pose};
use robocal::image::encode_png;
use robocal::synth::rig::{rig_scene, RigScene, RigSceneConfig};
use robocal::synth::{render, RenderOptions};
use robocal::target::Target;
use serde_json::Value;
use std::path::Path;

const TARGET: &str = "chessboard:10x7:60mm";

/// Whether every inner corner projects 60 px (one square) inside the image.
fn whole_board_inside(camera: &Camera, view: &View) -> bool {
    view.object_m.len() == 70
        && view.image_px.iter().all(|q| {
            q.x > 60.0
                && q.y > 60.0
                && q.x < camera.width as f64 - 61.0
                && q.y < camera.height as f64 - 61.0
        })
}

/// Renders every view that shows the whole board; returns the files of
/// each camera (named `camK_FFF.png`, FFF the frame) and the scene.
fn rendered_rig(dir: &Path) -> (Vec<Vec<String>>, RigScene) {
    let config = RigSceneConfig {
        pair_frames: 5,
        side_frames: 3,
        noise_px: 0.0,
        partial_fraction: 0.0,
        timing_ms: 0.0,
    };
    let scene = rig_scene(&config, 11);
    let target = Target::parse_spec(TARGET).expect("target");
    let mut files = vec![Vec::new(); 4];
    for (k, (views, list)) in scene.views.iter().zip(&mut files).enumerate() {
        for (f, view) in views {
            if !whole_board_inside(&scene.cameras[k], view) {
                continue;
            }
            let pose = scene.camera_from_rig[k] * scene.rig_from_target[*f];
            let options = RenderOptions {
                seed: (10 * f + k) as u64,
                ..RenderOptions::default()
            };
            let r = render(&scene.cameras[k], &target, &pose, &options).expect("render");
            let path = dir.join(format!("cam{k}_{f:03}.png"));
            std::fs::write(&path, encode_png(&r.image).expect("png")).expect("write");
            list.push(path.to_string_lossy().into_owned());
        }
    }
    (files, scene)
}

fn args_of(files: &[Vec<String>], keep: impl Fn(&str) -> bool) -> Vec<&str> {
    let mut args = vec!["rig", "--target", TARGET];
    for (k, list) in files.iter().enumerate() {
        args.extend(["--camera", ["cam0", "cam1", "cam2", "cam3"][k]]);
        args.extend(list.iter().map(String::as_str).filter(|f| keep(f)));
    }
    args
}

fn pose(v: &Value) -> Pose {
    serde_json::from_value::<robocal::geometry::PoseJson>(v.clone())
        .expect("pose")
        .to_pose()
        .expect("rotation")
}

#[test]
fn rig_on_rendered_images_recovers_every_camera_from_rig() {
    let dir = temp_dir("rig", "four");
    let (files, scene) = rendered_rig(&dir);
    let side = |f: &str| ["_010", "_011", "_012"].iter().any(|s| f.contains(s));
    assert!(files[1].iter().any(|f| side(f)) && files[2].iter().any(|f| side(f)));
    let out = dir.join("rig.json").to_string_lossy().into_owned();
    let mut args = args_of(&files, |_| true);
    args.extend(["-o", &out]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("frames seen together"), "{err}");
    // Each solved camera's own advice, named (cam0 saw 5 frames).
    let few = "camera cam0: only 5 views: 10 or more from varied angles are recommended";
    assert!(
        err.contains(&format!("robocal rig: warning: {few}\n")),
        "{err}"
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&out).expect("read")).expect("json");
    assert_eq!(report["rig_frame"], "cam0");
    assert_eq!(report["grouping"], "number");
    assert_eq!(report["co_observation"]["frames"][0][2], 0);
    assert!(
        report["warnings"]
            .as_array()
            .expect("warnings")
            .iter()
            .any(|w| w == few),
        "{}",
        report["warnings"]
    );
    // Rendered corners are found to ~0.05 px (tests/detect/detect_render.rs); with
    // 5-8 views per camera at 1.2 m each camera_from_rig is within 3 mm and
    // 3 mrad (about 10 of the reported std).
    for k in 1..4 {
        let got = pose(&report["cameras"][k]["camera_from_rig"]);
        let truth = scene.camera_from_rig[k];
        let dt = (got.translation.vector - truth.translation.vector).norm();
        let dr = rotvec_from_rotation(&(got.rotation * truth.rotation.inverse())).norm();
        assert!(dt < 3e-3 && dr < 3e-3, "cam{k}: {dt} m, {dr} rad; {err}");
    }
    assert!(report["rms_px"].as_f64().expect("rms") < 0.3);
    // --fix k3 holds k3 at exactly 0 in every camera, so the rig exports to
    // Kalibr's radtan (k1 k2 p1 p2), which has no k3.
    let held = dir.join("rig_k3.json").to_string_lossy().into_owned();
    let mut args = args_of(&files, |_| true);
    args.extend(["--fix", "k3", "-o", &held]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&held).expect("read")).expect("json");
    for k in 0..4 {
        let d = &report["cameras"][k]["calibration"]["distortion"];
        assert_eq!(d["k3"], 0.0, "cam{k}: {d}");
        assert_ne!(d["k1"], 0.0, "cam{k}: {d}");
    }
    // The rig file's `fix` key does what --fix does: the same report.
    let cameras: Vec<Value> = files
        .iter()
        .enumerate()
        .map(|(k, list)| serde_json::json!({"name": format!("cam{k}"), "images": list}))
        .collect();
    let input = dir.join("rig_input.json");
    let text = serde_json::json!({"target": TARGET, "fix": ["k3"], "cameras": cameras});
    std::fs::write(&input, text.to_string()).expect("write");
    let from_file = dir.join("rig_k3_file.json").to_string_lossy().into_owned();
    let input = input.to_string_lossy().into_owned();
    let (code, _, err) = robocal(&["rig", "--input", &input, "-o", &from_file]);
    assert_eq!(code, 0, "{err}");
    let again: Value =
        serde_json::from_str(&std::fs::read_to_string(&from_file).expect("read")).expect("json");
    for k in 0..4 {
        let (a, b) = (
            &again["cameras"][k]["calibration"],
            &report["cameras"][k]["calibration"],
        );
        assert_eq!(a["distortion"], b["distortion"], "cam{k}");
        assert_eq!(a["camera_matrix"], b["camera_matrix"], "cam{k}");
        assert!(a["camera_matrix"].is_array(), "cam{k}: {a}");
    }
    let (code, yaml, err) = robocal(&["export", &held, "--format", "kalibr"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        yaml.matches("distortion_model: radtan").count(),
        4,
        "{yaml}"
    );
}

#[test]
fn cameras_that_no_frame_links_are_named_and_flags_are_checked() {
    let dir = temp_dir("rig", "groups");
    let (files, _) = rendered_rig(&dir);
    let side = |f: &str| ["_010", "_011", "_012"].iter().any(|s| f.contains(s));
    let (code, _, err) = robocal(&args_of(&files, |f| !side(f)));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.trim_end().ends_with(
            "cameras are not connected by shared board views: {cam0, cam1} and {cam2, cam3}; \
             add frames where a camera of each group sees the board"
        ),
        "{err}"
    );
    let mut args = args_of(&files, |_| true);
    args.extend(["--camera-file", "top=top.json"]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 2);
    assert_eq!(
        err.trim_end(),
        "robocal: rig: --camera-file top=top.json: no --camera is named 'top' (see 'robocal rig --help')"
    );
}

/// A pose file with an `image` column: one row per frame of `frames`.
fn pose_file(poses: &[(usize, Pose)]) -> String {
    let mut s = String::from("image,x,y,z,qx,qy,qz,qw\n");
    for (f, p) in poses {
        let t = p.translation.vector;
        let q = p.rotation.coords;
        s += &format!(
            "cam0_{f:03}.png,{},{},{},{},{},{},{}\n",
            t.x, t.y, t.z, q.x, q.y, q.z, q.w
        );
    }
    s
}

#[test]
fn rig_on_a_robot_gives_gripper_from_rig_and_checks_the_poses() {
    use robocal::handeye::Setup;
    use robocal::synth::rig::robot_poses;
    let dir = temp_dir("rig", "robot");
    let (files, scene) = rendered_rig(&dir);
    let x = Pose::from_parts(
        nalgebra::Translation3::new(0.05, -0.12, 0.2),
        nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::new(0.3, -1.1, 0.4)),
    );
    let y = Pose::from_parts(
        nalgebra::Translation3::new(0.8, 0.1, -0.3),
        nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::new(2.0, 0.2, -0.5)),
    );
    let all = robot_poses(&scene, Setup::EyeInHand, &x, &y);
    // The frames that have an image, in key order.
    let mut seen: Vec<usize> = files
        .iter()
        .flatten()
        .map(|f| f[f.len() - 7..f.len() - 4].parse().expect("frame"))
        .collect();
    seen.sort();
    seen.dedup();
    let poses: Vec<(usize, Pose)> = seen.iter().map(|&f| (f, all[f])).collect();
    let path = |name: &str| dir.join(name).to_string_lossy().into_owned();
    std::fs::write(path("robot.csv"), pose_file(&poses)).expect("write");
    let out = path("rig.json");
    let mut args = args_of(&files, |_| true);
    let robot = path("robot.csv");
    args.extend(["--setup", "eye-in-hand", "--poses", &robot, "-o", &out]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("robocal rig: gripper_from_rig translation_m"),
        "{err}"
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&out).expect("read")).expect("json");
    let h = &report["handeye"];
    assert_eq!(h["setup"], "eye-in-hand");
    assert_eq!(h["frames"].as_array().expect("frames").len(), seen.len());
    // The rig is calibrated from the same renders (camera_from_rig within
    // 3 mm, 3 mrad, above); each frame's board pose pools the cameras, so
    // the rig transform lands within the same 3 mm and 3 mrad.
    let got = pose(&h["gripper_from_rig"]);
    let dt = (got.translation.vector - x.translation.vector).norm();
    let dr = rotvec_from_rotation(&(got.rotation * x.rotation.inverse())).norm();
    assert!(dt < 3e-3 && dr < 3e-3, "{dt} m, {dr} rad; {err}");
    let cam3 = pose(&h["cameras"][3]["gripper_from_camera"]);
    let expected = x * scene.camera_from_rig[3].inverse();
    let dt3 = (cam3.translation.vector - expected.translation.vector).norm();
    assert!(dt3 < 6e-3, "cam3 {dt3} m");
    // The rig's own uncertainty is in the std (its covariance in the report).
    assert_eq!(
        h["rig_uncertainty"]["included"], true,
        "{}",
        h["rig_uncertainty"]
    );
    assert!(
        report["covariance"]["parameters"]
            .as_array()
            .expect("covariance")
            .len()
            > 18
    );

    // The calibrated rig given back with --rig: the same hand-eye from the
    // same images (the JSON round trip is exact), the rig file copied.
    let again = path("again.json");
    let mut args = args_of(&files, |_| true);
    args.extend([
        "--rig",
        &out,
        "--setup",
        "eye-in-hand",
        "--poses",
        &robot,
        "-o",
        &again,
    ]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    let held: Value =
        serde_json::from_str(&std::fs::read_to_string(&again).expect("read")).expect("json");
    let h2 = &held["handeye"];
    let got2 = pose(&h2["gripper_from_rig"]);
    let d = (got2.translation.vector - got.translation.vector).norm();
    assert!(d < 1e-12, "--rig moved gripper_from_rig by {d} m");
    for key in ["translation_mm", "rotation_deg"] {
        let (a, b) = (
            &h["pose_refinement"]["camera_transform_std"][key],
            &h2["pose_refinement"]["camera_transform_std"][key],
        );
        for i in 0..3 {
            let (a, b) = (a[i].as_f64().expect("std"), b[i].as_f64().expect("std"));
            assert!((a - b).abs() <= 1e-9 * a, "std {key}[{i}]: {a} vs {b}");
        }
    }
    assert_eq!(held["cameras"], report["cameras"]);
    // The poses as a folder of one ROS pose YAML per frame (named by the
    // frame's number, as a teach pendant or a ROS logger writes them), given
    // with the calibrated rig: the same gripper_from_rig as the table.
    let folder = dir.join("poses");
    std::fs::create_dir_all(&folder).expect("mkdir");
    for (f, p) in &poses {
        let (t, q) = (p.translation.vector, p.rotation.coords);
        let text = format!(
            "position: {{x: {}, y: {}, z: {}}}\norientation: {{x: {}, y: {}, z: {}, w: {}}}\n",
            t.x, t.y, t.z, q.x, q.y, q.z, q.w
        );
        std::fs::write(folder.join(format!("pose_{f:03}.yaml")), text).expect("write");
    }
    let folder = folder.to_string_lossy().into_owned();
    let mut args = args_of(&files, |_| true);
    args.extend(["--rig", &out, "--setup", "eye-in-hand", "--poses", &folder]);
    let (code, out_json, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    let from_folder: Value = serde_json::from_str(&out_json).expect("json");
    let got3 = pose(&from_folder["handeye"]["gripper_from_rig"]);
    let d = (got3.translation.vector - got.translation.vector).norm();
    assert!(d < 1e-9, "--poses FOLDER moved gripper_from_rig by {d} m");
    // Only two of its cameras: fine; a camera the rig does not have: named.
    let two: Vec<Vec<String>> = vec![files[0].clone(), files[1].clone()];
    let mut args = args_of(&two, |_| true);
    args.extend(["--rig", &out, "--setup", "eye-in-hand", "--poses", &robot]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    let mut args = args_of(&files, |_| true);
    let i = args.iter().position(|a| *a == "cam3").expect("cam3");
    args[i] = "top";
    args.extend(["--rig", &out, "--setup", "eye-in-hand", "--poses", &robot]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 2, "{err}");
    assert_eq!(
        err.trim_end(),
        format!(
            "robocal: rig: '{out}': camera 'top' is not in the rig (its cameras are cam0, cam1, \
             cam2, cam3) (see 'robocal rig --help')"
        )
    );
    let (code, _, err) = robocal(&["rig", "--rig", &out, "--camera", "cam0", "x.png"]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(
        err.trim_end(),
        "robocal: rig: --rig holds a calibrated rig for the hand-eye: give --setup \
         eye-in-hand|eye-to-hand and --poses FILE with it (see 'robocal rig --help')"
    );

    // A frame without a robot pose: named.
    std::fs::write(path("short.csv"), pose_file(&poses[1..])).expect("write");
    let short = path("short.csv");
    let mut args = args_of(&files, |_| true);
    args.extend(["--setup", "eye-in-hand", "--poses", &short]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 1, "{err}");
    assert_eq!(
        err.lines().last().expect("message"),
        format!(
            "robocal: '{short}': no robot pose for frame(s) {}: give a pose for every frame, \
             or leave those frames' images out",
            seen[0]
        )
    );
    // Poses by order whose count differs from the frames'.
    let plain: String = poses[1..]
        .iter()
        .map(|(_, p)| {
            let t = p.translation.vector;
            let q = p.rotation.coords;
            format!("{} {} {} {} {} {} {}\n", t.x, t.y, t.z, q.x, q.y, q.z, q.w)
        })
        .collect();
    std::fs::write(path("plain.txt"), plain).expect("write");
    let plain = path("plain.txt");
    let mut args = args_of(&files, |_| true);
    args.extend([
        "--setup",
        "eye-in-hand",
        "--poses",
        &plain,
        "--pose-format",
        "xyz-quaternion-xyzw",
    ]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 1, "{err}");
    assert_eq!(
        err.lines().last().expect("message"),
        format!(
            "robocal: poses: {} robot poses but {} frames: give one robot pose per frame, \
             in frame order",
            seen.len() - 1,
            seen.len()
        )
    );
    let (code, _, err) = robocal(&["rig", "--target", TARGET, "--setup", "eye-in-hand"]);
    assert_eq!(code, 2);
    assert_eq!(
        err.trim_end(),
        "robocal: rig: --setup needs --poses FILE (see 'robocal rig --help')"
    );
}

#[test]
fn a_camera_whose_images_show_no_board_is_named() {
    let dir = temp_dir("rig", "empty");
    let a = dir.join("a1.png").to_string_lossy().into_owned();
    let b = dir.join("b1.png").to_string_lossy().into_owned();
    std::fs::write(&a, b"").expect("write");
    std::fs::write(&b, b"").expect("write");
    let (code, _, err) = robocal(&[
        "rig", "--target", TARGET, "--camera", "a", &a, "--camera", "b", &b,
    ]);
    assert_eq!(code, 1, "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(
        lines,
        [
            format!("robocal rig: camera a: {a} left out: not an image: the file is empty"),
            "robocal: rig: the target was found in no image of camera a".to_string(),
        ]
    );
}

/// Frame numbers that are not the last number of the name: `sync036_cam0`
/// (last number: the camera), `cam1_sync036` and `0001_cam2_36` (a capture
/// counter first). The default rule's error names the other rules; a
/// pattern, `first` and `last` group them.
#[test]
fn frames_group_by_the_first_number_the_last_or_a_pattern() {
    let dir = temp_dir("rig", "grouping");
    let (files, _) = rendered_rig(&dir);
    // The rendered files are camK_FFF.png; rename them as capture tools do.
    let renamed: Vec<Vec<String>> = files
        .iter()
        .enumerate()
        .map(|(k, list)| {
            list.iter()
                .enumerate()
                .map(|(i, f)| {
                    let frame = &f[f.len() - 7..f.len() - 4];
                    let name = match k {
                        0 => format!("sync{frame}_cam0.png"),
                        1 => format!("cam1_sync{frame}.png"),
                        2 => format!("{:04}_cam2_sync{frame}.png", i + 1),
                        _ => format!("sync{frame}_cam3.png"),
                    };
                    let path = dir.join(name);
                    std::fs::copy(f, &path).expect("copy");
                    path.to_string_lossy().into_owned()
                })
                .collect()
        })
        .collect();
    let rules = "(group by number or last (the last number in the name, the default), first \
                 (the first number), order (the position in each camera's list), or a pattern \
                 with one (\\d+) such as sync(\\d+)) (see 'robocal rig --help')";
    // 1. By the last number, cam0's frames all are frame 0.
    let (code, _, err) = robocal(&args_of(&renamed, |_| true));
    assert_eq!(code, 2, "{err}");
    let first_two: Vec<&str> = renamed[0][..2].iter().map(String::as_str).collect();
    assert_eq!(
        err.trim_end(),
        format!(
            "robocal: rig: frames are grouped by the last number in the file names, but number 0 \
             is in two camera cam0 images: {}, {} {rules}",
            first_two[0], first_two[1]
        )
    );
    // 2. first: cam1's first number is its camera number.
    let mut args = args_of(&renamed, |_| true);
    args.extend(["--group-by", "first"]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("frames are grouped by the first number in the file names, but number 1 is in two camera cam1 images"), "{err}");
    // 3. A rule that is neither.
    let mut args = args_of(&renamed, |_| true);
    args.extend(["--group-by", "sync"]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 2, "{err}");
    assert_eq!(
        err.trim_end(),
        "robocal: rig: --group-by takes number or last (the last number in the name, the \
         default), first (the first number), order (the position in each camera's list), or a \
         pattern with one (\\d+) such as sync(\\d+); got 'sync': not a rule name, and no (\\d+) \
         in it (see 'robocal rig --help')"
    );
    // 4. The pattern groups all four cameras as the original names did.
    let out = dir.join("rig.json").to_string_lossy().into_owned();
    let mut args = args_of(&renamed, |_| true);
    args.extend(["--group-by", "sync(\\d+)", "-o", &out]);
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(report["grouping"], "sync(\\d+)");
    let keys: Vec<&str> = report["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["key"].as_str().unwrap())
        .collect();
    let mut expected: Vec<String> = files
        .iter()
        .flatten()
        .map(|f| {
            f[f.len() - 7..f.len() - 4]
                .trim_start_matches('0')
                .to_string()
        })
        .map(|k| if k.is_empty() { "0".into() } else { k })
        .collect();
    expected.sort_by_key(|k| k.parse::<u32>().unwrap());
    expected.dedup();
    let keys: Vec<String> = keys.iter().map(|k| k.to_string()).collect();
    assert_eq!(keys, expected);
}
