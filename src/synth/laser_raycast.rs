//! Laser images of solid scenes (seed 003's cubes, the calibration sphere)
//! by supersampled ray casting, the loop both scenes share: every pixel
//! (in a window) is sampled by `SUB` x `SUB` rays through the camera's
//! unprojection; the scene returns the light each ray brings back (0 when
//! it meets nothing lit); the mean over the rays, the ambient grey and
//! Gaussian noise, rounded and clipped to 0..255.

use crate::camera::Camera;
use crate::error::Result;
use crate::image::GrayImage;
use crate::rng::Rng;
use nalgebra::{Point2, Vector3};

/// Rays per pixel axis.
pub const SUB: usize = 3;

/// The light of a sheet of `peak` grey and half-thickness `sigma_m` at a
/// point `s_m` metres off its plane.
pub fn sheet(peak: f64, sigma_m: f64, s_m: f64) -> f64 {
    peak * (-0.5 * s_m * s_m / (sigma_m * sigma_m)).exp()
}

/// The ambient grey and the noise of a laser image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Background {
    /// Grey level of the unlit scene.
    pub ambient: f64,
    /// Additive Gaussian noise, grey levels.
    pub noise_sigma: f64,
    /// Noise seed.
    pub seed: u64,
}

/// The laser image: `light(ray)` (camera frame, not normalised) for every
/// ray of the pixels where `inside(x, y)`, none elsewhere.
pub fn render_rays(
    camera: &Camera,
    background: &Background,
    inside: impl Fn(usize, usize) -> bool,
    mut light: impl FnMut(&Vector3<f64>) -> f64,
) -> Result<GrayImage> {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut rng = Rng::new(background.seed);
    let mut pixels = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let mut sum = 0.0;
            if inside(x, y) {
                for sy in 0..SUB {
                    for sx in 0..SUB {
                        let px = Point2::new(
                            x as f64 - 0.5 + (sx as f64 + 0.5) / SUB as f64,
                            y as f64 - 0.5 + (sy as f64 + 0.5) / SUB as f64,
                        );
                        let Ok(ray) = camera.unproject(&px) else {
                            continue;
                        };
                        sum += light(&ray);
                    }
                }
            }
            let v = background.ambient
                + sum / (SUB * SUB) as f64
                + rng.gaussian(background.noise_sigma);
            pixels.push(v.round().clamp(0.0, 255.0) as u8);
        }
    }
    GrayImage::new(camera.width, camera.height, pixels)
}
