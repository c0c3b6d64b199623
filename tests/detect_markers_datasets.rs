//! Marker boards on public frames (../shared/datasets or ROBOCAL_DATASETS;
//! skipped with a message when absent):
//! - aprilgrid-detection-samples: the tag counts its SOURCE.md states
//!   (EuRoC 36, TUM VI 36, iphone 66, two_boards 72 over two boards);
//! - moveit-handeye-pose-samples: MoveIt's ChArUco test image (5 x 7
//!   squares, DICT_5X5_250) detected with every marker's corners.

use robocal::detect::{detect_all, DetectOptions};
use robocal::target::{Detection, Target};
use std::collections::BTreeSet;
use std::path::PathBuf;

fn dataset(name: &str) -> Option<PathBuf> {
    let root = std::env::var("ROBOCAL_DATASETS")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/datasets"));
    let dir = root.join(name);
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("skipped: dataset {} not found", dir.display());
        None
    }
}

fn gray(path: &PathBuf) -> robocal::image::GrayImage {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    robocal::image::decode_gray(&bytes).unwrap()
}

/// Tags with at least one corner in an AprilGrid detection (Kalibr ids:
/// point `r * 2 cols + c` is on tag `(r / 2) cols + c / 2`).
fn tags(d: &Detection) -> BTreeSet<usize> {
    let Target::Aprilgrid {
        tag_cols, first_id, ..
    } = d.target
    else {
        panic!("not an AprilGrid");
    };
    d.points
        .iter()
        .map(|p| first_id + (p.id / (2 * tag_cols) / 2) * tag_cols + (p.id % (2 * tag_cols)) / 2)
        .collect()
}

#[test]
fn aprilgrid_samples_give_the_stated_tag_counts() {
    let Some(dir) = dataset("aprilgrid-detection-samples") else {
        return;
    };
    // Board sizes: EuRoC and TUM VI from SOURCE.md (6 x 6, 0.3); the phone
    // frames' boards counted on the images (11 x 6 tags; two 6 x 6 boards
    // with tags 0-35 and 36-71), their tag sizes irrelevant to the counts.
    for (file, spec, boards, count) in [
        ("EuRoC.png", "aprilgrid:6x6:88mm:0.3", 1, 36),
        ("TUM_VI.png", "aprilgrid:6x6:88mm:0.3", 1, 36),
        ("iphone.png", "aprilgrid:11x6:88mm:0.3", 1, 66),
        ("two_boards.png", "aprilgrid:6x6:88mm:0.3", 2, 72),
    ] {
        let img = gray(&dir.join(file));
        let t = Target::parse_spec(spec).unwrap();
        let found = detect_all(&img, &t, &DetectOptions::default())
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        let all: BTreeSet<usize> = found.iter().flat_map(tags).collect();
        let corners: usize = found.iter().map(|d| d.points.len()).sum();
        println!(
            "{file}: {} board(s), {} tags, {corners} corners",
            found.len(),
            all.len()
        );
        assert_eq!(found.len(), boards, "{file}: boards");
        assert_eq!(all.len(), count, "{file}: tags");
    }
}

#[test]
fn moveit_charuco_image_is_detected() {
    let Some(dir) = dataset("moveit-handeye-pose-samples") else {
        return;
    };
    let img = gray(&dir.join("test_charuco_board_detection.jpg"));
    // SOURCE.md: 5 x 7 squares, DICT_5X5_250, generator marker 50 px,
    // square 80 px; longest board side 0.1971 m -> square 0.1971 / 7 m.
    let square = 0.1971 / 7.0;
    let t = Target::Charuco {
        squares_x: 5,
        squares_y: 7,
        square_m: square,
        marker_m: square * 50.0 / 80.0,
        dictionary: robocal::target::Dictionary::DICT_5X5_250,
        first_id: 0,
        marker_ids: None,
        legacy: false,
    };
    let found = detect_all(&img, &t, &DetectOptions::default()).unwrap();
    println!(
        "moveit: {} corners of {}",
        found[0].points.len(),
        t.point_count()
    );
    assert_eq!(found.len(), 1);
    assert!(
        found[0].points.len() >= 20,
        "corners {}",
        found[0].points.len()
    );
}
