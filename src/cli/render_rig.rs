//! `robocal render --rig`: images of the seeded four-camera rig of
//! `robocal::synth::rig` (two pairs facing each other, linked only by the
//! side frames), one folder per camera, with the rig's ground truth.

use super::CliError;
use robocal::io::export_transform::transform_json;
use robocal::synth::rig::{rig_scene, RigSceneConfig, RIG_BOARD};
use robocal::synth::{render, RenderOptions};
use robocal::target::Target;
use std::path::Path;

/// What `--rig` renders.
pub struct RigArgs<'a> {
    pub out: &'a Path,
    pub pair_frames: usize,
    pub side_frames: usize,
    pub seed: u64,
    pub render: RenderOptions,
}

/// The chessboard whose inner corners are the synthetic rig's board points.
pub fn rig_target() -> Target {
    let (cols, rows, pitch) = RIG_BOARD;
    Target::Chessboard {
        cols,
        rows,
        square_m: pitch,
    }
}

/// Writes DIR/camK/camK_FFF.png for every view of camera K in frame FFF
/// (whole boards: no view is cut) and DIR/truth.json.
pub fn write_rig(args: RigArgs) -> Result<(), CliError> {
    if args.pair_frames == 0 || args.pair_frames > 100 || args.side_frames > 100 {
        return Err(CliError::usage(
            "render",
            "with --rig, --views (frames facing each pair) must be 1 to 100 and --side-frames 0 to 100",
        ));
    }
    let config = RigSceneConfig {
        pair_frames: args.pair_frames,
        side_frames: args.side_frames,
        noise_px: 0.0,
        partial_fraction: 0.0,
        timing_ms: 0.0,
    };
    let scene = rig_scene(&config, args.seed);
    let target = rig_target();
    let mut cameras = Vec::with_capacity(scene.names.len());
    let mut count = 0;
    for (k, name) in scene.names.iter().enumerate() {
        let dir = args.out.join(name);
        std::fs::create_dir_all(&dir)
            .map_err(|e| CliError::Io(format!("cannot create '{}': {e}", dir.display())))?;
        let mut images = Vec::new();
        for (frame, _) in &scene.views[k] {
            let pose = scene.camera_from_rig[k] * scene.rig_from_target[*frame];
            let options = RenderOptions {
                seed: args
                    .seed
                    .wrapping_mul(1000)
                    .wrapping_add((k * 1000 + frame) as u64),
                ..args.render.clone()
            };
            let rendered = render(&scene.cameras[k], &target, &pose, &options)?;
            let file = format!("{name}_{frame:03}.png");
            super::render::write_png(&dir.join(&file), &rendered.image)?;
            images.push(serde_json::json!({ "image": format!("{name}/{file}"), "frame": scene.frame_keys[*frame] }));
            count += 1;
        }
        cameras.push(serde_json::json!({
            "name": name,
            "camera": scene.cameras[k],
            "camera_from_rig": transform_json(&scene.camera_from_rig[k]),
            "images": images,
        }));
    }
    let frames: Vec<serde_json::Value> = scene
        .frame_keys
        .iter()
        .zip(&scene.rig_from_target)
        .map(|(key, pose)| serde_json::json!({ "key": key, "rig_from_target": transform_json(pose) }))
        .collect();
    let truth = serde_json::json!({
        "target": target.to_spec(),
        "seed": args.seed,
        "rig_frame": scene.names[0],
        "cameras": cameras,
        "frames": frames,
    });
    super::render::write_json(&args.out.join("truth.json"), &truth)?;
    eprintln!(
        "robocal render: wrote {count} images of a {}-camera rig ({} frames) and truth.json to {}",
        scene.names.len(),
        scene.frame_keys.len(),
        args.out.display()
    );
    Ok(())
}
