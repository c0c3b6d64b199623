//! The planar-at-any-height workflow from raw point pairs: group the pairs
//! by height, fit the transform per height, fit every parameter against
//! height, and (for four-corner plates) the pixel density against height.
//! Input and report are plain serialisable data shared by the CLI and wasm.

use super::linear_fit::LinearFit;
use super::planar::{fit_transform, PlanarFit, PointPair, TransformKind};
use super::planar_exact::PlaneFamily;
use super::planar_height::{
    fit_density, pixel_density, ByParameter, DensityFit, HeightModel, MappedPoint, PixelDensity,
};
use crate::camera::Camera;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// One observed point: the plate at `height_mm`, its image point and robot
/// coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HeightPoint {
    /// Calibration height, mm.
    pub height_mm: f64,
    /// Undistorted image point, px.
    pub image_px: [f64; 2],
    /// Robot X, Y, mm.
    pub robot_mm: [f64; 2],
}

/// Options of [`solve_planar`]. Missing JSON fields take their defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PlanarSolveOptions {
    /// The per-height transform model. Default: affine (the article's).
    pub transform: TransformKind,
    /// Reject high-dispersion heights per parameter beyond this many
    /// standard deviations (externally studentized), then refit. Default: none.
    pub reject_threshold: Option<f64>,
    /// Plate length |AB| and width |BC| in mm for the pixel density; when
    /// absent, the robot-measured side lengths are used. Only used when every
    /// height has exactly four points (corners A, B, C, D in order).
    pub plate_size_mm: Option<[f64; 2]>,
    /// A calibrated camera: when given, every image point is undistorted
    /// (mapped to the pixel the distortion-free camera would see) before
    /// fitting. Default: none (points already undistorted).
    pub camera: Option<Camera>,
}

impl Default for PlanarSolveOptions {
    fn default() -> Self {
        PlanarSolveOptions {
            transform: TransformKind::Affine,
            reject_threshold: None,
            plate_size_mm: None,
            camera: None,
        }
    }
}

/// The transform fitted at one calibration height.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HeightResult {
    /// Calibration height, mm.
    pub height_mm: f64,
    /// The fit with its residuals.
    #[serde(flatten)]
    pub fit: PlanarFit,
}

/// Everything [`solve_planar`] computes, with its inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanarSolveReport {
    /// Per height, sorted by height.
    pub heights: Vec<HeightResult>,
    /// Per parameter: its line against height.
    pub fit: ByParameter<LinearFit>,
    /// Per parameter: heights rejected before the final fit.
    pub rejected_heights_mm: ByParameter<Vec<f64>>,
    /// Pixel density per height (only for four-corner plates).
    pub pixel_density: Option<Vec<PixelDensity>>,
    /// Pixel density against height (only for four-corner plates).
    pub density_fit: Option<DensityFit>,
    /// The exact height-dependent homography family fitted to the same
    /// points by the DLT (see [`super::planar_exact`]); `None` when the DLT
    /// is not applicable (fewer than 6 points).
    pub exact_family: Option<PlaneFamily>,
    /// The points that were solved (undistorted when a camera was given).
    pub points: Vec<HeightPoint>,
    /// The options used.
    pub options: PlanarSolveOptions,
}

impl PlanarSolveReport {
    /// The height model (lines of every parameter) for mapping.
    pub fn model(&self) -> HeightModel {
        HeightModel {
            fit: self.fit.clone(),
            rejected_heights_mm: self.rejected_heights_mm.clone(),
            heights_mm: self.heights.iter().map(|h| h.height_mm).collect(),
        }
    }

    /// Map an image point at any height (see [`HeightModel::map`]).
    pub fn map(&self, height_mm: f64, image_px: [f64; 2]) -> MappedPoint {
        self.model().map(height_mm, image_px)
    }
}

/// Solve the whole workflow. Points at equal `height_mm` form one height.
pub fn solve_planar(
    points: &[HeightPoint],
    options: &PlanarSolveOptions,
) -> Result<PlanarSolveReport> {
    // 0. Undistort with the camera, if any.
    let points: Vec<HeightPoint> = match &options.camera {
        None => points.to_vec(),
        Some(camera) => points
            .iter()
            .map(|p| {
                undistort_pixel(camera, p.image_px).map(|image_px| HeightPoint { image_px, ..*p })
            })
            .collect::<Result<_>>()?,
    };
    let points = points.as_slice();
    // 1. Group by height, sorted.
    let groups = group_by_height(points);
    // 2. One transform per height.
    let heights: Vec<HeightResult> = groups
        .iter()
        .map(|(h, pts)| {
            let pairs: Vec<PointPair> = pts
                .iter()
                .map(|p| PointPair {
                    image_px: p.image_px,
                    robot_mm: p.robot_mm,
                })
                .collect();
            fit_transform(&pairs, options.transform).map(|fit| HeightResult { height_mm: *h, fit })
        })
        .collect::<Result<_>>()?;
    // 3. Every parameter against height.
    let hs: Vec<f64> = heights.iter().map(|h| h.height_mm).collect();
    let ms: Vec<_> = heights.iter().map(|h| h.fit.robot_from_image).collect();
    let model = HeightModel::fit(&hs, &ms, options.reject_threshold)?;
    // 4. Pixel density for four-corner plates.
    let four_corners = groups.iter().all(|(_, p)| p.len() == 4);
    let pixel_density = if four_corners {
        Some(
            groups
                .iter()
                .map(|(h, p)| corner_density(*h, p, options.plate_size_mm))
                .collect::<Result<Vec<_>>>()?,
        )
    } else {
        None
    };
    let density_fit = pixel_density.as_deref().map(fit_density).transpose()?;
    // 5. The exact homography family, where the DLT applies.
    let exact_family = match PlaneFamily::fit(points) {
        Ok(f) => Some(f),
        Err(Error::TooFew { .. }) => None,
        Err(e) => return Err(e),
    };
    Ok(PlanarSolveReport {
        heights,
        fit: model.fit,
        rejected_heights_mm: model.rejected_heights_mm,
        pixel_density,
        density_fit,
        exact_family,
        points: points.to_vec(),
        options: options.clone(),
    })
}

