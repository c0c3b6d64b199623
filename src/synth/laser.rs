//! Laser stripes in rendered images: a plane of light (camera frame) met
//! with the board's plane is a line in the image; the renderer adds its
//! light before the blur and the camera's gain, so it is blurred, vignetted,
//! noised and clipped at 255 (saturation) with the rest of the image.
//!
//! The cross-profile is a Gaussian in the image: at a pixel whose board
//! point lies `s` metres off the laser plane, the image distance to the
//! line is `s / |grad s|` (the gradient over the pixel grid, from the
//! renderer's ray/board intersections at the pixel corners), exact for a
//! pinhole and to first order under distortion. The light is `peak *
//! reflectance * exp(-dist^2 / (2 sigma^2)) * speckle`, supersampled over
//! the pixel, with the reflectance the print's grey level over its white
//! (the stripe is dim on black squares) and the speckle a multiplicative
//! factor `max(0, 1 + rms * g)`, `g` a unit Gaussian process along the
//! line correlated over `speckle_length_px`. The scene's own light is
//! scaled by `ambient` (1: as in the laser-off image; near 0: a filtered,
//! dark laser image).

use crate::laser::LaserPlane;
use crate::rng::Rng;
use nalgebra::{Isometry3, Point2, Point3, Vector3};
use serde::Serialize;

use super::Projection;

/// A laser stripe to draw.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LaserStripe {
    /// The plane of light in the camera frame.
    #[serde(serialize_with = "crate::laser::plane::serialize_camera_plane")]
    pub plane: LaserPlane,
    /// Grey level of the stripe's peak on white print, before gain (default
    /// 400: a white square saturates).
    pub peak: f64,
    /// Full width at half maximum of the cross-profile, pixels (default 5).
    pub width_px: f64,
    /// Relative RMS of the speckle (default 0.2; 0 = none).
    pub speckle: f64,
    /// Correlation length of the speckle along the line, pixels (default 3).
    pub speckle_length_px: f64,
    /// Scale of the scene's own light in the stripe image (default 1).
    pub ambient: f64,
    /// Seed of the speckle.
    pub seed: u64,
}

impl LaserStripe {
    /// The defaults for a plane.
    pub fn new(plane: LaserPlane) -> LaserStripe {
        LaserStripe {
            plane,
            peak: 400.0,
            width_px: 5.0,
            speckle: 0.2,
            speckle_length_px: 3.0,
            ambient: 1.0,
            seed: 7,
        }
    }
}

/// Sub-samples per pixel axis for the profile.
const SUB: usize = 5;

/// Add the stripe to `img` (albedo per pixel, row-major `w x h`) given the
/// board coordinates at the pixel corners (`(w + 1) x (h + 1)`).
pub(crate) fn add_stripe(
    img: &mut [f32],
    corners: &[Option<(f64, f64)>],
    w: usize,
    h: usize,
    camera_from_target: &Isometry3<f64>,
    white: f64,
    laser: &LaserStripe,
) {
    let n = laser.plane.normal.into_inner();
    let d = laser.plane.distance_m;
    let cw = w + 1;
    // Signed distance to the laser plane at every pixel corner.
    let s: Vec<Option<f64>> = corners
        .iter()
        .map(|c| c.map(|(x, y)| n.dot(&(camera_from_target * Point3::new(x, y, 0.0)).coords) - d))
        .collect();
    let sigma = laser.width_px / (8f64.ln().sqrt() * 2.0);
    let reach = 5.0 * sigma + 1.5;
    let speckle = Speckle::new(laser, w + h);
    for v in img.iter_mut() {
        *v *= laser.ambient as f32;
    }
    for y in 0..h {
        for x in 0..w {
            let (Some(a), Some(b), Some(c), Some(e)) = (
                s[y * cw + x],
                s[y * cw + x + 1],
                s[(y + 1) * cw + x],
                s[(y + 1) * cw + x + 1],
            ) else {
                continue;
            };
            let gx = 0.5 * (b - a + e - c);
            let gy = 0.5 * (c - a + e - b);
            let g = (gx * gx + gy * gy).sqrt();
            if g <= 0.0 {
                continue;
            }
            let centre = 0.25 * (a + b + c + e) / g;
            if centre.abs() > reach {
                continue;
            }
            let mut sum = 0.0;
            for sy in 0..SUB {
                let v = (sy as f64 + 0.5) / SUB as f64;
                for sx in 0..SUB {
                    let u = (sx as f64 + 0.5) / SUB as f64;
                    let sv = (a * (1.0 - u) + b * u) * (1.0 - v) + (c * (1.0 - u) + e * u) * v;
                    let dist = sv / g;
                    sum += (-0.5 * dist * dist / (sigma * sigma)).exp();
                }
            }
            let profile = sum / (SUB * SUB) as f64;
            // Position along the line: the pixel projected on the tangent.
            let along = (-gy * x as f64 + gx * y as f64) / g;
            let i = y * w + x;
            let albedo = img[i] as f64 / laser.ambient.max(1e-12);
            let reflectance = if laser.ambient > 0.0 {
                (albedo / white).clamp(0.0, 1.0)
            } else {
                1.0
            };
            img[i] += (laser.peak * reflectance * profile * speckle.at(along)) as f32;
        }
    }
}

