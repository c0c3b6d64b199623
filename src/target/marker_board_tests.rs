use super::*;
use crate::target::Dictionary;

#[test]
fn charuco_spec_parses_and_round_trips() {
    let t = Target::parse_spec("charuco:12x9:20mm:15mm:DICT_5X5_100").unwrap();
    assert_eq!(
        t,
        Target::Charuco {
            squares_x: 12,
            squares_y: 9,
            square_m: 0.02,
            marker_m: 0.015,
            dictionary: Dictionary::DICT_5X5_100,
            first_id: 0,
            marker_ids: None,
            legacy: false
        }
    );
    for spec in [
        "charuco:12x9:20mm:15mm:DICT_5X5_100",
        "charuco:5x7:28.1571mm:17.5982mm:DICT_5X5_250:first=10:legacy",
        "charuco:3x3:10mm:7mm:DICT_4X4_50:ids=9,3,44,0",
        "aprilgrid:6x6:88mm:0.3",
        "aprilgrid:6x6:88mm:0.3:first=36",
    ] {
        let t = Target::parse_spec(spec).unwrap();
        assert_eq!(t.to_spec(), spec);
        let json = serde_json::to_string(&t).unwrap();
        assert_eq!(serde_json::from_str::<Target>(&json).unwrap(), t, "{json}");
    }
    let j: Target = serde_json::from_str(
        r#"{"kind": "aprilgrid", "tag_cols": 6, "tag_rows": 6, "tag_m": 0.088, "spacing_ratio": 0.3}"#,
    )
    .unwrap();
    assert_eq!(j.to_spec(), "aprilgrid:6x6:88mm:0.3");
    let c: Target = serde_json::from_str(
        r#"{"kind": "charuco", "squares_x": 5, "squares_y": 7, "square_m": 0.04, "marker_m": 0.025, "dictionary": "DICT_5X5_250"}"#,
    )
    .unwrap();
    assert_eq!(c.to_spec(), "charuco:5x7:40mm:25mm:DICT_5X5_250");
}

#[test]
fn bad_marker_board_specs_say_what_is_wrong() {
    let e = |s: &str| Target::parse_spec(s).unwrap_err().to_string();
    assert!(e("charuco:12x9:20mm:15mm:DICT_8X8_50")
        .contains("unknown marker dictionary 'DICT_8X8_50'; known: DICT_4X4_50, DICT_4X4_100"));
    assert!(e("charuco:12x9:20mm:20mm:DICT_5X5_100")
        .contains("the marker side (20 mm) must be smaller than the square side (20 mm)"));
    assert!(e("charuco:12x9:20mm:15mm:DICT_4X4_50").contains(
        "too many markers: a 12x9 ChArUco board needs 54 markers from id 0, but DICT_4X4_50 has 50"
    ));
    assert!(e("charuco:5x5:20mm:15mm:DICT_4X4_50:first=40").contains("needs 12 markers from id 40"));
    assert!(e("charuco:3x3:10mm:7mm:DICT_4X4_50:ids=1,2,3").contains("has 4 markers, got 3 ids"));
    assert!(e("charuco:3x3:10mm:7mm:DICT_4X4_50:ids=1,2,3,3").contains("distinct"));
    assert!(
        e("charuco:3x3:10mm:7mm:DICT_4X4_50:mirror").contains("unknown ChArUco option 'mirror'")
    );
    assert!(e("charuco:12x9:20mm")
        .contains("expected charuco:SQUARESXxSQUARESY:SQUARE:MARKER:DICTIONARY"));
    assert!(
        e("aprilgrid:6x6:88mm").contains("expected aprilgrid:TAGCOLSxTAGROWS:TAGSIZE:SPACINGRATIO")
    );
    assert!(e("aprilgrid:6x6:88mm:1.5").contains("spacing ratio must be in (0, 1]"));
    assert!(e("aprilgrid:30x30:88mm:0.3").contains(
        "too many tags: a 30x30 AprilGrid needs 900 tag36h11 tags from id 0, the family has 587"
    ));
}

