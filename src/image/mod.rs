//! Decoding image bytes into the grey image the detectors work on.
//!
//! No filesystem here: callers pass bytes (from a file, an upload, a fetch).
//! Every format is decoded by the `image` crate: PNG (1-16 bit, palette,
//! interlaced), JPEG (baseline, progressive, CMYK), GIF (first frame), TIFF
//! (8/16/32-bit, uncompressed, LZW, deflate, PackBits, tiled), BMP, PNM and
//! WebP. The format is recognised from the content, not a file name.
//!
//! Every decode runs under `image`'s [`Limits`](::image::Limits) from the
//! first byte (header and metadata chunks included): at most
//! [`DecodeOptions::max_pixels`] pixels (checked against the header before
//! any pixel buffer exists) and [`DecodeOptions::max_alloc_bytes`] bytes of
//! decoder memory. The defaults are [`DEFAULT_MAX_PIXELS`] and
//! [`DEFAULT_MAX_ALLOC_BYTES`]: 100 MP and 1 GiB natively; 64 MP and 512 MiB
//! in wasm, where one worker's memory is at most 4 GiB and a tab runs
//! several. Over a limit the error names the image size or the limit, and
//! what to do. PNG goes through the `png` crate directly (`png_rows`): its
//! colour profile is never inflated and rows become grey strip by strip, so
//! a 16-bit RGBA PNG costs the grey image, not eight times it;
//! [`decode_peak`] gives any file's peak from its header.
//!
//! The EXIF Orientation (JPEG, TIFF, WebP, PNG's eXIf) is applied to the
//! grey image as OpenCV's `imread` and image viewers apply it, and reported
//! as [`ImageInfo::exif_orientation`]. A file cut short is an error that
//! says so (`truncation`), never a partly grey image.
//!
//! Grey is `image`'s luma conversion: 0.2126 R + 0.7152 G + 0.0722 B
//! (sRGB / Rec. 709 weights), 16-bit and float samples scaled to 8 bits
//! with rounding; alpha is ignored.

use crate::error::{Error, Result};
use ::image::metadata::Orientation;
use ::image::{DynamicImage, ImageDecoder, ImageError, ImageReader, Limits};
use serde::Serialize;
use std::io::Cursor;
use truncation::JpegEnd;

#[cfg(test)]
mod bounds_tests;
pub(crate) mod filter;
#[cfg(test)]
mod format_tests;
mod messages;
mod orientation;
mod png_rows;
use messages::{byte_count, check_size, decode_error, MEMORY_ADVICE};
use orientation::{exif_orientation, orient, orient_rgba};
mod truncation;
mod undistort;
pub use undistort::{remap_gray, undistort_image};

/// Largest image accepted by default, in pixels: a 100 MP sensor natively
/// (twice the 50 MP the detectors are specified for), 64 MP in wasm.
#[cfg(not(target_arch = "wasm32"))]
pub const DEFAULT_MAX_PIXELS: u64 = 100_000_000;
/// Largest image accepted by default, in pixels: a 100 MP sensor natively
/// (twice the 50 MP the detectors are specified for), 64 MP in wasm.
#[cfg(target_arch = "wasm32")]
pub const DEFAULT_MAX_PIXELS: u64 = 64_000_000;

/// Largest decoder allocation accepted by default, in bytes: 1 GiB natively,
/// 512 MiB in wasm.
#[cfg(not(target_arch = "wasm32"))]
pub const DEFAULT_MAX_ALLOC_BYTES: u64 = 1 << 30;
/// Largest decoder allocation accepted by default, in bytes: 1 GiB natively,
/// 512 MiB in wasm.
#[cfg(target_arch = "wasm32")]
pub const DEFAULT_MAX_ALLOC_BYTES: u64 = 512 << 20;

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
    /// WebP (lossy or lossless; the first frame of an animation).
    #[serde(rename = "webp")]
    WebP,
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
            ImageFormat::WebP => "WebP",
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
    /// The EXIF Orientation (2-8) that was applied to the pixels, as
    /// OpenCV's `imread` and image viewers apply it; absent when the file
    /// has none (or 1, "as stored"). `width` and `height` are the size after
    /// it: for 5-8 the file stores the image transposed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exif_orientation: Option<u8>,
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

