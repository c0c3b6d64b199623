//! The projection difference of two calibrations of one camera, as mrcal's
//! `mrcal-show-projection-diff` computes it: a grid of pixels over the
//! image is unprojected with model A to rays, the rotation that best maps
//! A's rays onto B's rays of the same pixels is fitted (least squares, the
//! "implied rotation": two calibrations of one camera may place the camera
//! frame differently, and a shift a rotation explains is no difference in
//! what the camera sees), and A's rays, rotated, are projected through B.
//! The pixel shift of every grid point is the difference: a map with its
//! worst, median and RMS.
//!
//! Points at infinity (rays only): the translation between the two camera
//! frames is not observable and is not compensated, as in mrcal with its
//! default distance.

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::geometry::{quaternion_xyzw_from_rotation, Rotation};
use nalgebra::{Matrix3, Point2, Point3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

/// Default grid: columns and rows of pixels compared.
pub const DEFAULT_GRID: [usize; 2] = [60, 40];
/// Fewest and most grid columns (or rows).
pub const GRID_BOUNDS: (usize, usize) = (2, 1000);

/// How to compare. Defaults: a 60 x 40 grid, every grid point weighs the
/// same in the rotation fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DiffOptions {
    /// Grid columns and rows, each between 2 and 1000; the grid spans the
    /// image from pixel 0 to the last pixel in both directions.
    pub grid: [usize; 2],
    /// Pixels where data were (the target points of the images the
    /// calibrations came from): when given, each grid point weighs in the
    /// rotation fit by the number of these points in its cell, so the
    /// rotation is fitted where both models were measured (mrcal fits
    /// where the uncertainty is low, to the same end).
    pub fit_px: Vec<[f64; 2]>,
    /// When given (and `fit_px` is empty), only grid points within this
    /// distance of the image centre enter the rotation fit, px (mrcal's
    /// `focus_radius`).
    pub focus_radius_px: Option<f64>,
}

impl Default for DiffOptions {
    fn default() -> Self {
        DiffOptions {
            grid: DEFAULT_GRID,
            fit_px: Vec::new(),
            focus_radius_px: None,
        }
    }
}

/// The projection difference: how far a point A projects to pixel `q`
/// lands in B, px, after the implied rotation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProjectionDiff {
    /// Image width and height, px (both cameras').
    pub image_size_px: [u32; 2],
    /// Grid columns and rows.
    pub grid: [usize; 2],
    /// Grid pixel x coordinates (columns).
    pub x_px: Vec<f64>,
    /// Grid pixel y coordinates (rows).
    pub y_px: Vec<f64>,
    /// Per row (y), per column (x): the shift, px; `None` where A cannot
    /// unproject the pixel or B cannot project the ray.
    pub map: Vec<Vec<Option<f64>>>,
    /// The largest shift, px.
    pub worst: f64,
    /// Where the largest shift is, px.
    pub worst_at_px: [f64; 2],
    /// The median shift, px.
    pub median: f64,
    /// The RMS shift, px.
    pub rms: f64,
    /// The fitted implied rotation b_from_a, quaternion x, y, z, w.
    pub b_from_a_quaternion_xyzw: [f64; 4],
    /// Its angle, degrees.
    pub implied_rotation_deg: f64,
    /// Grid points compared (where both models are defined).
    pub n_points: usize,
    /// Grid points that entered the rotation fit (weight > 0).
    pub n_fit: usize,
}

