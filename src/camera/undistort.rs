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