/// Decode image bytes: recognise the format from the content, read the
/// header under the limits, check the size, decode under the limits,
/// convert to grey, apply the EXIF orientation (and make a preview when
/// asked). A file cut short is an error that says so ([`truncation`]).
pub fn decode(bytes: &[u8], options: &DecodeOptions) -> Result<Decoded> {
    let opened = open(bytes, options, true)?;
    let (format, orientation) = (opened.format, opened.orientation);
    let fail = |e: ImageError| decode_error(format, e, bytes.len(), options);
    // The grey image, and the decoded image when its pixels are not grey
    // already (PNG rows are converted as they come).
    let (gray, image) = codec_guard(format, || match opened.source {
        Source::PngRows(reader) => {
            let pixels = reader
                .read_gray(opened.width, opened.height)
                .map_err(fail)?;
            Ok((
                Some(GrayImage::new(opened.width, opened.height, pixels)?),
                None,
            ))
        }
        Source::PngWhole(reader) => {
            let image = reader
                .read_whole(opened.width, opened.height)
                .map_err(fail)?;
            Ok((None, Some(image)))
        }
        Source::Other(decoder) => Ok((
            None,
            Some(DynamicImage::from_decoder(decoder).map_err(fail)?),
        )),
    })?;
    let (mut channels, mut bits_per_channel) = (opened.channels, opened.bits_per_channel);
    let mut small = None;
    let gray = match (gray, image) {
        (Some(gray), _) => gray,
        (None, Some(image)) => {
            if indexed(format, bytes) && all_grey(&image) {
                // `image` expands palettes to RGB: an 8-bit BMP or a GIF of a
                // mono camera (a palette of greys) would be listed as "RGB".
                (channels, bits_per_channel) = (1, 8);
            }
            small = options.preview_max_side.map(|side| preview(&image, side));
            // Moves the pixels of a grey image instead of copying them.
            let luma = image.into_luma8();
            GrayImage::new(luma.width(), luma.height(), luma.into_raw())?
        }
        (None, None) => {
            return Err(Error::invalid("pixels", "the decoder produced no image"));
        }
    };
    let preview = small.map(|p| orient_rgba(p, orientation)).transpose()?;
    let gray = orient(gray, orientation)?;
    let info = ImageInfo {
        format,
        width: gray.width,
        height: gray.height,
        channels,
        bits_per_channel,
        exif_orientation: exif_orientation(orientation),
    };
    Ok(Decoded {
        info,
        gray,
        preview,
    })
}

thread_local! {
    /// How many [`codec_guard`]s this thread is inside.
    static GUARDED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}

/// Whether this thread is decoding inside [`codec_guard`]: a host's panic
/// hook stays quiet then (the panic becomes the file's decode error).
pub fn inside_codec_guard() -> bool {
    GUARDED.with(|g| g.get() > 0)
}

/// Runs a codec, a panic inside it becoming this file's decode error
/// instead of the end of the process. The codec crates can panic on
/// crafted files: zune-jpeg 0.5.15's AVX2 inverse DCT unwraps a slice past
/// the end of its output on one found by the image_decode fuzzer (session
/// 20; fixtures/fuzz/image_decode/jpeg-avx2-idct-unwrap), where its scalar
/// path and its first store do not. The codec holds no state of ours, so
/// `AssertUnwindSafe` holds. Where panics abort (the wasm build) this does
/// nothing; the page's worker trap names the file instead.
fn codec_guard<T>(format: ImageFormat, decode: impl FnOnce() -> Result<T>) -> Result<T> {
    GUARDED.with(|g| g.set(g.get() + 1));
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode));
    GUARDED.with(|g| g.set(g.get().saturating_sub(1)));
    outcome.unwrap_or_else(|payload| {
        let why = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".into());
        Err(Error::Image {
            message: format!(
                "corrupt {} file: its decoder failed inside ({why}); the file is damaged or uses \
                 a coding the decoder mishandles: re-save it (e.g. as PNG) or take it again",
                format.name()
            ),
        })
    })
}

/// What decoding an image will cost, from its header: see [`decode_peak`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DecodePeak {
    /// Pixels of the image.
    pub pixels: u64,
    /// The most memory [`decode`] holds at once, in bytes (the input bytes
    /// not counted): the grey image, plus one strip of rows for a
    /// non-interlaced PNG or the whole image at the file's pixel format for
    /// every other file, plus a second grey buffer when the EXIF
    /// orientation rotates.
    pub bytes: u64,
}

