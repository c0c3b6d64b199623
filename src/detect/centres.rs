//! Perspective-correct centres of imaged circles (circle grids and dot
//! plates): the image of each circle's centre, not the centre of its
//! image.
//!
//! # Why
//!
//! A projective map sends a circle to an ellipse but not the circle's centre
//! to the ellipse's centre; the difference grows with the circle's image
//! radius squared and the tilt (0.1-0.3 px for 20 mm circles at 50 degrees
//! and 1280x960; lens distortion adds its own, smaller term). The image of
//! the centre is the pole of the imaged line at infinity with respect to
//! the imaged circle: `c ~ C^-1 l`, `l = H^-T (0, 0, 1)` for the
//! board-to-image homography `H`.
//!
//! # How (no camera needed)
//!
//! Each circle gets a **local board-to-image map** fitted to the current
//! centres of the grid points in a window around it (3x3 cells on
//! symmetric grids and dot plates, +-2 half-pitch cells on asymmetric
//! ones; shifted inside the board at its edges), so lens distortion, which no global homography follows, enters
//! only through its variation across one window. The circle's sub-pixel
//! edge points are pulled back through the map onto the board, where they
//! lie on a circle; the centre of the ellipse fitted there is mapped
//! forward. With the map a homography this *is* the pole construction
//! above (the map carries the fitted conic and the line at infinity
//! together) and needs no explicit conic algebra; the pull-back form also
//! takes a map with a quadratic term. Centres -> maps -> centres is
//! iterated until no centre moves by more than [`CONVERGED_PX`] (at most
//! [`MAX_PASSES`] passes; two usually suffice, since the maps barely depend
//! on the sub-pixel shifts).
//!
//! Lens distortion bends the grid inside each window; at the board's edges,
//! where the window lies on one side of the circle, the map extrapolates
//! that bending. So the bulk of it is then taken out: a one-parameter
//! division model about the image centre ([`Radial`]), its parameter chosen
//! so that one homography best maps the lattice to the undistorted centres
//! of that first pass (not to the ellipse centres: their perspective bias
//! is not a lens and a lens term would absorb part of it), is applied to
//! every centre and edge point, the iteration runs again there, and the
//! centres are distorted back. A grid that one homography already fits
//! keeps the first pass.
//!
//! [`CentreModel`] names the variants; which one is the default and why is
//! measured in the test `centre_models_compared_on_renders`
//! (tests/detect/detect_circles.rs) and recorded in `crate::detect`'s docs.

use super::blobs::Outline;
use super::ellipse::fit_ellipse;
use super::markers::homography::dlt_normal_equations;
use crate::target::CentreModel;
use nalgebra::{Matrix3, Point2, Vector2, Vector3};

/// Half-width of the window of grid neighbours a local map is fitted to,
/// lattice cells, on symmetric grids and dot plates: 1, a 3x3 window of 9
/// points (a 5x5 window left 0.035 px of lens-distortion bias on 44-px
/// circles through the strong-distortion lens, the 3x3 one 0.020 px, at the
/// same noise on the other cases).
pub(crate) const WINDOW_HALF_CELLS: i32 = 1;
/// The same on asymmetric grids, whose lattice cells are half the row
/// pitch: 2 takes the ring of the 6 nearest circles and the next ones,
/// about 13 points over the same board area as the symmetric 3x3 window.
pub(crate) const WINDOW_HALF_CELLS_ASYMMETRIC: i32 = 2;
/// Passes of centres -> local maps -> centres.
pub(crate) const MAX_PASSES: usize = 4;
/// A pass that moves no centre by more than this ends the iteration, px.
pub(crate) const CONVERGED_PX: f64 = 1e-4;
/// Points a local homography needs (4 determine it; 6 give a margin
/// against a noisy or degenerate window).
const MIN_POINTS_HOMOGRAPHY: usize = 6;
/// Points the quadratic term needs (6 more parameters: 14 in all, so 9
/// points, 18 equations, of a 3x3 window).
const MIN_POINTS_QUADRATIC: usize = 9;
/// The pulled-back centre lies within this many lattice units of the
/// circle's own board position, or the map is not trusted.
const MAX_BOARD_OFFSET: f64 = 0.25;

