//! The rows of the bad-input catalogue (docs/bad-inputs.md) that need real
//! data: rendered images (`robocal render` as a set-up step) and seeded
//! hand-eye scenes (robocal::synth) written as pose files, then spoiled the
//! way users spoil them: millimetres read as metres, the wrong setup,
//! pairing shifted by one, a robot that only translates, images of two
//! sizes, the same image twice, too few views, stereo names that do not pair;
//! and (issue 35) one pose row in mm or at 1e6 m, a camera pose at 1e308 m,
//! the same images for both stereo or rig cameras.

use crate::support;
use robocal::handeye::{Pose, Setup};
use robocal::synth::handeye::{handeye_scene, HandEyeSceneConfig};
use support::catalogue::{check_all, strings, Row, Stream};

/// One pose a line, `x y z qx qy qz qw` (metres), with the translation
/// scaled by `scale`.
fn pose_lines(poses: &[Pose], scale: f64) -> Vec<u8> {
    let mut text = String::new();
    for p in poses {
        let t = p.translation.vector * scale;
        let q = p.rotation.coords;
        text.push_str(&format!(
            "{} {} {} {} {} {} {}\n",
            t.x, t.y, t.z, q.x, q.y, q.z, q.w
        ));
    }
    text.into_bytes()
}

/// `poses` with pose 3 spoiled by `spoil` (issue 35: one bad row).
fn one_row(poses: &[Pose], spoil: impl Fn(&mut Pose)) -> Vec<Pose> {
    let mut out = poses.to_vec();
    spoil(&mut out[3]);
    out
}

/// A noise-free 10-view scene of `setup`: (robot poses, camera poses).
fn scene(setup: Setup) -> (Vec<Pose>, Vec<Pose>) {
    let s = handeye_scene(&HandEyeSceneConfig::noise_free(setup, 10), 4);
    (s.base_from_gripper, s.camera_from_target)
}

/// `robocal handeye --camera-poses` on robot.txt and camera.txt.
fn handeye_args(setup: &str) -> Vec<String> {
    strings(&[
        "handeye",
        "--setup",
        setup,
        "--poses",
        "robot.txt",
        "--pose-format",
        "xyz-quaternion-xyzw",
        "--camera-poses",
        "camera.txt",
        "--camera-pose-format",
        "xyz-quaternion-xyzw",
        "--bootstrap",
        "0",
    ])
}

fn pose_row(name: &str, robot: Vec<u8>, camera: Vec<u8>, setup: &str, message: &str) -> Row {
    Row {
        name: name.into(),
        files: vec![("robot.txt".into(), robot), ("camera.txt".into(), camera)],
        setup: Vec::new(),
        args: handeye_args(setup),
        code: 1,
        stream: Stream::Stderr,
        message: message.into(),
        last_line: false,
    }
}

/// A 640x480 camera without distortion, for renders of another size.
const SMALL_CAMERA: &str = r#"{"model":"brown","image_size_px":[640,480],"camera_matrix":[[560,0,319.5],[0,560,239.5],[0,0,1]],"distortion":{"k1":0,"k2":0,"p1":0,"p2":0,"k3":0}}"#;

fn render(out: &str, views: &str, extra: &[&str]) -> Vec<String> {
    let mut args = strings(&["render", "--out", out, "--views", views]);
    args.extend(strings(extra));
    args
}

fn image_row(name: &str, setup: Vec<Vec<String>>, args: &[&str], message: &str) -> Row {
    Row {
        name: name.into(),
        files: vec![("small.json".into(), SMALL_CAMERA.as_bytes().to_vec())],
        setup,
        args: strings(args),
        code: if args[0] == "stereo" { 2 } else { 1 },
        stream: Stream::Stderr,
        message: message.into(),
        // detect names each image's problem first, then sums up.
        last_line: args[0] != "detect",
    }
}

