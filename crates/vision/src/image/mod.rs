//! Decoding image bytes into the grey image the detectors work on.
//!
//! No filesystem here: callers pass bytes (from a file, an upload, a fetch).
//! Supported: PNG, JPEG, TIFF, BMP, PGM/PPM (PNM) and GIF, 8 or 16 bits,
//! grey or colour. Colour is converted to luma with the sRGB / Rec. 709
//! weights 0.2126 R + 0.7152 G + 0.0722 B in f32, computed exactly as the
//! `image` crate did before (so pixels match its output); 16-bit data is
//! scaled to 8 bits with rounding.
//!
//! Every format is read here ([`png_decode`], [`jpeg`], [`gif`], [`tiff`],
//! [`bmp`], [`pnm`]), with our [`lzw`] for GIF and TIFF and `fdeflate` for
//! the deflate of PNG and TIFF: no codec crates (they were most of the wasm). Each codec returns a [`raster::Raster`]
//! in its file's own channels and depth; the conversions to grey and to the
//! RGBA preview happen once, in [`raster`].

mod bmp;
#[cfg(test)]
mod bmp_tests;
mod codecs;
mod gif;
/// The JPEG decoder itself (public for its benchmark; use [`decode`]).
#[doc(hidden)]
pub mod jpeg;
mod lzw;
mod png_decode;
mod png_encode;
mod pnm;
mod raster;
mod tiff;
#[cfg(test)]
mod tiff_tests;

use crate::error::{Error, Result};
use serde::Serialize;

/// Largest image accepted by default, in pixels (a 100 MP sensor, twice the
/// 50 MP the detectors are specified for).
pub const DEFAULT_MAX_PIXELS: u64 = 100_000_000;

/// Largest decoder allocation accepted by default, in bytes.
pub const DEFAULT_MAX_ALLOC_BYTES: u64 = 1 << 30;

