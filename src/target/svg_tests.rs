//! Exact checks: the sheet's numbers are sums of the spec's millimetres
//! and the named layout constants, written with 4 decimals, so they are
//! compared as text or to 1e-9 mm.
use super::*;
use wasm_bindgen_test::wasm_bindgen_test;

fn target(spec: &str) -> Target {
    Target::parse_spec(spec).unwrap()
}

/// The value of attribute `name` in the first tag containing `tag`.
fn attr(svg: &str, tag: &str, name: &str) -> String {
    let start = svg.find(tag).unwrap_or_else(|| panic!("no {tag}"));
    let rest = &svg[start..];
    let rest = &rest[..rest.find('>').unwrap()];
    let key = format!(" {name}=\"");
    let at = rest
        .find(&key)
        .unwrap_or_else(|| panic!("no {name} in {rest}"))
        + key.len();
    rest[at..at + rest[at..].find('"').unwrap()].to_string()
}

fn mm(svg: &str, tag: &str, name: &str) -> f64 {
    attr(svg, tag, name).trim_end_matches("mm").parse().unwrap()
}

#[wasm_bindgen_test(unsupported = test)]
fn chessboard_sheet_is_true_scale_with_every_square() {
    let svg = board_svg(&target("chessboard:9x6:30mm"));
    // Board 9 + 1 + 2 quiet squares wide = 12 * 30 = 360 mm, 9 * 30 = 270 mm high.
    assert_eq!(
        mm(&svg, "<rect class=\"board\"", "width"),
        360.0,
        "board width, mm"
    );
    assert_eq!(
        mm(&svg, "<rect class=\"board\"", "height"),
        270.0,
        "board height, mm"
    );
    let (w, h) = (mm(&svg, "<svg", "width"), mm(&svg, "<svg", "height"));
    assert_eq!(w, 360.0 + 2.0 * PAGE_MARGIN_MM, "sheet width, mm");
    let expected_h =
        PAGE_MARGIN_MM + 270.0 + GAP_MM + CHECK_BAR_HEIGHT_MM + 4.0 * LINE_MM + PAGE_MARGIN_MM;
    assert!(
        (h - expected_h).abs() < 1e-9,
        "sheet height {h} mm, expected {expected_h} mm"
    );
    assert!(attr(&svg, "<svg", "width").ends_with("mm"));
    assert_eq!(
        attr(&svg, "<svg", "viewBox"),
        format!("0 0 {} {}", num(w), num(h))
    );
    // 10 x 7 squares, half of them (rounded up: the top-left is dark) printed.
    assert_eq!(svg.matches("class=\"square\"").count(), 35);
    // Point 0 lies two squares (quiet zone + first square) inside the
    // board area; the first dark square starts a square before it.
    assert_eq!(
        attr(&svg, "<g class=\"marks\"", "transform"),
        "translate(70 70)"
    );
    assert_eq!(mm(&svg, "class=\"square\"", "x"), -30.0);
    assert_eq!(mm(&svg, "class=\"square\"", "width"), 30.0);
}

