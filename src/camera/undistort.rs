//! Whole-image undistortion: a per-pixel lookup map and a bilinear remap.

use super::Camera;
use crate::error::{Error, Result};
use crate::image::GrayImage;
use nalgebra::{Point2, Point3};

/// For every pixel of an output image, the source pixel to sample (pixel
/// centre convention). `f32::NAN` marks output pixels whose ray the source
/// camera cannot image (outside its model's domain); they remap to 0.
#[derive(Clone, Debug, PartialEq)]
pub struct UndistortMap {
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// Source x per output pixel, row-major.
    pub map_x: Vec<f32>,
    /// Source y per output pixel, row-major.
    pub map_y: Vec<f32>,
}

impl Camera {
    /// The map that resamples an image of this camera into an image of
    /// `new_camera` (usually [`Camera::without_distortion`], possibly with
    /// another focal length or size): each output pixel is unprojected by
    /// `new_camera` and projected by `self`.
    pub fn undistort_map(&self, new_camera: &Camera) -> Result<UndistortMap> {
        if new_camera.width == 0 || new_camera.height == 0 {
            return Err(Error::invalid(
                "new_camera",
                format!(
                    "output image size must be positive, got {}x{}",
                    new_camera.width, new_camera.height
                ),
            ));
        }
        let n = new_camera.width as usize * new_camera.height as usize;
        let mut map_x = Vec::with_capacity(n);
        let mut map_y = Vec::with_capacity(n);
        for y in 0..new_camera.height {
            for x in 0..new_camera.width {
                let source = new_camera
                    .unproject(&Point2::new(x as f64, y as f64))
                    .and_then(|ray| self.project(&Point3::from(ray)));
                match source {
                    Ok(s) => {
                        map_x.push(s.x as f32);
                        map_y.push(s.y as f32);
                    }
                    Err(_) => {
                        map_x.push(f32::NAN);
                        map_y.push(f32::NAN);
                    }
                }
            }
        }
        Ok(UndistortMap {
            width: new_camera.width,
            height: new_camera.height,
            map_x,
            map_y,
        })
    }
}

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

impl Camera {
    /// The distortion-free camera that sees what this one sees, on an image
    /// scaled so that its longer side is at most `max_side` px (never
    /// enlarged): the output camera of an undistorted preview. Scaling keeps
    /// the pixel-centre convention (`c' = (c + 0.5) s - 0.5`).
    pub fn pinhole_preview(&self, max_side: u32) -> Result<Camera> {
        let longer = self.width.max(self.height);
        if max_side == 0 || longer == 0 {
            return Err(Error::invalid(
                "max_side",
                format!(
                    "needs a positive preview size and image size, got {max_side} for {}x{}",
                    self.width, self.height
                ),
            ));
        }
        let s = (max_side as f64 / longer as f64).min(1.0);
        let side = |n: u32| ((n as f64 * s).round() as u32).max(1);
        Ok(Camera {
            fx: self.fx * s,
            fy: self.fy * s,
            cx: (self.cx + 0.5) * s - 0.5,
            cy: (self.cy + 0.5) * s - 0.5,
            skew: self.skew * s,
            width: side(self.width),
            height: side(self.height),
            distortion: super::Distortion::None,
        })
    }
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
mod preview_tests {
    use super::*;
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
            distortion: super::super::Distortion::Brown {
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
}
