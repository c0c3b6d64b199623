//! What the kept frames cover: cells of the image, tilt about both image
//! axes and distance, each in documented bins; and what a new frame would
//! add.

use crate::calib::{homography, pose_from_homography};
use crate::camera::Camera;
use crate::geometry::Pose;
use crate::target::Detection;
use nalgebra::{Point2, Vector3};
use serde::Serialize;

/// Columns and rows of the grid of image cells.
pub const GRID: (usize, usize) = (8, 6);
/// A frame adds image coverage when its points fall in at least this many
/// cells that no kept frame has a point in.
pub const NEW_CELLS_MIN: usize = 4;
/// Tilt bin edges, degrees: below `-TILT_EDGE_DEG`, within, above.
pub const TILT_EDGE_DEG: f64 = 15.0;
/// Distance bin edges on the board's span (see [`Signature::span`]):
/// far below the first, near from the second on, middle between.
pub const SPAN_EDGES: (f64, f64) = (0.35, 0.52);
/// The focal length (in image widths) assumed before a calibration exists.
pub const GUESS_FOCAL_PER_WIDTH: f64 = 0.8;

/// What one frame covers.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Signature {
    /// Cells (row-major index in [`GRID`]) holding at least one point.
    pub cells: Vec<usize>,
    /// Tilt of the board about the image x axis, degrees (the angle of its
    /// normal from the optical axis, projected on the y-z plane).
    pub tilt_x_deg: f64,
    /// Tilt about the image y axis, degrees (x-z plane).
    pub tilt_y_deg: f64,
    /// Tilt bins: (about x, about y), each 0 (below -15 deg), 1 (within
    /// +-15 deg) or 2 (above 15 deg).
    pub tilt_bin: (usize, usize),
    /// The board's width (its larger side) as a fraction of the image
    /// width were it facing the camera at its distance: `f * side / (z *
    /// width)`. A measure of distance that needs no unit.
    pub span: f64,
    /// Distance bin: 0 far, 1 middle, 2 near.
    pub distance_bin: usize,
}

/// What the kept frames cover, for display and novelty.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Coverage {
    /// `[columns, rows]` of the cell grid.
    pub grid: [usize; 2],
    /// Points of kept frames per cell, row-major.
    pub cells: Vec<usize>,
    /// Kept frames per tilt bin, `[bin about x][bin about y]` (0: below
    /// -15 deg, 1: within +-15 deg, 2: above 15 deg).
    pub tilt: [[usize; 3]; 3],
    /// Kept frames per distance bin: `[far, middle, near]`.
    pub distance: [usize; 3],
    /// Frames kept.
    pub kept: usize,
}

/// What a frame adds to the coverage.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Novelty {
    /// Cells it covers that no kept frame does.
    pub new_cells: usize,
    /// Its tilt bin has no kept frame yet.
    pub new_tilt: bool,
    /// Its distance bin has no kept frame yet.
    pub new_distance: bool,
    /// With a running calibration that is not good enough: the predicted
    /// worst projection uncertainty after adding it, px
    /// ([`super::suggest::Predictor`]; `None` without one, or for a repeat
    /// of a kept view).
    pub predicted_max_std_px: Option<f64>,
    /// It lowers that prediction by at least
    /// [`super::suggest::LOWERS_UNCERTAINTY_BY`] of the calibration's.
    pub lowers_uncertainty: bool,
}

impl Novelty {
    /// Whether the frame adds information by the rule: at least
    /// [`NEW_CELLS_MIN`] new cells, or a new tilt bin, or a new distance
    /// bin, or (under a calibration not good enough) a lower predicted
    /// uncertainty.
    pub fn adds_information(&self) -> bool {
        self.new_cells >= NEW_CELLS_MIN
            || self.new_tilt
            || self.new_distance
            || self.lowers_uncertainty
    }
}

impl Coverage {
    /// Nothing covered.
    pub fn new() -> Coverage {
        Coverage {
            grid: [GRID.0, GRID.1],
            cells: vec![0; GRID.0 * GRID.1],
            tilt: [[0; 3]; 3],
            distance: [0; 3],
            kept: 0,
        }
    }

