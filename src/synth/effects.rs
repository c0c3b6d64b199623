//! Camera effects for the renderer: what real lenses, sensors and image
//! pipelines do to a calibration target, each optional and seeded.
//!
//! [`Effects::default()`] switches every effect off, and a render without
//! effects is bit-identical to one made before they existed. The ground
//! truth stays the exact ideal projection of each target point; the only
//! effect that moves it is the rolling shutter, whose shear is part of the
//! image geometry (the truth then is where the point is imaged).
//!
//! Where each effect acts in [`super::render`] (the order of a camera):
//! 1. rolling shutter: row `y` of the image sees the scene shifted by
//!    `rolling_shutter_px_per_row * (y - yc)` along x (`yc` the middle row);
//! 2. paper texture multiplies the print's albedo (board coordinates);
//! 3. the optics' field-dependent PSF, then motion blur, then the
//!    renderer's Gaussian blur (`RenderOptions::blur_sigma_px`: the sensor's
//!    pixel and the anti-aliasing filter);
//! 4. gain, vignetting and gradient give the linear signal in grey levels;
//! 5. the Bayer mosaic (RGGB, each site scaled by its channel's residual
//!    white-balance gain);
//! 6. sensor noise in electrons (shot + read, clipped at the full well),
//!    then the additive Gaussian noise of `RenderOptions::noise_sigma`;
//! 7. bilinear demosaicing and the grey conversion of the decoders;
//! 8. the camera response (gamma), rounding to 8 bits;
//! 9. JPEG compression at a quality, decoded again.
//!
//! The optics' PSF keeps its centroid on the ideal projection (coma's
//! centroid shift is the lens's distortion, which the camera model carries,
//! not the PSF): an unbiased corner detector stays on the truth, one that
//! locates edges by their mid-level or by a symmetric model does not when
//! the blur is asymmetric.

use crate::image::filter::Plane;
use crate::rng::Rng;

/// Camera effects, each `None` (off) by default.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Effects {
    /// Camera response: the linear signal `v` (grey levels, 0..255) is
    /// written as `255 (v / 255)^(1 / gamma)` (2.2: sRGB-like). Default off.
    pub gamma: Option<f64>,
    /// Field-dependent PSF of the lens. Default off.
    pub optics: Option<Optics>,
    /// Linear motion blur during the exposure. Default off.
    pub motion: Option<MotionBlur>,
    /// Rolling-shutter skew: the scene's x shift per image row, pixels per
    /// row, zero at the middle row. Default 0 (global shutter).
    pub rolling_shutter_px_per_row: f64,
    /// Bayer mosaic (RGGB) and bilinear demosaicing. Default off.
    pub bayer: Option<Bayer>,
    /// Signal-dependent sensor noise. Default off.
    pub sensor: Option<SensorNoise>,
    /// JPEG quality 1..=100 (`image`'s encoder, baseline 4:4:4 grey).
    /// Default off (lossless).
    pub jpeg_quality: Option<u8>,
    /// Paper texture under the print. Default off.
    pub paper: Option<Paper>,
}

/// A lens's blur, growing from the image centre to its corners. The field
/// radius `rho` is 0 at the image centre and 1 at its corners; the PSF is the
/// spread of rays through a uniformly lit circular pupil (third-order
/// aberrations), sampled with [`PUPIL_SAMPLES`] rays.
#[derive(Debug, Clone, PartialEq)]
pub struct Optics {
    /// Defocus disc radius at the image centre, pixels.
    pub defocus_px: f64,
    /// Extra defocus radius at the corners (field curvature, grows as
    /// `rho^2`), pixels.
    pub field_curvature_px: f64,
    /// Astigmatism: extra blur radius along the radial direction at the
    /// corners (grows as `rho^2`), pixels.
    pub astigmatism_px: f64,
    /// Coma at the corners (grows as `rho`): the radial spread of the comatic
    /// flare, pixels; the flare points away from the centre.
    pub coma_px: f64,
}

/// Uniform motion of the image during the exposure.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionBlur {
    /// Length of the image's path during the exposure, pixels.
    pub length_px: f64,
    /// Direction of the motion, radians from the image x axis towards y.
    pub angle_rad: f64,
}

/// Colour filter array RGGB (R at even x and even y) and the residual gains
/// of an imperfect white balance.
#[derive(Debug, Clone, PartialEq)]
pub struct Bayer {
    /// Gains of the R, G and B sites after white balance (1, 1, 1: perfect).
    pub channel_gain: [f64; 3],
}