/// The pixel a distortion-free camera with the same intrinsics would see.
pub fn undistort_pixel(camera: &Camera, image_px: [f64; 2]) -> Result<[f64; 2]> {
    let ray = camera.unproject(&nalgebra::Point2::from(image_px))?;
    if !(ray.z > 0.0) {
        return Err(Error::invalid(
            "image_px",
            format!(
                "({}, {}) looks at or beyond 90 degrees: no undistorted pixel",
                image_px[0], image_px[1]
            ),
        ));
    }
    let (x, y) = (ray.x / ray.z, ray.y / ray.z);
    Ok([
        camera.fx * x + camera.skew * y + camera.cx,
        camera.fy * y + camera.cy,
    ])
}

fn corner_density(h: f64, p: &[HeightPoint], size: Option<[f64; 2]>) -> Result<PixelDensity> {
    let corners = [p[0].image_px, p[1].image_px, p[2].image_px, p[3].image_px];
    let [length, width] = match size {
        Some(s) => s,
        None => {
            let d = |a: usize, b: usize| {
                let (x, y) = (p[a].robot_mm, p[b].robot_mm);
                ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2)).sqrt()
            };
            [(d(0, 1) + d(3, 2)) / 2.0, (d(1, 2) + d(0, 3)) / 2.0]
        }
    };
    pixel_density(h, &corners, length, width)
}

/// Points grouped by exact height, groups sorted by height, points in input order.
fn group_by_height(points: &[HeightPoint]) -> Vec<(f64, Vec<HeightPoint>)> {
    let mut groups: Vec<(f64, Vec<HeightPoint>)> = Vec::new();
    for p in points {
        match groups.iter_mut().find(|(h, _)| *h == p.height_mm) {
            Some((_, g)) => g.push(*p),
            None => groups.push((p.height_mm, vec![*p])),
        }
    }
    groups.sort_by(|a, b| a.0.total_cmp(&b.0));
    groups
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::workflows::planar::PlanarMatrix;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn points_to_lines_noise_free() {
        let family = |h: f64| {
            PlanarMatrix::from_array([
                0.0,
                0.7 - 2e-4 * h,
                -1750.0 + 0.35 * h,
                0.7 - 2e-4 * h,
                0.0,
                682.0 + 0.55 * h,
            ])
        };
        let corners = [
            [1280.0, 430.0],
            [1290.0, 3300.0],
            [3015.0, 3290.0],
            [3010.0, 428.0],
        ];
        let mut points = Vec::new();
        for h in [105.0, 15.0, 45.0] {
            for c in corners {
                points.push(HeightPoint {
                    height_mm: h,
                    image_px: c,
                    robot_mm: family(h).apply(c),
                });
            }
        }
        let r = solve_planar(&points, &PlanarSolveOptions::default()).unwrap();
        assert_eq!(
            r.heights.iter().map(|h| h.height_mm).collect::<Vec<_>>(),
            vec![15.0, 45.0, 105.0]
        );
        assert!(
            (r.fit.tx.slope - 0.35).abs() < 1e-9,
            "tx slope {}",
            r.fit.tx.slope
        );
        assert!(
            (r.fit.a12.slope + 2e-4).abs() < 1e-12,
            "a12 slope {}",
            r.fit.a12.slope
        );
        let m = r.map(80.0, [2000.0, 1000.0]);
        let truth = family(80.0).apply([2000.0, 1000.0]);
        assert!((m.robot_mm[0] - truth[0]).abs() < 1e-8 && (m.robot_mm[1] - truth[1]).abs() < 1e-8);
        assert_eq!(r.pixel_density.as_ref().map(|d| d.len()), Some(3));
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn camera_undistorts_before_fitting() {
        // Robot points seen through a Brown lens: after undistortion the
        // per-height affine fit of a fronto-parallel similarity is exact.
        let camera = Camera::example_brown();
        let pinhole = camera.without_distortion();
        let mut points = Vec::new();
        for h in [10.0, 50.0] {
            let depth = 1.0 - h * 1e-3;
            for (x, y) in [
                (-0.1, -0.05),
                (0.1, -0.05),
                (0.1, 0.05),
                (-0.1, 0.05),
                (0.0, 0.02),
            ] {
                let p = nalgebra::Point3::new(x, y, depth);
                let d = camera.project(&p).unwrap();
                let u = pinhole.project(&p).unwrap();
                points.push(HeightPoint {
                    height_mm: h,
                    image_px: [d.x, d.y],
                    robot_mm: [x * 1e3, y * 1e3],
                });
                let back = undistort_pixel(&camera, [d.x, d.y]).unwrap();
                assert!((back[0] - u.x).abs() < 1e-6 && (back[1] - u.y).abs() < 1e-6);
            }
        }
        let raw = solve_planar(&points, &PlanarSolveOptions::default()).unwrap();
        let options = PlanarSolveOptions {
            camera: Some(camera),
            ..Default::default()
        };
        let fixed = solve_planar(&points, &options).unwrap();
        for h in &fixed.heights {
            assert!(
                h.fit.rms_mm < 1e-6,
                "{} mm: rms {} mm",
                h.height_mm,
                h.fit.rms_mm
            );
        }
        assert!(
            raw.heights[0].fit.rms_mm > 1e-3,
            "distortion should show without the camera"
        );
    }
}
