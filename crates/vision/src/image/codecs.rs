//! JPEG through our own decoder ([`super::jpeg`]): read the header, check
//! the limits, decode into a [`Raster`].

use super::raster::{Raster, Samples};
use super::{check_alloc, check_size, corrupt, too_large, unsupported, DecodeOptions, ImageFormat};
use crate::error::Result;

/// JPEG (our decoder, [`super::jpeg`]): grey stays grey, everything else
/// (YCbCr, RGB, CMYK, YCCK) becomes RGB.
pub(super) fn decode_jpeg(bytes: &[u8], options: &DecodeOptions) -> Result<Raster> {
    use super::jpeg::JpegError;
    const F: ImageFormat = ImageFormat::Jpeg;
    let jpeg_error = |e: JpegError| match e {
        JpegError::Corrupt(detail) => corrupt(F, detail),
        JpegError::Unsupported(detail) => unsupported(F, detail),
        JpegError::TooLarge => too_large(F, options),
    };
    let header = super::jpeg::read_header(bytes).map_err(jpeg_error)?;
    check_size(header.width, header.height, options)?;
    let out = check_alloc(F, header.width, header.height, header.channels, 1, options)?;
    let working = options.max_alloc_bytes.saturating_sub(out as u64);
    let image = super::jpeg::decode(bytes, working).map_err(jpeg_error)?;
    Ok(Raster {
        width: image.width,
        height: image.height,
        channels: image.channels,
        samples: Samples::U8(image.pixels),
    })
}
