//! Growing a 2-D lattice of points from a seed, and matching a grown lattice
//! to a target's board coordinates (the ordering rule).
//!
//! Growth: a missing cell's position is predicted from its known neighbours
//! (extrapolation along rows/columns, quadratic where three cells line up,
//! and parallelogram completion, averaged), which follows perspective and
//! lens distortion locally; the nearest free point within 30% of the local
//! step is taken if `accept` agrees. Matching tries the 8
//! rotations/reflections of the lattice axes (composed with a 45-degree
//! change of basis for asymmetric grids).

use nalgebra::{Point2, Vector2};
use std::collections::{HashMap, HashSet, VecDeque};
use std::hash::{BuildHasherDefault, Hasher};

/// Fraction of the local grid step within which a point may be taken.
const SEARCH_FRACTION: f64 = 0.3;

/// Bucketed points for radius queries.
pub(crate) struct PointIndex<'a> {
    points: &'a [Point2<f64>],
    cell: f64,
    cols: usize,
    rows: usize,
    buckets: Vec<Vec<usize>>,
}

impl<'a> PointIndex<'a> {
    pub fn new(points: &'a [Point2<f64>], cell: f64) -> Self {
        let cell = cell.max(1.0);
        let maxx = points.iter().map(|p| p.x).fold(0.0, f64::max);
        let maxy = points.iter().map(|p| p.y).fold(0.0, f64::max);
        let cols = ((maxx / cell) as usize + 1).min(4096);
        let rows = ((maxy / cell) as usize + 1).min(4096);
        let mut buckets = vec![Vec::new(); cols * rows];
        for (i, p) in points.iter().enumerate() {
            let (bx, by) = Self::bucket(cell, cols, rows, p);
            buckets[by * cols + bx].push(i);
        }
        PointIndex {
            points,
            cell,
            cols,
            rows,
            buckets,
        }
    }

    fn bucket(cell: f64, cols: usize, rows: usize, p: &Point2<f64>) -> (usize, usize) {
        // `as usize` saturates: negatives and NaN give 0 (an `f64::max`
        // here was a call to `fmax` per lookup in the wasm build).
        let bx = ((p.x / cell) as usize).min(cols - 1);
        let by = ((p.y / cell) as usize).min(rows - 1);
        (bx, by)
    }

    /// Indices of points within `radius` of `q`, nearest first.
    pub fn within(&self, q: &Point2<f64>, radius: f64) -> Vec<usize> {
        let lo = Self::bucket(
            self.cell,
            self.cols,
            self.rows,
            &(q - Vector2::repeat(radius)),
        );
        let hi = Self::bucket(
            self.cell,
            self.cols,
            self.rows,
            &(q + Vector2::repeat(radius)),
        );
        let mut found: Vec<(f64, usize)> = Vec::new();
        for by in lo.1..=hi.1 {
            for bx in lo.0..=hi.0 {
                for &i in &self.buckets[by * self.cols + bx] {
                    let d = (self.points[i] - q).norm();
                    if d <= radius {
                        found.push((d, i));
                    }
                }
            }
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0));
        found.into_iter().map(|(_, i)| i).collect()
    }
}

/// A grown lattice: cell (a, b) -> point index.
pub(crate) type Cells = CellMap<usize>;

/// A map keyed by lattice cells, with [`CellHasher`].
pub(crate) type CellMap<V> = HashMap<(i32, i32), V, BuildHasherDefault<CellHasher>>;

/// A multiply-rotate hasher for small integer keys: several times cheaper
/// than the default SipHash (no untrusted keys here), and deterministic,
/// so iteration order does not change between runs.
#[derive(Default, Clone, Copy)]
pub(crate) struct CellHasher(u64);

impl CellHasher {
    const K: u64 = 0x517c_c1b7_2722_0a95;
    #[inline]
    fn add(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(Self::K);
    }
}

