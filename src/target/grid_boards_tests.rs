//! Issue 36: the ArUco grid and the origin-dot grid: specs, errors, board
//! points against OpenCV's `GridBoard` and ROS-Industrial's
//! `ModifiedCircleGridTarget::createPoints`, the print. Exact: the numbers
//! are sums of the spec's lengths (1e-12 m).

use super::*;
use wasm_bindgen_test::wasm_bindgen_test;

fn err(spec: &str) -> String {
    Target::parse_spec(spec).unwrap_err().to_string()
}

#[wasm_bindgen_test(unsupported = test)]
fn aruco_grid_and_origin_dot_specs_parse_and_round_trip() {
    assert_eq!(
        Target::parse_spec("arucogrid:5x7:40mm:10mm:DICT_6X6_250").unwrap(),
        Target::ArucoGrid {
            markers_x: 5,
            markers_y: 7,
            marker_m: 0.04,
            separation_m: 0.01,
            dictionary: Dictionary::DICT_6X6_250,
            first_id: 0,
        }
    );
    assert_eq!(
        Target::parse_spec("circles:10x10:25mm:origin-dot").unwrap(),
        Target::OriginDotGrid {
            cols: 10,
            rows: 10,
            spacing_m: 0.025,
        }
    );
    for spec in [
        "arucogrid:5x7:40mm:10mm:DICT_6X6_250",
        "arucogrid:4x3:33.3mm:7.5mm:DICT_4X4_50:first=12",
        "arucogrid:2x2:20mm:5mm:DICT_APRILTAG_36h11",
        "circles:10x10:25mm:origin-dot",
        "circles:7x5:12.5mm:origin-dot",
    ] {
        let t = Target::parse_spec(spec).unwrap();
        assert_eq!(t.to_spec(), spec);
        let json = serde_json::to_string(&t).unwrap();
        assert_eq!(serde_json::from_str::<Target>(&json).unwrap(), t, "{json}");
    }
    let j: Target = serde_json::from_str(
        r#"{"kind": "aruco_grid", "markers_x": 5, "markers_y": 7, "marker_m": 0.04, "separation_m": 0.01, "dictionary": "DICT_6X6_250"}"#,
    )
    .unwrap();
    assert_eq!(j.to_spec(), "arucogrid:5x7:40mm:10mm:DICT_6X6_250");
    let o: Target = serde_json::from_str(
        r#"{"kind": "origin_dot_grid", "cols": 10, "rows": 10, "spacing_m": 0.025}"#,
    )
    .unwrap();
    assert_eq!(o.to_spec(), "circles:10x10:25mm:origin-dot");
}

#[wasm_bindgen_test(unsupported = test)]
fn bad_aruco_grid_and_origin_dot_specs_say_what_is_wrong() {
    assert_eq!(
        err("arucogrid:5x7:40mm:10mm"),
        "target: 'arucogrid:5x7:40mm:10mm' is not an ArUco grid spec; expected arucogrid:COLSxROWS:MARKER:SEPARATION:DICTIONARY[:first=N] (e.g. arucogrid:5x7:40mm:10mm:DICT_6X6_250)"
    );
    assert_eq!(
        err("arucogrid:5x7:40mm:10mm:DICT_6X6_250:first=x"),
        "target: 'x' is not a marker id (first=N)"
    );
    assert_eq!(
        err("arucogrid:5x7:40mm:10mm:DICT_6X6_250:legacy"),
        "target: unknown ArUco grid option 'legacy' (expected first=N, the id of the top-left marker)"
    );
    assert_eq!(
        err("arucogrid:10x10:40mm:10mm:DICT_4X4_50"),
        "target: too many markers: a 10x10 ArUco grid needs 100 markers from id 0, but DICT_4X4_50 has 50 (use a larger dictionary or fewer markers)"
    );
    assert_eq!(
        err("arucogrid:5x7:40mm:10mm:DICT_4X4_50:first=20"),
        "target: too many markers: a 5x7 ArUco grid needs 35 markers from id 20, but DICT_4X4_50 has 50 (use a larger dictionary or fewer markers)"
    );
    assert_eq!(
        err("arucogrid:5x7:40mm:0mm:DICT_6X6_250"),
        "target: the marker separation must be a positive length, got 0 mm"
    );
    assert_eq!(
        err("arucogrid:0x7:40mm:10mm:DICT_6X6_250"),
        "target: a grid needs 2 to 100000 points with at least 2 per side, got 0x7"
    );
    assert!(err("arucogrid:5x7:40mm:10mm:DICT_9X9_1")
        .starts_with("target: unknown marker dictionary 'DICT_9X9_1'; known: DICT_4X4_50, "));
    let origin_dot_only = "is not an origin-dot grid spec; expected circles:COLSxROWS:PITCH:origin-dot with no other option than the print (:dark-on-light or :light-on-dark; ROS-Industrial's grid is symmetric; e.g. circles:10x10:25mm:origin-dot)";
    assert_eq!(
        err("circles:10x10:25mm:origin-dot:asymmetric"),
        format!("target: 'circles:10x10:25mm:origin-dot:asymmetric' {origin_dot_only}")
    );
    // The print is an option of every kind: it is taken off before the
    // grid's own options are read.
    assert_eq!(
        Target::parse_spec_print("circles:10x10:25mm:light-on-dark:origin-dot").unwrap(),
        (
            Target::OriginDotGrid {
                cols: 10,
                rows: 10,
                spacing_m: 0.025,
            },
            Some(Polarity::LightOnDark)
        )
    );
    assert_eq!(
        err("circles:1x10:25mm:origin-dot"),
        "target: a grid needs 2 to 100000 points with at least 2 per side, got 1x10"
    );
    assert_eq!(
        err("circles:10x10:-25mm:origin-dot"),
        "target: the dot spacing must be a positive length, got -25 mm"
    );
    assert_eq!(
        err("circles:10x10:25mm:origin"),
        "target: unknown circle-grid option 'origin' (expected asymmetric, symmetric, dark-on-light, light-on-dark or origin-dot)"
    );
}