fn pose_rows() -> Vec<Row> {
    let (robot, camera) = scene(Setup::EyeInHand);
    let (robot_eth, camera_eth) = scene(Setup::EyeToHand);
    let n = robot.len();
    let mut still = robot.clone();
    for p in &mut still {
        p.rotation = robot[0].rotation;
    }
    vec![
        pose_row(
            "handeye-robot-mm-read-as-m",
            pose_lines(&robot, 1000.0),
            pose_lines(&camera, 1.0),
            "eye-in-hand",
            "robocal: robot poses: the robot translations fit the camera motion only when scaled by 0.0010: the robot poses look like millimetres while the camera poses are metres: convert the robot translations to metres (divide by 1000) or choose a pose format with mm units",
        ),
        pose_row(
            "handeye-camera-mm-read-as-m",
            pose_lines(&robot, 1.0),
            pose_lines(&camera, 1000.0),
            "eye-in-hand",
            "robocal: robot poses: the robot translations fit the camera motion only when scaled by 1000.0000: the camera poses look like millimetres while the robot poses are metres: convert the camera translations to metres (divide by 1000)",
        ),
        pose_row(
            "handeye-wrong-setup",
            pose_lines(&robot_eth, 1.0),
            pose_lines(&camera_eth, 1.0),
            "eye-in-hand",
            "robocal: robot poses: these poses fit eye-to-hand (the camera fixed, the target on the gripper), not the eye-in-hand chosen: as eye-to-hand they fit the camera motion with rotation RMS 0.000 deg, against 29.779 deg as eye-in-hand: choose the setup eye-to-hand, which solves base_from_camera. Inverting the poses instead would give the same numbers under the wrong frame names; do that only if the setup really is eye-in-hand and the file holds gripper_from_base",
        ),
        pose_row(
            "handeye-shifted-by-one",
            pose_lines(&robot[1..], 1.0),
            pose_lines(&camera[..n - 1], 1.0),
            "eye-in-hand",
            "robocal: robot poses: the pose file looks shifted by one against the images: pairing robot pose i with image i+1 fits with rotation RMS 0.000 deg, against 40.844 deg as given: remove the extra first image so that the lists pair up",
        ),
        pose_row(
            "handeye-one-row-in-mm",
            pose_lines(&one_row(&robot, |p| p.translation.vector *= 1000.0), 1.0),
            pose_lines(&camera, 1.0),
            "eye-in-hand",
            "robocal: poses: pose pair 3 (robot pose and camera pose 3, counting from 0) is a gross error: with it left out the other 9 fit one hand-eye transform with a median residual of 0.000 mm, and it is off by 1766099.5 mm and 0.00 deg: that row holds a typo or another unit (millimetres in a metre file?): fix or remove it",
        ),
        pose_row(
            "handeye-one-row-at-1e6",
            pose_lines(&one_row(&robot, |p| p.translation.vector.x = 1e6), 1.0),
            pose_lines(&camera, 1.0),
            "eye-in-hand",
            "robocal: base_from_gripper: pose 3 (counting from 0) has a translation of 1.000e6 m, beyond 10000 m: that row holds a typo or another unit (translations are metres): fix or remove it",
        ),
        pose_row(
            "handeye-camera-pose-at-1e308",
            pose_lines(&robot, 1.0),
            pose_lines(&one_row(&camera, |p| p.translation.vector.z = 1e308), 1.0),
            "eye-in-hand",
            "robocal: camera_from_target: pose 3 (counting from 0) has a translation of 1.000e308 m, beyond 10000 m: that row holds a typo or another unit (translations are metres): fix or remove it",
        ),
        pose_row(
            "handeye-translations-only",
            pose_lines(&still, 1.0),
            pose_lines(&camera, 1.0),
            "eye-in-hand",
            "robocal: the robot only translated: the largest rotation between two poses is 0.00 deg and 0 motion pair(s) rotate at least 2 deg (2 needed); the hand-eye rotation is unobservable: rotate the gripper between poses, ideally by 30 deg or more about at least two different axes",
        ),
        pose_row(
            "handeye-1001-poses",
            pose_lines(&cycled(&robot, 1001), 1.0),
            pose_lines(&cycled(&camera, 1001), 1.0),
            "eye-in-hand",
            "robocal: poses: 1001 poses: at most 1000 are supported (the solvers and the repeatability check use every pair of poses, which grows with the square); keep a subset spread over the workspace, e.g. every 2nd pose",
        ),
    ]
}

