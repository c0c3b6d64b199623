//! Seeded renderer of calibration targets with exact ground truth.
//!
//! Given a camera (anything implementing [`Projection`]: pinhole here,
//! distorted models through the same trait), a [`Target`] and its pose
//! `camera_from_target`, renders an 8-bit grey image: the board's albedo is
//! integrated over each pixel (pixels whose four corners see the same colour
//! take it directly; others are supersampled on an n x n grid whose board
//! coordinates are interpolated between the exact ray-plane intersections
//! at the pixel corners), then Gaussian blur, gain with vignetting and a
//! linear illumination gradient, Gaussian noise and rounding. Ground truth
//! is the exact projection of every board point.
//!
//! Board print: chessboards have a white margin one square wide; the outer
//! square diagonally beyond corner 0 is black (the detector's ordering
//! rule). Circle grids and dot plates have a one-unit margin, square grids
//! a one-pitch margin beyond the outer squares. ChArUco boards and
//! AprilGrids are drawn as printed (`crate::target::marker_board`: OpenCV's
//! and Kalibr's layouts) with a white quiet zone of one square (ChArUco) or
//! half a tag beyond the corner squares (AprilGrid). Beyond the
//! print the scene is a uniform grey wall. [`RenderOptions::light_on_dark`]
//! inverts the print (margins included): the same board printed light on
//! dark.

use crate::error::{Error, Result};
use crate::image::GrayImage;
use crate::rng::Rng;
use crate::synth::albedo::Albedo;
use crate::synth::bow::Bow;
use crate::synth::effects::{self, Effects};
use crate::target::{DetectedPoint, Polarity, Target};
use nalgebra::{Isometry3, Point2, Point3, Vector3};

/// A camera as the renderer needs it: pixels to rays and points to pixels.
pub trait Projection {
    /// Pixel of a point in the camera frame; `None` when it does not image.
    fn project_point(&self, p: &Point3<f64>) -> Option<Point2<f64>>;
    /// Ray direction (any length, z > 0 in front) through a pixel.
    fn unproject_pixel(&self, px: &Point2<f64>) -> Option<Vector3<f64>>;
    /// `(width, height)` in pixels.
    fn image_size(&self) -> (u32, u32);
}

/// A distortion-free pinhole camera.
#[derive(Debug, Clone, PartialEq)]
pub struct Pinhole {
    /// Focal lengths, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

impl Projection for Pinhole {
    fn project_point(&self, p: &Point3<f64>) -> Option<Point2<f64>> {
        (p.z > 1e-9)
            .then(|| Point2::new(self.fx * p.x / p.z + self.cx, self.fy * p.y / p.z + self.cy))
    }
    fn unproject_pixel(&self, px: &Point2<f64>) -> Option<Vector3<f64>> {
        Some(Vector3::new(
            (px.x - self.cx) / self.fx,
            (px.y - self.cy) / self.fy,
            1.0,
        ))
    }
    fn image_size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
}

impl Projection for crate::camera::Camera {
    fn project_point(&self, p: &Point3<f64>) -> Option<Point2<f64>> {
        self.project(p).ok()
    }
    fn unproject_pixel(&self, px: &Point2<f64>) -> Option<Vector3<f64>> {
        self.unproject(px).ok()
    }
    fn image_size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
}

/// Photometric settings of a render.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Grey level of the print's black (before gain), default 30.
    pub black: f64,
    /// Grey level of the print's white, default 220.
    pub white: f64,
    /// Grey level of the wall behind the board, default 120.
    pub background: f64,
    /// Global gain, default 1.
    pub gain: f64,
    /// Relative brightness loss at the image corners (cos^4-like, quadratic
    /// in the radius), 0..1, default 0.
    pub vignetting: f64,
    /// Relative brightness change from the left to the right edge, default 0.
    pub gradient: f64,
    /// Gaussian blur sigma, pixels (default 0.7: a sharp lens).
    pub blur_sigma_px: f64,
    /// Additive Gaussian noise sigma, grey levels (default 2).
    pub noise_sigma: f64,
    /// Supersampling per axis for pixels on an edge (default 8).
    pub supersample: u32,
    /// Circle diameter over the grid unit for circle grids (default 0.5;
    /// dot plates use their own diameter).
    pub circle_diameter_ratio: f64,
    /// Noise seed.
    pub seed: u64,
    /// Camera effects (gamma, lens PSF, motion, rolling shutter, Bayer,
    /// sensor noise, JPEG, paper texture); default: all off.
    pub effects: Effects,
    /// A laser stripe drawn over the scene ([`crate::synth::laser`]);
    /// default none.
    pub laser: Option<crate::synth::laser::LaserStripe>,
    /// The board's flex, metres: mrcal's paraboloid (`calib::BoardWarp`)
    /// over the extent of the target's points, along the target's +z;
    /// default flat.
    pub board_warp_m: [f64; 2],
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            black: 30.0,
            white: 220.0,
            background: 120.0,
            gain: 1.0,
            vignetting: 0.0,
            gradient: 0.0,
            blur_sigma_px: 0.7,
            noise_sigma: 2.0,
            supersample: 8,
            circle_diameter_ratio: 0.5,
            seed: 1,
            effects: Effects::default(),
            laser: None,
            board_warp_m: [0.0, 0.0],
        }
    }
}

