//! Helpers shared by the integration tests (`mod support;` in each file
//! that needs them): running the real `robocal` binary, scratch folders,
//! and locating the public datasets.

#![allow(dead_code)] // each test crate uses a different subset

pub mod catalogue;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Run the `robocal` binary built for this test run: (exit code, stdout, stderr).
pub fn robocal(args: &[&str]) -> (i32, String, String) {
    robocal_in(Path::new("."), args)
}

/// [`robocal`] with `dir` as the working folder.
pub fn robocal_in(dir: &Path, args: &[impl AsRef<std::ffi::OsStr>]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run robocal");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh scratch folder `robocal-<suite>-<name>-<pid>` in the temp dir.
pub fn temp_dir(suite: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("robocal-{suite}-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// `<datasets>/<rel>` when it exists, where `<datasets>` is, in turn,
/// `$ROBOCAL_DATASETS`, `../shared/datasets` beside the crate root (the
/// CI layout) or `/work/shared/datasets` (the build machine, for git
/// worktrees elsewhere). `None` (the caller skips with a message) when
/// absent, as in a user's clone.
pub fn dataset(rel: &str) -> Option<PathBuf> {
    let mut roots: Vec<PathBuf> = std::env::var_os("ROBOCAL_DATASETS")
        .map(PathBuf::from)
        .into_iter()
        .collect();
    roots.push(PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/datasets"
    )));
    roots.push(PathBuf::from("/work/shared/datasets"));
    roots.into_iter().map(|r| r.join(rel)).find(|p| p.exists())
}

/// Every `step`-th frame of `video` from frame `first`, `count` of them,
/// as PNGs `<prefix>_NNN.png` in `dir` (sorted paths); `None` when ffmpeg
/// cannot run (the caller skips with a message).
pub fn video_frames(
    video: &Path,
    dir: &Path,
    prefix: &str,
    first: usize,
    step: usize,
    count: usize,
) -> Option<Vec<PathBuf>> {
    let pattern = dir.join(format!("{prefix}_%03d.png"));
    let status = Command::new("ffmpeg")
        .args(["-v", "error", "-y", "-i"])
        .arg(video)
        .args([
            "-vf",
            &format!("select=gte(n\\,{first})*not(mod(n\\,{step}))"),
            "-vsync",
            "0",
            "-frames:v",
        ])
        .arg(count.to_string())
        .arg(&pattern)
        .status()
        .ok()?;
    if !status.success() {
        return None;
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(&format!("{prefix}_")))
        })
        .collect();
    files.sort();
    Some(files)
}

/// ChArUco board of caliscope's four-webcam session
/// (`caliscope-4cam-charuco-video`, SOURCE.md), printed light on dark.
pub const CALISCOPE_TARGET: &str = "charuco:4x5:54mm:40.5mm:DICT_4X4_1000";

/// Frames extracted from each caliscope camera by [`caliscope_frames`].
pub const CALISCOPE_FRAMES: usize = 30;

/// Every third frame of caliscope's `cam_<camera>.mp4` from frame 21 (the
/// board comes into view near frame 63 of 111), [`CALISCOPE_FRAMES`] of
/// them, as PNGs `cam<camera>_NNN.png` in `dir`; `None`, with the reason
/// printed for the caller to skip, when the dataset or ffmpeg is absent.
pub fn caliscope_frames(dir: &Path, camera: usize) -> Option<Vec<PathBuf>> {
    let Some(videos) = dataset("caliscope-4cam-charuco-video/video") else {
        eprintln!("skipped: dataset caliscope-4cam-charuco-video not found (../shared/datasets or ROBOCAL_DATASETS)");
        return None;
    };
    let video = videos.join(format!("cam_{camera}.mp4"));
    let files = video_frames(
        &video,
        dir,
        &format!("cam{camera}"),
        21,
        3,
        CALISCOPE_FRAMES,
    );
    if files.is_none() {
        eprintln!(
            "skipped: ffmpeg could not extract frames from {}",
            video.display()
        );
    }
    files
}
