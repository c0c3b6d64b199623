//! The capture guide over `robocal render --video`'s frames, natively, as
//! the page runs it: each frame through `CaptureSession::push_image` (the
//! rendered grey through the video's luma round trip), the running
//! calibration after every capture from the 4th, and the video played
//! `--loops` times (Chromium's fake camera loops the file). Prints each
//! capture with the worst projection uncertainty after it.
//!
//! `--extra DIR`: the PNGs of DIR (e.g. `robocal render --out DIR --views
//! N --camera` the video's camera) appended to the video as holds of one
//! second each, as tests/e2e/capture.mjs appends them.
//!
//!     cargo run --release --example live_guide -- [--fps 5] [--seed 11] [--loops 2] [--extra DIR]

use robocal::capture::{CaptureConfig, CaptureSession};
use robocal::image::GrayImage;
use robocal::synth::{video_camera, BoardVideo, RenderOptions, VideoOptions};
use robocal::target::Target;

fn arg(name: &str, default: f64) -> f64 {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (fps, seed, loops) = (
        arg("--fps", 5.0),
        arg("--seed", 11.0) as u64,
        arg("--loops", 2.0) as usize,
    );
    let target = Target::parse_spec("chessboard:9x6:30mm")?;
    let camera = video_camera(640, 480);
    let options = VideoOptions {
        fps,
        seed,
        ..VideoOptions::default()
    };
    let video = BoardVideo::new(&camera, &target, &options)?;
    let frames: Vec<GrayImage> = (0..video.frames.len())
        .map(|i| {
            let r = video.render_frame(i, &RenderOptions::default())?;
            // Grey -> video-range luma -> grey, as the page reads the fake camera.
            let px = r.image.pixels.iter().map(|g| {
                let y = (16.0 + *g as f64 * 219.0 / 255.0).round();
                ((y - 16.0) * 255.0 / 219.0).round().clamp(0.0, 255.0) as u8
            });
            GrayImage::new(640, 480, px.collect())
        })
        .collect::<Result<_, _>>()?;
    let mut frames = frames;
    let mut times: Vec<f64> = video.frames.iter().map(|f| f.time_ms).collect();
    let mut holds: Vec<Option<usize>> = video.frames.iter().map(|f| f.hold).collect();
    let args: Vec<String> = std::env::args().collect();
    if let Some(dir) = args
        .iter()
        .position(|a| a == "--extra")
        .and_then(|i| args.get(i + 1))
    {
        let mut pngs: Vec<_> = std::fs::read_dir(dir)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "png"))
            .collect();
        pngs.sort();
        for (k, png) in pngs.iter().enumerate() {
            let img = robocal::image::decode_gray(&std::fs::read(png)?)?;
            for _ in 0..fps as usize {
                times.push(times.last().unwrap() + 1000.0 / fps);
                holds.push(Some(video.holds.len() + k));
                frames.push(img.clone());
            }
        }
    }
    let mut s = CaptureSession::new(target, 640, 480, CaptureConfig::default())?;
    let period = frames.len() as f64 * 1000.0 / fps;
    for l in 0..loops {
        for ((time_ms, hold), img) in times.iter().zip(&holds).zip(&frames) {
            let r = s.push_image(img, l as f64 * period + time_ms + 1.0)?;
            if r.keep {
                let worst = if s.used() >= 4 {
                    format!("{:.3}", s.calibrate()?.projection_uncertainty.max_std_px)
                } else {
                    "-".into()
                };
                let n = r.novelty.as_ref().unwrap();
                println!(
                    "loop {l} hold {:?} capture {}: cells {} tilt {} dist {} predicted {:?} -> worst {worst} px good enough {}",
                    hold, r.kept, n.new_cells, n.new_tilt, n.new_distance, n.predicted_max_std_px, s.good_enough()
                );
            }
        }
    }
    Ok(())
}
