//! Reading a video file's frames through `ffmpeg` (issue 36, recordings).
//!
//! Only the CLI spawns processes: the library sees grey frames
//! ([`GrayImage`]) and never a file or a codec.
//!
//! 1. `ffprobe` gives the first video stream's size, codec and frame rate;
//! 2. `ffmpeg -i FILE -map 0:v:0 -f rawvideo -pix_fmt gray -` writes every
//!    frame as `width * height` grey bytes to a pipe, in decoding order
//!    (rawvideo keeps every frame: no frame is dropped or repeated);
//! 3. frames are read one after the other; the caller may stop early, then
//!    ffmpeg is ended.
//!
//! When ffmpeg or ffprobe is not on the PATH the error names the file and
//! says to install ffmpeg or to extract the frames as images.

use super::CliError;
use robocal::image::GrayImage;
use std::io::Read;
use std::process::{Child, ChildStdout, Command, Stdio};

/// File name endings read as videos (case-insensitive).
pub const VIDEO_EXTENSIONS: [&str; 6] = ["mp4", "m4v", "mov", "avi", "mkv", "webm"];

/// Whether `path` names a video by its extension.
pub fn is_video(path: &str) -> bool {
    let base = path.rsplit(['/', '\\']).next().unwrap_or(path);
    base.rsplit_once('.')
        .is_some_and(|(_, ext)| VIDEO_EXTENSIONS.iter().any(|v| v.eq_ignore_ascii_case(ext)))
}

/// The first video stream of a file, as ffprobe describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct VideoInfo {
    pub width: u32,
    pub height: u32,
    /// ffmpeg's codec name (`mpeg4`, `h264`, `vp9`, ...).
    pub codec: String,
    /// Frames per second (the stream's average rate; 0 when unknown).
    pub fps: f64,
}

/// The error of a missing ffmpeg or ffprobe.
fn not_installed(path: &str, program: &str) -> CliError {
    CliError::Io(format!(
        "'{path}' is a video: reading it needs ffmpeg ('{program}' is not on the PATH). \
         Install ffmpeg (apt install ffmpeg, brew install ffmpeg, or https://ffmpeg.org), \
         or extract its frames as images and give those: \
         ffmpeg -i '{path}' frame_%04d.png"
    ))
}

/// The failure of a video given to a command that takes images only.
pub fn not_read_here(path: &str) -> String {
    format!(
        "'{path}' is a video: this command takes images; detect, intrinsics and rig read videos \
         (docs/video.md; two cameras' videos make a rig: robocal rig --camera left left.mp4 \
         --camera right right.mp4), or extract frames: ffmpeg -i '{path}' frame_%04d.png"
    )
}

/// Spawn `program` with `args`, its missing executable named as such.
fn spawn(path: &str, program: &str, args: &[&str], stdout: Stdio) -> Result<Child, CliError> {
    Command::new(program)
        .args(args)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => not_installed(path, program),
            _ => CliError::Io(format!("cannot run {program} for '{path}': {e}")),
        })
}

/// The last lines of a tool's error output, for a message.
fn tail(stderr: &[u8]) -> String {
    let text = String::from_utf8_lossy(stderr);
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    lines[lines.len().saturating_sub(3)..].join(" / ")
}

/// A frame rate `30000/1001` or `25`.
fn rate(text: &str) -> f64 {
    let value = match text.split_once('/') {
        Some((n, d)) => match (n.trim().parse::<f64>(), d.trim().parse::<f64>()) {
            (Ok(n), Ok(d)) if d > 0.0 => n / d,
            _ => 0.0,
        },
        None => text.trim().parse().unwrap_or(0.0),
    };
    if value.is_finite() && value > 0.0 {
        value
    } else {
        0.0
    }
}

/// The size, codec and frame rate of `path`'s first video stream.
pub fn probe(path: &str) -> Result<VideoInfo, CliError> {
    if !std::path::Path::new(path).is_file() {
        return Err(CliError::Io(format!("cannot read '{path}': no such file")));
    }
    let args = [
        "-v",
        "error",
        "-select_streams",
        "v:0",
        "-show_entries",
        "stream=width,height,codec_name,avg_frame_rate,r_frame_rate",
        "-of",
        "default=noprint_wrappers=1",
        "--",
        path,
    ];
    let out = spawn(path, "ffprobe", &args, Stdio::piped())?
        .wait_with_output()
        .map_err(|e| CliError::Io(format!("cannot run ffprobe for '{path}': {e}")))?;
    let text = String::from_utf8_lossy(&out.stdout);
    let field = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(key).and_then(|r| r.strip_prefix('=')))
            .map(str::trim)
    };
    let size = field("width")
        .and_then(|w| w.parse::<u32>().ok())
        .zip(field("height").and_then(|h| h.parse::<u32>().ok()))
        .filter(|&(w, h)| w > 0 && h > 0);
    let Some((width, height)) = size else {
        let why = if out.status.success() {
            "no video stream".to_string()
        } else {
            tail(&out.stderr)
        };
        return Err(CliError::Io(format!(
            "cannot read '{path}' as a video: {why}"
        )));
    };
    let fps = [field("avg_frame_rate"), field("r_frame_rate")]
        .into_iter()
        .flatten()
        .map(rate)
        .find(|r| *r > 0.0)
        .unwrap_or(0.0);
    Ok(VideoInfo {
        width,
        height,
        codec: field("codec_name").unwrap_or("unknown").to_string(),
        fps,
    })
}

