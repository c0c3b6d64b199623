//! Truncated files, named as such whatever the decoder managed to read.
//!
//! A file cut short (an interrupted copy or download, a full card) must not
//! reach the detectors half grey: JPEG decoders fill the missing blocks and
//! succeed, and the user is told "board not found". Calibration wants every
//! image whole, so a truncated file is an error that says so and what to do.
//!
//! - JPEG: the marker segments are walked from SOI by their lengths (an
//!   embedded EXIF thumbnail is inside a segment, so it is skipped) and the
//!   entropy-coded data scanned for the next marker; a file that ends before
//!   the EOI marker is truncated. This is a check of the container's framing,
//!   not a decoder: the pixels are still `image`'s.
//! - PNG, TIFF, BMP, PNM: the decoders stop with an end-of-file error (PNG is
//!   read up to its IEND chunk, so a file cut after its last image data is
//!   caught too); [`message`] turns that error into the same sentence.

use super::ImageFormat;
use ::image::ImageError;

/// The error text of a truncated file of `len` bytes.
pub(super) fn message(format: ImageFormat, len: usize) -> String {
    format!(
        "the {} file is truncated: it ends after {len} bytes, before the end of its image data \
         (an interrupted copy or download?): copy it again from the camera or its source",
        format.name()
    )
}

/// Whether the decoder's error is an unexpected end of the data.
pub(super) fn is_end_of_file(e: &ImageError) -> bool {
    matches!(e, ImageError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof)
}

/// How a JPEG's framing ends.
#[derive(Debug, PartialEq, Eq)]
pub(super) enum JpegEnd {
    /// The EOI marker was reached.
    Complete,
    /// The bytes end before EOI.
    Truncated,
    /// Not a marker where one must be: left to the decoder to describe.
    Malformed,
}

/// Walk a JPEG's marker segments from SOI to EOI.
pub(super) fn jpeg_end(bytes: &[u8]) -> JpegEnd {
    if bytes.len() < 2 || bytes[0] != 0xFF || bytes[1] != 0xD8 {
        return JpegEnd::Malformed;
    }
    let mut i = 2;
    loop {
        let Some(&first) = bytes.get(i) else {
            return JpegEnd::Truncated;
        };
        if first != 0xFF {
            return JpegEnd::Malformed;
        }
        // A marker may be preceded by any number of fill bytes 0xFF.
        while bytes.get(i) == Some(&0xFF) {
            i += 1;
        }
        let Some(&marker) = bytes.get(i) else {
            return JpegEnd::Truncated;
        };
        i += 1;
        match marker {
            0xD9 => return JpegEnd::Complete,
            // Standalone markers: restart intervals and TEM carry no length.
            0xD0..=0xD7 | 0x01 => continue,
            0x00 => return JpegEnd::Malformed,
            _ => {}
        }
        let Some(len) = bytes
            .get(i..i + 2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]) as usize)
        else {
            return JpegEnd::Truncated;
        };
        if len < 2 {
            return JpegEnd::Malformed;
        }
        if i + len > bytes.len() {
            return JpegEnd::Truncated;
        }
        i += len;
        if marker == 0xDA {
            match entropy_end(bytes, i) {
                Some(next) => i = next,
                None => return JpegEnd::Truncated,
            }
        }
    }
}

/// The offset of the marker that ends the entropy-coded data starting at
/// `start` (a 0xFF not followed by a stuffed 0x00 or a restart marker), or
/// `None` when the bytes end first.
fn entropy_end(bytes: &[u8], start: usize) -> Option<usize> {
    let mut j = start;
    loop {
        j += bytes.get(j..)?.iter().position(|&b| b == 0xFF)?;
        match bytes.get(j + 1)? {
            0x00 | 0xD0..=0xD7 | 0xFF => j += 1,
            _ => return Some(j),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jpeg_framing_is_walked_to_eoi() {
        // SOI, an APP0 of 4 bytes, SOS of 4 bytes, entropy data with a
        // stuffed byte and a restart marker, EOI.
        let whole = [
            0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x04, 0xAA, 0xBB, 0xFF, 0xDA, 0x00, 0x04, 0x01, 0x02,
            0x12, 0xFF, 0x00, 0x34, 0xFF, 0xD3, 0x56, 0xFF, 0xD9,
        ];
        assert_eq!(jpeg_end(&whole), JpegEnd::Complete);
        for cut in 2..whole.len() - 1 {
            assert_eq!(jpeg_end(&whole[..cut]), JpegEnd::Truncated, "cut at {cut}");
        }
        assert_eq!(jpeg_end(b"\xFF\xD8hello"), JpegEnd::Malformed);
    }
}
