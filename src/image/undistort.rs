//! Whole-image undistortion, the pixels' part: an image resampled (bilinear)
//! through a camera's [`UndistortMap`] (`Camera::undistort_map`, the maths in
//! `camera::undistort`), and the undistorted preview of a whole image.

use super::GrayImage;
use crate::camera::{Camera, UndistortMap};
use crate::error::{Error, Result};

/// Resample `source` through `map` with bilinear interpolation. Samples
/// within half a pixel of the border use the edge pixels; samples outside
/// the image (or NaN) give 0.
pub fn remap_gray(source: &GrayImage, map: &UndistortMap) -> GrayImage {
    let (w, h) = (source.width as usize, source.height as usize);
    let mut pixels = Vec::with_capacity(map.map_x.len());
    for (&sx, &sy) in map.map_x.iter().zip(&map.map_y) {
        pixels.push(sample_bilinear(source, w, h, sx as f64, sy as f64));
    }
    GrayImage {
        width: map.width,
        height: map.height,
        pixels,
    }
}

fn sample_bilinear(image: &GrayImage, w: usize, h: usize, x: f64, y: f64) -> u8 {
    // NaN fails both comparisons and lands here too.
    if w == 0 || h == 0 || !(x >= -0.5 && y >= -0.5 && x <= w as f64 - 0.5 && y <= h as f64 - 0.5) {
        return 0;
    }
    let x = x.clamp(0.0, (w - 1) as f64);
    let y = y.clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f64, y - y0 as f64);
    let at = |xx: usize, yy: usize| image.pixels.get(yy * w + xx).copied().unwrap_or(0) as f64;
    let top = at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx;
    let bottom = at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx;
    (top * (1.0 - fy) + bottom * fy).round().clamp(0.0, 255.0) as u8
}

/// `source`, an image taken by `camera`, resampled (bilinear) into an image
/// of `new_camera` (usually distortion-free: see
/// [`Camera::pinhole_preview`]). The source must have the camera's size.
pub fn undistort_image(
    source: &GrayImage,
    camera: &Camera,
    new_camera: &Camera,
) -> Result<GrayImage> {
    if (source.width, source.height) != (camera.width, camera.height) {
        return Err(Error::invalid(
            "image",
            format!(
                "the image is {}x{} px but the camera was calibrated on {}x{} px images",
                source.width, source.height, camera.width, camera.height
            ),
        ));
    }
    Ok(remap_gray(source, &camera.undistort_map(new_camera)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Distortion;
    use nalgebra::Point2;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// A smooth pattern over normalised undistorted coordinates.
    fn pattern(x: f64, y: f64) -> f64 {
        128.0 + 90.0 * (9.0 * x).sin() * (7.0 * y).cos()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn undistorted_preview_shows_the_scene_through_a_pinhole() {
        // Ground truth: every pixel of the distorted source holds the pattern
        // at its undistorted ray, so an exact undistortion shows the pattern
        // at the preview camera's rays.
        let camera = Camera {
            width: 160,
            height: 120,
            ..Camera::pinhole(150.0, 152.0, 80.3, 59.6, 160, 120)
        };
        let camera = Camera {
            distortion: Distortion::Brown {
                k1: -0.25,
                k2: 0.08,
                k3: 0.0,
                p1: 0.001,
                p2: -0.0005,
            },
            ..camera
        };
        let mut pixels = Vec::new();
        for v in 0..camera.height {
            for u in 0..camera.width {
                let d = Point2::new(
                    (u as f64 - camera.cx) / camera.fx,
                    (v as f64 - camera.cy) / camera.fy,
                );
                let n = camera.undistort_normalized(&d).expect("inside the model");
                pixels.push(pattern(n.x, n.y).round() as u8);
            }
        }
        let source = GrayImage::new(camera.width, camera.height, pixels).expect("image");
        let preview = camera.pinhole_preview(80).expect("preview camera");
        assert_eq!((preview.width, preview.height), (80, 60));
        assert!((preview.fx - 75.0).abs() < 1e-12 && (preview.cx - 39.9).abs() < 1e-12);
        let out = undistort_image(&source, &camera, &preview).expect("undistort");
        let mut worst: f64 = 0.0;
        let mut compared = 0;
        for v in 4..56u32 {
            for u in 4..76u32 {
                let x = (u as f64 - preview.cx) / preview.fx;
                let y = (v as f64 - preview.cy) / preview.fy;
                let src = camera
                    .project(&nalgebra::Point3::new(x, y, 1.0))
                    .expect("in front");
                if src.x < 1.0 || src.y < 1.0 || src.x > 158.0 || src.y > 118.0 {
                    continue;
                }
                let got = out.get(u, v).expect("inside") as f64;
                worst = worst.max((got - pattern(x, y)).abs());
                compared += 1;
            }
        }
        assert!(compared > 3000, "{compared} pixels compared");
        // Bilinear sampling of the pattern (at most ~0.1 rad phase change per
        // source pixel: error below 90 * 0.1^2 / 8 per axis) plus two roundings.
        assert!(worst < 3.0, "worst error {worst} grey levels");
        let small = GrayImage::new(10, 10, vec![0; 100]).expect("image");
        assert_eq!(
            undistort_image(&small, &camera, &preview)
                .unwrap_err()
                .to_string(),
            "image: the image is 10x10 px but the camera was calibrated on 160x120 px images"
        );
        assert_eq!(
            camera.pinhole_preview(0).unwrap_err().to_string(),
            "max_side: needs a positive preview size and image size, got 0 for 160x120"
        );
    }

    /// A ramp image I = 2x + y through the undistortion map of a small
    /// Brown-Conrady camera (the map itself is checked in camera's tests).
    #[wasm_bindgen_test(unsupported = test)]
    fn remap_resamples_a_ramp_to_the_interpolated_ramp() {
        let small = Camera {
            width: 64,
            height: 48,
            fx: 50.0,
            fy: 50.1,
            cx: 31.5,
            cy: 23.5,
            ..Camera::example_brown()
        };
        let map = small
            .undistort_map(&small.without_distortion())
            .unwrap_or_else(|e| panic!("{e}"));
        // A ramp image I = 2x + y resamples to the interpolated ramp (exact for bilinear).
        let ramp: Vec<u8> = (0..48)
            .flat_map(|y| (0..64).map(move |x| (2 * x + y) as u8))
            .collect();
        let image = GrayImage::new(64, 48, ramp).unwrap_or_else(|e| panic!("{e}"));
        let out = remap_gray(&image, &map);
        for (k, &v) in out.pixels.iter().enumerate() {
            let (sx, sy) = (map.map_x[k] as f64, map.map_y[k] as f64);
            let expected = if sx >= 0.0 && sy >= 0.0 && sx <= 63.0 && sy <= 47.0 {
                (2.0 * sx + sy).round()
            } else if sx >= -0.5 && sy >= -0.5 && sx <= 63.5 && sy <= 47.5 {
                (2.0 * sx.clamp(0.0, 63.0) + sy.clamp(0.0, 47.0)).round()
            } else {
                0.0
            };
            assert!(
                (v as f64 - expected).abs() <= 1.0,
                "pixel {k}: {v} vs {expected}"
            );
        }
    }
}