/// The projection difference of `a` and `b` (two calibrations of one
/// camera at one image size).
pub fn projection_diff(a: &Camera, b: &Camera, options: &DiffOptions) -> Result<ProjectionDiff> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(Error::invalid(
            "b",
            format!(
                "image size {}x{} differs from a's {}x{}: a projection difference compares two \
                 calibrations of one camera at one resolution",
                b.width, b.height, a.width, a.height
            ),
        ));
    }
    for (axis, &n) in ["columns", "rows"].iter().zip(&options.grid) {
        if n < GRID_BOUNDS.0 || n > GRID_BOUNDS.1 {
            return Err(Error::invalid(
                "grid",
                format!(
                    "{axis} must be between {} and {}, got {n}",
                    GRID_BOUNDS.0, GRID_BOUNDS.1
                ),
            ));
        }
    }
    let [cols, rows] = options.grid;
    let at = |i: usize, n: usize, size: u32| i as f64 * (size as f64 - 1.0) / (n - 1) as f64;
    let x_px: Vec<f64> = (0..cols).map(|i| at(i, cols, a.width)).collect();
    let y_px: Vec<f64> = (0..rows).map(|i| at(i, rows, a.height)).collect();
    // 1. The rays of both models at every grid pixel.
    let mut samples = Vec::with_capacity(cols * rows);
    for (r, &y) in y_px.iter().enumerate() {
        for (c, &x) in x_px.iter().enumerate() {
            let q = Point2::new(x, y);
            if let (Ok(ray_a), Ok(ray_b)) = (a.unproject(&q), b.unproject(&q)) {
                samples.push(Sample {
                    row: r,
                    col: c,
                    q,
                    ray_a,
                    ray_b,
                });
            }
        }
    }
    // 2. The weights and the implied rotation.
    let weights = fit_weights(&samples, a, &x_px, &y_px, options);
    let n_fit = weights.iter().filter(|w| **w > 0.0).count();
    let b_from_a = fit_rotation(&samples, &weights)?;
    // 3. A's rays, rotated, through B.
    let mut map = vec![vec![None; cols]; rows];
    let mut shifts = Vec::with_capacity(samples.len());
    let (mut worst, mut worst_at_px) = (0.0, [0.0, 0.0]);
    for s in &samples {
        let Ok(p) = b.project(&Point3::from(b_from_a * s.ray_a)) else {
            continue;
        };
        let d = (p - s.q).norm();
        if !d.is_finite() {
            continue;
        }
        map[s.row][s.col] = Some(d);
        shifts.push(d);
        if d > worst {
            (worst, worst_at_px) = (d, [s.q.x, s.q.y]);
        }
    }
    if shifts.is_empty() {
        return Err(Error::degenerate(
            "no grid pixel is defined in both models: they are not calibrations of one camera",
        ));
    }
    let rms = (shifts.iter().map(|d| d * d).sum::<f64>() / shifts.len() as f64).sqrt();
    shifts.sort_by(f64::total_cmp);
    let median = shifts[shifts.len() / 2];
    Ok(ProjectionDiff {
        image_size_px: [a.width, a.height],
        grid: options.grid,
        x_px,
        y_px,
        map,
        worst,
        worst_at_px,
        median,
        rms,
        b_from_a_quaternion_xyzw: quaternion_xyzw_from_rotation(&b_from_a),
        implied_rotation_deg: b_from_a.angle().to_degrees(),
        n_points: shifts.len(),
        n_fit,
    })
}

/// One grid pixel with its ray in each model.
struct Sample {
    row: usize,
    col: usize,
    q: Point2<f64>,
    ray_a: Vector3<f64>,
    ray_b: Vector3<f64>,
}

/// Each sample's weight in the rotation fit (see [`DiffOptions`]).
fn fit_weights(
    samples: &[Sample],
    camera: &Camera,
    x_px: &[f64],
    y_px: &[f64],
    options: &DiffOptions,
) -> Vec<f64> {
    if !options.fit_px.is_empty() {
        // The cell of a pixel: the nearest grid point.
        let nearest = |v: f64, grid: &[f64]| -> Option<usize> {
            let step = grid.get(1).map(|g| g - grid[0]).filter(|s| *s > 0.0)?;
            let i = (v - grid[0]) / step;
            (i.is_finite() && i > -0.5 && i < grid.len() as f64 - 0.5).then(|| i.round() as usize)
        };
        let mut counts = vec![vec![0.0; x_px.len()]; y_px.len()];
        for p in &options.fit_px {
            if let (Some(c), Some(r)) = (nearest(p[0], x_px), nearest(p[1], y_px)) {
                counts[r][c] += 1.0;
            }
        }
        let w: Vec<f64> = samples.iter().map(|s| counts[s.row][s.col]).collect();
        if w.iter().any(|v| *v > 0.0) {
            return w;
        }
    }
    if let Some(radius) = options.focus_radius_px {
        let centre = Point2::new(
            (camera.width as f64 - 1.0) / 2.0,
            (camera.height as f64 - 1.0) / 2.0,
        );
        let w: Vec<f64> = samples
            .iter()
            .map(|s| f64::from(u8::from((s.q - centre).norm() <= radius)))
            .collect();
        if w.iter().any(|v| *v > 0.0) {
            return w;
        }
    }
    vec![1.0; samples.len()]
}

