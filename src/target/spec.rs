//! Target specs as the CLI and the page write them (`chessboard:9x6:30mm`,
//! `charuco:12x9:20mm:15mm:DICT_5X5_100`, ...): parsing and writing back.

use super::*;

impl Target {
    /// Parse a CLI target spec: `chessboard:9x6:30mm`,
    /// `circles:4x11:20mm[:asymmetric]`, `dots:7x7:25mm[:12.5mm]`
    /// (dot diameter defaults to half the pitch), `circle:10mm`,
    /// `squares:8x8:12.7mm:22.5778mm` (squares per row x rows, side, pitch),
    /// `charuco:12x9:20mm:15mm:DICT_5X5_100[:first=N][:ids=A,B,...][:legacy]`
    /// (squares, square side, marker side, OpenCV dictionary name; first
    /// marker id, explicit marker ids, the pre-4.6 layout),
    /// `aprilgrid:6x6:88mm:0.3` (tags, tag size, spacing ratio, as Kalibr),
    /// `arucogrid:5x7:40mm:10mm:DICT_6X6_250[:first=N]` (OpenCV's GridBoard:
    /// markers, marker side, separation, dictionary; first marker id),
    /// `circles:10x10:25mm:origin-dot` (ROS-Industrial's modified circle
    /// grid: dots, pitch; the origin dot is twice as large).
    /// Lengths take a unit: `mm`, `cm` or `m`. Any spec may add
    /// `:dark-on-light` or `:light-on-dark` (see [`Target::parse_spec_print`]);
    /// this function keeps only the geometry (and a circle grid's polarity).
    pub fn parse_spec(spec: &str) -> Result<Target> {
        Ok(Target::parse_spec_print(spec)?.0)
    }

    /// Parse a CLI target spec ([`Target::parse_spec`]) with its print
    /// option: `:dark-on-light` or `:light-on-dark` anywhere after the kind
    /// forces the detector to that print (`DetectOptions::polarity`);
    /// without one the detector finds the print itself. A circle grid's
    /// `polarity` field takes the option too.
    pub fn parse_spec_print(spec: &str) -> Result<(Target, Option<Polarity>)> {
        let all: Vec<&str> = spec.trim().split(':').collect();
        let mut print: Option<Polarity> = None;
        let mut parts = Vec::with_capacity(all.len());
        for (k, part) in all.iter().enumerate() {
            match Polarity::from_spec_option(part) {
                Some(p) if k > 0 => {
                    if print.is_some_and(|q| q != p) {
                        return Err(Error::invalid(
                            "target",
                            format!(
                                "'{spec}' asks for both dark-on-light and light-on-dark; give one"
                            ),
                        ));
                    }
                    print = Some(p);
                }
                _ => parts.push(*part),
            }
        }
        let mut target = parse_parts(spec, &parts)?;
        if let (Target::CircleGrid { polarity, .. }, Some(p)) = (&mut target, print) {
            *polarity = p;
        }
        Ok((target, print))
    }
}

/// The geometry of a spec split at ':' (print options taken out).
fn parse_parts(spec: &str, parts: &[&str]) -> Result<Target> {
    let bad = |m: String| Error::invalid("target", m);
    match parts {
            ["chessboard", grid, size] => {
                let (cols, rows) = parse_grid(grid)?;
                Target::Chessboard {
                    cols,
                    rows,
                    square_m: parse_length(size)?,
                }
                .validated()
            }
            ["circles", grid, size, flags @ ..] if flags.contains(&"origin-dot") => {
                parse_origin_dot(spec, grid, size, flags)
            }
            ["circles", grid, size, flags @ ..] => {
                let (cols, rows) = parse_grid(grid)?;
                let mut asymmetric = false;
                // The print option was taken out by `parse_spec_print`.
                let polarity = Polarity::DarkOnLight;
                for f in flags {
                    match *f {
                        "asymmetric" => asymmetric = true,
                        "symmetric" => asymmetric = false,
                        other => {
                            return Err(bad(format!(
                                "unknown circle-grid option '{other}' (expected asymmetric, symmetric, dark-on-light, light-on-dark or origin-dot)"
                            )))
                        }
                    }
                }
                Target::CircleGrid {
                    cols,
                    rows,
                    spacing_m: parse_length(size)?,
                    asymmetric,
                    polarity,
                }
                .validated()
            }
            ["dots", grid, pitch, rest @ ..] if rest.len() <= 1 => {
                let (cols, rows) = parse_grid(grid)?;
                let pitch_m = parse_length(pitch)?;
                let dot_diameter_m = match rest.first() {
                    Some(d) => parse_length(d)?,
                    None => pitch_m / 2.0,
                };
                Target::DotPlate {
                    cols,
                    rows,
                    pitch_m,
                    dot_diameter_m,
                }
                .validated()
            }
            ["circle", d] => Target::SingleCircle {
                diameter_m: parse_length(d)?,
            }
            .validated(),
            ["squares", grid, side, pitch] => {
                let (cols, rows) = parse_grid(grid)?;
                Target::SquareGrid {
                    cols,
                    rows,
                    side_m: parse_length(side)?,
                    pitch_m: parse_length(pitch)?,
                }
                .validated()
            }
            ["charuco", rest @ ..] => parse_charuco(spec, rest),
            ["aprilgrid", rest @ ..] => parse_aprilgrid(spec, rest),
            ["arucogrid", rest @ ..] => parse_aruco_grid(spec, rest),
            ["squares", ..] => Err(bad(format!(
                "'{spec}' is not a square-grid spec; expected squares:COLSxROWS:SIDE:PITCH (e.g. squares:8x8:12.7mm:22.5778mm)"
            ))),
            _ => Err(bad(format!(
                "'{spec}' is not a target spec; expected chessboard:COLSxROWS:SIZE, circles:COLSxROWS:SIZE[:asymmetric], dots:COLSxROWS:PITCH[:DIAMETER], squares:COLSxROWS:SIDE:PITCH, charuco:SQUARESXxSQUARESY:SQUARE:MARKER:DICTIONARY, aprilgrid:TAGCOLSxTAGROWS:TAGSIZE:SPACINGRATIO, arucogrid:COLSxROWS:MARKER:SEPARATION:DICTIONARY, circles:COLSxROWS:PITCH:origin-dot or circle:DIAMETER (e.g. chessboard:9x6:30mm)"
            ))),
        }
}

