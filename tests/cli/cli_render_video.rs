//! `robocal render --video`: a Y4M file Chromium's fake camera can play
//! (header, 4:2:0 planes, frame count) whose frames show the board where the
//! truth file says. Tolerances: the frames are renders with grey noise
//! sigma 2, blur 0.7 px and vignetting, like `robocal render`'s images,
//! whose corners the detector finds within 0.2 px (tests/cli/cli_render.rs);
//! the luma mapping (16 + 219 g / 255) only scales the contrast.

use robocal::image::GrayImage;
use robocal::target::Target;
use std::process::Command;

fn robocal(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(args)
        .output()
        .unwrap()
}

/// Every frame's luma plane back to full-range grey.
fn read_y4m(path: &std::path::Path) -> (usize, usize, String, Vec<GrayImage>) {
    let file = std::fs::File::open(path).unwrap();
    let mut decoder = y4m::decode(std::io::BufReader::new(file)).unwrap();
    let (w, h) = (decoder.get_width(), decoder.get_height());
    let rate = decoder.get_framerate();
    let rate = format!("{}:{}", rate.num, rate.den);
    assert!(matches!(decoder.get_colorspace(), y4m::Colorspace::C420));
    let mut frames = vec![];
    while let Ok(frame) = decoder.read_frame() {
        assert_eq!(frame.get_u_plane().len(), (w / 2) * (h / 2));
        assert!(frame.get_u_plane().iter().all(|c| *c == 128), "grey chroma");
        let grey = frame
            .get_y_plane()
            .iter()
            .map(|y| {
                ((*y as f64 - 16.0) * 255.0 / 219.0)
                    .round()
                    .clamp(0.0, 255.0) as u8
            })
            .collect();
        frames.push(GrayImage::new(w as u32, h as u32, grey).unwrap());
    }
    (w, h, rate, frames)
}

fn render_video(dir: &std::path::Path, name: &str, extra: &[&str]) -> serde_json::Value {
    let video = dir.join(name);
    let mut args = vec!["render", "--video", video.to_str().unwrap()];
    args.extend_from_slice(extra);
    let out = robocal(&args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let truth = std::fs::read_to_string(video.with_extension("json")).unwrap();
    serde_json::from_str(&truth).unwrap()
}

/// Largest and mean distance (px) between detected points and the truth.
fn compare(found: &robocal::target::Detection, exact: &serde_json::Value) -> (f64, f64) {
    let exact = exact.as_array().unwrap();
    assert_eq!(found.points.len(), exact.len(), "every point found");
    let mut worst: f64 = 0.0;
    let mut sum = 0.0;
    for (p, q) in found.points.iter().zip(exact) {
        assert_eq!(p.id as u64, q["id"].as_u64().unwrap());
        let e = (p.x_px - q["x_px"].as_f64().unwrap()).hypot(p.y_px - q["y_px"].as_f64().unwrap());
        worst = worst.max(e);
        sum += e;
    }
    (worst, sum / exact.len() as f64)
}

#[test]
fn a_chessboard_video_plays_the_truth_frame_by_frame() {
    let dir = std::env::temp_dir().join(format!("robocal-video-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let truth = render_video(&dir, "board.y4m", &["--fps", "2", "--seed", "3"]);
    let (w, h, rate, frames) = read_y4m(&dir.join("board.y4m"));
    assert_eq!((w, h, rate.as_str()), (640, 480, "2:1"));
    let truth_frames = truth["frames"].as_array().unwrap();
    assert_eq!(frames.len(), truth_frames.len(), "one truth per frame");
    // 2 fps: a 2-frame lead-in, 12 holds of 2 frames, 11 moves of 2 frames.
    assert_eq!(frames.len(), 2 + 12 * 2 + 11 * 2);
    let holds = truth["holds"].as_array().unwrap();
    assert_eq!(holds.len(), 12);
    assert_eq!(truth["frames"][1]["time_ms"].as_f64(), Some(500.0));
    let target = Target::parse_spec("chessboard:9x6:30mm").unwrap();
    // The lead-in starts with the board out of view.
    assert_eq!(truth_frames[0]["points"].as_array().unwrap().len(), 0);
    assert!(robocal::detect::detect(&frames[0], &target, &Default::default()).is_err());
    for (k, hold) in holds.iter().enumerate() {
        let first = hold["first_frame"].as_u64().unwrap() as usize;
        let last = hold["last_frame"].as_u64().unwrap() as usize;
        assert_eq!(last, first + 1);
        for frame in &truth_frames[first..=last] {
            assert_eq!(frame["hold"].as_u64(), Some(k as u64));
            assert_eq!(frame["camera_from_target"], hold["camera_from_target"]);
        }
        assert!(truth_frames[last + 1..]
            .first()
            .is_none_or(|f| f["hold"].as_u64() != Some(k as u64)));
        let found = robocal::detect::detect(&frames[first], &target, &Default::default())
            .unwrap_or_else(|e| panic!("hold {k}: {e}"));
        let (worst, mean) = compare(&found, &truth_frames[first]["points"]);
        assert!(worst < 0.2, "hold {k}: a corner off by {worst} px");
        assert!(mean < 0.06, "hold {k}: mean corner error {mean} px");
    }
    // Same seed, same bytes.
    render_video(&dir, "again.y4m", &["--fps", "2", "--seed", "3"]);
    assert!(
        std::fs::read(dir.join("board.y4m")).unwrap()
            == std::fs::read(dir.join("again.y4m")).unwrap()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_charuco_video_at_720p_shows_its_corners_where_the_truth_says() {
    let dir = std::env::temp_dir().join(format!("robocal-video-charuco-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = "charuco:8x6:30mm:22mm:DICT_4X4_50";
    let truth = render_video(
        &dir,
        "charuco.y4m",
        &["--fps", "1", "--size", "1280x720", "--target", spec],
    );
    let (w, h, _, frames) = read_y4m(&dir.join("charuco.y4m"));
    assert_eq!((w, h), (1280, 720));
    let target = Target::parse_spec(spec).unwrap();
    for hold in truth["holds"].as_array().unwrap().iter().step_by(3) {
        let i = hold["first_frame"].as_u64().unwrap() as usize;
        let found = robocal::detect::detect(&frames[i], &target, &Default::default()).unwrap();
        let (worst, _) = compare(&found, &truth["frames"][i]["points"]);
        assert!(worst < 0.2, "frame {i}: a corner off by {worst} px");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_video_sizes_and_rates_are_usage_errors() {
    let out = robocal(&["render", "--video", "/tmp/x.y4m", "--size", "641x480"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).trim(),
        "robocal: render: --size expects WIDTHxHEIGHT with even sides up to 3840x2160 (e.g. 640x480 or 1280x720), got '641x480' (see 'robocal render --help')"
    );
    let out = robocal(&["render", "--video", "/tmp/x.y4m", "--fps", "0"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).trim(),
        "robocal: render: --fps must be between 1 and 120, got 0 (see 'robocal render --help')"
    );
}