#[test]
fn charuco_points_and_markers_are_opencvs() {
    // OpenCV 4.14: CharucoBoard((5, 4), 0.02, 0.015, DICT_4X4_50):
    // getChessboardCorners()[:5] = (0.02, 0.02), (0.04, 0.02), (0.06, 0.02),
    // (0.08, 0.02), (0.02, 0.04); getObjPoints()[0][0] = (0.0225, 0.0025),
    // [1][0] = (0.0625, 0.0025), [2][0] = (0.0025, 0.0225); with
    // setLegacyPattern(True): [0][0] = (0.0025, 0.0025), [1][0] = (0.0425,
    // 0.0025).
    let t = Target::parse_spec("charuco:5x4:20mm:15mm:DICT_4X4_50").unwrap();
    let pts = t.object_points();
    assert_eq!(pts.len(), 12);
    let expect = [
        (0.02, 0.02),
        (0.04, 0.02),
        (0.06, 0.02),
        (0.08, 0.02),
        (0.02, 0.04),
    ];
    for ((id, p), (x, y)) in pts.iter().zip(expect) {
        assert!(
            (p.x - x).abs() < 1e-12 && (p.y - y).abs() < 1e-12,
            "corner {id}"
        );
    }
    let l = layout(&t).unwrap();
    assert_eq!(l.markers.len(), 10);
    let first = |l: &MarkerLayout, k: usize| (l.markers[k].corners[0].x, l.markers[k].corners[0].y);
    let close =
        |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12;
    assert!(close(first(&l, 0), (0.0225, 0.0025)));
    assert!(close(first(&l, 1), (0.0625, 0.0025)));
    assert!(close(first(&l, 2), (0.0025, 0.0225)));
    let legacy = Target::parse_spec("charuco:5x4:20mm:15mm:DICT_4X4_50:legacy").unwrap();
    let l = layout(&legacy).unwrap();
    assert!(close(first(&l, 0), (0.0025, 0.0025)));
    assert!(close(first(&l, 1), (0.0425, 0.0025)));
    // Odd rows: both layouts are the same.
    let a = layout(&Target::parse_spec("charuco:5x5:20mm:15mm:DICT_4X4_50").unwrap()).unwrap();
    let b =
        layout(&Target::parse_spec("charuco:5x5:20mm:15mm:DICT_4X4_50:legacy").unwrap()).unwrap();
    assert_eq!(a.markers, b.markers);
}

#[test]
fn aprilgrid_points_follow_kalibrs_numbering() {
    // Kalibr: point r * 2 cols + c at ((c / 2) p + (c % 2) s, (r / 2) p +
    // (r % 2) s) with y up; ours has y = H - that.
    let t = Target::parse_spec("aprilgrid:2x2:100mm:0.5").unwrap();
    let (p, s) = (0.15, 0.1);
    let h = p + s;
    let pts = t.object_points();
    assert_eq!(pts.len(), 16);
    for (id, q) in pts {
        let (r, c) = (id / 4, id % 4);
        let x = (c / 2) as f64 * p + (c % 2) as f64 * s;
        let y_up = (r / 2) as f64 * p + (r % 2) as f64 * s;
        assert!(
            (q.x - x).abs() < 1e-12 && (q.y - (h - y_up)).abs() < 1e-12,
            "point {id}"
        );
    }
    // Tag 0 is the bottom-left tag: its OpenCV corner 0 (the printed
    // bottom-right) is Kalibr's point 1.
    let l = layout(&t).unwrap();
    assert_eq!(l.markers[0].id, 0);
    assert!((l.markers[0].corners[0] - Point2::new(s, h)).norm() < 1e-12);
    assert!(
        (l.markers[3].corners[2] - Point2::new(p, 0.0)).norm() < 1e-12,
        "tag 3 top-left"
    );
}

#[test]
fn the_print_matches_the_markers_bits() {
    // ChArUco marker 0 of DICT_4X4_50 sits in square (1, 0) at rotation 0:
    // its cell (row 1, col 1) (the first data bit) reads the code's first
    // bit; the border is dark; a black square is dark.
    let t = Target::parse_spec("charuco:5x4:20mm:15mm:DICT_4X4_50").unwrap();
    let print = Print::new(&t).unwrap();
    let code = Dictionary::DICT_4X4_50.code(0).unwrap();
    let cell = 0.015 / 6.0;
    let at = |row: f64, col: f64| {
        print.dark_at(0.0225 + (col + 0.5) * cell, 0.0025 + (row + 0.5) * cell)
    };
    assert!(at(0.0, 0.0) && at(5.0, 5.0), "border");
    assert_eq!(at(1.0, 1.0), (code >> 15) & 1 == 0, "first data bit");
    assert_eq!(at(4.0, 4.0), code & 1 == 0, "last data bit");
    assert!(print.dark_at(0.01, 0.01), "black square (0, 0)");
    assert!(
        !print.dark_at(0.021, 0.001),
        "white margin of square (1, 0)"
    );
    // AprilGrid: corner squares dark, gaps light.
    let g = Target::parse_spec("aprilgrid:2x2:100mm:0.5").unwrap();
    let print = Print::new(&g).unwrap();
    assert!(print.dark_at(-0.025, -0.025) && print.dark_at(0.125, 0.125));
    assert!(!print.dark_at(0.125, 0.05), "gap between tags");
}
