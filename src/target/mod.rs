//! Calibration targets and detections: the plain-data seam between the
//! detectors (pixels in) and the solvers (correspondences out).
//!
//! # Targets and board order
//!
//! Every target numbers its points row by row from the board origin; the
//! board frame has x along a row, y from row to row and z = 0 on the board
//! plane (z points away from the printed side, i.e. into the scene when the
//! camera sees the board). Units are metres.
//!
//! | kind | points, id = `i + j * cols` | position (x, y) |
//! |---|---|---|
//! | `chessboard` | `cols x rows` inner corners | `(i, j) * square_m` |
//! | `circle_grid`, symmetric | `cols x rows` circles | `(i, j) * spacing_m` |
//! | `circle_grid`, asymmetric | `cols` circles per row, `rows` rows | `(2 i + j % 2, j) * spacing_m` (OpenCV's layout) |
//! | `dot_plate` | `cols x rows` dots | `(i, j) * pitch_m` |
//! | `single_circle` | one point, id 0 | `(0, 0)`, the circle centre |
//! | `square_grid` | `cols x rows` separate squares, 4 corners each: id = `4 (i + j * cols) + k` | square `(i, j)` spans `(i, j) * pitch_m` to that `+ side_m`; corner `k` = 0 `(x0, y0)`, 1 `(x0 + side, y0)`, 2 `(x0 + side, y0 + side)`, 3 `(x0, y0 + side)` |
//! | `charuco` | `(squares_x - 1) x (squares_y - 1)` inner chessboard corners, id = `i + j (squares_x - 1)` (OpenCV's) | `(i + 1, j + 1) * square_m` |
//! | `aprilgrid` | 4 corners per tag, Kalibr's ids (row of corners from the bottom) | see [`marker_board`] |
//! | `aruco_grid` | 4 corners per marker, id = `4 k + c` for the `k`-th marker (row by row from the top left, dictionary id `first_id + k`) and OpenCV's corner `c` | marker `(i, j)` spans `(i, j) * (marker_m + separation_m)` to that `+ marker_m`; corners as a square grid's (OpenCV's `GridBoard`, see [`marker_board`]) |
//! | `origin_dot_grid` | `cols x rows` dots, id = `i + j * cols` (ROS-Industrial's numbering: row 0 is the row farthest from the big origin dot, which is id `(rows - 1) cols`) | `(i, j) * spacing_m`; ROS-Industrial's frame (origin at the big dot, y up, z out of the print) is `(x, (rows - 1) spacing_m - y, -z)`, see [`origin_dot`] |
//!
//! A square grid's corners run square by square (row by row of squares) and,
//! within a square, clockwise on screen from the corner nearest the board
//! origin. Zhang's 1998 target (`Model.txt`, `squares:8x8:12.7mm:22.5778mm`,
//! side 0.5 inch, pitch 8/9 inch) lists its squares in the same order
//! within a row and a square, but its rows run the other way (its y axis is
//! ours minus `7 pitch + side`): Zhang's line `n` (0-based, corners `k` =
//! 0..3) is our square `n % 8 + 8 (7 - n / 8)`, i.e. id
//! `4 (n % 8 + 8 (7 - n / 8)) + k`.
//!
//! # Detection JSON
//!
//! ```json
//! {
//!   "image_size_px": [640, 480],
//!   "target": {"kind": "chessboard", "cols": 9, "rows": 6, "square_m": 0.03},
//!   "points": [
//!     {"id": 0, "x_px": 244.21, "y_px": 94.53},
//!     {"id": 1, "x_px": 274.57, "y_px": 92.96, "covariance_px2": [0.001, 0.0, 0.001]}
//!   ]
//! }
//! ```
//!
//! `points` are sorted by id; ids missing from a partial detection are simply
//! absent. `covariance_px2` (optional) is the 2x2 covariance of the point as
//! `[xx, xy, yy]` in square pixels. Pixel coordinates follow the crate
//! convention (0, 0 = centre of the top-left pixel). Other target kinds:
//! `{"kind": "circle_grid", "cols": 4, "rows": 11, "spacing_m": 0.02,
//! "asymmetric": true, "polarity": "dark_on_light"}`, `{"kind": "dot_plate",
//! "cols": 7, "rows": 7, "pitch_m": 0.025, "dot_diameter_m": 0.0125}`,
//! `{"kind": "single_circle", "diameter_m": 0.01}`, `{"kind": "square_grid",
//! "cols": 8, "rows": 8, "side_m": 0.0127, "pitch_m": 0.0225778}`,
//! `{"kind": "charuco", "squares_x": 12, "squares_y": 9, "square_m": 0.02,
//! "marker_m": 0.015, "dictionary": "DICT_5X5_100", "first_id": 0,
//! "legacy": false}` (optional `"marker_ids": [...]` instead of
//! `first_id`; `first_id` and `legacy` default to 0 and false),
//! `{"kind": "aprilgrid", "tag_cols": 6, "tag_rows": 6, "tag_m": 0.088,
//! "spacing_ratio": 0.3, "first_id": 0}` (`first_id` optional, 0 by default),
//! `{"kind": "aruco_grid", "markers_x": 5, "markers_y": 7, "marker_m": 0.04,
//! "separation_m": 0.01, "dictionary": "DICT_6X6_250", "first_id": 0}`
//! (`first_id` optional, 0 by default), `{"kind": "origin_dot_grid",
//! "cols": 10, "rows": 10, "spacing_m": 0.025}`. Marker-board detections may
//! hold any subset of the points (partial views).

