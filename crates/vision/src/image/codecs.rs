//! PNG and GIF through their single-format crates, JPEG through our own
//! decoder: read the header, check the limits, decode into a [`Raster`].

use super::raster::{Raster, Samples};
use super::{check_alloc, check_size, corrupt, too_large, unsupported, DecodeOptions, ImageFormat};
use crate::error::Result;
use std::io::Cursor;

fn alloc_limit(options: &DecodeOptions) -> usize {
    usize::try_from(options.max_alloc_bytes).unwrap_or(usize::MAX)
}

/// PNG: palettes and sub-byte grey expanded to 8 bits, tRNS to alpha; 16-bit
/// kept.
pub(super) fn decode_png(bytes: &[u8], options: &DecodeOptions) -> Result<Raster> {
    const F: ImageFormat = ImageFormat::Png;
    let png_error = |e: png::DecodingError| match e {
        png::DecodingError::LimitsExceeded => too_large(F, options),
        other => corrupt(F, other),
    };
    let limits = png::Limits {
        bytes: alloc_limit(options),
    };
    let mut decoder = png::Decoder::new_with_limits(Cursor::new(bytes), limits);
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(png_error)?;
    let (width, height) = (reader.info().width, reader.info().height);
    check_size(width, height, options)?;
    let (color, depth) = reader.output_color_type();
    let channels = color.samples() as u8;
    let sixteen = depth == png::BitDepth::Sixteen;
    let size = check_alloc(F, width, height, channels, 1 + sixteen as u8, options)?;
    if reader.output_buffer_size() != Some(size) {
        return Err(unsupported(F, format!("{color:?} at {depth:?} bits")));
    }
    let mut buf = vec![0u8; size];
    reader.next_frame(&mut buf).map_err(png_error)?;
    let samples = if sixteen {
        Samples::U16(
            buf.chunks_exact(2)
                .map(|b| u16::from_be_bytes([b[0], b[1]]))
                .collect(),
        )
    } else {
        Samples::U8(buf)
    };
    Ok(Raster {
        width,
        height,
        channels,
        samples,
    })
}

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

/// GIF: the first frame, RGBA, placed on the logical screen at its offset
/// (outside the frame: transparent black, as the `image` crate does).
pub(super) fn decode_gif(bytes: &[u8], options: &DecodeOptions) -> Result<Raster> {
    const F: ImageFormat = ImageFormat::Gif;
    let gif_error = |e: gif::DecodingError| corrupt(F, e);
    let mut gif_options = gif::DecodeOptions::new();
    gif_options.set_color_output(gif::ColorOutput::RGBA);
    if let Some(limit) = std::num::NonZeroU64::new(options.max_alloc_bytes) {
        gif_options.set_memory_limit(gif::MemoryLimit::Bytes(limit));
    }
    let mut decoder = gif_options
        .read_info(Cursor::new(bytes))
        .map_err(gif_error)?;
    let (width, height) = (decoder.width() as u32, decoder.height() as u32);
    check_size(width, height, options)?;
    let size = check_alloc(F, width, height, 4, 1, options)?;
    let frame = decoder
        .read_next_frame()
        .map_err(gif_error)?
        .ok_or_else(|| corrupt(F, "no image frame"))?;
    let mut canvas = vec![0u8; size];
    let (fw, fh) = (frame.width as usize, frame.height as usize);
    let (left, top) = (frame.left as usize, frame.top as usize);
    let (w, h) = (width as usize, height as usize);
    if fw > 0 && left < w {
        let copy = fw.min(w - left) * 4;
        for (fy, src) in frame.buffer.chunks_exact(fw * 4).take(fh).enumerate() {
            let y = top + fy;
            if y >= h {
                break;
            }
            let at = (y * w + left) * 4;
            canvas[at..at + copy].copy_from_slice(&src[..copy]);
        }
    }
    Ok(Raster {
        width,
        height,
        channels: 4,
        samples: Samples::U8(canvas),
    })
}