impl Target {
    /// The CLI spec of this target, the inverse of [`Target::parse_spec`]:
    /// `parse_spec(&t.to_spec())` gives `t` back bit for bit. Lengths are
    /// written in millimetres with the fewest decimals that read back to
    /// the same metres (metres when no such decimal exists); a dot plate's
    /// diameter is left out when it is the default (half the pitch).
    pub fn to_spec(&self) -> String {
        match self {
            Target::Chessboard {
                cols,
                rows,
                square_m,
            } => format!("chessboard:{cols}x{rows}:{}", spec_length(*square_m)),
            Target::CircleGrid {
                cols,
                rows,
                spacing_m,
                asymmetric,
                polarity,
            } => {
                let layout = if *asymmetric { ":asymmetric" } else { "" };
                let print = match polarity {
                    Polarity::DarkOnLight => "",
                    Polarity::LightOnDark => ":light-on-dark",
                };
                format!(
                    "circles:{cols}x{rows}:{}{layout}{print}",
                    spec_length(*spacing_m)
                )
            }
            Target::DotPlate {
                cols,
                rows,
                pitch_m,
                dot_diameter_m,
            } => {
                let pitch = spec_length(*pitch_m);
                if *dot_diameter_m == pitch_m / 2.0 {
                    format!("dots:{cols}x{rows}:{pitch}")
                } else {
                    format!(
                        "dots:{cols}x{rows}:{pitch}:{}",
                        spec_length(*dot_diameter_m)
                    )
                }
            }
            Target::SingleCircle { diameter_m } => format!("circle:{}", spec_length(*diameter_m)),
            Target::SquareGrid {
                cols,
                rows,
                side_m,
                pitch_m,
            } => format!(
                "squares:{cols}x{rows}:{}:{}",
                spec_length(*side_m),
                spec_length(*pitch_m)
            ),
            Target::OriginDotGrid {
                cols,
                rows,
                spacing_m,
            } => format!(
                "circles:{cols}x{rows}:{}:origin-dot",
                spec_length(*spacing_m)
            ),
            Target::Charuco { .. } | Target::Aprilgrid { .. } | Target::ArucoGrid { .. } => {
                marker_board_spec(self).unwrap_or_default()
            }
        }
    }
}

fn parse_grid(text: &str) -> Result<(usize, usize)> {
    let err = || {
        Error::invalid(
            "target",
            format!("'{text}' is not a grid size; expected COLSxROWS such as 9x6"),
        )
    };
    let (c, r) = text.split_once(['x', 'X']).ok_or_else(err)?;
    Ok((c.parse().map_err(|_| err())?, r.parse().map_err(|_| err())?))
}

/// Most decimals a spec length is written with in millimetres (a
/// nanometre); a length that needs more is written in metres.
const SPEC_MM_DECIMALS: usize = 6;