/// Centres of the circles whose outlines are `outlines`, in the order of
/// `board` (their lattice cells), by `model`. A circle whose local map
/// cannot be fitted keeps its ellipse centre.
pub(crate) fn circle_centres(
    board: &[(i32, i32)],
    asymmetric: bool,
    outlines: &[Outline],
    model: CentreModel,
    image_size: (u32, u32),
) -> Vec<Point2<f64>> {
    let ellipse_centres: Vec<Point2<f64>> = outlines.iter().map(|o| o.ellipse.centre).collect();
    let quadratic = match model {
        CentreModel::EllipseCentre => return ellipse_centres,
        CentreModel::PerspectivePole => false,
        CentreModel::LocalQuadratic => true,
    };
    let cells: Vec<Vector2<f64>> = board
        .iter()
        .map(|&(a, b)| Vector2::new(a as f64, b as f64))
        .collect();
    let half = if asymmetric {
        WINDOW_HALF_CELLS_ASYMMETRIC
    } else {
        WINDOW_HALF_CELLS
    };
    let window = Window::new(board, half);
    let poles = |start: Vec<Point2<f64>>, edges: &[Vec<Point2<f64>>]| {
        pole_iteration(board, &window, &cells, start, edges, quadratic)
    };
    // First pass in the image as it is: perspective-correct centres, up to
    // the lens's bending across each window.
    let image_edges: Vec<Vec<Point2<f64>>> = outlines.iter().map(|o| o.edges.clone()).collect();
    let first = poles(ellipse_centres, &image_edges);
    // The board's radial distortion, fitted to those centres (not to the
    // ellipse centres, whose perspective bias a lens term would absorb), is
    // taken out, and the local maps run again on (nearly) a homography.
    let radial = Radial::fit(&cells, &first, image_size);
    if radial.lambda == 0.0 {
        return first;
    }
    let start: Vec<Point2<f64>> = first.iter().map(|p| radial.undistort(p)).collect();
    let edges: Vec<Vec<Point2<f64>>> = image_edges
        .iter()
        .map(|e| e.iter().map(|p| radial.undistort(p)).collect())
        .collect();
    poles(start, &edges)
        .iter()
        .zip(&first)
        .map(|(p, f)| radial.distort(p).unwrap_or(*f))
        .collect()
}

/// Centres -> local maps -> centres from `start`, until no centre moves by
/// [`CONVERGED_PX`] (at most [`MAX_PASSES`]); a circle whose map cannot be
/// fitted keeps its current centre.
fn pole_iteration(
    board: &[(i32, i32)],
    window: &Window,
    cells: &[Vector2<f64>],
    start: Vec<Point2<f64>>,
    edges: &[Vec<Point2<f64>>],
    quadratic: bool,
) -> Vec<Point2<f64>> {
    let mut centres = start;
    for _ in 0..MAX_PASSES {
        let next: Vec<Point2<f64>> = (0..centres.len())
            .map(|k| {
                let members = window.members(board, k);
                let fitted = LocalMap::fit(&members, cells, &centres, k, quadratic)
                    .and_then(|map| pulled_back_centre(&map, &edges[k]));
                fitted.unwrap_or(centres[k])
            })
            .collect();
        let moved = next
            .iter()
            .zip(&centres)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        centres = next;
        if moved <= CONVERGED_PX {
            break;
        }
    }
    centres
}

/// One-parameter division model about the image centre, `u = c + (d - c)
/// / (1 + lambda r^2)` with `r = |d - c| / s` (`s` the half diagonal): the
/// bulk of a lens's radial distortion, fitted to the grid so that the
/// undistorted centres are best fitted by one homography. Without it the
/// local maps of circles at the board's edges, whose windows lie on one
/// side of them, extrapolate the lens's bending (0.03 px mean, 0.11 px max
/// on ~40-px circles at 45 degrees through k1 = -0.28,
/// docs/benchmark-history.md).
struct Radial {
    c: Vector2<f64>,
    s: f64,
    lambda: f64,
}

