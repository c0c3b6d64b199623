//! ROS-Industrial's modified circle grid (`circles:COLSxROWS:PITCH:origin-dot`).
//!
//! Source: ros-industrial/industrial_calibration,
//! `target_finders/opencv/src/modified_circle_grid_target_finder.cpp`
//! (`ModifiedCircleGridTarget::createPoints`, the corner-size comparison
//! in `extractKeyPoints`) and the header's description of the target, with
//! the print of `target_finders/opencv/script/modified_circle_grid_target_generator.py`.
//!
//! # The print
//!
//! `cols x rows` dark dots on white at `spacing_m` centre distance, the
//! generator's defaults scaled to the pitch: dots [`DOT_DIAMETER_RATIO`]
//! of the pitch across (10 mm at 25 mm), the origin dot twice that
//! ([`ORIGIN_DOT_SCALE`]; the generator draws it with radius `dotSize`
//! where the others have `dotSize / 2`). Seen from the printed side the
//! origin dot is the bottom-left one. (The generator also punches a white
//! pin-hole, 3 % of the dot size, into every dot; robocal's sheet and
//! renderer leave it out, and the detector fits the dots' outer edges, so
//! prints with or without it read the same.)
//!
//! ROS-Industrial's target configuration `{rows: R, cols: C, spacing: S}`
//! (metres; `ModifiedCircleGridTargetFinderFactory`) is the spec
//! `circles:CxR:S:origin-dot` here (columns first, as every robocal grid).
//!
//! # Numbering and frame
//!
//! ROS-Industrial numbers the dots row by row starting with the row
//! farthest from the origin dot, left to right: point `i + j cols` is
//! column `i` of row `j`, and the origin dot is point `(rows - 1) cols`
//! (the first of the last row). robocal keeps these ids.
//!
//! ROS-Industrial's target frame has its origin at the centre of the big
//! dot, x along its row (towards increasing ids), y up the print towards
//! row 0 and z out of the printed side: point `i + j cols` is at
//! `(i, rows - 1 - j) spacing`. robocal places the points as every other
//! grid of the crate ([`crate::target`], as it does for Kalibr's AprilGrid):
//! origin at point 0's centre (the top-left dot), x along a row, y down the
//! print from row to row, z into the board, point `i + j cols` at `(i, j)
//! spacing`; the origin dot is at `(0, H)` with `H = (rows - 1) spacing`.
//! The two frames differ by a half turn about x and a shift of `H`:
//! `ros (x, y, z) = (x, H - y, -z)`, i.e. `ros_from_robocal` has rotation
//! `diag(1, -1, -1)` and translation `(0, H, 0)` (a board pose from robocal
//! `camera_from_board` is ROS-Industrial's `camera_from_target` times
//! `ros_from_robocal`).
//!
//! The origin dot fixes the orientation: the grid is read the same way
//! when it is seen upside down (turned 180 degrees), and a square grid
//! in any of its four turns.

/// Dot diameter over the pitch (the generator's 10 mm dots at its default
/// 25 mm spacing).
pub const DOT_DIAMETER_RATIO: f64 = 0.4;
/// The origin dot's diameter over the other dots'.
pub const ORIGIN_DOT_SCALE: f64 = 2.0;

/// Id of the origin dot of a grid with `cols` dots per row and `rows` rows.
pub fn origin_id(cols: usize, rows: usize) -> usize {
    rows.saturating_sub(1) * cols
}

/// Radius of dot `id` in metres.
pub fn dot_radius_m(id: usize, cols: usize, rows: usize, spacing_m: f64) -> f64 {
    let r = 0.5 * DOT_DIAMETER_RATIO * spacing_m;
    if id == origin_id(cols, rows) {
        ORIGIN_DOT_SCALE * r
    } else {
        r
    }
}
