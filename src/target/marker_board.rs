//! Marker boards: ChArUco and the ArUco GridBoard as OpenCV 4.6+ defines
//! them and AprilGrid as Kalibr defines it. Specs, checks, board points and the printed layout that the
//! SVG sheet, the renderer and the detector share.
//!
//! # ChArUco (`cv::aruco::CharucoBoard`)
//!
//! `squares_x x squares_y` chessboard squares of side `square_m`, the board
//! origin at the outer top-left corner, x right, y down. Square `(x, y)` is
//! black when `x % 2 == y % 2` (the top-left square is black); a white
//! square holds a marker of side `marker_m` centred in it, drawn at its
//! rotation 0 (the marker's top-left bit at the square's top-left) with a
//! one-bit black border. Markers are numbered row by row from the top over
//! the white squares and take ids `first_id, first_id + 1, ...` (or the
//! explicit `marker_ids`). Points are the inner chessboard corners, id
//! `i + j (squares_x - 1)` at `((i + 1), (j + 1)) * square_m`: OpenCV's
//! `getChessboardCorners` order, so poses compare with OpenCV's.
//!
//! `legacy`: boards made with OpenCV before 4.6 differ when `squares_y` is
//! even: the top-left square is white (black when `(y + 1) % 2 == x % 2`),
//! OpenCV's `setLegacyPattern(true)`. For odd `squares_y` both layouts are
//! the same.
//!
//! # AprilGrid (Kalibr's `GridCalibrationTargetAprilgrid`)
//!
//! `tag_cols x tag_rows` AprilTag 36h11 tags of side `tag_m` (the black
//! square, edge to edge, with Kalibr's two-bit black border), `spacing_ratio
//! * tag_m` apart, black squares of the spacing's side at every tag corner.
//! Kalibr prints tag 0 at the bottom left, ids growing to the right, then
//! upwards, each tag at OpenCV's `DICT_APRILTAG_36h11` bits turned half a
//! turn. Points are Kalibr's: four per tag, point `r * 2 tag_cols + c` for
//! row `r` of corners counted from the bottom and column `c` from the left
//! (a tag's corners are bottom-left, bottom-right, top-left + 2 tag_cols,
//! ...). Tag ids start at `first_id` (0 in Kalibr; spec option `first=N`
//! for a second board printed with the next ids). Positions follow this crate's board frame (x right, y down on the
//! print, z into it), with the origin at the top-left tag's top-left
//! corner: `x = (c / 2) pitch + (c % 2) tag_m`, `y = H - ((r / 2) pitch + (r %
//! 2) tag_m)` with `pitch = (1 + spacing_ratio) tag_m` and `H = (tag_rows -
//! 1) pitch + tag_m`. Kalibr's frame (origin at tag 0's bottom-left corner,
//! y up, z out of the print) is this one turned half a turn about x and
//! shifted by `H`: `kalibr (x, y, z) = (x, H - y, -z)`.
//!
//! # ArUco grid (`cv::aruco::GridBoard`)
//!
//! `markers_x x markers_y` markers of side `marker_m` (black border
//! included), `separation_m` apart, nothing else printed. OpenCV's
//! constructor (`modules/objdetect/src/aruco/aruco_board.cpp`, 4.6+) puts
//! marker `k = x + y markers_x` (row by row from the top left) at top-left
//! corner `(x, y) (marker_m + separation_m)`, its corners 0..3 at that
//! `+ (0, 0)`, `(marker_m, 0)`, `(marker_m, marker_m)`, `(0, marker_m)`
//! (top-left, top-right, bottom-right, bottom-left on the print: the
//! marker's own corner order at rotation 0), with id `first_id + k` (OpenCV's
//! default ids are `0..`, a board made with explicit consecutive ids
//! `N, N+1, ...` is `first=N`). So the board frame is OpenCV's and this
//! crate's: origin at the top-left marker's top-left corner, x right, y
//! down the print, z into it; poses compare with OpenCV's
//! `estimatePoseBoard`/`solvePnP` on `matchImagePoints` directly. (OpenCV's
//! aruco module before 4.6 had y up from the bottom row instead.) Points
//! are the markers' corners, point id `4 k + c` for corner `c` of marker
//! `k` (the square grid's scheme: marker id `first_id + k` corner `c` is
//! point `4 (id - first_id) + c`). Markers are printed with OpenCV's
//! one-bit border (`generateImage`'s default `borderBits`).

