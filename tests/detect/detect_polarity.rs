//! Every target kind printed light on dark (issue 36): renders of the
//! inverted print (`RenderOptions::light_on_dark`, margins and quiet zones
//! inverted too) are detected without any option, with the same ids as
//! the dark-on-light print, and the detection says which print it found.
//!
//! Tolerances: the renders are those of tests/detect/detect_render.rs and
//! tests/detect/detect_markers.rs (noise sigma 2 grey levels on a 190-level
//! contrast), inverted; the detectors see the same edges with the opposite
//! sign, so the bounds are theirs: chessboard and marker-board corners mean
//! <= 0.05 px, max <= 0.25 px; circle and dot centres mean <= 0.03 px,
//! max <= 0.15 px; square-grid corners mean <= 0.05 px, max <= 0.2 px; a
//! single circle's centre within 0.1 px. Recall: whole boards in view, so
//! every point must be found with the truth's id.

use robocal::detect::{detect, detect_all, DetectOptions};
use robocal::error::Error;
use robocal::synth::{board_pose as pose, render, RenderOptions};
use robocal::target::{DetectedPoint, Detection, Polarity, Target};

use crate::renders::camera;

/// Mean and max distance between detection and truth, matched by id; every
/// truth point must be detected.
fn errors(spec: &str, det: &Detection, truth: &[DetectedPoint]) -> (f64, f64) {
    let ids: Vec<usize> = det.points.iter().map(|p| p.id).collect();
    let truth_ids: Vec<usize> = truth.iter().map(|p| p.id).collect();
    assert_eq!(ids, truth_ids, "{spec}: detected ids against the truth's");
    let mut sum = 0.0;
    let mut max: f64 = 0.0;
    for (d, t) in det.points.iter().zip(truth) {
        let e = ((d.x_px - t.x_px).powi(2) + (d.y_px - t.y_px).powi(2)).sqrt();
        sum += e;
        max = max.max(e);
    }
    (sum / truth.len() as f64, max)
}

/// One view of `spec` printed `print`: the render and its truth.
struct View {
    target: Target,
    image: robocal::image::GrayImage,
    truth: Vec<DetectedPoint>,
}

fn view(
    spec: &str,
    print: Polarity,
    (w, h): (u32, u32),
    rpy: (f64, f64, f64),
    dist: f64,
    seed: u64,
) -> View {
    let target = Target::parse_spec(spec).unwrap();
    let cam = camera(w, h, 1.1 * w as f64);
    let o = RenderOptions {
        seed,
        ..RenderOptions::default()
    }
    .printed(print);
    let r = render(&cam, &target, &pose(&target, rpy, (0.01, -0.005, dist)), &o).unwrap();
    assert_eq!(
        r.points.len(),
        target.point_count(),
        "{spec}: whole board in view"
    );
    View {
        target,
        image: r.image,
        truth: r.points,
    }
}

/// Detect without options; check the print found and the errors.
fn check(spec: &str, v: &View, print: Polarity, mean_bound: f64, max_bound: f64) {
    let det = detect(&v.image, &v.target, &DetectOptions::default())
        .unwrap_or_else(|e| panic!("{spec} printed {print:?}: {e}"));
    assert_eq!(det.polarity, Some(print), "{spec}: the print found");
    let symmetric =
        matches!(v.target, Target::Chessboard { cols, rows, .. } if (cols + rows) % 2 == 0);
    let (mean, max) = if symmetric {
        // A board with cols + rows even is the same after a half turn (both
        // ends have the print's first square beyond them; the detector
        // takes the one nearest the image's top-left): compare either way.
        let n = v.truth.len();
        let mut turned = det.clone();
        turned.points.iter_mut().for_each(|p| p.id = n - 1 - p.id);
        turned.points.reverse();
        let direct = errors(spec, &det, &v.truth);
        let half_turn = errors(spec, &turned, &v.truth);
        if direct.0 <= half_turn.0 {
            direct
        } else {
            half_turn
        }
    } else {
        errors(spec, &det, &v.truth)
    };
    eprintln!(
        "{spec} {print:?}: {} points, mean {mean:.4} px, max {max:.4} px",
        v.truth.len()
    );
    assert!(
        mean <= mean_bound && max <= max_bound,
        "{spec} printed {print:?}: mean {mean} px (bound {mean_bound}), max {max} px (bound {max_bound})"
    );
}