/// Shot and read noise of a sensor: the linear signal `v` grey levels holds
/// `v / gain_dn_per_e` electrons; the shot noise is Poisson (drawn as its
/// Gaussian approximation, exact in variance), the read noise Gaussian; the
/// result is clipped at 0 and at the full well. Grey-level variance:
/// `gain * v + (gain * read)^2`.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorNoise {
    /// Full-well capacity, electrons.
    pub full_well_e: f64,
    /// Conversion gain, grey levels per electron.
    pub gain_dn_per_e: f64,
    /// Read noise sigma, electrons.
    pub read_noise_e: f64,
}

/// Paper texture: the albedo times `1 + t(x, y)`, `t` a sum of
/// [`PAPER_WAVES`] plane waves in board coordinates with random directions,
/// phases and wavelengths in `[wavelength_m, 2 wavelength_m]`, scaled so that
/// its RMS is `rms`. The ink's black and the paper's white themselves are
/// `RenderOptions::black` and `white` (a print is never 0 or 255).
#[derive(Debug, Clone, PartialEq)]
pub struct Paper {
    /// RMS of the relative albedo change.
    pub rms: f64,
    /// Shortest wavelength of the texture, metres on the board.
    pub wavelength_m: f64,
    /// Texture seed: a board's texture is the same in every view.
    pub seed: u64,
}

/// Rays through the pupil per pixel for the optics' PSF. A uniform field
/// loses energy within the PSF's reach of the image border (the light
/// spreads out of the image and none comes in).
pub const PUPIL_SAMPLES: usize = 96;
/// Plane waves of the paper texture.
pub const PAPER_WAVES: usize = 8;
/// Motion-blur samples per pixel of path length.
const MOTION_SAMPLES_PER_PX: f64 = 4.0;
/// Grey conversion of RGB as `image` (robocal's decoder) does: Rec. 709 luma.
pub const LUMA: [f64; 3] = [0.2126, 0.7152, 0.0722];

impl Effects {
    /// A cheap camera at its usual settings: gamma 2.2; a lens slightly out
    /// of focus (0.5 px disc) whose blur grows to the corners (curvature
    /// 0.8 px, astigmatism 0.8 px, coma 0.6 px); 0.5 px of motion at 30
    /// degrees; Bayer with 5 % white-balance residuals; a small sensor
    /// (6000 e- full well, 255 grey levels at 6000 e-, 4 e- read noise);
    /// JPEG quality 90; paper texture of 2 % RMS at 4 cm. Global shutter:
    /// add `rolling_shutter_px_per_row` for a moving camera.
    pub fn realistic() -> Effects {
        Effects {
            gamma: Some(2.2),
            optics: Some(Optics {
                defocus_px: 0.5,
                field_curvature_px: 0.8,
                astigmatism_px: 0.8,
                coma_px: 0.6,
            }),
            motion: Some(MotionBlur {
                length_px: 0.5,
                angle_rad: 30f64.to_radians(),
            }),
            rolling_shutter_px_per_row: 0.0,
            bayer: Some(Bayer {
                channel_gain: [0.95, 1.0, 1.05],
            }),
            sensor: Some(SensorNoise {
                full_well_e: 6000.0,
                gain_dn_per_e: 255.0 / 6000.0,
                read_noise_e: 4.0,
            }),
            jpeg_quality: Some(90),
            paper: Some(Paper {
                rms: 0.02,
                wavelength_m: 0.04,
                seed: 17,
            }),
        }
    }

    /// Whether every effect is off.
    pub fn is_off(&self) -> bool {
        *self == Effects::default()
    }
}

/// Pupil points, uniform over the unit disc (Vogel's sunflower spiral).
fn pupil() -> Vec<(f64, f64)> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..PUPIL_SAMPLES)
        .map(|k| {
            let r = ((k as f64 + 0.5) / PUPIL_SAMPLES as f64).sqrt();
            let t = k as f64 * golden;
            (r * t.cos(), r * t.sin())
        })
        .collect()
}