use super::dictionary::Dictionary;
use super::Target;
use crate::error::{Error, Result};
use nalgebra::{Point2, Point3};

/// Kalibr's black border around an AprilGrid tag's bits, in bits.
pub const APRILGRID_BORDER_BITS: usize = 2;
/// OpenCV's black border around a ChArUco marker's bits, in bits.
pub const CHARUCO_BORDER_BITS: usize = 1;
/// OpenCV's black border around a GridBoard marker's bits, in bits.
pub const ARUCO_GRID_BORDER_BITS: usize = 1;

/// One marker as printed: its dictionary id and its corners in board metres
/// in the marker's own order (top-left, top-right, bottom-right,
/// bottom-left of the marker image at rotation 0, OpenCV's order).
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedMarker {
    /// Dictionary id.
    pub id: usize,
    /// Corners, metres, z = 0.
    pub corners: [Point2<f64>; 4],
}

/// Which points of the board a marker's corners are, for AprilGrids (the
/// tag corners themselves); for ChArUco boards the chessboard corners
/// around the marker's square.
#[derive(Debug, Clone, PartialEq)]
pub struct MarkerLayout {
    /// The markers' dictionary.
    pub dictionary: Dictionary,
    /// Black border width, bits.
    pub border_bits: usize,
    /// Every marker, in dictionary-id order of the board.
    pub markers: Vec<PlacedMarker>,
    /// `(x0, y0, x1, y1)` of the printed board with its white quiet zone,
    /// metres.
    pub extent: (f64, f64, f64, f64),
}

/// The marker-board checks of [`Target::validated`] (after the common grid
/// and length checks).
pub(super) fn validate(target: &Target) -> Result<()> {
    let bad = |m: String| Err(Error::invalid("target", m));
    match target {
        Target::Charuco {
            squares_x,
            squares_y,
            square_m,
            marker_m,
            dictionary,
            first_id,
            marker_ids,
            ..
        } => {
            if marker_m >= square_m {
                return bad(format!(
                    "the marker side ({} mm) must be smaller than the square side ({} mm)",
                    marker_m * 1000.0,
                    square_m * 1000.0
                ));
            }
            let needed = charuco_marker_count(*squares_x, *squares_y);
            match marker_ids {
                Some(ids) => {
                    if *first_id != 0 {
                        return bad("give either first=N or ids=..., not both".into());
                    }
                    if ids.len() != needed {
                        return bad(format!(
                            "a {squares_x}x{squares_y} ChArUco board has {needed} markers, got {} ids",
                            ids.len()
                        ));
                    }
                    if let Some(id) = ids.iter().find(|&&id| id >= dictionary.len()) {
                        return bad(format!(
                            "marker id {id} is not in {} (ids 0 to {})",
                            dictionary.name(),
                            dictionary.len() - 1
                        ));
                    }
                    let mut sorted = ids.clone();
                    sorted.sort_unstable();
                    if sorted.windows(2).any(|w| w[0] == w[1]) {
                        return bad("the marker ids must be distinct".into());
                    }
                }
                None => {
                    if first_id.saturating_add(needed) > dictionary.len() {
                        return bad(format!(
                            "too many markers: a {squares_x}x{squares_y} ChArUco board needs {needed} markers from id {first_id}, but {} has {} (use a larger dictionary or fewer squares)",
                            dictionary.name(),
                            dictionary.len()
                        ));
                    }
                }
            }
            Ok(())
        }
        Target::Aprilgrid {
            tag_cols,
            tag_rows,
            spacing_ratio,
            first_id,
            ..
        } => {
            if !(spacing_ratio.is_finite() && *spacing_ratio > 0.0 && *spacing_ratio <= 1.0) {
                return bad(format!(
                    "the AprilGrid spacing ratio must be in (0, 1] (Kalibr's tagSpacing), got {}",
                    crate::error::compact(*spacing_ratio)
                ));
            }
            let d = Dictionary::DICT_APRILTAG_36h11;
            if first_id.saturating_add(tag_cols * tag_rows) > d.len() {
                return bad(format!(
                    "too many tags: a {tag_cols}x{tag_rows} AprilGrid needs {} tag36h11 tags from id {first_id}, the family has {}",
                    tag_cols * tag_rows,
                    d.len()
                ));
            }
            Ok(())
        }
        Target::ArucoGrid {
            markers_x,
            markers_y,
            dictionary,
            first_id,
            ..
        } => {
            let needed = markers_x * markers_y;
            if first_id.saturating_add(needed) > dictionary.len() {
                return bad(format!(
                    "too many markers: a {markers_x}x{markers_y} ArUco grid needs {needed} markers from id {first_id}, but {} has {} (use a larger dictionary or fewer markers)",
                    dictionary.name(),
                    dictionary.len()
                ));
            }
            Ok(())
        }
        Target::Chessboard { .. }
        | Target::CircleGrid { .. }
        | Target::DotPlate { .. }
        | Target::SingleCircle { .. }
        | Target::SquareGrid { .. }
        | Target::OriginDotGrid { .. } => Ok(()),
    }
}

