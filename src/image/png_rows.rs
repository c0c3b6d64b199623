//! PNG through the `png` crate directly, for two things `image`'s wrapper
//! does not offer:
//!
//! - ancillary chunks that inflate are skipped or bounded: the colour
//!   profile (iCCP) is never inflated (grey detection does no colour
//!   management), compressed text is kept compressed, and every allocation
//!   the reader makes counts against [`DecodeOptions::max_alloc_bytes`]
//!   from the first byte on, header included;
//! - a non-interlaced image is read row by row and converted to 8-bit grey
//!   in strips of [`STRIP_ROWS`] rows, so the peak is the grey image (1 byte
//!   a pixel) plus one strip whatever the file's pixel format: a 16-bit RGBA
//!   file (8 bytes a pixel) no longer needs its full-depth buffer.
//!
//! Interlaced (Adam7) files, and every file when an RGBA preview is asked
//! for, are read whole into a buffer of the file's pixel format (under the
//! same limits). A file that ends before its IEND chunk is truncated; the
//! caller says so.

use super::{DecodeOptions, ImageFormat};
use crate::error::Result;
use ::image::error::{
    DecodingError, ImageFormatHint, LimitError, LimitErrorKind, ParameterError, ParameterErrorKind,
};
use ::image::{
    DynamicImage, GrayAlphaImage, GrayImage as LumaImage, ImageBuffer, ImageError, Luma, LumaA,
    Rgb, RgbImage, Rgba, RgbaImage,
};
use std::io::Cursor;

/// Rows converted to grey at a time: large enough that the per-strip
/// overhead vanishes, small enough that a strip of a 100 MP 16-bit RGBA
/// image (10000 px wide: 80 KB a row) stays near 5 MB.
pub(super) const STRIP_ROWS: usize = 64;

/// A PNG reader positioned on the first row, with the limits on.
pub(super) struct PngReader<'a> {
    reader: png::Reader<Cursor<&'a [u8]>>,
    /// Bytes of [`DecodeOptions::max_alloc_bytes`] left beside the grey
    /// image, for a whole-image buffer ([`PngReader::read_whole`]).
    left_bytes: u64,
}

/// What the header and the chunks before the image data say.
pub(super) struct PngHeader {
    pub width: u32,
    pub height: u32,
    pub channels: u8,
    pub bits_per_channel: u8,
    pub interlaced: bool,
    /// The raw eXIf chunk, if any (its Orientation tag is applied).
    pub exif: Option<Vec<u8>>,
}

/// Open `bytes` as PNG: read the header, check the size
/// ([`super::check_size`]), then every chunk up to the image data with what
/// is left of `max_alloc_bytes` beside the grey image, skipping iCCP.
pub(super) fn open<'a>(
    bytes: &'a [u8],
    options: &DecodeOptions,
) -> Result<(PngReader<'a>, PngHeader)> {
    let fail = |e: png::DecodingError| {
        super::decode_error(ImageFormat::Png, from_png(e), bytes.len(), options)
    };
    // The header chunk alone is read with the default limit (64 MiB).
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    let (width, height) = {
        let info = decoder.read_header_info().map_err(fail)?;
        (info.width, info.height)
    };
    super::check_size(width, height, options)?;
    let left_bytes = options
        .max_alloc_bytes
        .saturating_sub(width as u64 * height as u64);
    decoder.set_limits(png::Limits {
        bytes: usize::try_from(left_bytes).unwrap_or(usize::MAX),
    });
    decoder.set_ignore_iccp_chunk(true);
    // Text chunks are not needed (zTXt and iTXt would be kept compressed
    // anyway; this skips storing them).
    decoder.set_ignore_text_chunk(true);
    // Palettes and depths under 8 bits are expanded to 8 bits, 16-bit
    // samples are kept (as `image` does).
    decoder.set_transformations(png::Transformations::EXPAND);
    let reader = decoder.read_info().map_err(fail)?;
    let info = reader.info();
    let (color, depth) = reader.output_color_type();
    let header = PngHeader {
        width,
        height,
        channels: color.samples() as u8,
        bits_per_channel: if depth == png::BitDepth::Sixteen {
            16
        } else {
            8
        },
        interlaced: info.interlaced,
        exif: info.exif_metadata.as_ref().map(|c| c.to_vec()),
    };
    Ok((PngReader { reader, left_bytes }, header))
}