impl Radial {
    /// The `lambda` in [-0.5, 0.5] (golden section) that minimises the
    /// residual of one homography from the lattice `cells` to the
    /// undistorted `centres`; zero when the grid is too small, when one
    /// homography already fits, or when no `lambda` lowers the residual.
    fn fit(cells: &[Vector2<f64>], centres: &[Point2<f64>], (w, h): (u32, u32)) -> Radial {
        let c = Vector2::new(0.5 * (w as f64 - 1.0), 0.5 * (h as f64 - 1.0));
        let s = c.norm().max(1.0);
        let mut radial = Radial { c, s, lambda: 0.0 };
        if centres.len() < 8 {
            return radial;
        }
        let all: Vec<usize> = (0..centres.len()).collect();
        let cost = |lambda: f64| -> f64 {
            let r = Radial { c, s, lambda };
            let u: Vec<Point2<f64>> = centres.iter().map(|p| r.undistort(p)).collect();
            let Some(map) = LocalMap::fit(&all, cells, &u, 0, false) else {
                return f64::MAX;
            };
            all.iter()
                .map(|&i| {
                    map.forward(&(cells[i] - cells[0]))
                        .map_or(f64::MAX, |q| (q - u[i]).norm_squared())
                })
                .sum()
        };
        // A grid one homography already fits to 1e-6 of its spread (an
        // exact homography, no lens) keeps lambda = 0.
        if cost(0.0) <= 1e-12 * centres.len() as f64 {
            return radial;
        }
        let g = 0.5 * (5f64.sqrt() - 1.0);
        let (mut a, mut b) = (-0.5f64, 0.5f64);
        let (mut x1, mut x2) = (b - g * (b - a), a + g * (b - a));
        let (mut f1, mut f2) = (cost(x1), cost(x2));
        for _ in 0..40 {
            if f1 <= f2 {
                b = x2;
                (x2, f2) = (x1, f1);
                x1 = b - g * (b - a);
                f1 = cost(x1);
            } else {
                a = x1;
                (x1, f1) = (x2, f2);
                x2 = a + g * (b - a);
                f2 = cost(x2);
            }
        }
        let lambda = 0.5 * (a + b);
        if cost(lambda) < cost(0.0) {
            radial.lambda = lambda;
        }
        radial
    }

    fn undistort(&self, p: &Point2<f64>) -> Point2<f64> {
        let d = p.coords - self.c;
        let r2 = d.norm_squared() / (self.s * self.s);
        Point2::from(self.c + d / (1.0 + self.lambda * r2))
    }

    /// The inverse of [`Radial::undistort`]; `None` past the model's fold.
    fn distort(&self, p: &Point2<f64>) -> Option<Point2<f64>> {
        let d = p.coords - self.c;
        let ru = d.norm() / self.s;
        // lambda ru rd^2 - rd + ru = 0, the root near rd = ru.
        let disc = 1.0 - 4.0 * self.lambda * ru * ru;
        if !(disc >= 0.0) {
            return None;
        }
        let factor = 2.0 / (1.0 + disc.sqrt());
        Some(Point2::from(self.c + d * factor))
    }
}

/// The board's lattice bounds, for windows shifted inside the board.
struct Window {
    lo: (i32, i32),
    hi: (i32, i32),
    half: i32,
}

impl Window {
    fn new(board: &[(i32, i32)], half: i32) -> Self {
        let fold = |f: fn(&(i32, i32)) -> i32| {
            let v: Vec<i32> = board.iter().map(f).collect();
            (
                v.iter().copied().min().unwrap_or(0),
                v.iter().copied().max().unwrap_or(0),
            )
        };
        let (a, b) = (fold(|c| c.0), fold(|c| c.1));
        Window {
            lo: (a.0, b.0),
            hi: (a.1, b.1),
            half,
        }
    }

    /// Indices of the grid points in the window around point `k`.
    fn members(&self, board: &[(i32, i32)], k: usize) -> Vec<usize> {
        let r = self.half;
        // Twice the window centre, so odd-sized boards centre exactly.
        let centre2 = |v: i32, lo: i32, hi: i32| {
            if hi - lo <= 2 * r {
                lo + hi
            } else {
                2 * v.clamp(lo + r, hi - r)
            }
        };
        let ca = centre2(board[k].0, self.lo.0, self.hi.0);
        let cb = centre2(board[k].1, self.lo.1, self.hi.1);
        board
            .iter()
            .enumerate()
            .filter(|(_, &(a, b))| (2 * a - ca).abs() <= 2 * r && (2 * b - cb).abs() <= 2 * r)
            .map(|(i, _)| i)
            .collect()
    }
}