/// A unit Gaussian process along the line, correlated over a length.
struct Speckle {
    rms: f64,
    offset: f64,
    values: Vec<f64>,
}

impl Speckle {
    fn new(laser: &LaserStripe, span: usize) -> Speckle {
        let n = 2 * span + 8;
        if laser.speckle <= 0.0 {
            return Speckle {
                rms: 0.0,
                offset: 0.0,
                values: Vec::new(),
            };
        }
        let mut rng = Rng::new(laser.seed ^ 0x1A5E_5EED);
        let white: Vec<f64> = (0..n).map(|_| rng.gaussian(1.0)).collect();
        let l = laser.speckle_length_px.max(0.3);
        let r = (3.0 * l).ceil() as isize;
        let k: Vec<f64> = (-r..=r)
            .map(|i| (-0.5 * (i as f64 / l).powi(2)).exp())
            .collect();
        let norm = k.iter().map(|v| v * v).sum::<f64>().sqrt();
        let values = (0..n as isize)
            .map(|i| {
                (-r..=r)
                    .map(|a| white[(i + a).clamp(0, n as isize - 1) as usize] * k[(a + r) as usize])
                    .sum::<f64>()
                    / norm
            })
            .collect();
        Speckle {
            rms: laser.speckle,
            offset: span as f64 + 4.0,
            values,
        }
    }

    fn at(&self, along: f64) -> f64 {
        if self.values.is_empty() {
            return 1.0;
        }
        let t = (along + self.offset).clamp(0.0, (self.values.len() - 2) as f64);
        let i = t.floor() as usize;
        let f = t - i as f64;
        let g = self.values[i] * (1.0 - f) + self.values[i + 1] * f;
        (1.0 + self.rms * g).max(0.0)
    }
}

/// The exact stripe centre (the plane/board intersection line projected)
/// in every column (`along_columns`) or row where it is imaged: `(scan
/// index, centre)` pairs.
pub fn stripe_truth(
    camera: &dyn Projection,
    camera_from_target: &Isometry3<f64>,
    plane: &LaserPlane,
    along_columns: bool,
) -> Vec<(usize, f64)> {
    let n = plane.normal.into_inner();
    let m = camera_from_target.rotation * Vector3::z();
    let e = m.dot(&camera_from_target.translation.vector);
    let u = n.cross(&m);
    if u.norm() < 1e-9 {
        return Vec::new();
    }
    // The point of the line closest to the origin.
    let p0 = Point3::from((m.cross(&u) * plane.distance_m + u.cross(&n) * e) / u.norm_squared());
    let u = u.normalize();
    let (w, h) = camera.image_size();
    let scale = p0.coords.norm().max(0.05);
    let steps = 40_000;
    let samples: Vec<Point2<f64>> = (0..=steps)
        .filter_map(|k| {
            let s = (k as f64 / steps as f64 - 0.5) * 8.0 * scale;
            camera.project_point(&(p0 + u * s))
        })
        .collect();
    let limit = if along_columns { w } else { h };
    let other = if along_columns { h } else { w } as f64;
    let mut found: Vec<Option<f64>> = vec![None; limit as usize];
    for pair in samples.windows(2) {
        let (a, b) = if along_columns {
            ((pair[0].x, pair[0].y), (pair[1].x, pair[1].y))
        } else {
            ((pair[0].y, pair[0].x), (pair[1].y, pair[1].x))
        };
        if a.0 == b.0 || (b.0 - a.0).abs() > 2.0 {
            continue;
        }
        let (lo, hi) = (a.0.min(b.0).ceil().max(0.0), a.0.max(b.0).floor());
        let mut c = lo;
        while c <= hi && c < limit as f64 {
            let v = a.1 + (b.1 - a.1) * (c - a.0) / (b.0 - a.0);
            let slot = &mut found[c as usize];
            if slot.is_none() && v >= 0.0 && v <= other - 1.0 {
                *slot = Some(v);
            }
            c += 1.0;
        }
    }
    found
        .into_iter()
        .enumerate()
        .filter_map(|(i, v)| v.map(|v| (i, v)))
        .collect()
}

/// One board pose as a laser sensor films it for the plane's pairs: the
/// board with the laser off (render seed `seed`) and with `stripe` on
/// (seed `seed + 1`), the same scene otherwise (default render options).
/// Returns `(board, stripe)`.
pub fn laser_pair(
    camera: &dyn Projection,
    target: &crate::target::Target,
    camera_from_target: &Isometry3<f64>,
    stripe: &LaserStripe,
    seed: u64,
) -> crate::error::Result<(crate::image::GrayImage, crate::image::GrayImage)> {
    let off = super::RenderOptions {
        seed,
        ..super::RenderOptions::default()
    };
    let on = super::RenderOptions {
        seed: seed + 1,
        laser: Some(stripe.clone()),
        ..super::RenderOptions::default()
    };
    Ok((
        super::render(camera, target, camera_from_target, &off)?.image,
        super::render(camera, target, camera_from_target, &on)?.image,
    ))
}