#[wasm_bindgen_test(unsupported = test)]
fn check_bar_is_100_mm_with_words_and_spec() {
    for spec in [
        "chessboard:9x6:30mm",
        "circles:4x11:20mm:asymmetric:light-on-dark",
        "dots:7x7:25mm:10mm",
        "circle:10mm",
        "squares:8x8:12.7mm:22.5778mm",
    ] {
        let svg = board_svg(&target(spec));
        assert_eq!(
            mm(&svg, "class=\"check-bar\"", "width"),
            100.0,
            "{spec}: bar, mm"
        );
        assert!(
            svg.contains("This bar is 100 mm long. Measure it"),
            "{spec}"
        );
        assert!(
            svg.contains(&format!("robocal target {spec}</text>")),
            "{spec}: spec on the sheet"
        );
        // The sheet is wide enough for the bar and the text column.
        assert!(
            mm(&svg, "<svg", "width") >= TEXT_WIDTH_MM + 2.0 * PAGE_MARGIN_MM,
            "{spec}"
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn circle_grids_count_circles_and_keep_polarity() {
    let svg = board_svg(&target("circles:4x11:20mm:asymmetric"));
    assert_eq!(svg.matches("class=\"circle\"").count(), 44);
    assert_eq!(
        mm(&svg, "class=\"circle\"", "r"),
        5.0,
        "radius = 0.25 unit, mm"
    );
    // Asymmetric: x up to (2 * 3 + 1) * 20 = 140 mm, plus a unit each side.
    assert_eq!(mm(&svg, "<rect class=\"board\"", "width"), 180.0);
    assert_eq!(mm(&svg, "<rect class=\"board\"", "height"), 240.0);
    assert_eq!(attr(&svg, "<rect class=\"board\"", "fill"), "#fff");
    let light = board_svg(&target("circles:4x5:20mm:light-on-dark"));
    assert_eq!(light.matches("class=\"circle\"").count(), 20);
    assert_eq!(attr(&light, "<rect class=\"board\"", "fill"), "#000");
    assert_eq!(
        attr(&light, "<g class=\"marks\"", "fill"),
        "#fff",
        "light circles"
    );
    assert!(light.contains("symmetric, light on dark"));
}

#[wasm_bindgen_test(unsupported = test)]
fn dot_plates_single_circles_and_square_grids() {
    let dots = board_svg(&target("dots:7x7:25mm:12.5mm"));
    assert_eq!(dots.matches("class=\"circle\"").count(), 49);
    assert_eq!(mm(&dots, "class=\"circle\"", "r"), 6.25);
    assert_eq!(mm(&dots, "<rect class=\"board\"", "width"), 200.0);

    let one = board_svg(&target("circle:10mm"));
    assert_eq!(one.matches("class=\"circle\"").count(), 1);
    assert_eq!(mm(&one, "class=\"circle\"", "r"), 5.0);
    assert_eq!(mm(&one, "class=\"circle\"", "cx"), 0.0);
    assert_eq!(
        attr(&one, "<g class=\"marks\"", "transform"),
        "translate(30 30)"
    );
    assert_eq!(mm(&one, "<rect class=\"board\"", "width"), 40.0);

    let zhang = board_svg(&target("squares:8x8:12.7mm:22.5778mm"));
    assert_eq!(zhang.matches("class=\"square\"").count(), 64);
    assert_eq!(attr(&zhang, "class=\"square\"", "width"), "12.7");
    // 7 pitches + a side + a pitch of quiet zone on each side.
    let w = mm(&zhang, "<rect class=\"board\"", "width");
    assert!(
        (w - (9.0 * 22.5778 + 12.7)).abs() < 1e-9,
        "board width {w} mm"
    );
    assert_eq!(attr(&zhang, "class=\"square\"", "x"), "0");
    assert_eq!(
        attr(&zhang, "<g class=\"marks\"", "transform"),
        format!("translate({0} {0})", num(PAGE_MARGIN_MM + 22.5778))
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn specs_round_trip_through_to_spec() {
    for spec in [
        "chessboard:9x6:30mm",
        "chessboard:7x5:0.5mm",
        "circles:4x11:20mm:asymmetric",
        "circles:4x5:20.1mm:light-on-dark",
        "circles:4x11:20mm:asymmetric:light-on-dark",
        "dots:7x7:25mm",
        "dots:7x7:25mm:10mm",
        "circle:10mm",
        "squares:8x8:12.7mm:22.5778mm",
    ] {
        let t = target(spec);
        assert_eq!(t.to_spec(), spec);
        assert_eq!(target(&t.to_spec()), t, "{spec}");
    }
    // Other spellings come back in the canonical one, to the bit.
    assert_eq!(target("circle:0.7cm").to_spec(), "circle:7mm");
    assert_eq!(
        target("circles:4x5:2cm:symmetric:dark-on-light").to_spec(),
        "circles:4x5:20mm"
    );
    // A length with no short millimetre decimal is written in metres.
    let odd = Target::SingleCircle {
        diameter_m: 0.1 / 3.0,
    };
    assert_eq!(odd.to_spec(), "circle:0.03333333333333333m");
    assert_eq!(target(&odd.to_spec()), odd);
}

#[wasm_bindgen_test(unsupported = test)]
fn text_is_escaped() {
    assert_eq!(xml("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
    assert_eq!(num(-0.00001), "0");
    assert_eq!(num(12.70000), "12.7");
}