/// An 8-bit single-channel image, row-major, no padding.
///
/// Pixel (0, 0) is the top-left pixel; its centre has coordinates (0.0, 0.0)
/// (see the crate's conventions).
#[derive(Debug, Clone, PartialEq)]
pub struct GrayImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` grey levels, row after row.
    pub pixels: Vec<u8>,
}

impl GrayImage {
    /// Wrap a pixel buffer, checking its length.
    pub fn new(width: u32, height: u32, pixels: Vec<u8>) -> Result<Self> {
        let expected = width as usize * height as usize;
        if pixels.len() != expected {
            return Err(Error::invalid(
                "pixels",
                format!(
                    "a {width}x{height} image needs {expected} bytes, got {}",
                    pixels.len()
                ),
            ));
        }
        Ok(GrayImage {
            width,
            height,
            pixels,
        })
    }

    /// Grey level at integer pixel (x, y); `None` outside the image.
    pub fn get(&self, x: u32, y: u32) -> Option<u8> {
        if x < self.width && y < self.height {
            self.pixels
                .get(y as usize * self.width as usize + x as usize)
                .copied()
        } else {
            None
        }
    }
}

/// An 8-bit RGBA image, row-major (used for previews and thumbnails).
#[derive(Debug, Clone, PartialEq)]
pub struct RgbaImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `4 * width * height` bytes, R G B A per pixel.
    pub pixels: Vec<u8>,
}

/// The container format an image was decoded from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ImageFormat {
    /// Portable Network Graphics.
    Png,
    /// JPEG / JFIF.
    Jpeg,
    /// TIFF (baseline, uncompressed, LZW, deflate, PackBits).
    Tiff,
    /// Windows bitmap.
    Bmp,
    /// Netpbm PGM / PPM / PBM.
    Pnm,
    /// GIF (first frame).
    Gif,
}

impl ImageFormat {
    /// The usual name of the format, upper case ("PNG").
    pub fn name(self) -> &'static str {
        match self {
            ImageFormat::Png => "PNG",
            ImageFormat::Jpeg => "JPEG",
            ImageFormat::Tiff => "TIFF",
            ImageFormat::Bmp => "BMP",
            ImageFormat::Pnm => "PNM",
            ImageFormat::Gif => "GIF",
        }
    }
}

/// What is known about a decoded image besides its pixels.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImageInfo {
    /// Container format.
    pub format: ImageFormat,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Number of channels in the file (1 grey, 2 grey+alpha, 3 RGB, 4 RGBA).
    pub channels: u8,
    /// Bits per channel in the file (8 or 16, 32 for float TIFF).
    pub bits_per_channel: u8,
}

/// Options for [`decode`].
#[derive(Debug, Clone, PartialEq)]
pub struct DecodeOptions {
    /// Reject images with more pixels than this. Default [`DEFAULT_MAX_PIXELS`].
    pub max_pixels: u64,
    /// Reject decodes that would allocate more bytes than this.
    /// Default [`DEFAULT_MAX_ALLOC_BYTES`].
    pub max_alloc_bytes: u64,
    /// Also produce an RGBA preview whose longer side is at most this many
    /// pixels. `None` (the default) makes no preview.
    pub preview_max_side: Option<u32>,
}

impl Default for DecodeOptions {
    fn default() -> Self {
        DecodeOptions {
            max_pixels: DEFAULT_MAX_PIXELS,
            max_alloc_bytes: DEFAULT_MAX_ALLOC_BYTES,
            preview_max_side: None,
        }
    }
}

/// A decoded image: its description, its grey pixels and an optional preview.
#[derive(Debug, Clone, PartialEq)]
pub struct Decoded {
    /// Format, size, channels.
    pub info: ImageInfo,
    /// Full-resolution grey image.
    pub gray: GrayImage,
    /// Small RGBA preview when [`DecodeOptions::preview_max_side`] was set.
    pub preview: Option<RgbaImage>,
}

/// Decode image bytes with the default options (grey only, no preview).
pub fn decode_gray(bytes: &[u8]) -> Result<GrayImage> {
    decode(bytes, &DecodeOptions::default()).map(|d| d.gray)
}

/// Decode image bytes: detect the format from the content (not a file name),
/// check the size limits before allocating, convert to grey.
pub fn decode(bytes: &[u8], options: &DecodeOptions) -> Result<Decoded> {
    let format = sniff_format(bytes)?;
    let raster = match format {
        ImageFormat::Png => png_decode::decode(bytes, options)?,
        ImageFormat::Jpeg => codecs::decode_jpeg(bytes, options)?,
        ImageFormat::Tiff => tiff::decode(bytes, options)?,
        ImageFormat::Gif => gif::decode(bytes, options)?,
        ImageFormat::Bmp => bmp::decode(bytes, options)?,
        ImageFormat::Pnm => pnm::decode(bytes, options)?,
    };
    let info = ImageInfo {
        format,
        width: raster.width,
        height: raster.height,
        channels: raster.channels,
        bits_per_channel: raster.bits_per_channel(),
    };
    let preview = options.preview_max_side.map(|side| raster.preview(side));
    let gray = raster.into_gray();
    Ok(Decoded {
        info,
        gray,
        preview,
    })
}

/// Formats recognised by their magic bytes but not decoded, with the name the
/// error message gives them.
const UNSUPPORTED_MAGIC: [(&[u8], &str); 9] = [
    (b"DDS ", "Dds"),
    (&[0, 0, 1, 0], "Ico"),
    (b"#?RADIANCE", "Hdr"),
    (&[0x76, 0x2f, 0x31, 0x01], "OpenExr"),
    (b"qoif", "Qoi"),
    (b"farbfeld", "Farbfeld"),
    (b"II+\x00", "BigTiff"),
    (b"MM\x00+", "BigTiff"),
    (b"\x00\x00\x00\x0cjP  ", "Jpeg2000"),
];

/// Identify the container from its magic bytes.
pub fn sniff_format(bytes: &[u8]) -> Result<ImageFormat> {
    if bytes.is_empty() {
        return Err(Error::Image {
            message: "not an image: the file is empty".into(),
        });
    }
    let starts = |magic: &[u8]| bytes.starts_with(magic);
    if starts(b"\x89PNG\r\n\x1a\n") {
        return Ok(ImageFormat::Png);
    }
    if starts(&[0xff, 0xd8, 0xff]) {
        return Ok(ImageFormat::Jpeg);
    }
    if starts(b"GIF89a") || starts(b"GIF87a") {
        return Ok(ImageFormat::Gif);
    }
    if starts(b"MM\x00*") || starts(b"II*\x00") {
        return Ok(ImageFormat::Tiff);
    }
    if starts(b"BM") {
        return Ok(ImageFormat::Bmp);
    }
    if bytes.len() >= 2 && bytes[0] == b'P' && (b'1'..=b'7').contains(&bytes[1]) {
        return Ok(ImageFormat::Pnm);
    }
    let other = if bytes.len() >= 12 && starts(b"RIFF") && &bytes[8..12] == b"WEBP" {
        Some("WebP")
    } else if bytes.len() >= 12 && &bytes[4..12] == b"ftypavif" {
        Some("Avif")
    } else {
        UNSUPPORTED_MAGIC
            .iter()
            .find(|(magic, _)| starts(magic))
            .map(|(_, name)| *name)
    };
    Err(Error::Image {
        message: match other {
            Some(name) => {
                format!("unsupported image format {name}: use PNG, JPEG, TIFF, BMP, PGM/PPM or GIF")
            }
            None => {
                "not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF".into()
            }
        },
    })
}

/// Refuse empty images and images over [`DecodeOptions::max_pixels`]; called
/// by every codec with the header's dimensions, before any pixel buffer.
fn check_size(width: u32, height: u32, options: &DecodeOptions) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::Image {
            message: format!("image is {width}x{height} pixels: it has no pixels"),
        });
    }
    let pixels = width as u64 * height as u64;
    if pixels > options.max_pixels {
        return Err(Error::Image {
            message: format!(
                "image is {width}x{height} = {:.1} MP, more than the limit of {:.1} MP: downscale it first",
                pixels as f64 / 1e6,
                options.max_pixels as f64 / 1e6
            ),
        });
    }
    Ok(())
}

/// Refuse a decoded buffer of `width * height * channels * bytes_per_sample`
/// bytes over [`DecodeOptions::max_alloc_bytes`]; returns the byte count.
fn check_alloc(
    format: ImageFormat,
    width: u32,
    height: u32,
    channels: u8,
    bytes_per_sample: u8,
    options: &DecodeOptions,
) -> Result<usize> {
    let bytes = width as u64 * height as u64 * channels as u64 * bytes_per_sample as u64;
    if bytes > options.max_alloc_bytes || usize::try_from(bytes).is_err() {
        return Err(too_large(format, options));
    }
    Ok(bytes as usize)
}

fn too_large(format: ImageFormat, options: &DecodeOptions) -> Error {
    Error::Image {
        message: format!(
            "{} image too large to decode within the memory limit ({} bytes)",
            format.name(),
            options.max_alloc_bytes
        ),
    }
}

fn corrupt(format: ImageFormat, detail: impl std::fmt::Display) -> Error {
    Error::Image {
        message: format!("corrupt or truncated {} file: {detail}", format.name()),
    }
}

fn unsupported(format: ImageFormat, detail: impl std::fmt::Display) -> Error {
    Error::Image {
        message: format!("{} variant not supported: {detail}", format.name()),
    }
}

/// Encode a grey image as a binary PGM (P5); used by the renderer and tests.
pub fn encode_pgm(img: &GrayImage) -> Vec<u8> {
    let mut out = format!("P5\n{} {}\n255\n", img.width, img.height).into_bytes();
    out.extend_from_slice(&img.pixels);
    out
}

/// Encode a grey image as PNG (8-bit grey).
pub fn encode_png(img: &GrayImage) -> Result<Vec<u8>> {
    png_encode::encode_gray(img)
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn gradient(w: u32, h: u32) -> GrayImage {
        let pixels = (0..w * h)
            .map(|i| ((i % w) * 255 / w.max(1)) as u8)
            .collect();
        GrayImage::new(w, h, pixels).unwrap()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn png_round_trip_keeps_every_pixel() {
        let img = gradient(37, 21);
        let bytes = encode_png(&img).unwrap();
        let decoded = decode(
            &bytes,
            &DecodeOptions {
                preview_max_side: Some(10),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(decoded.gray, img);
        assert_eq!(decoded.info.format, ImageFormat::Png);
        assert_eq!(
            (
                decoded.info.width,
                decoded.info.height,
                decoded.info.channels
            ),
            (37, 21, 1)
        );
        let preview = decoded.preview.unwrap();
        assert_eq!((preview.width, preview.height), (10, 6));
        assert_eq!(preview.pixels.len(), 10 * 6 * 4);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn pgm_round_trip_keeps_every_pixel() {
        let img = gradient(5, 3);
        assert_eq!(decode_gray(&encode_pgm(&img)).unwrap(), img);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn garbage_is_not_an_image() {
        let err = decode_gray(b"hello, this is text").unwrap_err();
        assert_eq!(
            err.to_string(),
            "not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF"
        );
        assert_eq!(
            decode_gray(&[]).unwrap_err().to_string(),
            "not an image: the file is empty"
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn truncated_png_is_reported_as_corrupt() {
        let bytes = encode_png(&gradient(64, 64)).unwrap();
        let err = decode_gray(&bytes[..bytes.len() / 2])
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("corrupt or truncated PNG file"), "{err}");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn oversized_header_is_refused_before_allocating() {
        // A PGM header announcing 20000 x 20000 pixels with no data behind it.
        let bytes = b"P5\n20000 20000\n255\n".to_vec();
        let err = decode_gray(&bytes).unwrap_err().to_string();
        assert_eq!(
            err,
            "image is 20000x20000 = 400.0 MP, more than the limit of 100.0 MP: downscale it first"
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn random_bytes_never_panic() {
        // Seeded xorshift: random prefixes of real headers and pure noise.
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let png = encode_png(&gradient(16, 16)).unwrap();
        let bmp = crate::image::bmp_tests::palette_bmp();
        // Real headers of every format, cut anywhere and followed by noise.
        let headers: [&[u8]; 8] = [
            &png,
            &bmp,
            b"P6 4 4 255\n",
            b"P1 4 4\n",
            b"P7\nWIDTH 2\nHEIGHT 2\nDEPTH 4\nMAXVAL 65535\nENDHDR\n",
            b"GIF89a\x04\x00\x04\x00\xf0\x00\x00",
            b"II*\x00\x08\x00\x00\x00",
            b"\xff\xd8\xff\xe0\x00\x10JFIF\x00",
        ];
        for i in 0..800 {
            let len = (next() % 200) as usize;
            let mut bytes: Vec<u8> = (0..len).map(|_| next() as u8).collect();
            if i % 4 != 3 {
                let header = headers[(next() % headers.len() as u64) as usize];
                let keep = (next() as usize) % (header.len() + 1);
                bytes = [&header[..keep], &bytes[..]].concat();
            }
            let _ = decode(
                &bytes,
                &DecodeOptions {
                    preview_max_side: Some(8),
                    ..Default::default()
                },
            );
        }
    }
}
