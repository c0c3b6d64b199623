//! The EXIF orientation applied to decoded images, as OpenCV's imread does.

use super::{GrayImage, RgbaImage};
use crate::error::{Error, Result};
use ::image::metadata::Orientation;
use ::image::DynamicImage;

/// [`orient`] for the RGBA preview.
pub(super) fn orient_rgba(small: RgbaImage, orientation: Orientation) -> Result<RgbaImage> {
    if orientation == Orientation::NoTransforms {
        return Ok(small);
    }
    let (w, h) = (small.width, small.height);
    let buffer = ::image::RgbaImage::from_raw(w, h, small.pixels).ok_or_else(|| {
        Error::invalid(
            "preview",
            format!(
                "a {w}x{h} preview needs {} bytes",
                4 * w as usize * h as usize
            ),
        )
    })?;
    let mut image = DynamicImage::ImageRgba8(buffer);
    image.apply_orientation(orientation);
    let rgba = image.into_rgba8();
    Ok(RgbaImage {
        width: rgba.width(),
        height: rgba.height(),
        pixels: rgba.into_raw(),
    })
}

/// Rotate or flip the grey image as the EXIF Orientation tag says, as
/// OpenCV's `imread` and image viewers do (`image`'s `apply_orientation`).
pub(super) fn orient(gray: GrayImage, orientation: Orientation) -> Result<GrayImage> {
    if orientation == Orientation::NoTransforms {
        return Ok(gray);
    }
    let (w, h) = (gray.width, gray.height);
    let buffer = ::image::GrayImage::from_raw(w, h, gray.pixels).ok_or_else(|| {
        Error::invalid(
            "pixels",
            format!("a {w}x{h} image needs {} bytes", w as usize * h as usize),
        )
    })?;
    let mut image = DynamicImage::ImageLuma8(buffer);
    image.apply_orientation(orientation);
    let luma = image.into_luma8();
    GrayImage::new(luma.width(), luma.height(), luma.into_raw())
}

/// The EXIF Orientation value (2-8) applied, `None` when nothing was.
pub(super) fn exif_orientation(orientation: Orientation) -> Option<u8> {
    match orientation {
        Orientation::NoTransforms => None,
        other => Some(other.to_exif()),
    }
}