use crate::error::{Error, Result};
use nalgebra::{Point2, Point3};
use serde::{Deserialize, Serialize};

/// Which way round a target is printed: a circle grid's `polarity` field,
/// a detection's `polarity` (what the detector found) and the spec options
/// `:dark-on-light` / `:light-on-dark` that force one on any kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Polarity {
    /// Dark marks (squares, circles, markers) on a light background (the
    /// usual print).
    DarkOnLight,
    /// Light marks on a dark background (the usual print inverted: backlit
    /// and laser-cut boards, caliscope's ChArUco).
    LightOnDark,
}

impl Polarity {
    /// The other print.
    pub fn other(self) -> Polarity {
        match self {
            Polarity::DarkOnLight => Polarity::LightOnDark,
            Polarity::LightOnDark => Polarity::DarkOnLight,
        }
    }

    /// The spec option that forces this print: `dark-on-light` or
    /// `light-on-dark`.
    pub fn spec_option(self) -> &'static str {
        match self {
            Polarity::DarkOnLight => "dark-on-light",
            Polarity::LightOnDark => "light-on-dark",
        }
    }

    /// The spec option `text` names, if it names one.
    pub fn from_spec_option(text: &str) -> Option<Polarity> {
        match text {
            "dark-on-light" => Some(Polarity::DarkOnLight),
            "light-on-dark" => Some(Polarity::LightOnDark),
            _ => None,
        }
    }
}