impl RenderOptions {
    /// The same options with the print inverted (its black and white
    /// swapped, margins and quiet zones included): a board printed light on
    /// dark. Its points and ids are the normal print's; a chessboard's
    /// outer square beyond corner 0 becomes light, as a light-on-dark
    /// chessboard defines it.
    pub fn light_on_dark(self) -> RenderOptions {
        RenderOptions {
            black: self.white,
            white: self.black,
            ..self
        }
    }

    /// The options for a target printed `print` (`Polarity::DarkOnLight`:
    /// unchanged; a circle grid's own `polarity` is drawn on top of this).
    pub fn printed(self, print: Polarity) -> RenderOptions {
        match print {
            Polarity::DarkOnLight => self,
            Polarity::LightOnDark => self.light_on_dark(),
        }
    }
}

/// A rendered image and the exact pixels of the target points inside it.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The image.
    pub image: GrayImage,
    /// Ground truth, in id order, only points inside the image.
    pub points: Vec<DetectedPoint>,
}

/// Render `target` at `camera_from_target` through `camera`.
pub fn render(
    camera: &dyn Projection,
    target: &Target,
    camera_from_target: &Isometry3<f64>,
    options: &RenderOptions,
) -> Result<Rendered> {
    let (w, h) = camera.image_size();
    if w == 0 || h == 0 || (w as u64) * (h as u64) > 100_000_000 {
        return Err(Error::invalid(
            "camera",
            format!("cannot render a {w}x{h} image"),
        ));
    }
    let target = target.clone().validated()?;
    let albedo = Albedo::new(&target, options);
    let target_from_camera = camera_from_target.inverse();
    let normal = camera_from_target.rotation * Vector3::z();
    let origin = camera_from_target.translation.vector;
    let fx = &options.effects;
    let (hw, hh) = (0.5 * (w as f64 - 1.0), 0.5 * (h as f64 - 1.0));
    let skew = fx.rolling_shutter_px_per_row;
    // Board coordinates at the pixel corners (x - 0.5, y - 0.5).
    let bow = Bow::of(&target, options.board_warp_m);
    let (cw, ch) = (w as usize + 1, h as usize + 1);
    let mut corners: Vec<Option<(f64, f64)>> = Vec::with_capacity(cw * ch);
    for y in 0..ch {
        for x in 0..cw {
            let mut px = Point2::new(x as f64 - 0.5, y as f64 - 0.5);
            if skew != 0.0 {
                px.x -= skew * (px.y - hh);
            }
            corners.push(camera.unproject_pixel(&px).and_then(|ray| {
                let den = normal.dot(&ray);
                let lambda = normal.dot(&origin) / den;
                (den.abs() > 1e-12 && lambda > 0.0).then(|| {
                    let b = target_from_camera * Point3::from(ray * lambda);
                    match &bow {
                        Some(bow) => bow.hit(&target_from_camera, &ray, (b.x, b.y)),
                        None => (b.x, b.y),
                    }
                })
            }));
        }
    }
    let n = options.supersample.clamp(1, 32) as usize;
    let mut img = vec![0.0f32; w as usize * h as usize];
    for y in 0..h as usize {
        for x in 0..w as usize {
            let c = [
                corners[y * cw + x],
                corners[y * cw + x + 1],
                corners[(y + 1) * cw + x],
                corners[(y + 1) * cw + x + 1],
            ];
            let vals: Vec<f64> = c.iter().map(|q| albedo.at(*q)).collect();
            let same = vals.iter().all(|v| *v == vals[0]);
            img[y * w as usize + x] = if same && c.iter().all(|q| q.is_some()) {
                vals[0] as f32
            } else {
                supersample(&albedo, &c, n) as f32
            };
        }
    }
    if let Some(paper) = &fx.paper {
        apply_paper(&mut img, &corners, w as usize, paper);
    }
    if let Some(laser) = &options.laser {
        let white = options.white.max(options.black).max(options.background);
        crate::synth::laser::add_stripe(
            &mut img,
            &corners,
            w as usize,
            h as usize,
            camera_from_target,
            white,
            laser,
        );
    }
    let mut plane = crate::image::filter::Plane {
        w: w as usize,
        h: h as usize,
        data: img,
    };
    if let Some(optics) = &fx.optics {
        plane = effects::apply_optics(&plane, optics);
    }
    if let Some(motion) = &fx.motion {
        plane = effects::apply_motion(&plane, motion);
    }
    let blurred = if options.blur_sigma_px > 0.0 {
        plane.gaussian(options.blur_sigma_px).data
    } else {
        plane.data
    };
    let mut rng = Rng::new(options.seed);
    let rmax2 = hw * hw + hh * hh;
    let mut signal: Vec<f64> = blurred
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let (x, y) = ((i % w as usize) as f64, (i / w as usize) as f64);
            let r2 = ((x - hw).powi(2) + (y - hh).powi(2)) / rmax2.max(1e-9);
            let light = options.gain
                * (1.0 - options.vignetting * r2)
                * (1.0 + options.gradient * (x / (w as f64).max(1.0) - 0.5));
            *v as f64 * light
        })
        .collect();
    let pixels = if fx.is_off() {
        signal
            .iter()
            .map(|v| {
                (v + rng.gaussian(options.noise_sigma))
                    .round()
                    .clamp(0.0, 255.0) as u8
            })
            .collect()
    } else {
        camera_pipeline(&mut signal, w, h, options, &mut rng)?
    };
    let points = target
        .object_points()
        .into_iter()
        .filter_map(|(id, p)| {
            let p = match &bow {
                Some(bow) => Point3::new(p.x, p.y, p.z + bow.z(p.x, p.y)),
                None => p,
            };
            let mut q = camera.project_point(&(camera_from_target * p))?;
            if skew != 0.0 {
                q.x += skew * (q.y - hh);
            }
            let inside = q.x >= 0.0 && q.y >= 0.0 && q.x <= w as f64 - 1.0 && q.y <= h as f64 - 1.0;
            inside.then_some(DetectedPoint {
                id,
                x_px: q.x,
                y_px: q.y,
                covariance_px2: None,
            })
        })
        .collect();
    Ok(Rendered {
        image: GrayImage::new(w, h, pixels)?,
        points,
    })
}