/// A board-to-image map around one circle: `p = o + s (H(b) + Q(b))` with
/// `b` the board position relative to the circle's lattice cell (lattice
/// units), `H` a homography, `Q` an optional quadratic term and `o`, `s` the
/// image normalisation.
struct LocalMap {
    h: Matrix3<f64>,
    h_inv: Matrix3<f64>,
    origin: Vector2<f64>,
    scale: f64,
    /// Coefficients of `bx^2`, `bx by`, `by^2` (normalised image units).
    quad: Option<[Vector2<f64>; 3]>,
}

fn quad_basis(b: &Vector2<f64>) -> [f64; 3] {
    [b.x * b.x, b.x * b.y, b.y * b.y]
}

fn apply_h(h: &Matrix3<f64>, v: &Vector2<f64>) -> Option<Vector2<f64>> {
    let w = h * Vector3::new(v.x, v.y, 1.0);
    (w.z.abs() > 1e-12).then(|| Vector2::new(w.x / w.z, w.y / w.z))
}

impl LocalMap {
    /// Fit to the `members`' lattice `cells` and current `centres`, around
    /// point `k`: a normalised DLT with `h33 = 1` (the circle's own cell is
    /// the board origin and maps near the image origin, so `h33` is far
    /// from 0), then the quadratic term to its residuals.
    fn fit(
        members: &[usize],
        cells: &[Vector2<f64>],
        centres: &[Point2<f64>],
        k: usize,
        quadratic: bool,
    ) -> Option<LocalMap> {
        let need = if quadratic {
            MIN_POINTS_QUADRATIC
        } else {
            MIN_POINTS_HOMOGRAPHY
        };
        if members.len() < need {
            return None;
        }
        let cell = cells[k];
        let origin = centres[k].coords;
        let scale = (members
            .iter()
            .map(|&i| (centres[i].coords - origin).norm_squared())
            .sum::<f64>()
            / members.len() as f64)
            .sqrt();
        if !(scale > 1e-9) {
            return None;
        }
        let local = |i: usize| (cells[i] - cell, (centres[i].coords - origin) / scale);
        let (ata, atb) = dlt_normal_equations(members.iter().map(|&i| local(i)));
        let x = ata.cholesky()?.solve(&atb);
        let h = Matrix3::new(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], 1.0);
        let h_inv = h.try_inverse()?;
        let quad = if quadratic {
            let mut m = Matrix3::zeros();
            let (mut rx, mut ry) = (Vector3::zeros(), Vector3::zeros());
            for &i in members {
                let (b, u) = local(i);
                let e = u - apply_h(&h, &b)?;
                let phi = Vector3::from(quad_basis(&b));
                m += phi * phi.transpose();
                rx += phi * e.x;
                ry += phi * e.y;
            }
            let m = m.cholesky()?;
            let (cx, cy) = (m.solve(&rx), m.solve(&ry));
            Some([0, 1, 2].map(|j| Vector2::new(cx[j], cy[j])))
        } else {
            None
        };
        Some(LocalMap {
            h,
            h_inv,
            origin,
            scale,
            quad,
        })
    }

    fn quad_term(&self, b: &Vector2<f64>) -> Vector2<f64> {
        match &self.quad {
            Some(q) => {
                let phi = quad_basis(b);
                q[0] * phi[0] + q[1] * phi[1] + q[2] * phi[2]
            }
            None => Vector2::zeros(),
        }
    }

    /// Pixel of board position `b` (relative to the circle's cell).
    fn forward(&self, b: &Vector2<f64>) -> Option<Point2<f64>> {
        let u = apply_h(&self.h, b)? + self.quad_term(b);
        Some(Point2::from(self.origin + u * self.scale))
    }

    /// Board position (relative to the circle's cell) of pixel `p`: the
    /// homography's inverse, then a fixed-point iteration for the
    /// quadratic term (small against the homography: a few steps converge).
    fn backward(&self, p: &Point2<f64>) -> Option<Vector2<f64>> {
        let u = (p.coords - self.origin) / self.scale;
        let mut b = apply_h(&self.h_inv, &u)?;
        if self.quad.is_some() {
            for _ in 0..4 {
                b = apply_h(&self.h_inv, &(u - self.quad_term(&b)))?;
            }
        }
        Some(b)
    }
}

