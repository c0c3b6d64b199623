//! Whole-image undistortion, the camera's part: the per-pixel lookup map
//! from one camera to another and the pinhole camera of a preview. The
//! pixels are resampled through the map by `image::undistort` (the camera
//! never sees an image).

use super::Camera;
use crate::error::{Error, Result};
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
