//! `robocal rig` through the real binary on rendered images of the seeded
//! four-camera rig (`robocal::synth::rig`: two pairs facing each other,
//! linked only by side frames seen by cam1 and cam2): the extrinsics, the
//! rig file input, held intrinsics, and the exact errors for cameras no
//! frame connects and for bad flags.

mod support;
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
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(&out).expect("read")).expect("json");
    assert_eq!(report["rig_frame"], "cam0");
    assert_eq!(report["grouping"], "number");
    assert_eq!(report["co_observation"]["frames"][0][2], 0);
    // Rendered corners are found to ~0.05 px (tests/detect_render.rs); with
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