/// Markers on a ChArUco board: its white squares.
pub fn charuco_marker_count(squares_x: usize, squares_y: usize) -> usize {
    squares_x * squares_y / 2
}

/// Whether ChArUco square `(x, y)` is black (see the module docs).
pub fn charuco_square_is_black(x: usize, y: usize, squares_y: usize, legacy: bool) -> bool {
    if legacy && squares_y % 2 == 0 {
        (y + 1) % 2 == x % 2
    } else {
        y % 2 == x % 2
    }
}

/// Kalibr's AprilGrid point `(x, y)` in this crate's board frame.
pub fn aprilgrid_point(
    id: usize,
    tag_cols: usize,
    tag_rows: usize,
    tag_m: f64,
    spacing: f64,
) -> Point3<f64> {
    let corner_cols = 2 * tag_cols;
    let (r, c) = (id / corner_cols, id % corner_cols);
    let pitch = (1.0 + spacing) * tag_m;
    let height = (tag_rows as f64 - 1.0) * pitch + tag_m;
    let x = (c / 2) as f64 * pitch + (c % 2) as f64 * tag_m;
    let y_up = (r / 2) as f64 * pitch + (r % 2) as f64 * tag_m;
    Point3::new(x, height - y_up, 0.0)
}

/// The board's markers and print extent; `None` for targets without
/// markers.
pub fn layout(target: &Target) -> Option<MarkerLayout> {
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
            let inset = 0.5 * (square_m - marker_m);
            let mut markers = Vec::new();
            for y in 0..*squares_y {
                for x in 0..*squares_x {
                    if charuco_square_is_black(x, y, *squares_y, *legacy) {
                        continue;
                    }
                    let k = markers.len();
                    let id = match marker_ids {
                        Some(ids) => ids.get(k).copied().unwrap_or(k),
                        None => first_id + k,
                    };
                    let x0 = x as f64 * square_m + inset;
                    let y0 = y as f64 * square_m + inset;
                    markers.push(PlacedMarker {
                        id,
                        corners: square_corners(x0, y0, *marker_m),
                    });
                }
            }
            let (w, h) = (*squares_x as f64 * square_m, *squares_y as f64 * square_m);
            Some(MarkerLayout {
                dictionary: *dictionary,
                border_bits: CHARUCO_BORDER_BITS,
                markers,
                extent: (-square_m, -square_m, w + square_m, h + square_m),
            })
        }
        Target::Aprilgrid {
            tag_cols,
            tag_rows,
            tag_m,
            spacing_ratio,
            first_id,
        } => {
            let pitch = (1.0 + spacing_ratio) * tag_m;
            let mut markers = Vec::new();
            for k in 0..tag_cols * tag_rows {
                let id = first_id + k;
                let (i, row_up) = (k % tag_cols, k / tag_cols);
                let j = tag_rows - 1 - row_up;
                // The printed tag is OpenCV's marker turned half a turn: its
                // own top-left corner is the printed bottom-right.
                let [tl, tr, br, bl] = square_corners(i as f64 * pitch, j as f64 * pitch, *tag_m);
                markers.push(PlacedMarker {
                    id,
                    corners: [br, bl, tl, tr],
                });
            }
            let gap = spacing_ratio * tag_m;
            let (w, h) = (
                (*tag_cols as f64 - 1.0) * pitch + tag_m,
                (*tag_rows as f64 - 1.0) * pitch + tag_m,
            );
            let quiet = gap + 0.5 * tag_m;
            Some(MarkerLayout {
                dictionary: Dictionary::DICT_APRILTAG_36h11,
                border_bits: APRILGRID_BORDER_BITS,
                markers,
                extent: (-quiet, -quiet, w + quiet, h + quiet),
            })
        }
        Target::ArucoGrid {
            markers_x,
            markers_y,
            marker_m,
            separation_m,
            dictionary,
            first_id,
        } => {
            let pitch = marker_m + separation_m;
            let markers = (0..markers_x * markers_y)
                .map(|k| {
                    let (x, y) = ((k % markers_x) as f64, (k / markers_x) as f64);
                    PlacedMarker {
                        id: first_id + k,
                        corners: square_corners(x * pitch, y * pitch, *marker_m),
                    }
                })
                .collect();
            let (w, h) = (
                *markers_x as f64 * pitch - separation_m,
                *markers_y as f64 * pitch - separation_m,
            );
            let quiet = separation_m + 0.5 * marker_m;
            Some(MarkerLayout {
                dictionary: *dictionary,
                border_bits: ARUCO_GRID_BORDER_BITS,
                markers,
                extent: (-quiet, -quiet, w + quiet, h + quiet),
            })
        }
        Target::Chessboard { .. }
        | Target::CircleGrid { .. }
        | Target::DotPlate { .. }
        | Target::SingleCircle { .. }
        | Target::SquareGrid { .. }
        | Target::OriginDotGrid { .. } => None,
    }
}