/// The forward image of the centre of the ellipse fitted to `edges` pulled
/// back onto the board through `map`; `None` when the fit fails or lands
/// away from the circle's own cell.
fn pulled_back_centre(map: &LocalMap, edges: &[Point2<f64>]) -> Option<Point2<f64>> {
    let board: Option<Vec<Point2<f64>>> = edges
        .iter()
        .map(|p| map.backward(p).map(Point2::from))
        .collect();
    let fit = fit_ellipse(&board?)?;
    let b = fit.centre.coords;
    if b.norm() > MAX_BOARD_OFFSET || !b.x.is_finite() || !b.y.is_finite() {
        return None;
    }
    map.forward(&b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::ellipse::fit_ellipse;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// A homography board -> image with strong perspective.
    fn homography() -> Matrix3<f64> {
        Matrix3::new(60.0, 8.0, 400.0, -5.0, 45.0, 300.0, 0.04, -0.03, 1.0)
    }

    fn outline(h: &Matrix3<f64>, cell: (i32, i32), radius: f64) -> Outline {
        let edges: Vec<Point2<f64>> = (0..64)
            .map(|k| {
                let t = k as f64 / 64.0 * std::f64::consts::TAU;
                let b = Vector2::new(
                    cell.0 as f64 + radius * t.cos(),
                    cell.1 as f64 + radius * t.sin(),
                );
                Point2::from(apply_h(h, &b).unwrap())
            })
            .collect();
        Outline {
            ellipse: fit_ellipse(&edges).unwrap(),
            edges,
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn exact_under_a_homography_and_the_ellipse_centre_is_not() {
        // Exact outlines of circles of radius 0.3 cells under a strong
        // homography: the pole (and the quadratic map, whose quadratic term
        // fits to zero) recover the projected centres to 1e-5 px, while the
        // ellipse centres are off by a visible bias.
        let h = homography();
        let board: Vec<(i32, i32)> = (0..5).flat_map(|j| (0..7).map(move |i| (i, j))).collect();
        let outlines: Vec<Outline> = board.iter().map(|&c| outline(&h, c, 0.3)).collect();
        let truth: Vec<Point2<f64>> = board
            .iter()
            .map(|&(a, b)| Point2::from(apply_h(&h, &Vector2::new(a as f64, b as f64)).unwrap()))
            .collect();
        let worst = |c: &[Point2<f64>]| {
            c.iter()
                .zip(&truth)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max)
        };
        let ellipse = worst(&circle_centres(
            &board,
            false,
            &outlines,
            CentreModel::EllipseCentre,
            (800, 600),
        ));
        assert!(ellipse > 0.05, "ellipse-centre bias {ellipse} px");
        for model in [CentreModel::PerspectivePole, CentreModel::LocalQuadratic] {
            let e = worst(&circle_centres(&board, false, &outlines, model, (800, 600)));
            // The iteration stops once a pass moves no centre by 1e-4 px;
            // the passes converge linearly with a small factor, so what is
            // left is far below that.
            assert!(e < 1e-5, "{model:?}: {e} px");
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn windows_stay_inside_the_board() {
        let board: Vec<(i32, i32)> = (0..5).flat_map(|j| (0..7).map(move |i| (i, j))).collect();
        let w = Window::new(&board, 2);
        // Corner point: the 5x5 window at the corner, 25 points.
        assert_eq!(w.members(&board, 0).len(), 25);
        // 3x3: 9 points, also at the corner and the edge.
        let w = Window::new(&board, WINDOW_HALF_CELLS);
        assert_eq!(w.members(&board, 0).len(), 9);
        assert_eq!(w.members(&board, 3).len(), 9);
        // Asymmetric 4x11 lattice: (2i + j % 2, j).
        let asym: Vec<(i32, i32)> = (0..11)
            .flat_map(|j| (0..4).map(move |i| (2 * i + j % 2, j)))
            .collect();
        let w = Window::new(&asym, WINDOW_HALF_CELLS_ASYMMETRIC);
        let n = w.members(&asym, 20).len();
        assert!((12..=13).contains(&n), "{n} members");
    }
}
