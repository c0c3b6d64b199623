//! Which views a planar solver can use. A view may hold any subset of the
//! target's points (a marker board partly out of the image or occluded);
//! it is usable when its board points fix a homography: at least
//! [`MIN_POINTS_PER_VIEW`], and no line holding all of them but at most
//! one (then some 4 of them have no 3 on a line, which a homography needs).
//! Views that fail are left out with a message naming the view and why;
//! only too few remaining views is an error (the caller's).

use super::View;
use nalgebra::Point2;

/// Fewest points of a view that can fix a homography.
pub const MIN_POINTS_PER_VIEW: usize = 4;

/// Distance from a line, relative to the extent of the view's board points,
/// below which a point counts as on the line. Board coordinates are exact
/// multiples of the grid unit (rounding about 1e-16 relative), and a point
/// off a grid line is off by at least one unit, i.e. by more than 1e-5 of
/// the extent of the largest target (100,000 points); 1e-9 sits between the
/// two with margin on both sides.
pub const COLLINEAR_TOLERANCE: f64 = 1e-9;

/// Why a view's board points (target frame, z = 0) cannot fix a homography,
/// or `None` when they can.
pub fn homography_problem(board: &[Point2<f64>]) -> Option<String> {
    let n = board.len();
    if n < MIN_POINTS_PER_VIEW {
        let points = if n == 1 { "point" } else { "points" };
        return Some(format!(
            "{n} {points}: a homography needs at least {MIN_POINTS_PER_VIEW}"
        ));
    }
    if board.iter().any(|p| !(p.x.is_finite() && p.y.is_finite())) {
        return Some("a board point is not finite".to_string());
    }
    let extent = board
        .iter()
        .flat_map(|p| board.first().map(|q| (p - q).norm()))
        .fold(0.0, f64::max);
    let tolerance = COLLINEAR_TOLERANCE * extent;
    // A line holding all points but at most one holds at least two of any
    // three distinct points: it is the line through two of the first three.
    let distinct = distinct_points(board, 3, tolerance);
    let [a, b, c] = match distinct.as_slice() {
        [a, b, c] => [*a, *b, *c],
        _ => {
            return Some(format!(
                "its {n} points are at fewer than 3 places: {NEEDS}"
            ))
        }
    };
    let most = [(a, b), (a, c), (b, c)]
        .into_iter()
        .map(|(p, q)| on_line(board, p, q, tolerance))
        .max()
        .unwrap_or(0);
    if most == n {
        Some(format!("its {n} points lie on one line: {NEEDS}"))
    } else if most + 1 == n {
        Some(format!("{most} of its {n} points lie on one line: {NEEDS}"))
    } else {
        None
    }
}

/// |z| above which a target point is off the plane z = 0, metres (as in
/// Zhang's validation).
const PLANE_TOLERANCE_M: f64 = 1e-9;

/// What a homography needs, said after each degenerate case.
const NEEDS: &str = "a homography needs 4 points with no 3 on one line";

/// The first `k` points at least `tolerance` apart from each other.
fn distinct_points(points: &[Point2<f64>], k: usize, tolerance: f64) -> Vec<Point2<f64>> {
    let mut out: Vec<Point2<f64>> = Vec::with_capacity(k);
    for p in points {
        if out.len() == k {
            break;
        }
        if out.iter().all(|q| (p - q).norm() > tolerance) {
            out.push(*p);
        }
    }
    out
}

/// How many points lie within `tolerance` of the line through `p` and `q`.
fn on_line(points: &[Point2<f64>], p: Point2<f64>, q: Point2<f64>, tolerance: f64) -> usize {
    let d = q - p;
    let length = d.norm();
    points
        .iter()
        .filter(|r| {
            let e = **r - p;
            (d.x * e.y - d.y * e.x).abs() <= tolerance * length
        })
        .count()
}

/// A view left out of a solve, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct LeftOut {
    /// Position of the view in the input.
    pub index: usize,
    /// The view's name.
    pub name: String,
    /// Why it cannot be used.
    pub reason: String,
}

impl LeftOut {
    /// `view NAME left out: REASON`, the warning of a report.
    pub fn warning(&self) -> String {
        format!("view {} left out: {}", self.name, self.reason)
    }
}

/// The views whose board points fix a homography, and the others with the
/// reason. Views with a point off the plane z = 0 (a 3-D rig for the DLT)
/// are kept: the planar solvers refuse them with their own message.
pub fn usable_views(views: &[View]) -> (Vec<View>, Vec<LeftOut>) {
    let mut usable = Vec::with_capacity(views.len());
    let mut left_out = Vec::new();
    for (index, v) in views.iter().enumerate() {
        let board: Vec<Point2<f64>> = v.object_m.iter().map(|p| p.xy()).collect();
        let planar = v.object_m.iter().all(|p| p.z.abs() <= PLANE_TOLERANCE_M);
        match homography_problem(&board).filter(|_| planar) {
            None => usable.push(v.clone()),
            Some(reason) => left_out.push(LeftOut {
                index,
                name: v.name.clone(),
                reason,
            }),
        }
    }
    (usable, left_out)
}

/// `; left out: view a (reason), view b (reason)` for an error message, or
/// nothing when no view was left out.
pub fn left_out_clause(left_out: &[LeftOut]) -> String {
    if left_out.is_empty() {
        return String::new();
    }
    let list: Vec<String> = left_out
        .iter()
        .map(|l| format!("view {} ({})", l.name, l.reason))
        .collect();
    format!("; left out: {}", list.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn grid(cells: &[(i32, i32)]) -> Vec<Point2<f64>> {
        cells
            .iter()
            .map(|&(i, j)| Point2::new(0.03 * i as f64, 0.03 * j as f64))
            .collect()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn a_homography_needs_four_points_off_any_one_line() {
        assert_eq!(
            homography_problem(&grid(&[(0, 0), (1, 0), (0, 1)])),
            Some("3 points: a homography needs at least 4".to_string())
        );
        assert_eq!(
            homography_problem(&grid(&[(0, 2), (1, 2), (2, 2), (5, 2), (8, 2)])),
            Some(
                "its 5 points lie on one line: a homography needs 4 points with no 3 on one line"
                    .to_string()
            )
        );
        // A diagonal, with the odd point first (the line is not through it).
        assert_eq!(
            homography_problem(&grid(&[(3, 0), (0, 0), (1, 1), (2, 2), (4, 4)])),
            Some(
                "4 of its 5 points lie on one line: a homography needs 4 points with no 3 on one line"
                    .to_string()
            )
        );
        assert_eq!(
            homography_problem(&grid(&[(1, 1), (1, 1), (1, 1), (1, 1)])),
            Some(
                "its 4 points are at fewer than 3 places: a homography needs 4 points with no 3 \
                 on one line"
                    .to_string()
            )
        );
        // Two points off a long row are enough; so is a square.
        let mut row: Vec<(i32, i32)> = (0..50).map(|i| (i, 0)).collect();
        row.extend([(10, 1), (40, 1)]);
        assert_eq!(homography_problem(&grid(&row)), None);
        assert_eq!(
            homography_problem(&grid(&[(0, 0), (1, 0), (0, 1), (1, 1)])),
            None
        );
    }
}
