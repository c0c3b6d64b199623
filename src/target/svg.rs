//! The printable board: one SVG sheet at true scale for every [`Target`].
//!
//! The sheet's `width` and `height` are in millimetres and its `viewBox` is
//! the same numbers, so one user unit is one millimetre on paper when the
//! file is printed at 100 %. The board is drawn as the synthetic renderer
//! ([`crate::synth::render`]) draws it, the look the detectors are tested
//! on: the same quiet zone around the points, top-left chessboard square
//! dark, circle-grid circles half a grid unit across. Below the board: a
//! 100 mm check bar with the words to measure it, and the target's spec
//! ([`Target::to_spec`]) with the board frame, so a print can be checked
//! and typed back in.
//!
//! Point 0 (the board origin) is at the board's top left; x runs to the
//! right and y down, as in the module docs of [`crate::target`].

use super::{Polarity, Target};
use std::fmt::Write;

/// White paper around everything on the sheet, mm.
const PAGE_MARGIN_MM: f64 = 10.0;
/// Length of the check bar, mm.
const CHECK_BAR_MM: f64 = 100.0;
/// Thickness of the check bar, mm.
const CHECK_BAR_HEIGHT_MM: f64 = 3.0;
/// Space between the board and the check bar, mm.
const GAP_MM: f64 = 8.0;
/// Font size of the sheet's text, mm.
const TEXT_MM: f64 = 3.5;
/// Baseline-to-baseline distance of the text lines, mm.
const LINE_MM: f64 = 5.5;
/// The text column's width, mm: the sheet is at least this wide inside its
/// margins, so the longest line (about 75 characters of `TEXT_MM` type) fits.
const TEXT_WIDTH_MM: f64 = 150.0;
/// A circle grid's circle diameter over its grid unit (the renderer's
/// `RenderOptions::circle_diameter_ratio` default, what the detector is
/// tested on).
const CIRCLE_DIAMETER_RATIO: f64 = 0.5;
/// Decimals of the coordinates written, mm (a tenth of a micrometre).
const COORD_DECIMALS: usize = 4;

/// The board in millimetres, in board coordinates (point 0 at (0, 0)).
struct Board {
    /// `(x0, y0, x1, y1)`: the printed area, quiet zone included.
    extent: (f64, f64, f64, f64),
    /// Light circles on a dark area instead of dark marks on white.
    light_on_dark: bool,
    /// Dark squares `(x, y, side)` (chessboards and square grids).
    squares: Vec<(f64, f64, f64)>,
    /// Circles `(cx, cy, r)` (circle grids, dot plates, the single circle).
    circles: Vec<(f64, f64, f64)>,
}