impl Hasher for CellHasher {
    fn write(&mut self, bytes: &[u8]) {
        bytes.iter().for_each(|&b| self.add(b as u64));
    }
    #[inline]
    fn write_i32(&mut self, v: i32) {
        self.add(v as u32 as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// Local axes at a cell being added: steps along a and b, image pixels.
pub(crate) struct Prediction {
    pub pos: Point2<f64>,
    pub step_a: Vector2<f64>,
    pub step_b: Vector2<f64>,
}

/// Whether the point at an index may take a lattice cell, given the cell's
/// predicted position.
pub(crate) type Accept<'a> = dyn Fn(usize, (i32, i32), &Prediction) -> bool + 'a;

/// Grow from `seed` with initial steps `step_a`, `step_b`. `accept(point,
/// cell, prediction)` vets a point for a cell. Stops at `max_cells`.
pub(crate) fn grow(
    index: &PointIndex,
    seed: usize,
    step_a: Vector2<f64>,
    step_b: Vector2<f64>,
    max_cells: usize,
    accept: &Accept,
) -> Cells {
    let pts = index.points;
    let mut cells = Cells::default();
    let mut used = vec![false; pts.len()];
    cells.insert((0, 0), seed);
    used[seed] = true;
    let mut queue: VecDeque<(i32, i32)> = VecDeque::new();
    let mut tried: CellMap<u8> = CellMap::default();
    push_neighbours(&mut queue, (0, 0));
    while let Some(cell) = queue.pop_front() {
        if cells.contains_key(&cell) || cells.len() >= max_cells {
            continue;
        }
        let t = tried.entry(cell).or_insert(0);
        if *t >= 2 {
            continue;
        }
        *t += 1;
        let Some(pred) = predict(pts, &cells, cell, step_a, step_b) else {
            continue;
        };
        let step = pred.step_a.norm().min(pred.step_b.norm());
        let radius = SEARCH_FRACTION * step;
        let hit = index
            .within(&pred.pos, radius)
            .into_iter()
            .find(|&i| !used[i] && accept(i, cell, &pred));
        if let Some(i) = hit {
            cells.insert(cell, i);
            used[i] = true;
            push_neighbours(&mut queue, cell);
            // Earlier failures next to this cell may succeed now.
            for n in neighbours(cell) {
                if !cells.contains_key(&n) && tried.get(&n).copied().unwrap_or(0) > 0 {
                    queue.push_back(n);
                }
            }
        }
    }
    cells
}

fn neighbours(c: (i32, i32)) -> [(i32, i32); 4] {
    [
        (c.0 + 1, c.1),
        (c.0 - 1, c.1),
        (c.0, c.1 + 1),
        (c.0, c.1 - 1),
    ]
}

fn push_neighbours(queue: &mut VecDeque<(i32, i32)>, c: (i32, i32)) {
    queue.extend(neighbours(c));
}

/// Predicted position and local steps of `cell` from grown neighbours.
pub(crate) fn predict(
    pts: &[Point2<f64>],
    cells: &Cells,
    cell: (i32, i32),
    step_a: Vector2<f64>,
    step_b: Vector2<f64>,
) -> Option<Prediction> {
    let get = |a: i32, b: i32| cells.get(&(a, b)).map(|&i| pts[i].coords);
    let (a, b) = cell;
    let mut sum = Vector2::zeros();
    let mut n = 0.0;
    let mut sa: Option<Vector2<f64>> = None;
    let mut sb: Option<Vector2<f64>> = None;
    for (da, db) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
        if let (Some(p1), Some(p2)) = (get(a - da, b - db), get(a - 2 * da, b - 2 * db)) {
            let s = p1 - p2;
            // With a third point along the line, the step's change too (the
            // second difference): perspective shrinks or stretches the steps
            // from cell to cell, and beyond about 55 degrees of tilt the
            // linear guess misses the far rows by more than the search
            // radius where the quadratic one follows them.
            let change = get(a - 3 * da, b - 3 * db).map_or(Vector2::zeros(), |p3| s - (p2 - p3));
            sum += p1 + s + change;
            n += 1.0;
            let signed = if da + db > 0 { s } else { -s };
            if da != 0 {
                sa.get_or_insert(signed);
            } else {
                sb.get_or_insert(signed);
            }
        }
    }
    // Parallelogram completion from the four diagonal quadrants.
    for (da, db) in [(1, 1), (1, -1), (-1, 1), (-1, -1)] {
        if let (Some(pa), Some(pb), Some(pab)) =
            (get(a - da, b), get(a, b - db), get(a - da, b - db))
        {
            sum += pa + pb - pab;
            n += 1.0;
            // pb - pab runs along a, pa - pab along b.
            sa.get_or_insert((pb - pab) * da as f64);
            sb.get_or_insert((pa - pab) * db as f64);
        }
    }
    if n == 0.0 {
        // Only a single neighbour: step with the seed's axes.
        for (da, db) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            if let Some(p1) = get(a - da, b - db) {
                let s = step_a * da as f64 + step_b * db as f64;
                sum += p1 + s;
                n += 1.0;
            }
        }
    }
    if n == 0.0 {
        return None;
    }
    Some(Prediction {
        pos: Point2::from(sum / n),
        step_a: sa.unwrap_or(step_a),
        step_b: sb.unwrap_or(step_b),
    })
}

/// When growth took in more cells than a `cols x rows` board has (clutter
/// next to the board that happens to sit on the lattice), the cells of the
/// one completely filled `cols x rows` (or `rows x cols`) window of the
/// lattice. `None` when no window or more than one is full.
pub(crate) fn trim_to_window(cells: &Cells, cols: usize, rows: usize) -> Option<Cells> {
    let n = cols * rows;
    if cells.len() <= n {
        return None;
    }
    let (mut lo, mut hi) = ((i32::MAX, i32::MAX), (i32::MIN, i32::MIN));
    for &(a, b) in cells.keys() {
        lo = (lo.0.min(a), lo.1.min(b));
        hi = (hi.0.max(a), hi.1.max(b));
    }
    let mut found: Option<Cells> = None;
    let shapes = if cols == rows {
        vec![(cols as i32, rows as i32)]
    } else {
        vec![(cols as i32, rows as i32), (rows as i32, cols as i32)]
    };
    for (wa, wb) in shapes {
        for a0 in lo.0..=hi.0 - wa + 1 {
            for b0 in lo.1..=hi.1 - wb + 1 {
                let window: Option<Cells> = (a0..a0 + wa)
                    .flat_map(|a| (b0..b0 + wb).map(move |b| (a, b)))
                    .map(|c| cells.get(&c).map(|&i| (c, i)))
                    .collect();
                if let Some(w) = window {
                    if found.is_some() {
                        return None;
                    }
                    found = Some(w);
                }
            }
        }
    }
    found
}

/// A lattice-to-board map `board = m * (a, b) + t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BoardMap {
    pub m: [[i32; 2]; 2],
    pub t: (i32, i32),
}