/// A length for a spec: millimetres with the fewest decimals that
/// [`parse_length`] reads back to exactly `m`, else metres (Rust's shortest
/// round-trip decimal).
fn spec_length(m: f64) -> String {
    for decimals in 0..=SPEC_MM_DECIMALS {
        let text = format!("{:.*}", decimals, m * 1000.0);
        if parse_length(&format!("{text}mm")).ok() == Some(m) {
            return format!("{text}mm");
        }
    }
    format!("{m}m")
}

fn parse_length(text: &str) -> Result<f64> {
    let (number, exponent) = if let Some(n) = text.strip_suffix("mm") {
        (n, -3)
    } else if let Some(n) = text.strip_suffix("cm") {
        (n, -2)
    } else if let Some(n) = text.strip_suffix('m') {
        (n, 0)
    } else {
        return Err(Error::invalid(
            "target",
            format!("length '{text}' needs a unit: mm, cm or m (e.g. 30mm)"),
        ));
    };
    let v = number
        .parse::<f64>()
        .ok()
        .ok_or_else(|| Error::invalid("target", format!("'{text}' is not a length")))?;
    // The decimal shifted to metres and rounded once (22.5778mm -> the
    // double nearest 0.0225778, not 22.5778 * 0.001 = 0.022577800000000002),
    // so that a spec and the JSON it is written to compare equal.
    if exponent == 0 || number.contains(['e', 'E']) {
        return Ok(v * 10f64.powi(exponent));
    }
    Ok(format!("{number}e{exponent}")
        .parse::<f64>()
        .ok()
        .unwrap_or(v * 10f64.powi(exponent)))
}

// Marker boards: ChArUco and AprilGrid (layouts in `marker_board`).

/// Parse `GRID:SQUARE:MARKER:DICT[:first=N][:ids=A,B,...][:legacy]`.
fn parse_charuco(spec: &str, rest: &[&str]) -> Result<Target> {
    let bad = |m: String| Error::invalid("target", m);
    let [grid, square, marker, dict, options @ ..] = rest else {
        return Err(bad(format!(
            "'{spec}' is not a ChArUco spec; expected charuco:SQUARESXxSQUARESY:SQUARE:MARKER:DICTIONARY[:first=N][:ids=A,B,...][:legacy] (e.g. charuco:12x9:20mm:15mm:DICT_5X5_100)"
        )));
    };
    let (squares_x, squares_y) = parse_grid(grid)?;
    let mut first_id = 0;
    let mut marker_ids = None;
    let mut legacy = false;
    for option in options {
        if *option == "legacy" {
            legacy = true;
        } else if let Some(n) = option.strip_prefix("first=") {
            first_id = n
                .parse()
                .map_err(|_| bad(format!("'{n}' is not a marker id (first=N)")))?;
        } else if let Some(list) = option.strip_prefix("ids=") {
            let ids: std::result::Result<Vec<usize>, _> =
                list.split(',').map(|s| s.trim().parse()).collect();
            marker_ids = Some(ids.map_err(|_| {
                bad(format!(
                    "'{list}' is not a list of marker ids (ids=A,B,...)"
                ))
            })?);
        } else {
            return Err(bad(format!(
                "unknown ChArUco option '{option}' (expected first=N, ids=A,B,... or legacy)"
            )));
        }
    }
    Target::Charuco {
        squares_x,
        squares_y,
        square_m: parse_length(square)?,
        marker_m: parse_length(marker)?,
        dictionary: Dictionary::from_name(dict)?,
        first_id,
        marker_ids,
        legacy,
    }
    .validated()
}

/// Parse `COLSxROWS:TAG:SPACING_RATIO[:first=N]`.
fn parse_aprilgrid(spec: &str, rest: &[&str]) -> Result<Target> {
    let (grid, tag, spacing, first) = match rest {
        [grid, tag, spacing] => (grid, tag, spacing, None),
        [grid, tag, spacing, option] => (grid, tag, spacing, Some(option)),
        _ => {
            return Err(Error::invalid(
                "target",
                format!("'{spec}' is not an AprilGrid spec; expected aprilgrid:TAGCOLSxTAGROWS:TAGSIZE:SPACINGRATIO[:first=N] (e.g. aprilgrid:6x6:88mm:0.3)"),
            ))
        }
    };
    let first_id = match first {
        None => 0,
        Some(option) => option
            .strip_prefix("first=")
            .and_then(|n| n.parse().ok())
            .ok_or_else(|| {
                Error::invalid(
                    "target",
                    format!(
                        "unknown AprilGrid option '{option}' (expected first=N, the id of tag 0)"
                    ),
                )
            })?,
    };
    let (tag_cols, tag_rows) = parse_grid(grid)?;
    let spacing_ratio = spacing.parse::<f64>().map_err(|_| {
        Error::invalid(
            "target",
            format!(
                "'{spacing}' is not a spacing ratio; expected the gap over the tag size, e.g. 0.3"
            ),
        )
    })?;
    Target::Aprilgrid {
        tag_cols,
        tag_rows,
        tag_m: parse_length(tag)?,
        spacing_ratio,
        first_id,
    }
    .validated()
}