const BOTH: [Polarity; 2] = [Polarity::DarkOnLight, Polarity::LightOnDark];

#[test]
fn chessboards_in_either_print() {
    // 8x6 (cols + rows even): the corner squares' colour says the print, and
    // an inverted board is numbered from its light corner. 9x6 (odd): the
    // inverted print is the usual one turned 180 degrees; found without an
    // option it is numbered as dark on light (id k at the truth's 53 - k)
    // and says so (src/detect/polarity.rs docs).
    let views = [
        ((0.1, -0.2, 0.05), 0.55),
        ((0.45, 0.3, -0.3), 0.6),
        ((-0.35, 0.5, 2.9), 0.6),
    ];
    for (k, (rpy, dist)) in views.into_iter().enumerate() {
        for print in BOTH {
            let v = view(
                "chessboard:8x6:30mm",
                print,
                (1280, 960),
                rpy,
                dist,
                10 + k as u64,
            );
            check("chessboard:8x6:30mm", &v, print, 0.05, 0.25);
        }
        let spec = "chessboard:9x6:30mm";
        let v = view(
            spec,
            Polarity::DarkOnLight,
            (1280, 960),
            rpy,
            dist,
            10 + k as u64,
        );
        check(spec, &v, Polarity::DarkOnLight, 0.05, 0.25);
        let v = view(
            spec,
            Polarity::LightOnDark,
            (1280, 960),
            rpy,
            dist,
            10 + k as u64,
        );
        let det = detect(&v.image, &v.target, &DetectOptions::default()).unwrap();
        assert_eq!(det.polarity, Some(Polarity::DarkOnLight), "{spec} inverted");
        let mut turned = det.clone();
        turned.points.iter_mut().for_each(|p| p.id = 53 - p.id);
        turned.points.reverse();
        let (mean, max) = errors(spec, &turned, &v.truth);
        eprintln!("{spec} LightOnDark, found as DarkOnLight: mean {mean:.4} px, max {max:.4} px");
        assert!(
            mean <= 0.05 && max <= 0.25,
            "{spec} inverted, view {k}: mean {mean} px, max {max} px"
        );
    }
}

#[test]
fn circle_grids_dot_plates_and_square_grids_in_either_print() {
    let cases = [
        ("circles:4x11:20mm:asymmetric", 0.6, 0.03, 0.15),
        ("circles:7x5:20mm", 0.6, 0.03, 0.15),
        ("dots:7x7:25mm", 0.6, 0.03, 0.15),
        ("squares:8x8:12.7mm:22.5778mm", 0.5, 0.05, 0.2),
    ];
    for (spec, dist, mean, max) in cases {
        for (k, rpy) in [(0.25, -0.2, 0.1), (-0.3, 0.35, -0.4)]
            .into_iter()
            .enumerate()
        {
            for print in BOTH {
                let v = view(spec, print, (1280, 960), rpy, dist, 20 + k as u64);
                check(spec, &v, print, mean, max);
            }
        }
    }
}

#[test]
fn a_light_on_dark_circle_grid_spec_still_reads_and_finds_either_print_from_json() {
    // The spec option forces the print; the target JSON of the same grid
    // (polarity light_on_dark) only says which print to try first.
    let spec = "circles:6x4:20mm:light-on-dark";
    let (target, forced) = Target::parse_spec_print(spec).unwrap();
    assert_eq!(forced, Some(Polarity::LightOnDark));
    assert!(matches!(
        target,
        Target::CircleGrid {
            polarity: Polarity::LightOnDark,
            ..
        }
    ));
    let dark = view(
        "circles:6x4:20mm",
        Polarity::DarkOnLight,
        (1280, 960),
        (0.2, 0.1, 0.0),
        0.5,
        3,
    );
    let det = detect(&dark.image, &target, &DetectOptions::default()).unwrap();
    assert_eq!(det.polarity, Some(Polarity::DarkOnLight));
    let (mean, max) = errors(spec, &det, &dark.truth);
    assert!(mean <= 0.03 && max <= 0.15, "mean {mean} px, max {max} px");
}