/// The frames of one video, read on demand from ffmpeg's pipe.
pub struct FrameReader {
    path: String,
    info: VideoInfo,
    child: Child,
    stdout: ChildStdout,
    stderr: Option<std::thread::JoinHandle<Vec<u8>>>,
    next: usize,
    done: bool,
}

impl FrameReader {
    /// Probe `path` and start decoding it.
    pub fn open(path: &str) -> Result<FrameReader, CliError> {
        let info = probe(path)?;
        let args = [
            "-v", "error", "-nostdin", "-i", path, "-map", "0:v:0", "-f", "rawvideo", "-pix_fmt",
            "gray", "-",
        ];
        let mut child = spawn(path, "ffmpeg", &args, Stdio::piped())?;
        let (Some(stdout), Some(mut err)) = (child.stdout.take(), child.stderr.take()) else {
            let _ = child.kill();
            let _ = child.wait();
            return Err(CliError::Io(format!(
                "cannot run ffmpeg for '{path}': no pipe"
            )));
        };
        // Drained on its own thread, so a chatty ffmpeg never blocks on it.
        let stderr = std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = (&mut err).take(64 << 10).read_to_end(&mut bytes);
            bytes
        });
        Ok(FrameReader {
            path: path.to_string(),
            info,
            child,
            stdout,
            stderr: Some(stderr),
            next: 0,
            done: false,
        })
    }

    /// The video's size, codec and rate.
    pub fn info(&self) -> &VideoInfo {
        &self.info
    }

    /// The next frame and its index, `None` after the last one. A frame cut
    /// short, or ffmpeg failing, is an error naming the file.
    pub fn next_frame(&mut self) -> Result<Option<(usize, GrayImage)>, CliError> {
        if self.done {
            return Ok(None);
        }
        let len = self.info.width as usize * self.info.height as usize;
        let mut pixels = vec![0u8; len];
        let mut filled = 0;
        while filled < len {
            match self.stdout.read(&mut pixels[filled..]) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => {
                    return Err(CliError::Io(format!(
                        "cannot read '{}' through ffmpeg: {e}",
                        self.path
                    )))
                }
            }
        }
        if filled < len {
            self.done = true;
            let status = self.child.wait();
            let stderr = self
                .stderr
                .take()
                .and_then(|h| h.join().ok())
                .unwrap_or_default();
            let failed = !status.as_ref().is_ok_and(|s| s.success());
            if failed || filled > 0 || self.next == 0 {
                let why = match (filled, tail(&stderr)) {
                    (f, t) if f > 0 && t.is_empty() => format!("frame {} is cut short", self.next),
                    (_, t) if t.is_empty() => "ffmpeg decoded no frame".to_string(),
                    (_, t) => t,
                };
                return Err(CliError::Io(format!(
                    "cannot read '{}' through ffmpeg (codec {}): {why}",
                    self.path, self.info.codec
                )));
            }
            return Ok(None);
        }
        let index = self.next;
        self.next += 1;
        let image = GrayImage {
            width: self.info.width,
            height: self.info.height,
            pixels,
        };
        Ok(Some((index, image)))
    }
}

impl Drop for FrameReader {
    /// Stopping early ends ffmpeg rather than leaving it blocked on the pipe.
    fn drop(&mut self) {
        if !self.done {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
        if let Some(h) = self.stderr.take() {
            let _ = h.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn videos_are_known_by_their_extension() {
        for p in [
            "cam_0.mp4",
            "a/b.MOV",
            "x.webm",
            "c:\\v\\y.Mkv",
            "z.avi",
            "q.m4v",
        ] {
            assert!(is_video(p), "{p}");
        }
        for p in ["cam_0.png", "mp4", "a.mp4/b.jpg", "noext", "x.mp4.png"] {
            assert!(!is_video(p), "{p}");
        }
    }

    #[test]
    fn frame_rates_read_as_ffprobe_writes_them() {
        assert_eq!(rate("6/1"), 6.0);
        assert!((rate("30000/1001") - 29.97).abs() < 0.01);
        assert_eq!(rate("0/0"), 0.0);
        assert_eq!(rate("25"), 25.0);
        assert_eq!(rate("n/a"), 0.0);
    }
}