impl BoardMap {
    pub fn apply(&self, c: (i32, i32)) -> (i32, i32) {
        (
            self.m[0][0] * c.0 + self.m[0][1] * c.1 + self.t.0,
            self.m[1][0] * c.0 + self.m[1][1] * c.1 + self.t.1,
        )
    }
}

/// Every map under which the grown cells cover the board coordinates
/// `board` exactly (one cell per board point). `diagonal`: the lattice
/// steps are the board's diagonals (asymmetric circle grids).
pub(crate) fn complete_maps(cells: &Cells, board: &[(i32, i32)], diagonal: bool) -> Vec<BoardMap> {
    if cells.len() != board.len() || board.is_empty() {
        return Vec::new();
    }
    let set: HashSet<(i32, i32), BuildHasherDefault<CellHasher>> = board.iter().copied().collect();
    let bmin = (
        board.iter().map(|c| c.0).min().unwrap_or(0),
        board.iter().map(|c| c.1).min().unwrap_or(0),
    );
    let mut out = Vec::new();
    for m in candidate_matrices(diagonal) {
        let id = BoardMap { m, t: (0, 0) };
        let mapped: Vec<(i32, i32)> = cells.keys().map(|&c| id.apply(c)).collect();
        let min = (
            mapped.iter().map(|c| c.0).min().unwrap_or(0),
            mapped.iter().map(|c| c.1).min().unwrap_or(0),
        );
        let t = (bmin.0 - min.0, bmin.1 - min.1);
        if mapped.iter().all(|c| set.contains(&(c.0 + t.0, c.1 + t.1))) {
            out.push(BoardMap { m, t });
        }
    }
    out
}

