//! `robocal render --video board.y4m`: the board-moving video of
//! [`robocal::synth::video`] as a Y4M file (4:2:0, 8-bit, written with the
//! `y4m` crate) that Chromium's fake camera plays, and its truth as JSON.

use super::output::AtomicFile;
use super::CliError;
use robocal::camera::Camera;
use robocal::synth::{BoardVideo, RenderOptions, VideoOptions};
use robocal::target::{DetectedPoint, Target};
use std::path::{Path, PathBuf};

/// What `render --video` needs beyond the shared render options.
pub struct VideoArgs<'a> {
    pub video: &'a str,
    pub truth: Option<&'a str>,
    pub size: &'a str,
    pub fps: f64,
    pub camera: Option<Camera>,
    pub target: Target,
    pub seed: u64,
    pub render: RenderOptions,
}

/// Grey level (0..255, full range) to Y4M luma (video range 16..235), so a
/// player converting with BT.601 limited range shows the rendered grey.
pub fn luma_from_grey(g: u8) -> u8 {
    (16.0 + g as f64 * 219.0 / 255.0).round() as u8
}

/// `WxH` with both sides even (4:2:0 chroma) and at most 3840x2160.
pub fn parse_size(text: &str) -> Result<(u32, u32), CliError> {
    let bad = || {
        CliError::usage(
            "render",
            format!("--size expects WIDTHxHEIGHT with even sides up to 3840x2160 (e.g. 640x480 or 1280x720), got '{text}'"),
        )
    };
    let [w, h]: [u32; 2] = super::values::by_pair(text, false).ok_or_else(bad)?;
    if w < 64 || h < 48 || w > 3840 || h > 2160 || w % 2 != 0 || h % 2 != 0 {
        return Err(bad());
    }
    Ok((w, h))
}

/// The truth file beside the video: `board.y4m` -> `board.json`.
pub fn truth_path(video: &str, truth: Option<&str>) -> PathBuf {
    truth.map_or_else(|| Path::new(video).with_extension("json"), PathBuf::from)
}

pub fn write_video(a: VideoArgs) -> Result<(), CliError> {
    let (w, h) = parse_size(a.size)?;
    if !(a.fps.is_finite() && (1.0..=120.0).contains(&a.fps)) {
        return Err(CliError::usage(
            "render",
            format!(
                "--fps must be between 1 and 120, got {}",
                robocal::error::compact(a.fps)
            ),
        ));
    }
    let camera = match a.camera {
        Some(c) if (c.width, c.height) != (w, h) => {
            return Err(CliError::usage(
                "render",
                format!(
                    "the camera file is {}x{} but --size asks for {w}x{h}: give the camera's size",
                    c.width, c.height
                ),
            ))
        }
        Some(c) => c,
        None => robocal::synth::video_camera(w, h),
    };
    let options = VideoOptions {
        fps: a.fps,
        seed: a.seed,
        ..VideoOptions::default()
    };
    let video = BoardVideo::new(&camera, &a.target, &options)?;
    let mut file = AtomicFile::create(Path::new(a.video))?;
    let written = encode(&mut file, &video, &a.render, (w, h), a.fps);
    let points = match written {
        Ok(points) => {
            file.finish(Ok(()))?;
            points
        }
        Err(Encode::Io(e)) => return file.finish(Err(e)),
        Err(Encode::Robocal(e)) => return Err(e.into()),
    };
    let mut truth = serde_json::to_value(&video).map_err(|e| CliError::Io(e.to_string()))?;
    truth["video"] = Path::new(a.video)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .into();
    truth["size_px"] = serde_json::json!([w, h]);
    for (frame, pts) in truth["frames"]
        .as_array_mut()
        .into_iter()
        .flatten()
        .zip(points)
    {
        frame["points"] = serde_json::to_value(pts).map_err(|e| CliError::Io(e.to_string()))?;
    }
    let path = truth_path(a.video, a.truth);
    let text = serde_json::to_string_pretty(&truth).map_err(|e| CliError::Io(e.to_string()))?;
    super::output::write_file(&path, (text + "\n").as_bytes())?;
    eprintln!(
        "robocal render: wrote {} frames ({w}x{h}, {} fps, {} holds) to {} and the truth to {}",
        video.frames.len(),
        a.fps,
        video.holds.len(),
        a.video,
        path.display()
    );
    Ok(())
}

/// Why encoding the video stopped.
enum Encode {
    Io(std::io::Error),
    Robocal(robocal::Error),
}

/// Encode every frame of `video` into `out`; the rendered points of each.
fn encode(
    out: &mut AtomicFile,
    video: &BoardVideo,
    render: &RenderOptions,
    (w, h): (u32, u32),
    fps: f64,
) -> Result<Vec<Vec<DetectedPoint>>, Encode> {
    let io = |e: y4m::Error| match e {
        y4m::Error::IoError(e) => Encode::Io(e),
        other => Encode::Io(std::io::Error::other(format!("{other:?}"))),
    };
    // Integer frame rates exactly; others as a ratio over 1000.
    let rate = if fps.fract() == 0.0 {
        y4m::Ratio::new(fps as usize, 1)
    } else {
        y4m::Ratio::new((fps * 1000.0).round() as usize, 1000)
    };
    let mut encoder = y4m::encode(w as usize, h as usize, rate)
        .with_colorspace(y4m::Colorspace::C420)
        .write_header(out)
        .map_err(io)?;
    let chroma = vec![128u8; w.div_ceil(2) as usize * h.div_ceil(2) as usize];
    let mut points = Vec::with_capacity(video.frames.len());
    for i in 0..video.frames.len() {
        let rendered = video.render_frame(i, render).map_err(Encode::Robocal)?;
        let luma: Vec<u8> = rendered
            .image
            .pixels
            .iter()
            .map(|g| luma_from_grey(*g))
            .collect();
        encoder
            .write_frame(&y4m::Frame::new([&luma, &chroma, &chroma], None))
            .map_err(io)?;
        points.push(rendered.points);
    }
    Ok(points)
}
