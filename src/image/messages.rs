//! The decoder's refusals in words: the image size against the limit, the
//! memory it would need, and `image`'s errors naming the format and what to do.

use super::*;

/// Refuse empty images and images over [`DecodeOptions::max_pixels`], from
/// the header's dimensions, before any pixel buffer.
pub(super) fn check_size(width: u32, height: u32, options: &DecodeOptions) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::Image {
            message: format!("image is {width}x{height} pixels: it has no pixels"),
        });
    }
    let pixels = width as u64 * height as u64;
    if pixels > options.max_pixels {
        return Err(Error::Image {
            message: format!(
                "image is {width}x{height} = {}, more than the limit of {}: downscale it first, \
                 or raise the limit (--max-pixels in the CLI, \"max_pixels\" in the JSON options)",
                pixel_count(pixels, options.max_pixels),
                pixel_count(options.max_pixels, pixels)
            ),
        });
    }
    Ok(())
}

/// A pixel count as people say it: "12.3 MP", or "3015 pixels" when small
/// or when "MP" would print it the same as `other` (the count it is set
/// against in the message).
pub(super) fn pixel_count(n: u64, other: u64) -> String {
    let mp = |n: u64| format!("{:.1} MP", n as f64 / 1e6);
    if n >= 100_000 && mp(n) != mp(other) {
        mp(n)
    } else {
        format!("{n} pixels")
    }
}

/// What to do about an image over the memory limit.
pub(super) const MEMORY_ADVICE: &str =
    "downscale it, or save it as 8-bit grey (all calibration uses); \
     --max-pixels N in the CLI raises the limit to 10 bytes a pixel";

/// A byte count as people read it: "1.0 GiB (1073741824 bytes)", or
/// "1000 bytes" under a mebibyte.
pub(super) fn byte_count(n: u64) -> String {
    const MIB: u64 = 1 << 20;
    if n >= 1 << 30 {
        format!("{:.1} GiB ({n} bytes)", n as f64 / (1u64 << 30) as f64)
    } else if n >= MIB {
        format!("{:.1} MiB ({n} bytes)", n as f64 / MIB as f64)
    } else {
        format!("{n} bytes")
    }
}

/// `image`'s error as ours, naming the format and what to do; `len` is the
/// file's length (a truncated file is named as such).
pub(super) fn decode_error(
    format: ImageFormat,
    e: ImageError,
    len: usize,
    options: &DecodeOptions,
) -> Error {
    if truncation::is_end_of_file(&e) {
        return Error::Image {
            message: truncation::message(format, len),
        };
    }
    let name = format.name();
    let message = match e {
        ImageError::Limits(_) => format!(
            "{name} image needs more memory to decode than the limit of {}: {MEMORY_ADVICE}",
            byte_count(options.max_alloc_bytes)
        ),
        ImageError::Unsupported(e) => format!("{name} variant not supported: {e}"),
        ImageError::Decoding(e) => format!("corrupt or truncated {name} file: {e}"),
        ImageError::IoError(e) => format!("corrupt or truncated {name} file: {e}"),
        ImageError::Parameter(e) => format!("corrupt or truncated {name} file: {e}"),
        ImageError::Encoding(e) => format!("corrupt {name} file: {e}"),
    };
    // Some decoders end their text with a newline (JPEG's I/O errors).
    let message = message.trim_end().to_string();
    Error::Image { message }
}