/// The lattice-to-board matrices `complete_maps` tries: the 8 turns and
/// reflections of the axes, or for `diagonal` lattices (asymmetric grids,
/// whose points are the board cells with `i + j` even) every basis of that
/// lattice with steps of at most two cells along each axis: the diagonals
/// `(1, 1)`, `(1, -1)` and also a row or column step `(2, 0)`, `(0, 2)`
/// beside a diagonal (the nearest neighbours of a grid tilted beyond about
/// 55 degrees, where a row step is foreshortened below a diagonal one).
fn candidate_matrices(diagonal: bool) -> Vec<[[i32; 2]; 2]> {
    if !diagonal {
        let mut out = Vec::new();
        for swap in [false, true] {
            for sa in [1, -1] {
                for sb in [1, -1] {
                    out.push(if swap {
                        [[0, sa], [sb, 0]]
                    } else {
                        [[sa, 0], [0, sb]]
                    });
                }
            }
        }
        return out;
    }
    // Columns (a step, b step) in board cells: each on the lattice (even
    // coordinate sum), together a basis of it (determinant +-2).
    let mut out = Vec::new();
    for a in -2..=2i32 {
        for b in -2..=2i32 {
            for c in -2..=2i32 {
                for d in -2..=2i32 {
                    let on_lattice = (a + c) % 2 == 0 && (b + d) % 2 == 0;
                    if on_lattice && (a * d - b * c).abs() == 2 {
                        out.push([[a, b], [c, d]]);
                    }
                }
            }
        }
    }
    // The diagonal bases first (the usual case; the order only matters for
    // the cost of the search).
    out.sort_by_key(|m| m.iter().flatten().map(|v| v.abs()).sum::<i32>());
    out
}

/// Board-ordered image points for `map` (index = id), from `cells`.
pub(crate) fn ordered(cells: &Cells, map: &BoardMap, board: &[(i32, i32)]) -> Option<Vec<usize>> {
    let by_board: CellMap<usize> = cells.iter().map(|(&c, &i)| (map.apply(c), i)).collect();
    board.iter().map(|c| by_board.get(c).copied()).collect()
}

/// Signed area of the polygon through the board's extreme points in id
/// order (positive when the board's x to y turns clockwise on screen,
/// i.e. the board's z axis points away from the camera).
pub(crate) fn handedness(pts: &[Point2<f64>], order: &[usize], cols: usize) -> f64 {
    let n = order.len();
    if n < 3 || cols == 0 {
        return 0.0;
    }
    let corners = [0, cols - 1, n - 1, n - cols];
    let mut area = 0.0;
    for k in 0..4 {
        let p = pts[order[corners[k]]];
        let q = pts[order[corners[(k + 1) % 4]]];
        area += p.x * q.y - q.x * p.y;
    }
    0.5 * area
}