    /// What `s` would add.
    pub fn novelty(&self, s: &Signature) -> Novelty {
        Novelty {
            new_cells: s.cells.iter().filter(|c| self.cells[**c] == 0).count(),
            new_tilt: self.tilt[s.tilt_bin.0][s.tilt_bin.1] == 0,
            new_distance: self.distance[s.distance_bin] == 0,
            predicted_max_std_px: None,
            lowers_uncertainty: false,
        }
    }

    /// Count a kept frame with `points_per_cell` (row-major, as
    /// [`cell_counts`] gives).
    pub fn add(&mut self, s: &Signature, points_per_cell: &[usize]) {
        for (c, n) in self.cells.iter_mut().zip(points_per_cell) {
            *c += n;
        }
        self.tilt[s.tilt_bin.0][s.tilt_bin.1] += 1;
        self.distance[s.distance_bin] += 1;
        self.kept += 1;
    }
}

impl Default for Coverage {
    fn default() -> Self {
        Coverage::new()
    }
}

/// The camera assumed before a calibration exists: focal length
/// [`GUESS_FOCAL_PER_WIDTH`] image widths, principal point at the centre.
pub fn guess_camera(width: u32, height: u32) -> Camera {
    let f = GUESS_FOCAL_PER_WIDTH * width as f64;
    let (cx, cy) = (0.5 * (width as f64 - 1.0), 0.5 * (height as f64 - 1.0));
    Camera::pinhole(f, f, cx, cy, width, height)
}

/// Points per cell of [`GRID`] (row-major) for pixels in a `width x height` image.
pub fn cell_counts(pixels: &[Point2<f64>], width: u32, height: u32) -> Vec<usize> {
    let mut counts = vec![0; GRID.0 * GRID.1];
    for p in pixels {
        let cx = (p.x / width as f64 * GRID.0 as f64).floor();
        let cy = (p.y / height as f64 * GRID.1 as f64).floor();
        if cx >= 0.0 && cy >= 0.0 && (cx as usize) < GRID.0 && (cy as usize) < GRID.1 {
            counts[cy as usize * GRID.0 + cx as usize] += 1;
        }
    }
    counts
}

/// The board's pose from a detection through `camera` (its points
/// undistorted, a homography, Zhang's decomposition); `None` when the
/// points do not fix a homography.
pub fn pose_of(detection: &Detection, camera: &Camera) -> Option<Pose> {
    let (object, image) = detection.correspondences();
    let plane: Vec<Point2<f64>> = object.iter().map(|p| p.xy()).collect();
    let ideal: Option<Vec<Point2<f64>>> = image
        .iter()
        .map(|p| {
            let ray = camera.unproject(p).ok()?;
            (ray.z > 1e-9).then(|| {
                let m = Point2::new(ray.x / ray.z, ray.y / ray.z);
                Point2::new(
                    camera.fx * m.x + camera.skew * m.y + camera.cx,
                    camera.fy * m.y + camera.cy,
                )
            })
        })
        .collect();
    let h = homography(&plane, &ideal?).ok()?;
    let k = camera.without_distortion().camera_matrix();
    pose_from_homography(&k, &h).ok()
}

/// The signature of a board at `camera_from_target` whose points are
/// seen at `pixels`.
pub fn signature(
    pixels: &[Point2<f64>],
    camera_from_target: &Pose,
    camera: &Camera,
    board_side_m: f64,
) -> Signature {
    let cells = cell_counts(pixels, camera.width, camera.height)
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(i, _)| i)
        .collect();
    // The normal facing the camera.
    let mut n = camera_from_target.rotation * Vector3::z();
    if n.z > 0.0 {
        n = -n;
    }
    let tilt_x_deg = (-n.y).atan2(-n.z).to_degrees();
    let tilt_y_deg = n.x.atan2(-n.z).to_degrees();
    let bin = |t: f64| {
        if t < -TILT_EDGE_DEG {
            0
        } else if t > TILT_EDGE_DEG {
            2
        } else {
            1
        }
    };
    let z = camera_from_target.translation.vector.z.max(1e-9);
    let span = camera.fx * board_side_m / (z * camera.width as f64);
    let distance_bin = if span < SPAN_EDGES.0 {
        0
    } else if span < SPAN_EDGES.1 {
        1
    } else {
        2
    };
    Signature {
        cells,
        tilt_x_deg,
        tilt_y_deg,
        tilt_bin: (bin(tilt_x_deg), bin(tilt_y_deg)),
        span,
        distance_bin,
    }
}