/// The spec of a ChArUco board or an AprilGrid (`None` for other kinds).
fn marker_board_spec(target: &Target) -> Option<String> {
    match target {
        Target::Charuco {
            squares_x,
            squares_y,
            square_m,
            marker_m,
            dictionary,
            first_id,
            marker_ids,
            legacy,
        } => {
            let mut s = format!(
                "charuco:{squares_x}x{squares_y}:{}:{}:{}",
                spec_length(*square_m),
                spec_length(*marker_m),
                dictionary.name()
            );
            if *first_id != 0 {
                s += &format!(":first={first_id}");
            }
            if let Some(ids) = marker_ids {
                let list: Vec<String> = ids.iter().map(|i| i.to_string()).collect();
                s += &format!(":ids={}", list.join(","));
            }
            if *legacy {
                s += ":legacy";
            }
            Some(s)
        }
        Target::Aprilgrid {
            tag_cols,
            tag_rows,
            tag_m,
            spacing_ratio,
            first_id,
        } => {
            let first = if *first_id == 0 {
                String::new()
            } else {
                format!(":first={first_id}")
            };
            Some(format!(
                "aprilgrid:{tag_cols}x{tag_rows}:{}:{spacing_ratio}{first}",
                spec_length(*tag_m)
            ))
        }
        Target::ArucoGrid {
            markers_x,
            markers_y,
            marker_m,
            separation_m,
            dictionary,
            first_id,
        } => {
            let first = if *first_id == 0 {
                String::new()
            } else {
                format!(":first={first_id}")
            };
            Some(format!(
                "arucogrid:{markers_x}x{markers_y}:{}:{}:{}{first}",
                spec_length(*marker_m),
                spec_length(*separation_m),
                dictionary.name()
            ))
        }
        Target::Chessboard { .. }
        | Target::CircleGrid { .. }
        | Target::DotPlate { .. }
        | Target::SingleCircle { .. }
        | Target::SquareGrid { .. }
        | Target::OriginDotGrid { .. } => None,
    }
}

/// Parse `arucogrid:COLSxROWS:MARKER:SEPARATION:DICT[:first=N]`.
fn parse_aruco_grid(spec: &str, rest: &[&str]) -> Result<Target> {
    let bad = |m: String| Error::invalid("target", m);
    let (grid, marker, separation, dict, first) = match rest {
        [grid, marker, separation, dict] => (grid, marker, separation, dict, None),
        [grid, marker, separation, dict, option] => (grid, marker, separation, dict, Some(option)),
        _ => {
            return Err(bad(format!(
                "'{spec}' is not an ArUco grid spec; expected arucogrid:COLSxROWS:MARKER:SEPARATION:DICTIONARY[:first=N] (e.g. arucogrid:5x7:40mm:10mm:DICT_6X6_250)"
            )))
        }
    };
    let first_id = match first {
        None => 0,
        Some(option) => {
            let n = option.strip_prefix("first=").ok_or_else(|| {
                bad(format!(
                    "unknown ArUco grid option '{option}' (expected first=N, the id of the top-left marker)"
                ))
            })?;
            n.parse()
                .map_err(|_| bad(format!("'{n}' is not a marker id (first=N)")))?
        }
    };
    let (markers_x, markers_y) = parse_grid(grid)?;
    Target::ArucoGrid {
        markers_x,
        markers_y,
        marker_m: parse_length(marker)?,
        separation_m: parse_length(separation)?,
        dictionary: Dictionary::from_name(dict)?,
        first_id,
    }
    .validated()
}

/// Parse `circles:COLSxROWS:PITCH:origin-dot` (ROS-Industrial's modified
/// circle grid: symmetric, no other option than the print, which
/// [`Target::parse_spec_print`] takes off first).
fn parse_origin_dot(spec: &str, grid: &str, pitch: &str, flags: &[&str]) -> Result<Target> {
    if flags != ["origin-dot"] {
        return Err(Error::invalid(
            "target",
            format!(
                "'{spec}' is not an origin-dot grid spec; expected circles:COLSxROWS:PITCH:origin-dot with no other option than the print (:dark-on-light or :light-on-dark; ROS-Industrial's grid is symmetric; e.g. circles:10x10:25mm:origin-dot)"
            ),
        ));
    }
    let (cols, rows) = parse_grid(grid)?;
    Target::OriginDotGrid {
        cols,
        rows,
        spacing_m: parse_length(pitch)?,
    }
    .validated()
}