/// Shared ordering rule: keep right-handed maps (see [`handedness`]), then
/// those `prefer` likes (if any), then the one whose id 0 is nearest the
/// image's top-left pixel.
pub(crate) fn choose_order(
    pts: &[Point2<f64>],
    cells: &Cells,
    maps: &[BoardMap],
    board: &[(i32, i32)],
    cols: usize,
    prefer: &dyn Fn(&[usize]) -> bool,
) -> Option<Vec<usize>> {
    let orders: Vec<Vec<usize>> = maps
        .iter()
        .filter_map(|m| ordered(cells, m, board))
        .filter(|o| handedness(pts, o, cols) > 0.0)
        .collect();
    let preferred: Vec<&Vec<usize>> = orders.iter().filter(|o| prefer(o)).collect();
    let pool: Vec<&Vec<usize>> = if preferred.is_empty() {
        orders.iter().collect()
    } else {
        preferred
    };
    pool.into_iter()
        .min_by(|a, b| pts[a[0]].coords.norm().total_cmp(&pts[b[0]].coords.norm()))
        .cloned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn grows_and_orders_a_rotated_grid_with_clutter() {
        // A 5x3 grid rotated by 30 degrees, plus clutter points.
        let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
        let mut pts = Vec::new();
        for j in 0..3 {
            for i in 0..5 {
                let (x, y) = (i as f64 * 20.0, j as f64 * 20.0);
                pts.push(Point2::new(100.0 + c * x - s * y, 50.0 + s * x + c * y));
            }
        }
        pts.push(Point2::new(10.0, 10.0));
        pts.push(Point2::new(300.0, 20.0));
        let index = PointIndex::new(&pts, 16.0);
        let cells = grow(
            &index,
            7,
            pts[8] - pts[7],
            pts[12] - pts[7],
            100,
            &|_, _, _| true,
        );
        assert_eq!(cells.len(), 15);
        let board: Vec<(i32, i32)> = (0..3).flat_map(|j| (0..5).map(move |i| (i, j))).collect();
        let maps = complete_maps(&cells, &board, false);
        assert_eq!(maps.len(), 4, "{maps:?}");
        let order = choose_order(&pts, &cells, &maps, &board, 5, &|_| false).unwrap();
        // The generated order is right-handed with id 0 nearest the top-left.
        assert_eq!(order, (0..15).collect::<Vec<_>>());
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn orders_an_asymmetric_grid_grown_along_a_row_and_a_diagonal() {
        // A 4x5 asymmetric grid (board cells (2 i + j % 2, j)) squeezed
        // to 0.4 along x, as a strong tilt does: a row step (2, 0) is then
        // 0.8 units, shorter than a diagonal (1.08), and the lattice grows
        // along a row and a diagonal. Issue 36: every circle was in the
        // lattice but no map took that basis ("found 20 of 20").
        let board: Vec<(i32, i32)> = (0..5)
            .flat_map(|j| (0..4).map(move |i| (2 * i + j % 2, j)))
            .collect();
        let pts: Vec<Point2<f64>> = board
            .iter()
            .map(|&(x, y)| Point2::new(50.0 + 8.0 * x as f64, 40.0 + 20.0 * y as f64))
            .collect();
        let index = PointIndex::new(&pts, 16.0);
        // Seed 5 is board (3, 1): its row neighbour 6 is (5, 1), its
        // diagonal neighbour 9 is (4, 2).
        let cells = grow(
            &index,
            5,
            pts[6] - pts[5],
            pts[9] - pts[5],
            100,
            &|_, _, _| true,
        );
        assert_eq!(cells.len(), 20);
        let maps = complete_maps(&cells, &board, true);
        assert!(!maps.is_empty());
        let order = choose_order(&pts, &cells, &maps, &board, 4, &|_| false).unwrap();
        assert_eq!(order, (0..20).collect::<Vec<_>>());
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn grows_an_asymmetric_grid_tilted_64_degrees_to_its_far_rows() {
        // A 7x11 asymmetric grid of 15 mm (board cells (2 i + j % 2, j))
        // seen by a 1000 px pinhole 0.3 m away, tilted 64 degrees about its
        // x axis after a turn of 90 degrees in its plane (view 3 of
        // tests/detect/detect_circles_asym.rs): from row to row the step
        // shrinks by up to a fifth, and a guess from two cells missed the
        // far rows by more than the search radius (73 of 77 cells grown).
        let board: Vec<(i32, i32)> = (0..11)
            .flat_map(|j| (0..7).map(move |i| (2 * i + j % 2, j)))
            .collect();
        let unit = 0.015;
        let r = Rotation3::from_axis_angle(&Vector3::x_axis(), 64f64.to_radians())
            * Rotation3::from_axis_angle(&Vector3::z_axis(), 90f64.to_radians());
        let t = Vector3::new(0.01, -0.01, 0.3) - r * Vector3::new(6.5 * unit, 5.0 * unit, 0.0);
        let pts: Vec<Point2<f64>> = board
            .iter()
            .map(|&(x, y)| {
                let p = r * Vector3::new(x as f64 * unit, y as f64 * unit, 0.0) + t;
                Point2::new(641.5 + 1000.0 * p.x / p.z, 478.25 + 1002.0 * p.y / p.z)
            })
            .collect();
        // Seed 4 is board (8, 0), on the near edge; its nearest neighbours
        // are 10 = (7, 1) (a diagonal) and 5 = (10, 0) (a row step).
        let index = PointIndex::new(&pts, 16.0);
        let cells = grow(
            &index,
            4,
            pts[10] - pts[4],
            pts[5] - pts[4],
            200,
            &|_, _, _| true,
        );
        assert_eq!(cells.len(), 77);
        let maps = complete_maps(&cells, &board, true);
        let order = choose_order(&pts, &cells, &maps, &board, 7, &|_| false).unwrap();
        assert_eq!(order, (0..77).collect::<Vec<_>>());
    }
}