/// A calibration target's geometry (see the module docs for the point order).
///
/// In JSON an object tagged by `kind` (`{"kind": "chessboard", "cols": 9,
/// ...}`), read and written by serde's derives: an unknown kind is
/// "unknown variant `x`, expected one of `chessboard`, ...", a missing
/// field "missing field `cols`". Reading does not check sizes and counts
/// (a detection file is read as written); [`Target::validated`] does.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Target {
    /// A chessboard, counted by inner corners (a 10 x 7 squares board is 9 x 6).
    Chessboard {
        /// Inner corners along a row.
        cols: usize,
        /// Inner corners along a column.
        rows: usize,
        /// Side of one square, metres.
        square_m: f64,
    },
    /// A grid of circles, symmetric or asymmetric (OpenCV's layouts).
    CircleGrid {
        /// Circles per row.
        cols: usize,
        /// Rows of circles.
        rows: usize,
        /// Grid unit, metres: the centre distance in a symmetric grid; in an
        /// asymmetric grid half the centre distance within a row (also the
        /// row-to-row distance).
        spacing_m: f64,
        /// Rows shifted by half a period (OpenCV's asymmetric grid).
        asymmetric: bool,
        /// Dark on light or light on dark.
        polarity: Polarity,
    },
    /// A plate of dark dots on a light background (seed 004: 12.5 mm dots at
    /// 25 mm pitch).
    DotPlate {
        /// Dots per row.
        cols: usize,
        /// Rows of dots.
        rows: usize,
        /// Centre distance, metres.
        pitch_m: f64,
        /// Dot diameter, metres.
        dot_diameter_m: f64,
    },
    /// One dark circle on a light background (seed 002's XY-table target).
    SingleCircle {
        /// Circle diameter, metres.
        diameter_m: f64,
    },
    /// A grid of separate dark squares on a light background, four corners
    /// per square (Zhang's 1998 target: 8 x 8 squares).
    SquareGrid {
        /// Squares per row.
        cols: usize,
        /// Rows of squares.
        rows: usize,
        /// Side of one square, metres.
        side_m: f64,
        /// Distance between neighbouring squares' origins, metres (larger
        /// than the side: the squares do not touch).
        pitch_m: f64,
    },
    /// A ChArUco board as OpenCV 4.6+ defines it ([`marker_board`] docs).
    Charuco {
        /// Chessboard squares along a row (OpenCV's squaresX).
        squares_x: usize,
        /// Chessboard squares along a column (OpenCV's squaresY).
        squares_y: usize,
        /// Side of one square, metres.
        square_m: f64,
        /// Side of one marker (its black border included), metres.
        marker_m: f64,
        /// The markers' dictionary.
        dictionary: Dictionary,
        /// Id of the first marker (the others follow); 0 by default.
        #[serde(default)]
        first_id: usize,
        /// Explicit marker ids in board order, instead of `first_id`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        marker_ids: Option<Vec<usize>>,
        /// The layout of boards made before OpenCV 4.6 (differs for an
        /// even `squares_y`).
        #[serde(default)]
        legacy: bool,
    },
    /// A Kalibr AprilGrid of tag36h11 tags ([`marker_board`] docs).
    Aprilgrid {
        /// Tags along a row (Kalibr's tagCols).
        tag_cols: usize,
        /// Rows of tags (Kalibr's tagRows).
        tag_rows: usize,
        /// Side of one tag, edge to edge, metres (Kalibr's tagSize).
        tag_m: f64,
        /// Gap between tags over the tag side (Kalibr's tagSpacing).
        spacing_ratio: f64,
        /// Id of tag 0 (0 in Kalibr; a second board printed with the next
        /// ids has `first_id` = the first board's tag count).
        #[serde(default)]
        first_id: usize,
    },
    /// OpenCV's ArUco `GridBoard`: a grid of markers and nothing else
    /// ([`marker_board`] docs).
    ArucoGrid {
        /// Markers along a row (OpenCV's size.width, markersX).
        markers_x: usize,
        /// Rows of markers (OpenCV's size.height, markersY).
        markers_y: usize,
        /// Side of one marker (its black border included), metres.
        marker_m: f64,
        /// Gap between neighbouring markers, metres (markerSeparation).
        separation_m: f64,
        /// The markers' dictionary.
        dictionary: Dictionary,
        /// Id of the top-left marker (the others follow row by row); 0 by
        /// default.
        #[serde(default)]
        first_id: usize,
    },
    /// ROS-Industrial's modified circle grid: a symmetric grid of dark dots
    /// whose origin dot is twice as large ([`origin_dot`] docs).
    OriginDotGrid {
        /// Dots per row.
        cols: usize,
        /// Rows of dots.
        rows: usize,
        /// Centre distance, metres.
        spacing_m: f64,
    },
}

/// One detected target point in pixels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DetectedPoint {
    /// Board id (see [`Target::object_points`]).
    pub id: usize,
    /// Column coordinate, pixels.
    pub x_px: f64,
    /// Row coordinate, pixels.
    pub y_px: f64,
    /// Covariance `[xx, xy, yy]`, square pixels, when the detector estimates it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub covariance_px2: Option<[f64; 3]>,
}

/// A target found in one image: what the solvers consume.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Detection {
    /// `[width, height]` of the image, pixels.
    pub image_size_px: [u32; 2],
    /// The target that was searched for.
    pub target: Target,
    /// Detected points, sorted by id.
    pub points: Vec<DetectedPoint>,
    /// Circle grids and dot plates: which point of each imaged circle the
    /// points are (absent for other targets and in files written before
    /// the key existed, whose circle centres are ellipse centres).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_model: Option<CentreModel>,
    /// The print the detector found the target in (written by every
    /// detection; absent in files written before the key existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarity: Option<Polarity>,
}

impl Detection {
    /// Board points (metres) paired with their pixels, in id order.
    pub fn correspondences(&self) -> (Vec<Point3<f64>>, Vec<Point2<f64>>) {
        let board = self.target.object_points();
        let mut object = Vec::with_capacity(self.points.len());
        let mut image = Vec::with_capacity(self.points.len());
        for p in &self.points {
            // Ids are positions on most targets; a board whose ids start
            // elsewhere (a marker board's first id) is searched by id.
            let by_id = board
                .get(p.id)
                .filter(|(id, _)| *id == p.id)
                .or_else(|| board.iter().find(|(id, _)| *id == p.id));
            if let Some((_, o)) = by_id {
                object.push(*o);
                image.push(Point2::new(p.x_px, p.y_px));
            }
        }
        (object, image)
    }
}