#[test]
fn single_circle_in_either_print() {
    let target = Target::parse_spec("circle:10mm").unwrap();
    let cam = camera(640, 480, 700.0);
    for print in BOTH {
        let o = RenderOptions::default().printed(print);
        let r = render(
            &cam,
            &target,
            &pose(&target, (0.2, 0.1, 0.0), (0.003, 0.002, 0.2)),
            &o,
        )
        .unwrap();
        let det = detect(&r.image, &target, &DetectOptions::default())
            .unwrap_or_else(|e| panic!("{print:?}: {e}"));
        assert_eq!(det.polarity, Some(print));
        let (p, t) = (&det.points[0], &r.points[0]);
        let e = ((p.x_px - t.x_px).powi(2) + (p.y_px - t.y_px).powi(2)).sqrt();
        assert!(e < 0.1, "{print:?}: centre error {e} px");
    }
}

#[test]
fn marker_boards_in_either_print_keep_their_marker_and_corner_ids() {
    // The inverted print's markers decode on the inverted bits; its corner
    // ids are those of the usual print (equal to the truth's, id by id).
    let cases = [
        ("charuco:5x7:30mm:22mm:DICT_4X4_50", 0.5),
        ("charuco:12x9:20mm:15mm:DICT_5X5_100", 0.5),
        ("charuco:4x5:54mm:40.5mm:DICT_4X4_1000", 0.6),
        ("aprilgrid:6x6:40mm:0.3", 0.7),
    ];
    for (spec, dist) in cases {
        for (k, rpy) in [(0.3, -0.25, 0.1), (-0.2, 0.4, -2.5)]
            .into_iter()
            .enumerate()
        {
            for print in BOTH {
                let v = view(spec, print, (1280, 960), rpy, dist, 30 + k as u64);
                check(spec, &v, print, 0.05, 0.25);
                let all = detect_all(&v.image, &v.target, &DetectOptions::default()).unwrap();
                assert_eq!(all.len(), 1, "{spec}: one board");
                assert_eq!(all[0].polarity, Some(print), "{spec}: detect_all's print");
            }
        }
    }
}

#[test]
fn a_forced_print_finds_its_board_and_names_the_option_when_the_other_print_is_in_view() {
    let spec = "charuco:5x7:30mm:22mm:DICT_4X4_50";
    let v = view(
        spec,
        Polarity::LightOnDark,
        (1280, 960),
        (0.3, -0.25, 0.1),
        0.5,
        7,
    );
    let forced = |print| DetectOptions {
        polarity: Some(print),
        ..DetectOptions::default()
    };
    let det = detect(&v.image, &v.target, &forced(Polarity::LightOnDark)).unwrap();
    assert_eq!(det.polarity, Some(Polarity::LightOnDark));
    assert_eq!(det.points.len(), v.truth.len());
    let e = detect(&v.image, &v.target, &forced(Polarity::DarkOnLight)).unwrap_err();
    assert!(matches!(e, Error::NotFound { .. }), "{e}");
    assert_eq!(
        e.to_string(),
        "no DICT_4X4_50 markers found: is the board in view, sharp and lit, and the dictionary right?; \
         printed light-on-dark the board is in view: the target spec forces ':dark-on-light', \
         write ':light-on-dark' or leave the option out to find either print \
         (charuco:5x7:30mm:22mm:DICT_4X4_50)"
    );
    // Dot plates: forced light-on-dark on the usual print.
    let dots = view(
        "dots:7x7:25mm",
        Polarity::DarkOnLight,
        (1280, 960),
        (0.25, -0.2, 0.1),
        0.6,
        8,
    );
    let e = detect(&dots.image, &dots.target, &forced(Polarity::LightOnDark)).unwrap_err();
    assert!(
        e.to_string().ends_with(
            "; printed dark-on-light the board is in view: the target spec forces ':light-on-dark', \
             write ':dark-on-light' or leave the option out to find either print (dots:7x7:25mm)"
        ),
        "{e}"
    );
}

#[test]
fn a_forced_chessboard_print_numbers_from_that_print_s_first_square() {
    // Forcing the wrong print on a 9x6 board turns its numbering 180
    // degrees (id k becomes 53 - k): the board's frame is the forced
    // print's.
    let spec = "chessboard:9x6:30mm";
    let v = view(
        spec,
        Polarity::LightOnDark,
        (1280, 960),
        (0.1, -0.2, 0.05),
        0.55,
        5,
    );
    let forced = |print| DetectOptions {
        polarity: Some(print),
        ..DetectOptions::default()
    };
    let right = detect(&v.image, &v.target, &forced(Polarity::LightOnDark)).unwrap();
    let (mean, max) = errors(spec, &right, &v.truth);
    assert!(mean <= 0.05 && max <= 0.25, "mean {mean} px, max {max} px");
    let wrong = detect(&v.image, &v.target, &forced(Polarity::DarkOnLight)).unwrap();
    assert_eq!(wrong.polarity, Some(Polarity::DarkOnLight));
    for p in &wrong.points {
        let t = &v.truth[53 - p.id];
        let e = ((p.x_px - t.x_px).powi(2) + (p.y_px - t.y_px).powi(2)).sqrt();
        assert!(e < 0.25, "id {}: {e} px from truth id {}", p.id, 53 - p.id);
    }
}

