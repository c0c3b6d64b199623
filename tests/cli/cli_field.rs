//! `robocal handeye --tcp --holdout` and `robocal plan` (docs/handeye-field.md,
//! docs/pose-plan.md): the new report keys, the exported programs, the
//! messages for bad flags.

use super::cli_handeye::read_json;
use crate::support;
use robocal::synth::handeye_looking::{looking_scene, LookingConfig};

fn line(p: &robocal::handeye::Pose) -> String {
    let m = p.to_homogeneous();
    (0..4)
        .flat_map(|i| (0..4).map(move |j| format!("{:.17e}", m[(i, j)])))
        .collect::<Vec<_>>()
        .join(" ")
        + "\n"
}

#[test]
fn handeye_reports_the_error_at_the_tcp_and_on_held_out_poses() {
    let scene = looking_scene(
        &LookingConfig::half_metre(robocal::handeye::Setup::EyeInHand, 15),
        21,
    );
    let dir = support::temp_dir("cli_field", "handeye");
    let robot: String = scene.base_from_gripper.iter().map(line).collect();
    let camera: String = scene.camera_from_target.iter().map(line).collect();
    std::fs::write(dir.join("robot.txt"), robot).unwrap();
    std::fs::write(dir.join("camera.txt"), camera).unwrap();
    let out = dir.join("handeye.json");
    let args = [
        "handeye",
        "--setup",
        "eye-in-hand",
        "--poses",
        "robot.txt",
        "--pose-format",
        "matrix",
        "--camera-poses",
        "camera.txt",
        "--bootstrap",
        "0",
        "--tcp",
        "0,0,150mm",
        "--holdout",
        "3",
        "-o",
        "handeye.json",
    ];
    let run = support::robocal_in(&dir, &args);
    assert_eq!(run.0, 0, "{}", run.2);
    let report = read_json(&out);
    let w = &report["work_point_error"];
    assert!(w["bound95_mm"].as_f64().unwrap() >= 0.0, "{w}");
    assert_eq!(w["frame"], "gripper");
    assert_eq!(report["tcp_error"]["point_m"][2].as_f64().unwrap(), 0.15);
    assert_eq!(report["holdout"]["per_pose"].as_array().unwrap().len(), 3);
    assert_eq!(report["holdout"]["per_pose"][0]["view"], 12);
    assert!(
        run.2
            .contains("hand-eye error at the target centre: within "),
        "{}",
        run.2
    );
    assert!(
        run.2
            .contains("hand-eye error at the tool centre point: within "),
        "{}",
        run.2
    );
    let bad = support::robocal_in(&dir, &[&args[..11], &["--tcp", "0,0,150"]].concat());
    assert_eq!(bad.0, 2, "{}", bad.2);
    assert!(
        bad.2
            .contains("--tcp '0,0,150': needs a unit: mm, cm or m (e.g. 0,0,150mm)"),
        "{}",
        bad.2
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plan_writes_poses_a_program_and_its_predicted_error() {
    let dir = support::temp_dir("cli_field", "plan");
    let camera = robocal::Camera::pinhole(1000.0, 1000.0, 640.0, 480.0, 1280, 960);
    std::fs::write(
        dir.join("camera.json"),
        serde_json::to_string(&camera).unwrap(),
    )
    .unwrap();
    // The robot pointing down at 0.8 m; the board 0.5 m in front of the camera.
    std::fs::write(
        dir.join("now.csv"),
        "x,y,z,rx,ry,rz\n0.5,0.1,0.8,3.14159,0,0\n",
    )
    .unwrap();
    let view = robocal::handeye::Pose::translation(-0.12, -0.075, 0.5);
    std::fs::write(dir.join("view.txt"), line(&view)).unwrap();
    let guess = robocal::handeye::Pose::translation(0.03, -0.02, 0.1);
    std::fs::write(dir.join("guess.txt"), line(&guess)).unwrap();
    let base = [
        "plan",
        "--setup",
        "eye-in-hand",
        "--robot-pose",
        "now.csv",
        "--pose-format",
        "ur",
        "--camera",
        "camera.json",
        "--target",
        "chessboard:9x6:30mm",
        "--camera-pose",
        "view.txt",
        "--guess",
        "guess.txt",
        "--poses",
        "10",
    ];
    for (format, marker) in [
        ("ur-script", "movel(p["),
        ("kuka-krl", "LIN {X "),
        ("abb-rapid", "MoveL [["),
        ("kuka", "A,B,C"),
    ] {
        let run = support::robocal_in(
            &dir,
            &[
                &base[..],
                &[
                    "--export",
                    "robot.out",
                    "--format",
                    format,
                    "-o",
                    "plan.json",
                ],
            ]
            .concat(),
        );
        assert_eq!(run.0, 0, "{format}: {}", run.2);
        let text = std::fs::read_to_string(dir.join("robot.out")).unwrap();
        assert!(text.contains(marker), "{format}: {text}");
        let plan = read_json(&dir.join("plan.json"));
        assert_eq!(plan["kind"], "handeye-plan");
        assert_eq!(plan["poses"].as_array().unwrap().len(), 10);
        assert!(plan["predicted"]["bound95_mm"].as_f64().unwrap() > 0.0);
        assert_eq!(plan["predicted"]["placement"], "board-centre");
        assert!(
            run.2
                .contains("note: joint limits, reachability and collisions are not modelled"),
            "{}",
            run.2
        );
        // A camera pose, no image: nothing to measure the noise on.
        assert_eq!(plan["noise"]["pixel_sigma_from"], "default");
        assert_eq!(plan["noise"]["pixel_sigma_px"], 0.3);
        assert!(
            run.2
                .contains("note: the prediction assumes 0.30 px corner noise, not measured"),
            "{}",
            run.2
        );
    }
    let given = support::robocal_in(
        &dir,
        &[&base[..], &["--pixel-noise", "0.1", "-o", "plan.json"]].concat(),
    );
    assert_eq!(given.0, 0, "{}", given.2);
    let plan = read_json(&dir.join("plan.json"));
    assert_eq!(plan["noise"]["pixel_sigma_from"], "given");
    assert_eq!(plan["noise"]["pixel_sigma_px"], 0.1);
    let negative = support::robocal_in(&dir, &[&base[..], &["--pixel-noise", "0"]].concat());
    assert_eq!(negative.0, 2, "{}", negative.2);
    assert!(
        negative
            .2
            .contains("--pixel-noise 0: a positive number of pixels"),
        "{}",
        negative.2
    );
    let bad = support::robocal_in(&dir, &[&base[..], &["--distance", "0.4,0.6"]].concat());
    assert_eq!(bad.0, 2, "{}", bad.2);
    assert!(
        bad.2
            .contains("--distance '0.4,0.6': needs a unit: mm, cm or m"),
        "{}",
        bad.2
    );
    let _ = std::fs::remove_dir_all(&dir);
}