/// The board's marks and extent; see the module docs for the look.
fn board(target: &Target) -> Board {
    let mm = |m: f64| m * 1000.0;
    let unit = mm(target.unit_m());
    let points: Vec<(f64, f64)> = target
        .grid_coords()
        .into_iter()
        .map(|(i, j)| (f64::from(i) * unit, f64::from(j) * unit))
        .collect();
    let max_x = points.iter().map(|p| p.0).fold(0.0, f64::max);
    let max_y = points.iter().map(|p| p.1).fold(0.0, f64::max);
    let dots = |r: f64| points.iter().map(|&(x, y)| (x, y, r)).collect();
    match target {
        Target::Chessboard { cols, rows, .. } => {
            // (cols + 1) x (rows + 1) squares; square (i, j) spans
            // [(i - 1) s, i s), and the top-left one (i + j even) is dark.
            let s = unit;
            let mut squares = Vec::new();
            for j in 0..=*rows {
                for i in 0..=*cols {
                    if (i + j) % 2 == 0 {
                        squares.push(((i as f64 - 1.0) * s, (j as f64 - 1.0) * s, s));
                    }
                }
            }
            Board {
                extent: (-2.0 * s, -2.0 * s, max_x + 2.0 * s, max_y + 2.0 * s),
                light_on_dark: false,
                squares,
                circles: Vec::new(),
            }
        }
        Target::CircleGrid { polarity, .. } => Board {
            extent: (-unit, -unit, max_x + unit, max_y + unit),
            light_on_dark: match polarity {
                Polarity::DarkOnLight => false,
                Polarity::LightOnDark => true,
            },
            squares: Vec::new(),
            circles: dots(0.5 * CIRCLE_DIAMETER_RATIO * unit),
        },
        Target::DotPlate { dot_diameter_m, .. } => Board {
            extent: (-unit, -unit, max_x + unit, max_y + unit),
            light_on_dark: false,
            squares: Vec::new(),
            circles: dots(0.5 * mm(*dot_diameter_m)),
        },
        Target::SingleCircle { diameter_m } => {
            let d = mm(*diameter_m);
            Board {
                extent: (-2.0 * d, -2.0 * d, 2.0 * d, 2.0 * d),
                light_on_dark: false,
                squares: Vec::new(),
                circles: vec![(0.0, 0.0, 0.5 * d)],
            }
        }
        Target::SquareGrid { side_m, .. } => {
            let side = mm(*side_m);
            Board {
                extent: (-unit, -unit, max_x + side + unit, max_y + side + unit),
                light_on_dark: false,
                squares: points.iter().map(|&(x, y)| (x, y, side)).collect(),
                circles: Vec::new(),
            }
        }
        Target::OriginDotGrid {
            cols,
            rows,
            spacing_m,
        } => Board {
            extent: (-unit, -unit, max_x + unit, max_y + unit),
            light_on_dark: false,
            squares: Vec::new(),
            circles: points
                .iter()
                .enumerate()
                .map(|(id, &(x, y))| {
                    let r = super::origin_dot::dot_radius_m(id, *cols, *rows, *spacing_m);
                    (x, y, mm(r))
                })
                .collect(),
        },
        Target::Charuco { .. } | Target::Aprilgrid { .. } | Target::ArucoGrid { .. } => {
            marker_board_marks(target)
        }
    }
}

/// A ChArUco board, an AprilGrid or an ArUco grid: its dark squares and every dark cell
/// of every marker, in millimetres (the layout of
/// [`super::marker_board`], OpenCV's and Kalibr's prints).
fn marker_board_marks(target: &Target) -> Board {
    let mm = |m: f64| m * 1000.0;
    let Some(layout) = super::marker_board::layout(target) else {
        return Board {
            extent: (0.0, 0.0, 0.0, 0.0),
            light_on_dark: false,
            squares: Vec::new(),
            circles: Vec::new(),
        };
    };
    let mut squares: Vec<(f64, f64, f64)> = super::marker_board::dark_squares(target)
        .into_iter()
        .map(|(x, y, side)| (mm(x), mm(y), mm(side)))
        .collect();
    let bits = layout.dictionary.marker_bits();
    let n = bits + 2 * layout.border_bits;
    for m in &layout.markers {
        let code = layout.dictionary.code(m.id).unwrap_or(0);
        let [c0, c1, _, c3] = m.corners;
        let (ex, ey) = ((c1 - c0) / n as f64, (c3 - c0) / n as f64);
        let cell = mm(ex.norm());
        for row in 0..n {
            for col in 0..n {
                if super::marker_board::marker_cell_dark(code, bits, layout.border_bits, row, col) {
                    // The cell's two opposite corners on the print; its
                    // top-left is the smaller of each coordinate.
                    let a = c0 + ex * col as f64 + ey * row as f64;
                    let b = a + ex + ey;
                    squares.push((mm(a.x.min(b.x)), mm(a.y.min(b.y)), cell));
                }
            }
        }
    }
    let (x0, y0, x1, y1) = layout.extent;
    Board {
        extent: (mm(x0), mm(y0), mm(x1), mm(y1)),
        light_on_dark: false,
        squares,
        circles: Vec::new(),
    }
}

