//! Marker boards on public frames (../shared/datasets or ROBOCAL_DATASETS;
//! skipped with a message when absent):
//! - aprilgrid-detection-samples: the tag counts its SOURCE.md states
//!   (EuRoC 36, TUM VI 36, iphone 66, two_boards 72 over two boards);
//! - moveit-handeye-pose-samples: MoveIt's ChArUco test image (5 x 7
//!   squares, DICT_5X5_250) detected with every marker's corners, and the
//!   board pose by PnP from robocal's corners with the stated camera within
//!   MoveIt's published tolerance.

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

/// MoveIt's expected board pose (SOURCE.md: t and Eigen's eulerAngles(0, 1,
/// 2), i.e. R = Rx(a) Ry(b) Rz(c)), compared with the PnP pose of robocal's
/// corners with the stated camera (K and plumb_bob D).
#[test]
fn moveit_charuco_board_pose_within_the_published_tolerance() {
    use nalgebra::{Point2, Point3, Rotation3, Vector3};
    use robocal::calib::pnp::camera_from_target;
    use robocal::calib::View;
    use robocal::camera::{Camera, Distortion};
    let Some(dir) = dataset("moveit-handeye-pose-samples") else {
        return;
    };
    let img = gray(&dir.join("test_charuco_board_detection.jpg"));
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
    let det = &detect_all(&img, &t, &DetectOptions::default()).unwrap()[0];
    let camera = Camera {
        fx: 590.6972346,
        fy: 592.84676713,
        cx: 322.33104773,
        cy: 247.40030325,
        skew: 0.0,
        width: 640,
        height: 480,
        distortion: Distortion::Brown {
            k1: 0.15405498,
            k2: -0.24916842,
            k3: 0.0,
            p1: 0.00350791,
            p2: -0.00110041,
        },
    };
    let objects: std::collections::HashMap<usize, Point3<f64>> =
        t.object_points().into_iter().collect();
    let view = View::new(
        "",
        det.points.iter().map(|p| objects[&p.id]).collect(),
        det.points
            .iter()
            .map(|p| Point2::new(p.x_px, p.y_px))
            .collect(),
    );
    let (camera_from_board, rms) = camera_from_target(&camera, &view).unwrap();
    let expected_t = Vector3::new(0.09752, 0.102848, 0.325596);
    let expected_r = Rotation3::from_axis_angle(&Vector3::x_axis(), 2.88409)
        * Rotation3::from_axis_angle(&Vector3::y_axis(), -0.147996)
        * Rotation3::from_axis_angle(&Vector3::z_axis(), 1.13757);
    // MoveIt's board frame (OpenCV 3's aruco module): origin at the board's
    // bottom-left outer corner, y up the board, z out of the print towards
    // the camera; robocal's (OpenCV >= 4.6): origin top-left, y down, z into
    // the print. The same board, turned by pi about x at (0, 7 squares).
    let board_from_moveit = nalgebra::Isometry3::from_parts(
        nalgebra::Translation3::new(0.0, 7.0 * square, 0.0),
        nalgebra::UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
    );
    let camera_from_moveit = camera_from_board * board_from_moveit;
    let dt = (camera_from_moveit.translation.vector - expected_t).norm();
    let dr = (camera_from_moveit.rotation.to_rotation_matrix() * expected_r.inverse()).angle();
    println!(
        "moveit board pose: reprojection rms {rms:.3} px, translation {:?} m, {:.2} mm and {:.3} deg from the expectation",
        camera_from_moveit.translation.vector.as_slice(),
        dt * 1e3,
        dr.to_degrees()
    );
    // MoveIt's test: Eigen isApprox(0.01), a 1 % relative difference of the
    // translation vector (|t| = 0.354 m -> 3.5 mm) and of the Euler-angle
    // vector (|(2.884, -0.148, 1.138)| = 3.104 rad -> 0.031 rad, asserted on
    // the rotation angle between the two poses, which is free of the Euler
    // triple's ambiguity).
    assert!(
        dt <= 0.01 * expected_t.norm(),
        "translation off by {:.2} mm",
        dt * 1e3
    );
    let euler_norm = Vector3::new(2.88409, -0.147996, 1.13757).norm();
    assert!(dr <= 0.01 * euler_norm, "rotation off by {:.4} rad", dr);
}