#[test]
fn specs_take_a_print_option_on_every_kind() {
    for (spec, geometry) in [
        ("chessboard:9x6:30mm:light-on-dark", "chessboard:9x6:30mm"),
        ("dots:7x7:25mm:light-on-dark", "dots:7x7:25mm"),
        ("dots:7x7:25mm:10mm:light-on-dark", "dots:7x7:25mm:10mm"),
        ("circle:10mm:light-on-dark", "circle:10mm"),
        (
            "squares:8x8:12.7mm:22.5778mm:light-on-dark",
            "squares:8x8:12.7mm:22.5778mm",
        ),
        (
            "charuco:4x5:54mm:40.5mm:DICT_4X4_1000:light-on-dark",
            "charuco:4x5:54mm:40.5mm:DICT_4X4_1000",
        ),
        (
            "charuco:4x5:54mm:40.5mm:DICT_4X4_1000:first=8:light-on-dark",
            "charuco:4x5:54mm:40.5mm:DICT_4X4_1000:first=8",
        ),
        (
            "aprilgrid:6x6:40mm:0.3:light-on-dark",
            "aprilgrid:6x6:40mm:0.3",
        ),
    ] {
        let (target, print) = Target::parse_spec_print(spec).unwrap();
        assert_eq!(print, Some(Polarity::LightOnDark), "{spec}");
        assert_eq!(target.to_spec(), geometry, "{spec}");
        let (_, print) =
            Target::parse_spec_print(&spec.replace("light-on-dark", "dark-on-light")).unwrap();
        assert_eq!(print, Some(Polarity::DarkOnLight), "{spec}");
        let (_, print) = Target::parse_spec_print(geometry).unwrap();
        assert_eq!(print, None, "{geometry}");
    }
    let e =
        Target::parse_spec_print("chessboard:9x6:30mm:light-on-dark:dark-on-light").unwrap_err();
    assert_eq!(
        e.to_string(),
        "target: 'chessboard:9x6:30mm:light-on-dark:dark-on-light' asks for both dark-on-light and light-on-dark; give one"
    );
}

#[test]
fn the_detection_json_says_which_print_was_found() {
    let v = view(
        "aprilgrid:6x6:40mm:0.3",
        Polarity::LightOnDark,
        (1280, 960),
        (0.3, -0.25, 0.1),
        0.7,
        9,
    );
    let det = detect(&v.image, &v.target, &DetectOptions::default()).unwrap();
    let json = serde_json::to_value(&det).unwrap();
    assert_eq!(json["polarity"], "light_on_dark");
    // Files written before the key existed still read, without a print.
    let mut old = json.clone();
    old.as_object_mut().unwrap().remove("polarity");
    let back: Detection = serde_json::from_value(old).unwrap();
    assert_eq!(back.polarity, None);
}

#[test]
fn aruco_grids_and_origin_dot_grids_in_either_print() {
    // The two kinds of issue 36's second half: found in either print without
    // an option, ids as in the usual print (the origin-dot grid's ids are
    // fixed by its big dot, so a half turn would show as a large error).
    let cases = [
        ("arucogrid:5x7:40mm:10mm:DICT_6X6_250", 0.9, 0.05, 0.3),
        ("circles:10x10:25mm:origin-dot", 0.7, 0.03, 0.15),
    ];
    for (spec, dist, mean_bound, max_bound) in cases {
        for (k, rpy) in [(0.3, -0.25, 0.1), (-0.2, 0.35, 3.0)]
            .into_iter()
            .enumerate()
        {
            for print in BOTH {
                let v = view(spec, print, (1280, 960), rpy, dist, 50 + k as u64);
                check(spec, &v, print, mean_bound, max_bound);
            }
        }
    }
}