/// The optics' PSF applied to a linear image: each input pixel spreads
/// over the ray offsets of its own field position (bilinear splats), so the
/// spread of every scene point is its PSF, centroid and energy kept.
pub(crate) fn apply_optics(img: &Plane, o: &Optics) -> Plane {
    let (w, h) = (img.w, img.h);
    let (cx, cy) = (0.5 * (w as f64 - 1.0), 0.5 * (h as f64 - 1.0));
    let rmax = cx.hypot(cy).max(1e-9);
    // The rays in the image frame, centred; their second moments give the
    // mean of coma's terms in any pixel's radial frame.
    let rays = pupil();
    let n = rays.len() as f64;
    let (mp, mq) = rays
        .iter()
        .fold((0.0, 0.0), |m, &(p, q)| (m.0 + p / n, m.1 + q / n));
    let rays: Vec<(f64, f64)> = rays.iter().map(|&(p, q)| (p - mp, q - mq)).collect();
    let (spp, sqq, spq) = rays.iter().fold((0.0, 0.0, 0.0), |m, &(p, q)| {
        (m.0 + p * p / n, m.1 + q * q / n, m.2 + p * q / n)
    });
    let mut out = vec![0.0f64; w * h];
    let mut splat = |x: f64, y: f64, v: f64| {
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        for (dx, dy, wt) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            let (xi, yi) = (x0 as isize + dx, y0 as isize + dy);
            if xi >= 0 && yi >= 0 && (xi as usize) < w && (yi as usize) < h {
                out[yi as usize * w + xi as usize] += wt * v;
            }
        }
    };
    for y in 0..h {
        for x in 0..w {
            let v = img.data[y * w + x] as f64 / rays.len() as f64;
            if v == 0.0 {
                continue;
            }
            let (dx, dy) = (x as f64 - cx, y as f64 - cy);
            let r = dx.hypot(dy);
            let rho = r / rmax;
            let (er_x, er_y) = if r > 1e-9 {
                (dx / r, dy / r)
            } else {
                (1.0, 0.0)
            };
            let (et_x, et_y) = (-er_y, er_x);
            let r_t = o.defocus_px + o.field_curvature_px * rho * rho;
            let astig = o.astigmatism_px * rho * rho;
            let k = o.coma_px * rho;
            // Means over the rays of a^2, b^2 and ab in this pixel's frame.
            let aa = er_x * er_x * spp + 2.0 * er_x * er_y * spq + er_y * er_y * sqq;
            let bb = er_y * er_y * spp - 2.0 * er_x * er_y * spq + er_x * er_x * sqq;
            let ab = -er_x * er_y * spp + (er_x * er_x - er_y * er_y) * spq + er_x * er_y * sqq;
            for &(p, q) in &rays {
                // Pupil point in the radial (a) and tangential (b) frame;
                // the isotropic defocus stays in the image frame (the same
                // ray pattern for every pixel), the rest is radial and
                // tangential with each term's mean removed.
                let (a, b) = (p * er_x + q * er_y, -p * er_y + q * er_x);
                let er = astig * a + k * (3.0 * (a * a - aa) + (b * b - bb));
                let et = k * 2.0 * (a * b - ab);
                let (ox, oy) = (
                    r_t * p + er * er_x + et * et_x,
                    r_t * q + er * er_y + et * et_y,
                );
                splat(x as f64 + ox, y as f64 + oy, v);
            }
        }
    }
    Plane {
        w,
        h,
        data: out.into_iter().map(|v| v as f32).collect(),
    }
}

/// Uniform motion blur along a segment centred on each pixel.
pub(crate) fn apply_motion(img: &Plane, m: &MotionBlur) -> Plane {
    let n = (m.length_px.abs() * MOTION_SAMPLES_PER_PX).ceil().max(1.0) as usize + 1;
    let (c, s) = (m.angle_rad.cos(), m.angle_rad.sin());
    let offsets: Vec<(f64, f64)> = (0..n)
        .map(|k| {
            let t = m.length_px * ((k as f64 + 0.5) / n as f64 - 0.5);
            (t * c, t * s)
        })
        .collect();
    let (w, h) = (img.w, img.h);
    let mut data = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let sum: f64 = offsets
                .iter()
                .map(|&(ox, oy)| img.bilinear(x as f64 - ox, y as f64 - oy) as f64)
                .sum();
            data[y * w + x] = (sum / n as f64) as f32;
        }
    }
    Plane { w, h, data }
}

/// Colour channel (0 R, 1 G, 2 B) of an RGGB site.
fn channel(x: usize, y: usize) -> usize {
    match (x % 2, y % 2) {
        (0, 0) => 0,
        (1, 1) => 2,
        _ => 1,
    }
}

/// The linear signal as the mosaic records it: each site times its
/// channel's gain.
pub(crate) fn mosaic(signal: &mut [f64], w: usize, b: &Bayer) {
    for (i, v) in signal.iter_mut().enumerate() {
        *v *= b.channel_gain[channel(i % w, i / w)];
    }
}