/// The first `n` poses of `poses` repeated.
fn cycled(poses: &[Pose], n: usize) -> Vec<Pose> {
    poses.iter().cycle().take(n).copied().collect()
}

fn image_rows() -> Vec<Row> {
    let target = "chessboard:9x6:30mm";
    vec![
        image_row(
            "intrinsics-two-image-sizes",
            vec![render("a", "3", &[]), render("b", "1", &["--camera", "small.json"])],
            &["intrinsics", "--target", target, "a/view_000.png", "a/view_001.png", "a/view_002.png", "b/view_000.png"],
            "robocal: image_size_px: the detections disagree: 1024x768 and 640x480 (b/view_000.png): one calibration takes the images of one camera at one resolution",
        ),
        image_row(
            "intrinsics-same-image-twice",
            vec![render("a", "3", &[])],
            &["intrinsics", "--target", target, "a/view_000.png", "a/view_001.png", "a/view_000.png"],
            "robocal: views: views 0 (a/view_000.png) and 2 (a/view_000.png) have identical image points: the same image was given twice; remove one of them",
        ),
        image_row(
            "intrinsics-two-views",
            vec![render("a", "2", &[])],
            &["intrinsics", "--target", target, "a/view_000.png", "a/view_001.png"],
            "robocal: views: 2 views with the target found, a calibration needs at least 3 (10 or more from varied angles are recommended): add images in which the whole target is found, or check the target's size (inner corners for a chessboard)",
        ),
        image_row(
            "intrinsics-wrong-target",
            vec![render("a", "3", &["--target", "circles:4x11:20mm:asymmetric"])],
            &["intrinsics", "--target", target, "a/view_000.png", "a/view_001.png", "a/view_002.png"],
            "robocal: views: 0 views with the target found, a calibration needs at least 3 (10 or more from varied angles are recommended): add images in which the whole target is found, or check the target's size (inner corners for a chessboard)",
        ),
        image_row(
            "detect-squares-counted-not-corners",
            vec![render("a", "2", &[])],
            &["detect", "--target", "chessboard:10x7:30mm", "a/view_001.png"],
            "robocal detect: a/view_001.png: found 9x6 inner corners, not the 10x7 of the target: the spec counts inner corners (a board of 10x7 squares has 9x6): use chessboard:9x6:SIZE",
        ),
        image_row(
            "stereo-names-do-not-pair",
            vec![render("a", "3", &[])],
            &["stereo", "--target", target, "--left", "a/view_000.png", "a/view_001.png", "--right", "a/view_000.png", "a/view_002.png"],
            "robocal: stereo: images are paired by the last number in their file names; no partner for: a/view_001.png (left, number 1), a/view_002.png (right, number 2) (see 'robocal stereo --help')",
        ),
        Row {
            code: 1,
            ..image_row(
                "stereo-same-images-both-sides",
                vec![render("a", "3", &[])],
                &["stereo", "--target", target, "--left", "a/view_000.png", "a/view_001.png", "a/view_002.png", "--right", "a/view_000.png", "a/view_001.png", "a/view_002.png"],
                "robocal: right: the left and right images have identical detections in all 3 pairs: the same images were given for both cameras, which would solve to a baseline of 0 m; give each camera its own images",
            )
        },
        Row {
            code: 1,
            ..image_row(
                "rig-same-images-two-cameras",
                vec![render("a", "3", &[])],
                &["rig", "--target", target, "--camera", "left", "a/view_000.png", "a/view_001.png", "a/view_002.png", "--camera", "right", "a/view_000.png", "a/view_001.png", "a/view_002.png"],
                "robocal: cameras: cameras left and right have identical detections in all 3 shared frames: the same images were given for both cameras, which would solve to a baseline of 0 m; give each camera its own images",
            )
        },
    ]
}

#[test]
fn spoiled_scenes_get_their_exact_messages() {
    let mut rows = pose_rows();
    rows.extend(image_rows());
    check_all("bad-scenes", &rows);
}