/// Steps 5-9 of [`effects`]: mosaic, sensor and additive noise, demosaic,
/// response, 8 bits, JPEG.
fn camera_pipeline(
    signal: &mut [f64],
    w: u32,
    h: u32,
    options: &RenderOptions,
    rng: &mut Rng,
) -> Result<Vec<u8>> {
    let fx = &options.effects;
    if let Some(bayer) = &fx.bayer {
        effects::mosaic(signal, w as usize, bayer);
    }
    if let Some(sensor) = &fx.sensor {
        // Its own stream: the additive noise keeps its draws.
        let mut shot = Rng::new(options.seed ^ SENSOR_SEED);
        effects::sensor_noise(signal, sensor, &mut shot);
    }
    for v in signal.iter_mut() {
        *v += rng.gaussian(options.noise_sigma);
    }
    let grey = match &fx.bayer {
        Some(_) => effects::demosaic_to_grey(signal, w as usize, h as usize),
        None => signal.to_vec(),
    };
    let pixels: Vec<u8> = grey
        .iter()
        .map(|&v| {
            let g = fx.gamma.map_or(v, |gamma| effects::response(v, gamma));
            g.round().clamp(0.0, 255.0) as u8
        })
        .collect();
    match fx.jpeg_quality {
        Some(q) => effects::jpeg_round_trip(&pixels, w, h, q),
        None => Ok(pixels),
    }
}

/// Seed offset of the sensor-noise stream.
const SENSOR_SEED: u64 = 0x5E45_0A11_D0C5_0001;

/// Paper texture at each pixel's centre (the mean of its corners' board
/// coordinates): the texture is smooth over a pixel.
fn apply_paper(img: &mut [f32], corners: &[Option<(f64, f64)>], w: usize, paper: &effects::Paper) {
    let texture = effects::Texture::new(paper);
    let cw = w + 1;
    for (i, v) in img.iter_mut().enumerate() {
        let (x, y) = (i % w, i / w);
        let c = [
            corners[y * cw + x],
            corners[y * cw + x + 1],
            corners[(y + 1) * cw + x],
            corners[(y + 1) * cw + x + 1],
        ];
        if let [Some(a), Some(b), Some(d), Some(e)] = c {
            let (bx, by) = (
                0.25 * (a.0 + b.0 + d.0 + e.0),
                0.25 * (a.1 + b.1 + d.1 + e.1),
            );
            *v = (*v as f64 * (1.0 + texture.at(bx, by))) as f32;
        }
    }
}

fn supersample(albedo: &Albedo, c: &[Option<(f64, f64)>; 4], n: usize) -> f64 {
    let [Some(a), Some(b), Some(d), Some(e)] = *c else {
        return albedo.background;
    };
    let mut sum = 0.0;
    for sy in 0..n {
        let v = (sy as f64 + 0.5) / n as f64;
        for sx in 0..n {
            let u = (sx as f64 + 0.5) / n as f64;
            let x = (a.0 * (1.0 - u) + b.0 * u) * (1.0 - v) + (d.0 * (1.0 - u) + e.0 * u) * v;
            let y = (a.1 * (1.0 - u) + b.1 * u) * (1.0 - v) + (d.1 * (1.0 - u) + e.1 * u) * v;
            sum += albedo.at(Some((x, y)));
        }
    }
    sum / (n * n) as f64
}
