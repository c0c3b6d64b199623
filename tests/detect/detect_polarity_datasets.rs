//! A real light-on-dark board (issue 36): caliscope's four-webcam session
//! (../shared/datasets/caliscope-4cam-charuco-video, SOURCE.md), an
//! inverted ChArUco `charuco:4x5:54mm:40.5mm:DICT_4X4_1000` filmed as mp4v
//! video. Every third frame of each camera from frame 21 (30 per camera) is extracted
//! with ffmpeg into a scratch folder and detected without a print option.
//! Skipped with a message when the dataset or ffmpeg is absent.
//!
//! Bounds: before issue 36 robocal found the board in none of these frames.
//! Measured on 2026-12-06 (benches/inverted_charuco.sh, BENCHMARKS.md
//! "Inverted boards"): frames with a board 16 / 26 / 15 / 14 and corners
//! 181 / 130 / 139 / 93 for cameras 0-3 (OpenCV 4.14's CharucoDetector on
//! the inverted frames: 15 / 23 / 14 / 15 frames, 180 / 121 / 166 / 170
//! corners; robocal's marker finder misses markers of about 25 px on the
//! small, blurred views of cameras 2 and 3, the same on frames inverted by
//! hand). The asserts keep one frame and 5% of the corners of margin for
//! other ffmpeg builds' decoding; every corner id is one of the 3 x 4
//! inner corners and every detection says light_on_dark.

use crate::support;

use robocal::detect::{detect, DetectOptions};
use robocal::error::Error;
use robocal::target::{Polarity, Target};
use std::path::PathBuf;

const SPEC: &str = support::CALISCOPE_TARGET;

#[test]
fn caliscope_inverted_charuco_frames_are_found_without_an_option() {
    let dir = support::temp_dir("polarity", "caliscope");
    let target = Target::parse_spec(SPEC).unwrap();
    let forced_dark = DetectOptions {
        polarity: Some(Polarity::DarkOnLight),
        ..DetectOptions::default()
    };
    // Measured (module docs): frames with a board, corners.
    let measured = [(16, 181), (26, 130), (15, 139), (14, 93)];
    for (camera, &(frames, points)) in measured.iter().enumerate() {
        let Some(files) = support::caliscope_frames(&dir, camera) else {
            return;
        };
        assert_eq!(
            files.len(),
            support::CALISCOPE_FRAMES,
            "camera {camera}: frames extracted"
        );
        let (mut found, mut full, mut corners) = (0, 0, 0);
        for file in &files {
            let image = robocal::image::decode_gray(&std::fs::read(file).unwrap()).unwrap();
            let Ok(det) = detect(&image, &target, &DetectOptions::default()) else {
                continue;
            };
            assert_eq!(
                det.polarity,
                Some(Polarity::LightOnDark),
                "{}",
                file.display()
            );
            assert!(det.points.iter().all(|p| p.id < 12), "{}", file.display());
            found += 1;
            full += usize::from(det.points.len() == 12);
            corners += det.points.len();
            // Forcing the usual print misses it and names the option.
            let e = detect(&image, &target, &forced_dark).unwrap_err();
            assert!(matches!(e, Error::NotFound { .. }), "{e}");
            assert!(
                e.to_string().contains("printed light-on-dark the board is in view: the target spec forces ':dark-on-light'"),
                "{}: {e}",
                file.display()
            );
        }
        eprintln!(
            "camera {camera}: {found} of {} frames found, {full} with all 12 corners, {corners} corners",
            files.len()
        );
        assert!(
            found + 1 >= frames && corners as f64 >= 0.95 * points as f64,
            "camera {camera}: {found} frames with {corners} corners, measured {frames} frames with {points} corners"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn usual_chessboards_stay_dark_on_light_with_their_numbering() {
    // OpenCV's 9x6 sample views (thin white margin, cut by the board's
    // edge, on dark backgrounds) and caliscope's 9x6 chessboard frames: the
    // usual print, numbered from the dark corner square as before issue 36
    // (corner 0 is the one OpenCV numbers 0 or 53: the same end of the
    // board diagonal under the dark-corner rule).
    let mut files: Vec<PathBuf> = Vec::new();
    for dir in [
        "opencv-left-right-9x6",
        "caliscope-4cam-charuco-video/chessboard_intrinsic",
    ] {
        let Some(dir) = support::dataset(dir) else {
            eprintln!("skipped: dataset {dir} not found (../shared/datasets or ROBOCAL_DATASETS)");
            return;
        };
        let mut more: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "jpg"))
            .collect();
        files.append(&mut more);
    }
    let target = Target::parse_spec("chessboard:9x6:30mm").unwrap();
    let mut found = 0;
    for file in &files {
        let image = robocal::image::decode_gray(&std::fs::read(file).unwrap()).unwrap();
        let Ok(det) = detect(&image, &target, &DetectOptions::default()) else {
            continue;
        };
        found += 1;
        assert_eq!(
            det.polarity,
            Some(Polarity::DarkOnLight),
            "{}",
            file.display()
        );
        let forced = DetectOptions {
            polarity: Some(Polarity::DarkOnLight),
            ..DetectOptions::default()
        };
        let same = detect(&image, &target, &forced).unwrap();
        assert_eq!(same.points, det.points, "{}", file.display());
    }
    assert!(
        found >= 30,
        "{found} of {} chessboard views found",
        files.len()
    );
}
