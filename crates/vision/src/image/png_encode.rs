//! A minimal PNG writer for 8-bit grey images: IHDR, one IDAT (rows with the
//! "Up" filter, zlib-compressed by `fdeflate`, the PNG-tuned compressor the
//! `png` crate also uses), IEND.

use super::GrayImage;
use crate::error::{Error, Result};

/// The chunk CRC (over type and data), by the workspace's crc32fast; the
/// reader checks chunks with it too.
pub(super) fn crc32(parts: &[&[u8]]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    for part in parts {
        h.update(part);
    }
    h.finalize()
}

/// Append one chunk: length, type, data, CRC.
pub(super) fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    out.extend_from_slice(&crc32(&[kind, data]).to_be_bytes());
}

/// Encode `img` as an 8-bit greyscale, non-interlaced PNG.
pub(super) fn encode_gray(img: &GrayImage) -> Result<Vec<u8>> {
    let (w, h) = (img.width as usize, img.height as usize);
    if w == 0 || h == 0 || img.pixels.len() != w * h {
        return Err(Error::Image {
            message: format!(
                "PNG encoding failed: a {}x{} image with {} bytes of pixels",
                img.width,
                img.height,
                img.pixels.len()
            ),
        });
    }
    // Filter type 2 (Up): each byte minus the byte above (the first row
    // minus zero, i.e. unchanged).
    let mut filtered = Vec::with_capacity((w + 1) * h);
    let mut above: &[u8] = &[];
    for row in img.pixels.chunks_exact(w) {
        filtered.push(2);
        if above.is_empty() {
            filtered.extend_from_slice(row);
        } else {
            filtered.extend(row.iter().zip(above).map(|(&p, &u)| p.wrapping_sub(u)));
        }
        above = row;
    }
    let idat = fdeflate::compress_to_vec(&filtered);
    let mut ihdr = Vec::with_capacity(13);
    ihdr.extend_from_slice(&img.width.to_be_bytes());
    ihdr.extend_from_slice(&img.height.to_be_bytes());
    // 8 bits, colour type 0 (grey), deflate, adaptive filtering, no interlace.
    ihdr.extend_from_slice(&[8, 0, 0, 0, 0]);
    let mut out = Vec::with_capacity(idat.len() + 64);
    out.extend_from_slice(b"\x89PNG\r\n\x1a\n");
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &idat);
    chunk(&mut out, b"IEND", &[]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn crc_matches_the_png_specification_example() {
        // The CRC of an IEND chunk is the well-known AE 42 60 82.
        assert_eq!(crc32(&[b"IEND"]), 0xAE42_6082);
        assert_eq!(crc32(&[b"123456789"]), 0xCBF4_3926);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn empty_image_is_refused() {
        let img = GrayImage {
            width: 0,
            height: 3,
            pixels: vec![],
        };
        assert_eq!(
            encode_gray(&img).unwrap_err().to_string(),
            "PNG encoding failed: a 0x3 image with 0 bytes of pixels"
        );
    }
}