/// Corners of an axis-aligned square from its top-left, clockwise on the
/// print (y down).
fn square_corners(x0: f64, y0: f64, side: f64) -> [Point2<f64>; 4] {
    [
        Point2::new(x0, y0),
        Point2::new(x0 + side, y0),
        Point2::new(x0 + side, y0 + side),
        Point2::new(x0, y0 + side),
    ]
}

/// Dark squares `(x, y, side)` of the print in board metres, besides the
/// markers' own cells: ChArUco's black chessboard squares, AprilGrid's
/// corner squares.
pub fn dark_squares(target: &Target) -> Vec<(f64, f64, f64)> {
    match target {
        Target::Charuco {
            squares_x,
            squares_y,
            square_m,
            legacy,
            ..
        } => {
            let mut out = Vec::new();
            for y in 0..*squares_y {
                for x in 0..*squares_x {
                    if charuco_square_is_black(x, y, *squares_y, *legacy) {
                        out.push((x as f64 * square_m, y as f64 * square_m, *square_m));
                    }
                }
            }
            out
        }
        Target::Aprilgrid {
            tag_cols,
            tag_rows,
            tag_m,
            spacing_ratio,
            ..
        } => {
            let pitch = (1.0 + spacing_ratio) * tag_m;
            let gap = spacing_ratio * tag_m;
            let mut out = Vec::new();
            for j in 0..=*tag_rows {
                for i in 0..=*tag_cols {
                    out.push((i as f64 * pitch - gap, j as f64 * pitch - gap, gap));
                }
            }
            out
        }
        Target::ArucoGrid { .. }
        | Target::Chessboard { .. }
        | Target::CircleGrid { .. }
        | Target::DotPlate { .. }
        | Target::SingleCircle { .. }
        | Target::SquareGrid { .. }
        | Target::OriginDotGrid { .. } => Vec::new(),
    }
}

/// A marker's printed cells: `(row, col, dark)` over the `(n + 2 border)^2`
/// grid of the marker image at rotation 0 (border cells dark, bit 1 white).
pub fn marker_cell_dark(code: u64, bits: usize, border: usize, row: usize, col: usize) -> bool {
    let side = bits + 2 * border;
    if row < border || col < border || row >= side - border || col >= side - border {
        return true;
    }
    let (r, c) = (row - border, col - border);
    (code >> (bits * bits - 1 - (r * bits + c))) & 1 == 0
}

/// The printed board as a function of board coordinates, for the renderer:
/// dark or light at any point (built once, constant time per point).
#[derive(Debug, Clone)]
pub struct Print {
    layout: MarkerLayout,
    dark_squares: Vec<(f64, f64, f64)>,
    codes: Vec<u64>,
    /// Cell size of the lookup grid (ChArUco square, AprilGrid pitch),
    /// metres, its origin and its columns and rows: every marker and dark
    /// square lies in one cell (an AprilGrid cell holds a tag and the
    /// corner square above-left of it).
    cell_m: f64,
    origin: (f64, f64),
    grid: (usize, usize),
    /// Marker index per lookup cell, row-major.
    cell_marker: Vec<Option<usize>>,
    /// Dark square index per lookup cell (ChArUco squares; AprilGrid
    /// corner squares are found from the cell below-right of them).
    cell_square: Vec<Option<usize>>,
}