impl Target {
    /// Check sizes and counts; returns the target unchanged when valid.
    pub fn validated(self) -> Result<Target> {
        let (cols, rows, min) = match &self {
            Target::Chessboard { cols, rows, .. } => (*cols, *rows, 2),
            Target::CircleGrid { cols, rows, .. } | Target::DotPlate { cols, rows, .. } => {
                (*cols, *rows, 2)
            }
            Target::SingleCircle { .. } => (1, 1, 1),
            Target::SquareGrid { cols, rows, .. } => (*cols, *rows, 2),
            Target::Charuco {
                squares_x,
                squares_y,
                ..
            } => (*squares_x, *squares_y, 2),
            Target::Aprilgrid {
                tag_cols, tag_rows, ..
            } => (*tag_cols, *tag_rows, 1),
            Target::ArucoGrid {
                markers_x,
                markers_y,
                ..
            } => (*markers_x, *markers_y, 1),
            Target::OriginDotGrid { cols, rows, .. } => (*cols, *rows, 2),
        };
        // Square grids and AprilGrids have four points per square or tag.
        let per_cell = match &self {
            Target::SquareGrid { .. } | Target::Aprilgrid { .. } | Target::ArucoGrid { .. } => 4,
            Target::Charuco { .. } | Target::OriginDotGrid { .. } => 1,
            Target::Chessboard { .. }
            | Target::CircleGrid { .. }
            | Target::DotPlate { .. }
            | Target::SingleCircle { .. } => 1,
        };
        if cols < min || rows < min || cols.saturating_mul(rows).saturating_mul(per_cell) > 100_000
        {
            return Err(Error::invalid(
                "target",
                format!(
                    "a grid needs 2 to 100000 points with at least 2 per side, got {cols}x{rows}"
                ),
            ));
        }
        let lengths: Vec<(&str, f64)> = match &self {
            Target::Chessboard { square_m, .. } => vec![("square size", *square_m)],
            Target::CircleGrid { spacing_m, .. } => vec![("circle spacing", *spacing_m)],
            Target::DotPlate {
                pitch_m,
                dot_diameter_m,
                ..
            } => vec![("dot pitch", *pitch_m), ("dot diameter", *dot_diameter_m)],
            Target::SingleCircle { diameter_m } => vec![("circle diameter", *diameter_m)],
            Target::SquareGrid {
                side_m, pitch_m, ..
            } => vec![("square side", *side_m), ("square pitch", *pitch_m)],
            Target::Charuco {
                square_m, marker_m, ..
            } => vec![("square side", *square_m), ("marker side", *marker_m)],
            Target::Aprilgrid { tag_m, .. } => vec![("tag size", *tag_m)],
            Target::ArucoGrid {
                marker_m,
                separation_m,
                ..
            } => vec![
                ("marker side", *marker_m),
                ("marker separation", *separation_m),
            ],
            Target::OriginDotGrid { spacing_m, .. } => vec![("dot spacing", *spacing_m)],
        };
        if let Some((name, l)) = lengths.iter().find(|(_, l)| !l.is_finite() || *l <= 0.0) {
            let got = if l.is_finite() {
                format!("{} mm", crate::error::compact(l * 1000.0))
            } else {
                l.to_string()
            };
            return Err(Error::invalid(
                "target",
                format!("the {name} must be a positive length, got {got}"),
            ));
        }
        if let Target::DotPlate {
            pitch_m,
            dot_diameter_m,
            ..
        } = &self
        {
            if dot_diameter_m >= pitch_m {
                return Err(Error::invalid(
                    "target",
                    "the dot diameter must be smaller than the pitch",
                ));
            }
        }
        if let Target::SquareGrid {
            side_m, pitch_m, ..
        } = &self
        {
            if side_m >= pitch_m {
                return Err(Error::invalid(
                    "target",
                    "the square side must be smaller than the pitch (the squares must not touch)",
                ));
            }
        }
        marker_board::validate(&self)?;
        Ok(self)
    }

    /// Number of points the target has.
    pub fn point_count(&self) -> usize {
        match self {
            Target::Chessboard { cols, rows, .. }
            | Target::CircleGrid { cols, rows, .. }
            | Target::DotPlate { cols, rows, .. } => cols * rows,
            Target::SingleCircle { .. } => 1,
            Target::SquareGrid { cols, rows, .. } => 4 * cols * rows,
            Target::Charuco {
                squares_x,
                squares_y,
                ..
            } => (squares_x.saturating_sub(1)) * (squares_y.saturating_sub(1)),
            Target::Aprilgrid {
                tag_cols, tag_rows, ..
            } => 4 * tag_cols * tag_rows,
            Target::ArucoGrid {
                markers_x,
                markers_y,
                ..
            } => 4 * markers_x * markers_y,
            Target::OriginDotGrid { cols, rows, .. } => cols * rows,
        }
    }