/// Bilinear demosaicing of an RGGB mosaic, then the decoders' grey
/// ([`LUMA`]). Borders mirror with a step of two, which keeps the sites'
/// colours.
pub(crate) fn demosaic_to_grey(raw: &[f64], w: usize, h: usize) -> Vec<f64> {
    let mirror = |i: isize, n: usize| -> usize {
        let n = n as isize;
        let j = if i < 0 {
            -i
        } else if i >= n {
            2 * (n - 1) - i
        } else {
            i
        };
        j.clamp(0, n - 1) as usize
    };
    let at = |x: isize, y: isize| raw[mirror(y, h) * w + mirror(x, w)];
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h as isize {
        for x in 0..w as isize {
            let own = at(x, y);
            let cross = 0.25 * (at(x - 1, y) + at(x + 1, y) + at(x, y - 1) + at(x, y + 1));
            let diag =
                0.25 * (at(x - 1, y - 1) + at(x + 1, y - 1) + at(x - 1, y + 1) + at(x + 1, y + 1));
            let horiz = 0.5 * (at(x - 1, y) + at(x + 1, y));
            let vert = 0.5 * (at(x, y - 1) + at(x, y + 1));
            let rgb = match channel(mirror(x, w), mirror(y, h)) {
                0 => [own, cross, diag],
                2 => [diag, cross, own],
                // G on an R row has R left and right, B above and below.
                _ if y % 2 == 0 => [horiz, own, vert],
                _ => [vert, own, horiz],
            };
            out.push(LUMA[0] * rgb[0] + LUMA[1] * rgb[1] + LUMA[2] * rgb[2]);
        }
    }
    out
}

/// Shot and read noise on the linear signal (grey levels), in place.
pub(crate) fn sensor_noise(signal: &mut [f64], s: &SensorNoise, rng: &mut Rng) {
    let gain = s.gain_dn_per_e.max(1e-12);
    for v in signal.iter_mut() {
        let e = (*v / gain).clamp(0.0, s.full_well_e);
        let noisy = e + rng.gaussian(e.sqrt()) + rng.gaussian(s.read_noise_e);
        *v = noisy.clamp(0.0, s.full_well_e) * gain;
    }
}

/// The camera response: linear grey levels to encoded ones.
pub(crate) fn response(v: f64, gamma: f64) -> f64 {
    255.0 * (v.max(0.0) / 255.0).powf(1.0 / gamma)
}

/// A low-frequency paper texture `t(x, y)` (board metres) with RMS `rms`.
pub(crate) struct Texture {
    waves: Vec<(f64, f64, f64)>,
    amplitude: f64,
}

impl Texture {
    pub(crate) fn new(p: &Paper) -> Texture {
        let mut rng = Rng::new(p.seed);
        let waves = (0..PAPER_WAVES)
            .map(|_| {
                let dir = rng.range(0.0, std::f64::consts::PI);
                let k = 2.0 * std::f64::consts::PI / (p.wavelength_m * rng.range(1.0, 2.0));
                (
                    k * dir.cos(),
                    k * dir.sin(),
                    rng.range(0.0, 2.0 * std::f64::consts::PI),
                )
            })
            .collect();
        // A sine has RMS 1/sqrt(2): the sum of n has sqrt(n / 2).
        Texture {
            waves,
            amplitude: p.rms / (PAPER_WAVES as f64 / 2.0).sqrt(),
        }
    }

    pub(crate) fn at(&self, x: f64, y: f64) -> f64 {
        self.amplitude
            * self
                .waves
                .iter()
                .map(|(kx, ky, ph)| (kx * x + ky * y + ph).sin())
                .sum::<f64>()
    }
}

/// JPEG round trip of an 8-bit grey image through `image`'s codec.
pub(crate) fn jpeg_round_trip(
    pixels: &[u8],
    w: u32,
    h: u32,
    quality: u8,
) -> crate::error::Result<Vec<u8>> {
    use ::image::ImageEncoder;
    let mut bytes = Vec::new();
    ::image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, quality.clamp(1, 100))
        .write_image(pixels, w, h, ::image::ExtendedColorType::L8)
        .map_err(|e| crate::error::Error::Image {
            message: format!("could not encode JPEG at quality {quality}: {e}"),
        })?;
    Ok(crate::image::decode_gray(&bytes)?.pixels)
}