/// What the target is, in words with millimetres, for the sheet.
fn description(target: &Target) -> String {
    let mm = |m: f64| format!("{} mm", num(m * 1000.0));
    match target {
        Target::Chessboard {
            cols,
            rows,
            square_m,
        } => format!(
            "{cols} x {rows} inner corners ({} x {} squares of {})",
            cols + 1,
            rows + 1,
            mm(*square_m)
        ),
        Target::CircleGrid {
            cols,
            rows,
            spacing_m,
            asymmetric,
            polarity,
        } => format!(
            "{cols} x {rows} circles, {}, {}, grid unit {}, circles {} across",
            if *asymmetric {
                "asymmetric"
            } else {
                "symmetric"
            },
            match polarity {
                Polarity::DarkOnLight => "dark on light",
                Polarity::LightOnDark => "light on dark",
            },
            mm(*spacing_m),
            mm(CIRCLE_DIAMETER_RATIO * spacing_m)
        ),
        Target::DotPlate {
            cols,
            rows,
            pitch_m,
            dot_diameter_m,
        } => format!(
            "{cols} x {rows} dots, pitch {}, dots {} across",
            mm(*pitch_m),
            mm(*dot_diameter_m)
        ),
        Target::SingleCircle { diameter_m } => {
            format!("one circle {} across", mm(*diameter_m))
        }
        Target::SquareGrid {
            cols,
            rows,
            side_m,
            pitch_m,
        } => format!(
            "{cols} x {rows} separate squares, side {}, pitch {}",
            mm(*side_m),
            mm(*pitch_m)
        ),
        Target::Charuco {
            squares_x,
            squares_y,
            square_m,
            marker_m,
            dictionary,
            legacy,
            ..
        } => format!(
            "ChArUco {squares_x} x {squares_y} squares of {}, markers {} {}{}",
            mm(*square_m),
            mm(*marker_m),
            dictionary.name(),
            if *legacy { ", pre-4.6 layout" } else { "" }
        ),
        Target::Aprilgrid {
            tag_cols,
            tag_rows,
            tag_m,
            spacing_ratio,
            ..
        } => format!(
            "AprilGrid {tag_cols} x {tag_rows} tag36h11, tags {}, spacing {spacing_ratio}",
            mm(*tag_m)
        ),
        Target::ArucoGrid {
            markers_x,
            markers_y,
            marker_m,
            separation_m,
            dictionary,
            first_id,
        } => format!(
            "ArUco grid {markers_x} x {markers_y}, markers {} {} from id {first_id}, gap {}",
            mm(*marker_m),
            dictionary.name(),
            mm(*separation_m)
        ),
        Target::OriginDotGrid {
            cols,
            rows,
            spacing_m,
        } => format!(
            "{cols} x {rows} dots, pitch {}, dots {}, origin dot {}",
            mm(*spacing_m),
            mm(super::origin_dot::DOT_DIAMETER_RATIO * spacing_m),
            mm(super::origin_dot::ORIGIN_DOT_SCALE
                * super::origin_dot::DOT_DIAMETER_RATIO
                * spacing_m)
        ),
    }
}

/// Where the board's point 0 and axes are, for the sheet.
fn origin_note(target: &Target) -> &'static str {
    match target {
        Target::Aprilgrid { .. } => "Tag 0 and point 0 at the bottom left (Kalibr).",
        Target::Charuco { .. } => "Origin at the top-left corner, x to the right, y down.",
        Target::ArucoGrid { .. } => {
            "Origin at marker 0's top-left corner, x right, y down (OpenCV)."
        }
        Target::OriginDotGrid { .. } => "Point 0 top left, x right, y down; big dot: ROS-I origin.",
        Target::Chessboard { .. }
        | Target::CircleGrid { .. }
        | Target::DotPlate { .. }
        | Target::SingleCircle { .. }
        | Target::SquareGrid { .. } => "Point 0 at the top left, x to the right, y down.",
    }
}

/// A coordinate in mm with at most [`COORD_DECIMALS`] decimals, no trailing
/// zeros (`30`, `22.5778`).
fn num(x: f64) -> String {
    let text = format!("{:.*}", COORD_DECIMALS, x);
    let text = text.trim_end_matches('0').trim_end_matches('.');
    match text {
        "-0" => "0".to_string(),
        t => t.to_string(),
    }
}