impl PngReader<'_> {
    /// Decode row by row into 8-bit grey (`image`'s luma conversion, strip
    /// by strip). Non-interlaced files only.
    pub(super) fn read_gray(
        mut self,
        width: u32,
        height: u32,
    ) -> std::result::Result<Vec<u8>, ImageError> {
        let (color, depth) = self.reader.output_color_type();
        let row_bytes = self
            .reader
            .output_line_size(width)
            .ok_or_else(limit_error)?;
        let mut gray = Vec::new();
        gray.try_reserve_exact(width as usize * height as usize)
            .map_err(|_| limit_error())?;
        let mut strip = Vec::with_capacity(row_bytes * STRIP_ROWS);
        let mut rows = 0u32;
        while let Some(row) = self.reader.next_row().map_err(from_png)? {
            strip.extend_from_slice(row.data());
            rows += 1;
            if rows as usize == STRIP_ROWS {
                gray.extend_from_slice(&strip_gray(color, depth, width, rows, &strip)?);
                strip.clear();
                rows = 0;
            }
        }
        if rows > 0 {
            gray.extend_from_slice(&strip_gray(color, depth, width, rows, &strip)?);
        }
        // Up to IEND: a file cut after its last image data is truncated too.
        self.reader.finish().map_err(from_png)?;
        Ok(gray)
    }

    /// Decode the whole frame into an image of the file's pixel format
    /// (interlaced files, previews).
    pub(super) fn read_whole(
        mut self,
        width: u32,
        height: u32,
    ) -> std::result::Result<DynamicImage, ImageError> {
        let (color, depth) = self.reader.output_color_type();
        let size = self.reader.output_buffer_size().ok_or_else(limit_error)?;
        if size as u64 > self.left_bytes {
            return Err(limit_error());
        }
        let mut buf = Vec::new();
        buf.try_reserve_exact(size).map_err(|_| limit_error())?;
        buf.resize(size, 0);
        self.reader.next_frame(&mut buf).map_err(from_png)?;
        self.reader.finish().map_err(from_png)?;
        to_dynamic(color, depth, width, height, buf)
    }
}

/// One strip of rows in the file's pixel format, as 8-bit grey.
fn strip_gray(
    color: png::ColorType,
    depth: png::BitDepth,
    width: u32,
    rows: u32,
    strip: &[u8],
) -> std::result::Result<Vec<u8>, ImageError> {
    if (color, depth) == (png::ColorType::Grayscale, png::BitDepth::Eight) {
        return Ok(strip.to_vec());
    }
    Ok(to_dynamic(color, depth, width, rows, strip.to_vec())?
        .into_luma8()
        .into_raw())
}

/// Rows of the `png` crate's output (16-bit samples big-endian) as an
/// `image` buffer of the same pixel format.
fn to_dynamic(
    color: png::ColorType,
    depth: png::BitDepth,
    width: u32,
    height: u32,
    data: Vec<u8>,
) -> std::result::Result<DynamicImage, ImageError> {
    use png::ColorType as C;
    let wrong_size = || {
        ImageError::Parameter(ParameterError::from_kind(
            ParameterErrorKind::DimensionMismatch,
        ))
    };
    if depth == png::BitDepth::Sixteen {
        let wide: Vec<u16> = data
            .chunks_exact(2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
            .collect();
        return match color {
            C::Grayscale => ImageBuffer::<Luma<u16>, _>::from_raw(width, height, wide)
                .map(DynamicImage::ImageLuma16),
            C::GrayscaleAlpha => ImageBuffer::<LumaA<u16>, _>::from_raw(width, height, wide)
                .map(DynamicImage::ImageLumaA16),
            C::Rgb => ImageBuffer::<Rgb<u16>, _>::from_raw(width, height, wide)
                .map(DynamicImage::ImageRgb16),
            C::Rgba => ImageBuffer::<Rgba<u16>, _>::from_raw(width, height, wide)
                .map(DynamicImage::ImageRgba16),
            C::Indexed => None,
        }
        .ok_or_else(wrong_size);
    }
    match color {
        C::Grayscale => LumaImage::from_raw(width, height, data).map(DynamicImage::ImageLuma8),
        C::GrayscaleAlpha => {
            GrayAlphaImage::from_raw(width, height, data).map(DynamicImage::ImageLumaA8)
        }
        C::Rgb => RgbImage::from_raw(width, height, data).map(DynamicImage::ImageRgb8),
        C::Rgba => RgbaImage::from_raw(width, height, data).map(DynamicImage::ImageRgba8),
        // EXPAND turns palettes into RGB(A).
        C::Indexed => None,
    }
    .ok_or_else(wrong_size)
}

fn limit_error() -> ImageError {
    ImageError::Limits(LimitError::from_kind(LimitErrorKind::InsufficientMemory))
}

/// The `png` crate's error as `image` reports it (so that the messages are
/// those of `image`'s own PNG decoder).
fn from_png(err: png::DecodingError) -> ImageError {
    use png::DecodingError as E;
    match err {
        E::IoError(e) => ImageError::IoError(e),
        e @ E::Format(_) => ImageError::Decoding(DecodingError::new(
            ImageFormatHint::Exact(ImageFormat::Png.to_image_crate()),
            e,
        )),
        e @ E::Parameter(_) => ImageError::Parameter(ParameterError::from_kind(
            ParameterErrorKind::Generic(e.to_string()),
        )),
        E::LimitsExceeded => limit_error(),
    }
}