/// The cost of decoding these bytes with these options, from the header
/// alone: what a caller running several decodes at once budgets for (the
/// CLI's `detect`). `bytes` may be the file's first bytes only, as long as
/// they hold the header (a truncated file is not reported here).
pub fn decode_peak(bytes: &[u8], options: &DecodeOptions) -> Result<DecodePeak> {
    let opened = open(bytes, options, false)?;
    let pixels = opened.width as u64 * opened.height as u64;
    let rotated = match opened.orientation {
        Orientation::NoTransforms | Orientation::FlipHorizontal | Orientation::FlipVertical => 0,
        _ => pixels,
    };
    let sample_bytes = opened.bits_per_channel.div_ceil(8) as u64;
    let decoded = match &opened.source {
        // One strip of rows at the file's depth, twice (the rows and their
        // samples widened), beside the grey image.
        Source::PngRows(_) => {
            let row = opened.width as u64 * opened.channels as u64 * sample_bytes;
            2 * row * png_rows::STRIP_ROWS as u64
        }
        Source::PngWhole(_) | Source::Other(_) => pixels * opened.channels as u64 * sample_bytes,
    };
    Ok(DecodePeak {
        pixels,
        bytes: decoded + pixels + rotated,
    })
}

/// A file whose header has been read: where its pixels come from.
struct Opened<'a> {
    format: ImageFormat,
    width: u32,
    height: u32,
    channels: u8,
    bits_per_channel: u8,
    orientation: Orientation,
    source: Source<'a>,
}

enum Source<'a> {
    /// A non-interlaced PNG, converted to grey row by row.
    PngRows(png_rows::PngReader<'a>),
    /// An interlaced PNG, or any PNG when a preview is asked for.
    PngWhole(png_rows::PngReader<'a>),
    /// Every other format, through `image`'s decoder.
    Other(Box<dyn ImageDecoder + 'a>),
}

/// Sniff the format, check a JPEG's framing for truncation (when `bytes`
/// are the `whole_file`), read the header
/// under the limits and check the size.
fn open<'a>(bytes: &'a [u8], options: &DecodeOptions, whole_file: bool) -> Result<Opened<'a>> {
    let format = sniff_format(bytes)?;
    let fail = |e: ImageError| decode_error(format, e, bytes.len(), options);
    if whole_file
        && format == ImageFormat::Jpeg
        && truncation::jpeg_end(bytes) == JpegEnd::Truncated
    {
        return Err(Error::Image {
            message: truncation::message(format, bytes.len()),
        });
    }
    if format == ImageFormat::Png {
        let (reader, header) = png_rows::open(bytes, options)?;
        let orientation = header
            .exif
            .as_deref()
            .and_then(Orientation::from_exif_chunk)
            .unwrap_or(Orientation::NoTransforms);
        let whole = header.interlaced || options.preview_max_side.is_some();
        return Ok(Opened {
            format,
            width: header.width,
            height: header.height,
            channels: header.channels,
            bits_per_channel: header.bits_per_channel,
            orientation,
            source: if whole {
                Source::PngWhole(reader)
            } else {
                Source::PngRows(reader)
            },
        });
    }
    let mut reader = ImageReader::new(Cursor::new(bytes));
    reader.set_format(format.to_image_crate());
    // The limits are on from the first byte: a header may hold chunks that
    // inflate (colour profiles, metadata), and those count too.
    reader.limits(limits(options));
    let mut decoder = reader.into_decoder().map_err(fail)?;
    let (width, height) = decoder.dimensions();
    check_size(width, height, options)?;
    // The output buffer counts against the allocation limit too; what is
    // left of it bounds the decoder's own working memory.
    let mut limits = limits(options);
    let needed = decoder.total_bytes();
    limits
        .reserve(needed)
        .and_then(|()| decoder.set_limits(limits))
        .map_err(|e| match e {
            ImageError::Limits(_) => Error::Image {
                message: format!(
                    "{} image is {width}x{height}: decoding it needs {needed} bytes, more than \
                     the memory limit of {}: {MEMORY_ADVICE}",
                    format.name(),
                    byte_count(options.max_alloc_bytes)
                ),
            },
            other => fail(other),
        })?;
    let color = decoder.original_color_type();
    let channels = color.channel_count();
    let bits_per_channel = (color.bits_per_pixel() / channels.max(1) as u16) as u8;
    // A damaged EXIF block is no reason to refuse the pixels: no rotation.
    let orientation = decoder.orientation().unwrap_or(Orientation::NoTransforms);
    Ok(Opened {
        format,
        width,
        height,
        channels,
        bits_per_channel,
        orientation,
        source: Source::Other(Box::new(decoder)),
    })
}

/// Whether the file stores palette indices: every GIF, and a BMP of at most
/// 8 bits per pixel (the `biBitCount` field at byte 28 of the file; `image`
/// does not report it).
fn indexed(format: ImageFormat, bytes: &[u8]) -> bool {
    match format {
        ImageFormat::Gif => true,
        ImageFormat::Bmp => bytes
            .get(28..30)
            .is_some_and(|b| u16::from_le_bytes([b[0], b[1]]) <= 8),
        _ => false,
    }
}