/// `text` with the XML specials escaped.
fn xml(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The printable sheet of `target` as an SVG document (see the module docs).
///
/// Board marks carry `class="square"` or `class="circle"`, the check bar
/// `class="check-bar"`, so a reader can count and measure them. The marks
/// sit in `<g class="marks" transform="translate(X Y)">` with coordinates in
/// board millimetres: `(X, Y)` is where point 0 (the board origin) lies on
/// the sheet, in mm from its top-left corner.
pub fn board_svg(target: &Target) -> String {
    let b = board(target);
    let spec = target.to_spec();
    // 1. Sheet layout, mm: the board at the top left inside the margin, then
    //    the check bar, then four lines of text.
    let (x0, y0, x1, y1) = b.extent;
    let (board_w, board_h) = (x1 - x0, y1 - y0);
    let (dx, dy) = (PAGE_MARGIN_MM - x0, PAGE_MARGIN_MM - y0);
    let bar_y = PAGE_MARGIN_MM + board_h + GAP_MM;
    let text_y = bar_y + CHECK_BAR_HEIGHT_MM + LINE_MM;
    let lines = [
        format!("This bar is {CHECK_BAR_MM} mm long. Measure it on the print: if it is not {CHECK_BAR_MM} mm,"),
        "print again at 100 % scale (actual size, no fit to page or scaling).".to_string(),
        format!("robocal target {spec}"),
        format!("{}. {}", description(target), origin_note(target)),
    ];
    let width = 2.0 * PAGE_MARGIN_MM + board_w.max(TEXT_WIDTH_MM).max(CHECK_BAR_MM);
    let height = text_y + (lines.len() as f64 - 1.0) * LINE_MM + PAGE_MARGIN_MM;
    let (w, h) = (num(width), num(height));

    // 2. The document: paper, board area, marks, bar, text. `write!` into a
    //    String cannot fail.
    let (paper, area, mark) = if b.light_on_dark {
        ("#fff", "#000", "#fff")
    } else {
        ("#fff", "#fff", "#000")
    };
    let mut s = String::new();
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}mm" height="{h}mm" viewBox="0 0 {w} {h}">"#
    );
    let _ = writeln!(
        s,
        "<title>robocal target {}: print at 100 % scale, then measure the {CHECK_BAR_MM} mm bar</title>",
        xml(&spec)
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="{paper}"/>"#);
    let _ = writeln!(
        s,
        r#"<rect class="board" x="{}" y="{}" width="{}" height="{}" fill="{area}"/>"#,
        num(PAGE_MARGIN_MM),
        num(PAGE_MARGIN_MM),
        num(board_w),
        num(board_h)
    );
    // The marks in board coordinates (mm, point 0 at the origin), moved
    // onto the sheet by the group's translation.
    let crisp = if b.squares.is_empty() {
        ""
    } else {
        r#" shape-rendering="crispEdges""#
    };
    let _ = writeln!(
        s,
        r#"<g class="marks" transform="translate({} {})" fill="{mark}"{crisp}>"#,
        num(dx),
        num(dy)
    );
    for (x, y, side) in &b.squares {
        let _ = writeln!(
            s,
            r#"<rect class="square" x="{}" y="{}" width="{}" height="{}"/>"#,
            num(*x),
            num(*y),
            num(*side),
            num(*side)
        );
    }
    for (x, y, r) in &b.circles {
        let _ = writeln!(
            s,
            r#"<circle class="circle" cx="{}" cy="{}" r="{}"/>"#,
            num(*x),
            num(*y),
            num(*r)
        );
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(
        s,
        r##"<rect class="check-bar" x="{}" y="{}" width="{}" height="{}" fill="#000"/>"##,
        num(PAGE_MARGIN_MM),
        num(bar_y),
        num(CHECK_BAR_MM),
        num(CHECK_BAR_HEIGHT_MM)
    );
    let _ = writeln!(
        s,
        r##"<g font-family="sans-serif" font-size="{}" fill="#000">"##,
        num(TEXT_MM)
    );
    for (k, line) in lines.iter().enumerate() {
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}">{}</text>"#,
            num(PAGE_MARGIN_MM),
            num(text_y + k as f64 * LINE_MM),
            xml(line)
        );
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(s, "</svg>");
    s
}

#[cfg(test)]
#[path = "svg_tests.rs"]
mod tests;