/// The rotation R minimising sum w |R a - b|^2 over unit rays (Kabsch:
/// the SVD of the weighted correlation, its determinant forced to +1).
fn fit_rotation(samples: &[Sample], weights: &[f64]) -> Result<Rotation> {
    let h = samples
        .iter()
        .zip(weights)
        .fold(Matrix3::zeros(), |h, (s, w)| {
            h + *w * s.ray_a * s.ray_b.transpose()
        });
    let svd = h.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(Error::degenerate(
            "the rotation between the models' rays cannot be fitted",
        ));
    };
    let v = v_t.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
    if !r.iter().all(|x| x.is_finite()) {
        return Err(Error::degenerate(
            "the rotation between the models' rays cannot be fitted",
        ));
    }
    Ok(Rotation::from_rotation_matrix(
        &Rotation3::from_matrix_unchecked(r),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Distortion;

    fn brown() -> Camera {
        Camera {
            distortion: Distortion::Brown {
                k1: -0.2,
                k2: 0.05,
                p1: 0.001,
                p2: -0.0005,
                k3: 0.0,
            },
            ..Camera::pinhole(800.0, 805.0, 512.0, 384.0, 1024, 768)
        }
    }

    #[test]
    fn identical_cameras_differ_by_nothing() {
        let d = projection_diff(&brown(), &brown(), &DiffOptions::default()).unwrap();
        assert_eq!(d.n_points, 60 * 40);
        assert!(d.worst < 1e-9, "worst {}", d.worst);
        assert!(d.implied_rotation_deg < 1e-6);
        assert_eq!(d.map.len(), 40);
        assert_eq!(d.map[0].len(), 60);
    }

    #[test]
    fn a_shift_a_rotation_explains_is_compensated() {
        // A long lens: moving the principal point 5 px is (almost) a
        // rotation of 5 / 4000 rad; what is left is second order.
        let a = Camera::pinhole(4000.0, 4000.0, 320.0, 240.0, 640, 480);
        let b = Camera {
            cx: 325.0,
            ..a.clone()
        };
        let d = projection_diff(&a, &b, &DiffOptions::default()).unwrap();
        assert!(d.worst < 0.05, "worst {} px", d.worst);
        let expected_deg = (5.0_f64 / 4000.0).atan().to_degrees();
        assert!((d.implied_rotation_deg - expected_deg).abs() < 1e-3);
    }

    #[test]
    fn a_focal_change_shows_at_the_corners_as_its_analytic_value() {
        let a = Camera::pinhole(800.0, 800.0, 511.5, 383.5, 1024, 768);
        let b = Camera {
            fx: 808.0,
            fy: 808.0,
            ..a.clone()
        };
        let d = projection_diff(&a, &b, &DiffOptions::default()).unwrap();
        // Symmetric grid about the principal point: no rotation, and the
        // shift at a pixel q is 1 % of its distance from the centre.
        let corner = (511.5f64.powi(2) + 383.5f64.powi(2)).sqrt() * 0.01;
        assert!(d.implied_rotation_deg < 1e-6);
        assert!((d.worst - corner).abs() < 1e-6, "{} vs {corner}", d.worst);
        let top_left = d.map[0][0].unwrap();
        assert!((top_left - corner).abs() < 1e-6);
        assert!(d.median < d.worst && d.median > 0.0);
        // With the same change in a distorted camera the corners move by
        // about as much (the distortion is held).
        let e = projection_diff(
            &brown(),
            &Camera {
                fx: brown().fx * 1.01,
                fy: brown().fy * 1.01,
                ..brown()
            },
            &DiffOptions::default(),
        )
        .unwrap();
        assert!(e.worst > 4.0 && e.worst < 9.0, "worst {}", e.worst);
    }

    #[test]
    fn fit_weights_follow_the_data_and_sizes_must_match() {
        let a = Camera::pinhole(4000.0, 4000.0, 320.0, 240.0, 640, 480);
        let b = Camera {
            cx: 325.0,
            ..a.clone()
        };
        let options = DiffOptions {
            fit_px: vec![
                [100.0, 100.0],
                [540.0, 100.0],
                [100.0, 380.0],
                [540.0, 380.0],
            ],
            ..DiffOptions::default()
        };
        let d = projection_diff(&a, &b, &options).unwrap();
        assert_eq!(d.n_fit, 4);
        assert!(d.worst < 0.05, "{}", d.worst);
        let radius = DiffOptions {
            focus_radius_px: Some(100.0),
            ..DiffOptions::default()
        };
        assert!(projection_diff(&a, &b, &radius).unwrap().n_fit < 60 * 40 / 2);
        let small = Camera::pinhole(400.0, 400.0, 160.0, 120.0, 320, 240);
        assert_eq!(
            projection_diff(&a, &small, &DiffOptions::default())
                .unwrap_err()
                .to_string(),
            "b: image size 320x240 differs from a's 640x480: a projection difference compares \
             two calibrations of one camera at one resolution"
        );
        let coarse = DiffOptions {
            grid: [1, 40],
            ..DiffOptions::default()
        };
        assert_eq!(
            projection_diff(&a, &a, &coarse).unwrap_err().to_string(),
            "grid: columns must be between 2 and 1000, got 1"
        );
    }
}
