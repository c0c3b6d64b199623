//! A decoded image in its file's own layout, and the two conversions every
//! format shares: to the grey image the detectors use and to the small RGBA
//! preview the web app shows.

use super::{GrayImage, RgbaImage};

/// Sample storage of a [`Raster`]: one variant per depth the codecs produce.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Samples {
    /// 8-bit samples (also 1/2/4-bit data expanded to 0..=255).
    U8(Vec<u8>),
    /// 16-bit samples, native values (not bytes).
    U16(Vec<u16>),
    /// 32-bit float samples, nominal range 0..=1 (float TIFF).
    F32(Vec<f32>),
}

/// Interleaved pixels: `channels` samples per pixel (1 grey, 2 grey+alpha,
/// 3 RGB, 4 RGBA), row-major, no padding.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Raster {
    pub width: u32,
    pub height: u32,
    pub channels: u8,
    pub samples: Samples,
}

/// Luma weights of linear sRGB / Rec. 709 primaries with a D65 white, as
/// f32 exactly as the `image` crate derives them (0.2126, 0.7152, 0.0722 to
/// 4 digits), so that our grey pixels equal the ones `image` produced.
const KR: f32 = f32::from_bits(0x3e59_c05b);
const KG: f32 = f32::from_bits(0x3f37_15fc);
const KB: f32 = f32::from_bits(0x3d93_cf75);

/// Luma of RGB in 0..=1, to 8 bits: (KR r + KG g + KB b) * 255 rounded, the
/// sum in this order, without fused multiply-add (saturating cast).
fn luma(r: f32, g: f32, b: f32) -> u8 {
    round_non_negative((r * KR + g * KG + b * KB) * 255.0) as u8
}

/// `x.round()` for `x >= 0` (and NaN) without the libm call that wasm makes
/// for `f32::round` (its native rounding is to even): `x - trunc(x)` is exact.
#[inline(always)]
fn round_non_negative(x: f32) -> f32 {
    let t = x.trunc();
    if x - t >= 0.5 {
        t + 1.0
    } else {
        t
    }
}

/// 16 -> 8 bits with rounding: round(v * 255 / 65535).
fn u16_to_u8(v: u16) -> u8 {
    ((v as u32 + 128) / 257) as u8
}

/// Float in 0..=1 -> 0..=255, clamped, rounded; NaN becomes 0.
fn f32_to_u8(v: f32) -> u8 {
    round_non_negative(v.clamp(0.0, 1.0) * 255.0) as u8
}

impl Raster {
    /// Bits per channel reported in [`super::ImageInfo`].
    pub fn bits_per_channel(&self) -> u8 {
        match self.samples {
            Samples::U8(_) => 8,
            Samples::U16(_) => 16,
            Samples::F32(_) => 32,
        }
    }

    fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Grey image: luma of RGB(A), the grey channel of grey(+alpha); alpha is
    /// ignored. Colour samples are scaled to 0..=1 first (v / 255 or
    /// v / 65535 in f32), grey ones go straight to 8 bits.
    pub fn into_gray(self) -> GrayImage {
        let n = self.pixel_count();
        let ch = self.channels.max(1) as usize;
        let pixels: Vec<u8> = match self.samples {
            Samples::U8(v) if ch == 1 => v,
            Samples::U8(v) => v
                .chunks_exact(ch)
                .map(|p| {
                    if ch < 3 {
                        p[0]
                    } else {
                        const S: f32 = 1.0 / 255.0;
                        luma(p[0] as f32 * S, p[1] as f32 * S, p[2] as f32 * S)
                    }
                })
                .collect(),
            Samples::U16(v) => v
                .chunks_exact(ch)
                .map(|p| {
                    if ch < 3 {
                        u16_to_u8(p[0])
                    } else {
                        const S: f32 = 1.0 / 65535.0;
                        luma(p[0] as f32 * S, p[1] as f32 * S, p[2] as f32 * S)
                    }
                })
                .collect(),
            Samples::F32(v) => v
                .chunks_exact(ch)
                .map(|p| {
                    if ch < 3 {
                        f32_to_u8(p[0])
                    } else {
                        luma(p[0], p[1], p[2])
                    }
                })
                .collect(),
        };
        // Codecs hand over exactly width * height * channels samples; a short
        // buffer (never expected) is padded rather than trusted.
        let mut pixels = pixels;
        pixels.resize(n, 0);
        GrayImage {
            width: self.width,
            height: self.height,
            pixels,
        }
    }

    /// One row as RGBA8 into `out` (length `4 * width`); `scratch` holds the
    /// row's samples at 8 bits. Loops are per channel layout, not per pixel,
    /// so they stay fast at opt-level "s".
    fn row_rgba(&self, y: usize, scratch: &mut Vec<u8>, out: &mut [u8]) {
        let ch = self.channels.clamp(1, 4) as usize;
        let n = self.width as usize * ch;
        let range = y * n..(y + 1) * n;
        scratch.clear();
        match &self.samples {
            Samples::U8(v) => scratch.extend_from_slice(v.get(range).unwrap_or(&[])),
            Samples::U16(v) => {
                scratch.extend(v.get(range).unwrap_or(&[]).iter().map(|&s| u16_to_u8(s)))
            }
            Samples::F32(v) => {
                scratch.extend(v.get(range).unwrap_or(&[]).iter().map(|&s| f32_to_u8(s)))
            }
        }
        scratch.resize(n, 0);
        let px = out.chunks_exact_mut(4);
        match ch {
            1 => px
                .zip(scratch.iter())
                .for_each(|(d, &g)| d.copy_from_slice(&[g, g, g, 255])),
            2 => px
                .zip(scratch.chunks_exact(2))
                .for_each(|(d, s)| d.copy_from_slice(&[s[0], s[0], s[0], s[1]])),
            3 => px
                .zip(scratch.chunks_exact(3))
                .for_each(|(d, s)| d.copy_from_slice(&[s[0], s[1], s[2], 255])),
            _ => out.copy_from_slice(&scratch[..out.len()]),
        }
    }