impl Print {
    /// The print of a marker board; `None` for other targets.
    pub fn new(target: &Target) -> Option<Print> {
        let layout = layout(target)?;
        let dark_squares = dark_squares(target);
        let cell_m = target.unit_m();
        let origin = match target {
            Target::Aprilgrid {
                tag_m,
                spacing_ratio,
                ..
            } => (-spacing_ratio * tag_m, -spacing_ratio * tag_m),
            Target::Charuco { .. }
            | Target::ArucoGrid { .. }
            | Target::Chessboard { .. }
            | Target::CircleGrid { .. }
            | Target::DotPlate { .. }
            | Target::SingleCircle { .. }
            | Target::SquareGrid { .. }
            | Target::OriginDotGrid { .. } => (0.0, 0.0),
        };
        let (_, _, x1, y1) = layout.extent;
        let gx = ((x1 - origin.0) / cell_m).ceil() as usize + 1;
        let gy = ((y1 - origin.1) / cell_m).ceil() as usize + 1;
        let mut print = Print {
            codes: layout
                .markers
                .iter()
                .map(|m| layout.dictionary.code(m.id).unwrap_or(0))
                .collect(),
            layout,
            dark_squares,
            cell_m,
            origin,
            grid: (gx, gy),
            cell_marker: vec![None; gx * gy],
            cell_square: vec![None; gx * gy],
        };
        for (k, m) in print.layout.markers.iter().enumerate() {
            let c = (m.corners[0] + m.corners[2].coords) * 0.5;
            if let Some(cell) = print.cell(c.x, c.y) {
                print.cell_marker[cell] = Some(k);
            }
        }
        for (k, &(x, y, side)) in print.dark_squares.iter().enumerate() {
            if let Some(cell) = print.cell(x + 0.5 * side, y + 0.5 * side) {
                print.cell_square[cell] = Some(k);
            }
        }
        Some(print)
    }

    /// The board's markers and extent.
    pub fn layout(&self) -> &MarkerLayout {
        &self.layout
    }

    fn cell(&self, x: f64, y: f64) -> Option<usize> {
        let (x0, y0) = self.origin;
        let i = ((x - x0) / self.cell_m).floor();
        let j = ((y - y0) / self.cell_m).floor();
        let (gx, gy) = self.grid;
        (i >= 0.0 && j >= 0.0 && (i as usize) < gx && (j as usize) < gy)
            .then(|| j as usize * gx + i as usize)
    }

    /// Whether the print is dark at board point `(x, y)` (metres; light
    /// outside the board, in its quiet zone).
    pub fn dark_at(&self, x: f64, y: f64) -> bool {
        let Some(cell) = self.cell(x, y) else {
            return false;
        };
        if let Some(k) = self.cell_square[cell] {
            let (sx, sy, side) = self.dark_squares[k];
            if x >= sx && x < sx + side && y >= sy && y < sy + side {
                return true;
            }
        }
        if let Some(k) = self.cell_marker[cell] {
            return self.marker_dark(k, x, y);
        }
        false
    }

    fn marker_dark(&self, k: usize, x: f64, y: f64) -> bool {
        let m = &self.layout.markers[k];
        let [c0, c1, _, c3] = m.corners;
        let (ex, ey) = (c1 - c0, c3 - c0);
        let side2 = ex.norm_squared();
        let d = Point2::new(x, y) - c0;
        let s = d.dot(&ex) / side2;
        let t = d.dot(&ey) / side2;
        if !(0.0..1.0).contains(&s) || !(0.0..1.0).contains(&t) {
            return false;
        }
        let bits = self.layout.dictionary.marker_bits();
        let n = bits + 2 * self.layout.border_bits;
        let col = ((s * n as f64) as usize).min(n - 1);
        let row = ((t * n as f64) as usize).min(n - 1);
        marker_cell_dark(self.codes[k], bits, self.layout.border_bits, row, col)
    }
}

#[cfg(test)]
#[path = "marker_board_tests.rs"]
mod tests;
