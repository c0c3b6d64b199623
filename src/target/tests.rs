//! Tests of the targets: specs, JSON, board order.

use super::*;
use wasm_bindgen_test::wasm_bindgen_test;

#[wasm_bindgen_test(unsupported = test)]
fn specs_parse_to_targets() {
    assert_eq!(
        Target::parse_spec("chessboard:9x6:30mm").unwrap(),
        Target::Chessboard {
            cols: 9,
            rows: 6,
            square_m: 0.03
        }
    );
    assert_eq!(
        Target::parse_spec("circles:4x11:20mm:asymmetric").unwrap(),
        Target::CircleGrid {
            cols: 4,
            rows: 11,
            spacing_m: 0.02,
            asymmetric: true,
            polarity: Polarity::DarkOnLight
        }
    );
    let Target::DotPlate { dot_diameter_m, .. } = Target::parse_spec("dots:7x7:25mm").unwrap()
    else {
        panic!("not a dot plate")
    };
    assert!((dot_diameter_m - 0.0125).abs() < 1e-15);
    assert_eq!(
        Target::parse_spec("circle:10mm").unwrap(),
        Target::SingleCircle { diameter_m: 0.01 }
    );
    assert_eq!(
        Target::parse_spec("chessboard:9x6:30")
            .unwrap_err()
            .to_string(),
        "target: length '30' needs a unit: mm, cm or m (e.g. 30mm)"
    );
    assert_eq!(
        Target::parse_spec("chessboard:1x6:30mm")
            .unwrap_err()
            .to_string(),
        "target: a grid needs 2 to 100000 points with at least 2 per side, got 1x6"
    );
    assert!(Target::parse_spec("hexagons:3x3:1mm").is_err());
    let Target::SquareGrid {
        cols: 8,
        rows: 8,
        side_m,
        pitch_m,
    } = Target::parse_spec("squares:8x8:12.7mm:22.5778mm").unwrap()
    else {
        panic!("not an 8x8 square grid")
    };
    // Rounded once from the decimal: equal to the literal, not 1 ulp off.
    assert_eq!((side_m, pitch_m), (0.0127, 0.0225778));
    assert_eq!(
        Target::parse_spec("squares:8x8:25mm:20mm")
            .unwrap_err()
            .to_string(),
        "target: the square side must be smaller than the pitch (the squares must not touch)"
    );
    assert_eq!(
        Target::parse_spec("squares:8x8:10mm")
            .unwrap_err()
            .to_string(),
        "target: 'squares:8x8:10mm' is not a square-grid spec; expected squares:COLSxROWS:SIDE:PITCH (e.g. squares:8x8:12.7mm:22.5778mm)"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn square_grid_corners_follow_the_documented_order_and_zhangs_mapping() {
    let t = Target::parse_spec("squares:8x8:12.7mm:22.5778mm").unwrap();
    assert_eq!(t.point_count(), 256);
    let p = t.object_points();
    assert_eq!(p.len(), 256);
    // Square 1 (i = 1, j = 0), corner 2: (pitch + side, side).
    assert_eq!(p[6].0, 6);
    assert!((p[6].1.x - 0.0352778).abs() < 1e-12 && (p[6].1.y - 0.0127).abs() < 1e-12);
    // Square 8 (i = 0, j = 1), corner 3: (0, pitch + side).
    assert!(p[35].1.x.abs() < 1e-12 && (p[35].1.y - 0.0352778).abs() < 1e-12);
    // Zhang's Model.txt line n, corner k (inches, y = -j pitch - side
    // ... -j pitch) is our id 4 (n % 8 + 8 (7 - n / 8)) + k shifted by
    // 7 pitch + side along y (module docs).
    let (inch, pitch_in, side_in) = (0.0254, 8.0 / 9.0, 0.5);
    for n in [0usize, 9, 63] {
        let (i, jz) = ((n % 8) as f64, (n / 8) as f64);
        let zhang = [
            (i * pitch_in, -0.5 - jz * pitch_in),
            (i * pitch_in + side_in, -0.5 - jz * pitch_in),
            (i * pitch_in + side_in, -jz * pitch_in),
            (i * pitch_in, -jz * pitch_in),
        ];
        for (k, (x, y)) in zhang.iter().enumerate() {
            let id = 4 * (n % 8 + 8 * (7 - n / 8)) + k;
            let ours = p[id].1;
            let shift = 7.0 * pitch_in + side_in;
            assert!((ours.x - x * inch).abs() < 1e-6, "n {n} k {k}");
            assert!((ours.y - (y + shift) * inch).abs() < 1e-6, "n {n} k {k}");
        }
    }
    let t = Target::SquareGrid {
        cols: 8,
        rows: 8,
        side_m: 0.0127,
        pitch_m: 0.0225778,
    };
    let json = serde_json::to_string(&t).unwrap();
    assert_eq!(
        json,
        r#"{"kind":"square_grid","cols":8,"rows":8,"side_m":0.0127,"pitch_m":0.0225778}"#
    );
    assert_eq!(serde_json::from_str::<Target>(&json).unwrap(), t);
}

#[wasm_bindgen_test(unsupported = test)]
fn object_points_follow_the_documented_order() {
    let t = Target::parse_spec("circles:4x11:20mm:asymmetric").unwrap();
    let p = t.object_points();
    assert_eq!(p.len(), 44);
    assert!((p[1].1.x - 0.04).abs() < 1e-12 && p[1].1.y == 0.0);
    assert!((p[4].1.x - 0.02).abs() < 1e-12 && (p[4].1.y - 0.02).abs() < 1e-12);
    let c = Target::parse_spec("chessboard:9x6:30mm").unwrap();
    let q = c.object_points();
    assert_eq!(q[10].0, 10);
    assert!((q[10].1.x - 0.03).abs() < 1e-12 && (q[10].1.y - 0.03).abs() < 1e-12);
}

#[wasm_bindgen_test(unsupported = test)]
fn detection_round_trips_through_json() {
    let d = Detection {
        image_size_px: [640, 480],
        target: Target::parse_spec("chessboard:3x2:10mm").unwrap(),
        points: vec![
            DetectedPoint {
                id: 4,
                x_px: 10.5,
                y_px: 20.25,
                covariance_px2: None,
            },
            DetectedPoint {
                id: 99,
                x_px: 1.0,
                y_px: 2.0,
                covariance_px2: Some([1.0, 0.0, 1.0]),
            },
        ],
        centre_model: None,
        polarity: None,
    };
    let json = serde_json::to_string(&d).unwrap();
    assert!(json.contains("\"kind\":\"chessboard\""), "{json}");
    assert!(!json.contains("centre_model"), "{json}");
    let back: Detection = serde_json::from_str(&json).unwrap();
    assert_eq!(back, d);
    // A circle grid's centre model round-trips by its name.
    let circles = Detection {
        target: Target::parse_spec("circles:4x11:20mm:asymmetric").unwrap(),
        centre_model: Some(CentreModel::PerspectivePole),
        polarity: None,
        ..d.clone()
    };
    let json = serde_json::to_string(&circles).unwrap();
    assert!(
        json.contains("\"centre_model\":\"perspective_pole\""),
        "{json}"
    );
    assert_eq!(serde_json::from_str::<Detection>(&json).unwrap(), circles);
    let (object, image) = d.correspondences();
    // id 99 does not exist on a 3x2 board and is dropped.
    assert_eq!(object.len(), 1);
    assert!((object[0].x - 0.01).abs() < 1e-12 && (object[0].y - 0.01).abs() < 1e-12);
    assert_eq!(image[0], Point2::new(10.5, 20.25));
}

#[wasm_bindgen_test(unsupported = test)]
fn specs_survive_json_bit_exactly() {
    // `robocal detect` writes the target as JSON and `robocal intrinsics
    // --target SPEC --detections FILE` compares the target read back with
    // the spec: equal to the bit, also for lengths like 22.5778mm (1 ulp
    // apart before lengths were rounded once from the decimal).
    for spec in [
        "chessboard:9x6:30mm",
        "squares:8x8:12.7mm:22.5778mm",
        "dots:7x7:25mm:12.5mm",
        "circles:4x11:20.1mm:asymmetric",
        "circle:0.7cm",
    ] {
        let t = Target::parse_spec(spec).unwrap();
        let back: Target = serde_json::from_str(&serde_json::to_string(&t).unwrap()).unwrap();
        assert_eq!(back, t, "{spec}");
    }
}