    /// RGBA preview whose longer side is at most `max_side`: an area (box)
    /// average over the source pixels that fall into each preview pixel.
    pub fn preview(&self, max_side: u32) -> RgbaImage {
        let max_side = max_side.max(1);
        let (w, h) = (self.width.max(1), self.height.max(1));
        let scale = (max_side as f64 / w.max(h) as f64).min(1.0);
        let tw = ((w as f64 * scale).round() as u32).clamp(1, w);
        let th = ((h as f64 * scale).round() as u32).clamp(1, h);
        let (w, h, tw_u, th_u) = (w as usize, h as usize, tw as usize, th as usize);
        // Source column x feeds preview column x * tw / w (each preview column
        // gets floor or ceil of w / tw source columns).
        let column: Vec<usize> = (0..w).map(|x| x * tw_u / w).collect();
        let mut width_of = vec![0u32; tw_u];
        for &c in &column {
            width_of[c] += 1;
        }
        let mut out = vec![0u8; tw_u * th_u * 4];
        let mut row = vec![0u8; w * 4];
        let mut scratch = Vec::with_capacity(w * self.channels as usize);
        let mut sums = vec![0u32; tw_u * 4];
        let mut y = 0;
        for ty in 0..th_u {
            sums.iter_mut().for_each(|s| *s = 0);
            let mut rows = 0u32;
            while y < h && y * th_u / h == ty {
                self.row_rgba(y, &mut scratch, &mut row);
                for (px, &c) in row.chunks_exact(4).zip(&column) {
                    for k in 0..4 {
                        sums[c * 4 + k] += px[k] as u32;
                    }
                }
                rows += 1;
                y += 1;
            }
            let dst = &mut out[ty * tw_u * 4..(ty + 1) * tw_u * 4];
            for (tx, d) in dst.chunks_exact_mut(4).enumerate() {
                let count = (width_of[tx] * rows).max(1);
                for k in 0..4 {
                    d[k] = ((sums[tx * 4 + k] + count / 2) / count) as u8;
                }
            }
        }
        RgbaImage {
            width: tw,
            height: th,
            pixels: out,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn rounding_without_libm_is_f32_round() {
        for x in [
            0.0f32,
            0.5,
            1.5,
            2.5,
            0.49999997,
            254.5,
            254.49998,
            8388607.5,
            1e9,
            f32::MIN_POSITIVE,
        ] {
            assert_eq!(round_non_negative(x), x.round(), "{x}");
        }
        assert!(round_non_negative(f32::NAN).is_nan());
        // Every 8-bit colour's luma before rounding (every blue step of 5).
        const S: f32 = 1.0 / 255.0;
        for r in 0..=255u8 {
            for g in 0..=255u8 {
                for b in (0..=255u8).step_by(5) {
                    let x = (r as f32 * S * KR + g as f32 * S * KG + b as f32 * S * KB) * 255.0;
                    assert_eq!(round_non_negative(x), x.round(), "{r} {g} {b}");
                }
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn luma_uses_the_srgb_weights_on_unit_samples() {
        let rgb8 = Raster {
            width: 2,
            height: 1,
            channels: 3,
            samples: Samples::U8(vec![255, 0, 0, 10, 200, 30]),
        };
        // 0.21265 * 255 = 54.2 -> 54; 255 * (0.21265 * 10 + 0.71518 * 200 + 0.07217 * 30) / 255 = 147.3.
        assert_eq!(rgb8.into_gray().pixels, vec![54, 147]);
        let rgb16 = Raster {
            width: 1,
            height: 1,
            channels: 4,
            samples: Samples::U16(vec![65535, 65535, 0, 7]),
        };
        // (0.21265 + 0.71518) * 255 = 236.6 -> 237.
        assert_eq!(rgb16.into_gray().pixels, vec![237]);
        let gray_alpha = Raster {
            width: 2,
            height: 1,
            channels: 2,
            samples: Samples::F32(vec![0.5, 0.0, 2.0, 1.0]),
        };
        assert_eq!(gray_alpha.into_gray().pixels, vec![128, 255]);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn preview_averages_whole_boxes() {
        // 4x2 grey, halved to 2x1: each preview pixel averages a 2x2 box.
        let img = Raster {
            width: 4,
            height: 2,
            channels: 1,
            samples: Samples::U8(vec![0, 10, 100, 200, 20, 30, 50, 250]),
        };
        let p = img.preview(2);
        assert_eq!((p.width, p.height), (2, 1));
        assert_eq!(p.pixels, vec![15, 15, 15, 255, 150, 150, 150, 255]);
        // No upscaling: a larger max side keeps the size and the pixels.
        let same = img.preview(100);
        assert_eq!((same.width, same.height), (4, 2));
        assert_eq!(&same.pixels[12..16], &[200, 200, 200, 255]);
    }
}
