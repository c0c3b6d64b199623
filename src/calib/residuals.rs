//! Per-point residual vectors and the lens-distortion vector field: the data
//! the web app draws (arrows over the image) and that plots read.

use super::View;
use crate::camera::Camera;
use crate::geometry::Pose;
use nalgebra::Point2;
use serde::{Deserialize, Serialize};

/// Grid of the distortion field (columns, rows).
const FIELD_GRID: (usize, usize) = (16, 12);

/// A vector anchored at a pixel, px.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PixelVector {
    /// Anchor x, px.
    pub x: f64,
    /// Anchor y, px.
    pub y: f64,
    /// Vector x component, px.
    pub dx: f64,
    /// Vector y component, px.
    pub dy: f64,
    /// The target's id of the point (residuals only; absent in the
    /// distortion field).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<usize>,
}

/// The lens distortion over the image: at each node of a coarse grid over
/// the (distorted) image, the distorted minus the undistorted pixel position
/// (`x + dx` is where the lens puts the ray that a pinhole with the same
/// camera matrix would put at `x`, read backwards: `(x, y)` is the observed
/// pixel, `(x - dx, y - dy)` its ideal pinhole position).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DistortionField {
    /// Grid nodes where the model can be inverted, row by row.
    pub vectors: Vec<PixelVector>,
}

/// Observed minus predicted pixel for every point of a view (outliers
/// included), anchored at the observed pixel, in the view's point order,
/// each with the target's id of the point (which corner of which view is
/// off). A point the camera cannot project (behind it) is left out.
pub fn view_residuals(camera: &Camera, pose: &Pose, view: &View) -> Vec<PixelVector> {
    view.object_m
        .iter()
        .zip(&view.image_px)
        .enumerate()
        .filter_map(|(index, (object, observed))| {
            let predicted = camera.project(&(pose * object)).ok()?;
            Some(PixelVector {
                x: observed.x,
                y: observed.y,
                dx: observed.x - predicted.x,
                dy: observed.y - predicted.y,
                id: Some(view.point_id(index)),
            })
        })
        .collect()
}

/// The distortion field of `camera` on a 16 x 12 grid spanning the image.
pub fn distortion_field(camera: &Camera) -> DistortionField {
    let (cols, rows) = FIELD_GRID;
    let at = |i: usize, n: usize, size: u32| i as f64 * (size as f64 - 1.0) / (n - 1) as f64;
    let pinhole = camera.without_distortion();
    let mut vectors = Vec::with_capacity(cols * rows);
    for r in 0..rows {
        for c in 0..cols {
            let pixel = Point2::new(at(c, cols, camera.width), at(r, rows, camera.height));
            let Ok(ray) = camera.unproject(&pixel) else {
                continue;
            };
            // Rays at or beyond 90 degrees have no pinhole position.
            if !(ray.z > 0.0) {
                continue;
            }
            let Ok(ideal) = pinhole.project(&nalgebra::Point3::from(ray)) else {
                continue;
            };
            vectors.push(PixelVector {
                x: pixel.x,
                y: pixel.y,
                dx: pixel.x - ideal.x,
                dy: pixel.y - ideal.y,
                id: None,
            });
        }
    }
    DistortionField { vectors }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Pose;
    use nalgebra::{Point3, Translation3, UnitQuaternion};
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn field_is_zero_without_distortion_and_matches_the_model_with_it() {
        let pinhole = Camera::pinhole(800.0, 800.0, 319.5, 239.5, 640, 480);
        let field = distortion_field(&pinhole);
        assert_eq!(field.vectors.len(), 16 * 12);
        assert!(field.vectors.iter().all(|v| v.dx.abs() + v.dy.abs() < 1e-9));
        let brown = Camera::example_brown();
        let field = distortion_field(&brown);
        for v in &field.vectors {
            // The ideal position distorted again lands on the grid node.
            let ideal = Point2::new(v.x - v.dx, v.y - v.dy);
            let m = Point2::new(
                (ideal.x - brown.cx) / brown.fx,
                (ideal.y - brown.cy) / brown.fy,
            );
            let d = brown.distort_normalized(&m).expect("distort");
            let back = Point2::new(brown.fx * d.x + brown.cx, brown.fy * d.y + brown.cy);
            assert!((back - Point2::new(v.x, v.y)).norm() < 1e-6, "px");
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn residuals_are_observed_minus_predicted() {
        let camera = Camera::pinhole(800.0, 800.0, 319.5, 239.5, 640, 480);
        let pose = Pose::from_parts(Translation3::new(0.0, 0.0, 1.0), UnitQuaternion::identity());
        let view = View::new(
            "v",
            vec![Point3::new(0.0, 0.0, 0.0), Point3::new(0.1, 0.0, 0.0)],
            vec![Point2::new(320.5, 239.0), Point2::new(399.5, 239.5)],
        );
        let r = view_residuals(&camera, &pose, &view);
        assert_eq!(r.len(), 2);
        assert!((r[0].dx - 1.0).abs() < 1e-12 && (r[0].dy + 0.5).abs() < 1e-12);
        assert!(r[1].dx.abs() < 1e-12 && r[1].dy.abs() < 1e-12);
        assert_eq!((r[1].x, r[1].y), (399.5, 239.5));
    }
}