/// Whether every pixel of an 8-bit RGB(A) image has R = G = B (and is
/// opaque): grey content stored as colour.
fn all_grey(image: &DynamicImage) -> bool {
    match image {
        DynamicImage::ImageRgb8(rgb) => rgb.pixels().all(|p| p[0] == p[1] && p[1] == p[2]),
        DynamicImage::ImageRgba8(rgba) => rgba
            .pixels()
            .all(|p| p[0] == p[1] && p[1] == p[2] && p[3] == 255),
        _ => false,
    }
}

fn limits(options: &DecodeOptions) -> Limits {
    let mut limits = Limits::default();
    let side = u32::try_from(options.max_pixels).unwrap_or(u32::MAX);
    limits.max_image_width = Some(side);
    limits.max_image_height = Some(side);
    limits.max_alloc = Some(options.max_alloc_bytes);
    limits
}

/// RGBA preview whose longer side is at most `max_side` (never upscaled):
/// `image`'s thumbnail, an area average over the source pixels.
fn preview(image: &DynamicImage, max_side: u32) -> RgbaImage {
    let max_side = max_side.max(1);
    let (w, h) = (image.width(), image.height());
    let scale = (max_side as f64 / w.max(h) as f64).min(1.0);
    let tw = ((w as f64 * scale).round() as u32).clamp(1, w.max(1));
    let th = ((h as f64 * scale).round() as u32).clamp(1, h.max(1));
    let small = if (tw, th) == (w, h) {
        image.to_rgba8()
    } else {
        image.thumbnail_exact(tw, th).into_rgba8()
    };
    RgbaImage {
        width: small.width(),
        height: small.height(),
        pixels: small.into_raw(),
    }
}

impl ImageFormat {
    fn to_image_crate(self) -> ::image::ImageFormat {
        match self {
            ImageFormat::Png => ::image::ImageFormat::Png,
            ImageFormat::Jpeg => ::image::ImageFormat::Jpeg,
            ImageFormat::Tiff => ::image::ImageFormat::Tiff,
            ImageFormat::Bmp => ::image::ImageFormat::Bmp,
            ImageFormat::Pnm => ::image::ImageFormat::Pnm,
            ImageFormat::Gif => ::image::ImageFormat::Gif,
            ImageFormat::WebP => ::image::ImageFormat::WebP,
        }
    }
}

/// The formats we decode, in the order error messages list them.
const SUPPORTED: &str = "PNG, JPEG, TIFF, BMP, PGM/PPM, GIF, WebP";

/// Identify the container from its magic bytes (`image`'s table).
pub fn sniff_format(bytes: &[u8]) -> Result<ImageFormat> {
    if bytes.is_empty() {
        return Err(Error::Image {
            message: "not an image: the file is empty".into(),
        });
    }
    use ::image::ImageFormat as F;
    match ::image::guess_format(bytes) {
        Ok(F::Png) => Ok(ImageFormat::Png),
        Ok(F::Jpeg) => Ok(ImageFormat::Jpeg),
        Ok(F::Tiff) => Ok(ImageFormat::Tiff),
        Ok(F::Bmp) => Ok(ImageFormat::Bmp),
        Ok(F::Pnm) => Ok(ImageFormat::Pnm),
        Ok(F::Gif) => Ok(ImageFormat::Gif),
        Ok(F::WebP) => Ok(ImageFormat::WebP),
        Ok(other) => Err(Error::Image {
            message: format!("unsupported image format {other:?}: use {SUPPORTED}"),
        }),
        Err(_) => Err(Error::Image {
            message: format!("not an image: the bytes match none of {SUPPORTED}"),
        }),
    }
}

/// Encode a grey image as a binary PGM (P5); used by the renderer and tests.
pub fn encode_pgm(img: &GrayImage) -> Vec<u8> {
    let mut out = format!("P5\n{} {}\n255\n", img.width, img.height).into_bytes();
    out.extend_from_slice(&img.pixels);
    out
}

/// Encode a grey image as PNG (8-bit grey) through `image`.
pub fn encode_png(img: &GrayImage) -> Result<Vec<u8>> {
    use ::image::ImageEncoder;
    let mut out = Vec::new();
    ::image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            &img.pixels,
            img.width,
            img.height,
            ::image::ExtendedColorType::L8,
        )
        .map_err(|e| Error::Image {
            message: format!("could not encode PNG: {e}"),
        })?;
    Ok(out)
}

#[cfg(test)]
mod tests;