    /// Integer board coordinates of every point in id order (metres are these
    /// times [`Target::unit_m`]); for square grids, of every square's origin
    /// in square order (the corners are in [`Target::object_points`]); for
    /// AprilGrids and ArUco grids, of every tag's or marker's top-left corner
    /// in units of the marker pitch, row by row from the top.
    pub(crate) fn grid_coords(&self) -> Vec<(i32, i32)> {
        if let Target::Charuco {
            squares_x,
            squares_y,
            ..
        } = self
        {
            let (cols, rows) = (*squares_x as i32 - 1, *squares_y as i32 - 1);
            return (0..rows)
                .flat_map(|j| (0..cols).map(move |i| (i + 1, j + 1)))
                .collect();
        }
        let (cols, rows) = match self {
            Target::Chessboard { cols, rows, .. }
            | Target::CircleGrid { cols, rows, .. }
            | Target::DotPlate { cols, rows, .. }
            | Target::SquareGrid { cols, rows, .. }
            | Target::OriginDotGrid { cols, rows, .. } => (*cols as i32, *rows as i32),
            Target::Aprilgrid {
                tag_cols, tag_rows, ..
            } => (*tag_cols as i32, *tag_rows as i32),
            Target::ArucoGrid {
                markers_x,
                markers_y,
                ..
            } => (*markers_x as i32, *markers_y as i32),
            Target::SingleCircle { .. } | Target::Charuco { .. } => (1, 1),
        };
        let asymmetric = matches!(
            self,
            Target::CircleGrid {
                asymmetric: true,
                ..
            }
        );
        let mut out = Vec::with_capacity((cols * rows) as usize);
        for j in 0..rows {
            for i in 0..cols {
                out.push(if asymmetric {
                    (2 * i + j % 2, j)
                } else {
                    (i, j)
                });
            }
        }
        out
    }

    /// Length of one grid unit, metres.
    pub(crate) fn unit_m(&self) -> f64 {
        match self {
            Target::Chessboard { square_m, .. } => *square_m,
            Target::CircleGrid { spacing_m, .. } => *spacing_m,
            Target::DotPlate { pitch_m, .. } | Target::SquareGrid { pitch_m, .. } => *pitch_m,
            Target::SingleCircle { .. } => 1.0,
            Target::Charuco { square_m, .. } => *square_m,
            Target::Aprilgrid {
                tag_m,
                spacing_ratio,
                ..
            } => (1.0 + spacing_ratio) * tag_m,
            Target::ArucoGrid {
                marker_m,
                separation_m,
                ..
            } => marker_m + separation_m,
            Target::OriginDotGrid { spacing_m, .. } => *spacing_m,
        }
    }

    /// Board points `(id, position in metres, z = 0)` in id order.
    pub fn object_points(&self) -> Vec<(usize, Point3<f64>)> {
        let unit = self.unit_m();
        let cells = self.grid_coords().into_iter();
        match self {
            Target::SquareGrid { side_m, .. }
            | Target::ArucoGrid {
                marker_m: side_m, ..
            } => cells
                .flat_map(|(i, j)| {
                    let (x0, y0) = (i as f64 * unit, j as f64 * unit);
                    SQUARE_CORNERS.map(|(u, v)| Point3::new(x0 + u * side_m, y0 + v * side_m, 0.0))
                })
                .enumerate()
                .collect(),
            Target::Aprilgrid {
                tag_cols,
                tag_rows,
                tag_m,
                spacing_ratio,
                ..
            } => (0..self.point_count())
                .map(|id| {
                    let p = marker_board::aprilgrid_point(
                        id,
                        *tag_cols,
                        *tag_rows,
                        *tag_m,
                        *spacing_ratio,
                    );
                    (id, p)
                })
                .collect(),
            Target::Chessboard { .. }
            | Target::OriginDotGrid { .. }
            | Target::Charuco { .. }
            | Target::CircleGrid { .. }
            | Target::DotPlate { .. }
            | Target::SingleCircle { .. } => cells
                .enumerate()
                .map(|(id, (x, y))| (id, Point3::new(x as f64 * unit, y as f64 * unit, 0.0)))
                .collect(),
        }
    }
}

/// A square's corners `k = 0..3` in units of its side, from its origin:
/// clockwise on screen when the board is seen from the front.
pub(crate) const SQUARE_CORNERS: [(f64, f64); 4] = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];

mod centre_model;
pub mod dictionary;
pub mod marker_board;
pub mod origin_dot;
pub mod placement;
mod spec;
pub mod svg;

pub use centre_model::CentreModel;
pub use dictionary::Dictionary;

#[cfg(test)]
mod grid_boards_tests;
#[cfg(test)]
mod tests;