/// OpenCV 4.6+ `GridBoard(Size(3, 2), 0.04, 0.01, dict)`: marker `k` at
/// `((k % 3) * 0.05, (k / 3) * 0.05)`, corners TL, TR, BR, BL, y down.
#[wasm_bindgen_test(unsupported = test)]
fn aruco_grid_points_are_opencvs_grid_board_obj_points() {
    let t = Target::parse_spec("arucogrid:3x2:40mm:10mm:DICT_4X4_50:first=7").unwrap();
    let pts = t.object_points();
    assert_eq!(pts.len(), 24);
    let corner = [(0.0, 0.0), (0.04, 0.0), (0.04, 0.04), (0.0, 0.04)];
    for (id, p) in &pts {
        let (k, c) = (id / 4, id % 4);
        let x = (k % 3) as f64 * 0.05 + corner[c].0;
        let y = (k / 3) as f64 * 0.05 + corner[c].1;
        assert!(
            (p.x - x).abs() < 1e-12 && (p.y - y).abs() < 1e-12 && p.z == 0.0,
            "point {id}: {p:?}, expected ({x}, {y}, 0) m"
        );
    }
    let layout = marker_board::layout(&t).unwrap();
    let ids: Vec<usize> = layout.markers.iter().map(|m| m.id).collect();
    assert_eq!(ids, vec![7, 8, 9, 10, 11, 12], "row-major from first=7");
    // The layout's marker corners are the board points of the same index.
    for (k, m) in layout.markers.iter().enumerate() {
        for c in 0..4 {
            let p = pts[4 * k + c].1;
            assert!((m.corners[c] - Point2::new(p.x, p.y)).norm() < 1e-12);
        }
    }
    assert_eq!(layout.border_bits, 1, "OpenCV's default borderBits");
}

/// ROS-Industrial's `createPoints` for rows = 3, cols = 4, spacing s:
/// point `k` at `(k % 4, 2 - k / 4) s`, big dot at point 8 = (0, 0); ours
/// is `(x, H - y_ros, -z)`.
#[wasm_bindgen_test(unsupported = test)]
fn origin_dot_ids_are_ros_industrials_and_the_frame_maps_by_a_half_turn() {
    let s = 0.025;
    let t = Target::parse_spec("circles:4x3:25mm:origin-dot").unwrap();
    let h = 2.0 * s;
    assert_eq!(origin_dot::origin_id(4, 3), 8);
    for (id, p) in t.object_points() {
        let ros = ((id % 4) as f64 * s, (2 - id / 4) as f64 * s);
        assert!(
            (p.x - ros.0).abs() < 1e-12 && (h - p.y - ros.1).abs() < 1e-12,
            "point {id}: ours {p:?}, ROS-Industrial ({}, {}) m",
            ros.0,
            ros.1
        );
    }
    let r = |id| origin_dot::dot_radius_m(id, 4, 3, s);
    assert!(
        (r(8) - 0.01).abs() < 1e-12,
        "origin dot 20 mm across: {} m radius",
        r(8)
    );
    assert!(
        (r(0) - 0.005).abs() < 1e-12,
        "dots 10 mm across: {} m radius",
        r(0)
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn the_sheets_draw_every_marker_and_the_big_dot() {
    let svg = svg::board_svg(&Target::parse_spec("circles:10x10:25mm:origin-dot").unwrap());
    assert_eq!(svg.matches("class=\"circle\"").count(), 100);
    assert_eq!(svg.matches(r#"r="5"/>"#).count(), 99, "dots 10 mm across");
    // The origin dot: point 90 at (0, 9 * 25) mm, 20 mm across.
    assert_eq!(
        svg.matches(r#"<circle class="circle" cx="0" cy="225" r="10"/>"#)
            .count(),
        1
    );
    assert!(svg.contains("robocal target circles:10x10:25mm:origin-dot"));
    assert!(svg.contains("big dot: ROS-I origin"));

    let t = Target::parse_spec("arucogrid:2x2:40mm:10mm:DICT_4X4_50").unwrap();
    let svg = svg::board_svg(&t);
    // Each 4x4 marker with its one-bit border is 6 x 6 cells of 40/6 mm:
    // 20 border cells plus its dark bits.
    let d = Dictionary::DICT_4X4_50;
    let dark_bits: usize = (0..4)
        .map(|id| 16 - d.code(id).unwrap().count_ones() as usize)
        .sum();
    assert_eq!(svg.matches("class=\"square\"").count(), 4 * 20 + dark_bits);
    // Marker 3's top-left border cell is at (50, 50) mm.
    assert!(svg.contains(r#"<rect class="square" x="50" y="50" width="6.6667" height="6.6667"/>"#));
    assert!(svg.contains("robocal target arucogrid:2x2:40mm:10mm:DICT_4X4_50"));
}
