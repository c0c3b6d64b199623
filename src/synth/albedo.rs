//! The board as the renderer sees it: the grey level of the print (and of
//! the wall beyond it) at any point of the board plane, for every target
//! kind (`super::render`'s module doc says how each is printed).

use crate::synth::RenderOptions;
use crate::target::{Polarity, Target};

/// Grey level of the scene at board coordinates (metres).
pub(crate) struct Albedo {
    target: Target,
    black: f64,
    white: f64,
    pub(crate) background: f64,
    radius_m: f64,
    extent: (f64, f64, f64, f64),
    /// Largest integer board coordinates (x, y).
    max_coord: (i64, i64),
    /// Marker boards' print.
    print: Option<crate::target::marker_board::Print>,
}

impl Albedo {
    pub(crate) fn new(target: &Target, o: &RenderOptions) -> Albedo {
        let unit = target.unit_m();
        let coords = target.grid_coords();
        let maxx = coords.iter().map(|c| c.0).max().unwrap_or(0) as f64 * unit;
        let maxy = coords.iter().map(|c| c.1).max().unwrap_or(0) as f64 * unit;
        let (radius_m, extent) = match target {
            Target::Chessboard { square_m, .. } => (
                0.0,
                (
                    -2.0 * square_m,
                    -2.0 * square_m,
                    maxx + 2.0 * square_m,
                    maxy + 2.0 * square_m,
                ),
            ),
            Target::CircleGrid { spacing_m, .. } => (
                0.5 * o.circle_diameter_ratio * spacing_m,
                (-spacing_m, -spacing_m, maxx + spacing_m, maxy + spacing_m),
            ),
            Target::DotPlate {
                pitch_m,
                dot_diameter_m,
                ..
            } => (
                0.5 * dot_diameter_m,
                (-pitch_m, -pitch_m, maxx + pitch_m, maxy + pitch_m),
            ),
            Target::SingleCircle { diameter_m } => (
                0.5 * diameter_m,
                (
                    -2.0 * diameter_m,
                    -2.0 * diameter_m,
                    2.0 * diameter_m,
                    2.0 * diameter_m,
                ),
            ),
            Target::SquareGrid {
                side_m, pitch_m, ..
            } => (
                0.0,
                (
                    -pitch_m,
                    -pitch_m,
                    maxx + side_m + pitch_m,
                    maxy + side_m + pitch_m,
                ),
            ),
            Target::OriginDotGrid { spacing_m, .. } => (
                0.5 * crate::target::origin_dot::DOT_DIAMETER_RATIO * spacing_m,
                (-spacing_m, -spacing_m, maxx + spacing_m, maxy + spacing_m),
            ),
            Target::Charuco { .. } | Target::Aprilgrid { .. } | Target::ArucoGrid { .. } => (
                0.0,
                crate::target::marker_board::layout(target)
                    .map_or((0.0, 0.0, 0.0, 0.0), |l| l.extent),
            ),
        };
        Albedo {
            target: target.clone(),
            black: o.black,
            white: o.white,
            background: o.background,
            radius_m,
            extent,
            max_coord: (
                coords.iter().map(|c| c.0).max().unwrap_or(0) as i64,
                coords.iter().map(|c| c.1).max().unwrap_or(0) as i64,
            ),
            print: crate::target::marker_board::Print::new(target),
        }
    }

    pub(crate) fn at(&self, q: Option<(f64, f64)>) -> f64 {
        let Some((x, y)) = q else {
            return self.background;
        };
        let (x0, y0, x1, y1) = self.extent;
        if x < x0 || y < y0 || x > x1 || y > y1 {
            return self.background;
        }
        match &self.target {
            Target::Chessboard {
                cols,
                rows,
                square_m,
            } => {
                let (i, j) = ((x / square_m).floor() as i64, (y / square_m).floor() as i64);
                let on_squares = i >= -1 && j >= -1 && i < *cols as i64 && j < *rows as i64;
                if on_squares && (i + j).rem_euclid(2) == 0 {
                    self.black
                } else {
                    self.white
                }
            }
            Target::CircleGrid { polarity, .. } => {
                let inside = self.in_dot(x, y);
                let dark = inside == (*polarity == Polarity::DarkOnLight);
                if dark {
                    self.black
                } else {
                    self.white
                }
            }
            Target::DotPlate { .. }
            | Target::SingleCircle { .. }
            | Target::OriginDotGrid { .. } => {
                if self.in_dot(x, y) {
                    self.black
                } else {
                    self.white
                }
            }
            Target::SquareGrid {
                cols,
                rows,
                side_m,
                pitch_m,
            } => {
                let (i, j) = ((x / pitch_m).floor(), (y / pitch_m).floor());
                let (u, v) = (x - i * pitch_m, y - j * pitch_m);
                let on_grid = i >= 0.0 && j >= 0.0 && i < *cols as f64 && j < *rows as f64;
                if on_grid && u < *side_m && v < *side_m {
                    self.black
                } else {
                    self.white
                }
            }
            Target::Charuco { .. } | Target::Aprilgrid { .. } | Target::ArucoGrid { .. } => {
                if self.print.as_ref().is_some_and(|p| p.dark_at(x, y)) {
                    self.black
                } else {
                    self.white
                }
            }
        }
    }

    fn in_dot(&self, x: f64, y: f64) -> bool {
        let unit = self.target.unit_m();
        let r2 = self.radius_m * self.radius_m;
        if let Target::SingleCircle { .. } = self.target {
            return x * x + y * y < r2;
        }
        if let Target::OriginDotGrid {
            rows, spacing_m, ..
        } = self.target
        {
            // The origin dot, twice as large, first (it reaches past the
            // 3x3 neighbourhood's own dots).
            let (ox, oy) = (0.0, (rows as f64 - 1.0) * spacing_m);
            let big = crate::target::origin_dot::ORIGIN_DOT_SCALE * self.radius_m;
            if (x - ox).powi(2) + (y - oy).powi(2) < big * big {
                return true;
            }
        }
        // Nearest grid points: check the 3x3 integer neighbourhood.
        let (gx, gy) = ((x / unit).round() as i64, (y / unit).round() as i64);
        let (cols_max, rows_max) = self.max_coord;
        let asym = matches!(
            self.target,
            Target::CircleGrid {
                asymmetric: true,
                ..
            }
        );
        for dy in -1..=1 {
            for dx in -1..=1 {
                let (cx, cy) = (gx + dx, gy + dy);
                if cx < 0
                    || cy < 0
                    || cx > cols_max
                    || cy > rows_max
                    || (asym && (cx + cy) % 2 != 0)
                {
                    continue;
                }
                let (px, py) = (cx as f64 * unit, cy as f64 * unit);
                if (x - px).powi(2) + (y - py).powi(2) < r2 {
                    return true;
                }
            }
        }
        false
    }
}
