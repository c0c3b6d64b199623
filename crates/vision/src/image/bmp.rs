//! Windows bitmap reader: 1/2/4/8-bit palette, 16/24/32-bit direct colour,
//! bottom-up and top-down rows, uncompressed, BI_BITFIELDS /
//! BI_ALPHABITFIELDS masks, RLE8 and RLE4. Headers: OS/2 core (12 bytes) and
//! the Windows INFO family (40 to 124 bytes). Output: RGB, or RGBA when the
//! masks include alpha.

use super::raster::{Raster, Samples};
use super::{check_alloc, check_size, corrupt, unsupported, DecodeOptions, ImageFormat};
use crate::error::Result;

const F: ImageFormat = ImageFormat::Bmp;

fn u16_at(b: &[u8], at: usize) -> Result<u16> {
    b.get(at..at + 2)
        .map(|s| u16::from_le_bytes([s[0], s[1]]))
        .ok_or_else(|| corrupt(F, "the header is truncated"))
}

fn u32_at(b: &[u8], at: usize) -> Result<u32> {
    b.get(at..at + 4)
        .map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
        .ok_or_else(|| corrupt(F, "the header is truncated"))
}

/// One channel mask: where it sits and how to scale it to 8 bits.
#[derive(Clone, Copy)]
struct Mask {
    mask: u32,
    shift: u32,
    max: u32,
}

impl Mask {
    fn new(mask: u32) -> Mask {
        let shift = if mask == 0 { 0 } else { mask.trailing_zeros() };
        let max = mask.checked_shr(shift).unwrap_or(0);
        Mask { mask, shift, max }
    }

    fn get(self, px: u32) -> u8 {
        if self.max == 0 {
            return 0;
        }
        let v = ((px & self.mask) >> self.shift) as u64;
        ((v * 255 + self.max as u64 / 2) / self.max as u64) as u8
    }
}

/// Decode a BMP file.
pub(super) fn decode(bytes: &[u8], options: &DecodeOptions) -> Result<Raster> {
    let data_offset = u32_at(bytes, 10)? as usize;
    let dib = u32_at(bytes, 14)? as usize;
    let (width, height_signed, bpp, compression, colours_used) = match dib {
        12 => (
            u16_at(bytes, 18)? as i64,
            u16_at(bytes, 20)? as i64,
            u16_at(bytes, 24)?,
            0,
            0,
        ),
        40..=124 => (
            u32_at(bytes, 18)? as i32 as i64,
            u32_at(bytes, 22)? as i32 as i64,
            u16_at(bytes, 28)?,
            u32_at(bytes, 30)?,
            u32_at(bytes, 46)? as usize,
        ),
        other => return Err(unsupported(F, format!("a {other}-byte info header"))),
    };
    let top_down = height_signed < 0;
    let (width, height) = (width, height_signed.abs());
    if width < 0 || width > u32::MAX as i64 || height > u32::MAX as i64 {
        return Err(corrupt(F, format!("size {width}x{height_signed}")));
    }
    let (width, height) = (width as u32, height as u32);
    check_size(width, height, options)?;
    // Masks sit at offset 54 whether inside a V2+ header or right after a
    // 40-byte INFO header; the palette follows them.
    let mut palette_at = 14 + dib;
    let masks = match (compression, bpp) {
        (0, 16) => Some([0x7C00, 0x03E0, 0x001F, 0]),
        (0, 24 | 32) => Some([0xFF_0000, 0xFF00, 0xFF, 0]),
        (3 | 6, 16 | 32) => {
            let alpha = if compression == 6 || dib >= 56 {
                u32_at(bytes, 66)?
            } else {
                0
            };
            if dib == 40 {
                palette_at += if compression == 6 { 16 } else { 12 };
            }
            Some([
                u32_at(bytes, 54)?,
                u32_at(bytes, 58)?,
                u32_at(bytes, 62)?,
                alpha,
            ])
        }
        (0, 1 | 2 | 4 | 8) | (1, 8) | (2, 4) => None,
        _ => {
            return Err(unsupported(
                F,
                format!("{bpp} bits per pixel with compression {compression}"),
            ))
        }
    };
    if top_down && compression != 0 && masks.is_none() {
        return Err(corrupt(F, "a top-down bitmap cannot be RLE-compressed"));
    }
    let channels = if masks.is_some_and(|m| m[3] != 0) {
        4
    } else {
        3
    };
    let size = check_alloc(F, width, height, channels, 1, options)?;
    let pixel_data = bytes.get(data_offset..).ok_or_else(|| {
        corrupt(
            F,
            format!("pixel data offset {data_offset} beyond the file"),
        )
    })?;
    let (w, h) = (width as usize, height as usize);
    let mut out = vec![0u8; size];
    // File row r is image row `r` (top-down) or `h - 1 - r` (bottom-up).
    let image_row = |r: usize| if top_down { r } else { h - 1 - r };
    match masks {
        Some(m) => {
            let stride = (w * bpp as usize).div_ceil(32) * 4;
            check_length(pixel_data, stride, h)?;
            let m = m.map(Mask::new);
            let step = bpp as usize / 8;
            for (r, row) in pixel_data.chunks_exact(stride).take(h).enumerate() {
                let dst = &mut out[image_row(r) * w * channels as usize..][..w * channels as usize];
                for (src, px) in row
                    .chunks_exact(step)
                    .zip(dst.chunks_exact_mut(channels as usize))
                {
                    let v = src.iter().rev().fold(0u32, |acc, &b| (acc << 8) | b as u32);
                    for (c, slot) in px.iter_mut().enumerate() {
                        *slot = m[c].get(v);
                    }
                }
            }
        }
        None => {
            let entry = if dib == 12 { 3 } else { 4 };
            let listed = if colours_used == 0 {
                1 << bpp
            } else {
                colours_used.min(256)
            };
            // The palette ends where the pixels begin.
            let listed = listed.min(data_offset.saturating_sub(palette_at) / entry);
            let mut palette = [[0u8; 3]; 256];
            for (i, slot) in palette.iter_mut().enumerate().take(listed) {
                if let Some(e) = bytes.get(palette_at + i * entry..palette_at + i * entry + 3) {
                    *slot = [e[2], e[1], e[0]];
                }
            }
            let indices = match compression {
                0 => unpack_indices(pixel_data, w, h, bpp as usize)?,
                _ => rle(pixel_data, w, h, compression == 2)?,
            };
            for (r, row) in indices.chunks_exact(w).enumerate() {
                let dst = &mut out[image_row(r) * w * 3..][..w * 3];
                for (&i, px) in row.iter().zip(dst.chunks_exact_mut(3)) {
                    px.copy_from_slice(&palette[i as usize]);
                }
            }
        }
    }
    Ok(Raster {
        width,
        height,
        channels,
        samples: Samples::U8(out),
    })
}

fn check_length(data: &[u8], stride: usize, rows: usize) -> Result<()> {
    if data.len() < stride * rows {
        return Err(corrupt(
            F,
            format!("{} bytes of pixels for {}", data.len(), stride * rows),
        ));
    }
    Ok(())
}

/// Uncompressed palette rows (file order) to one index per pixel.
fn unpack_indices(data: &[u8], w: usize, h: usize, bpp: usize) -> Result<Vec<u8>> {
    let stride = (w * bpp).div_ceil(32) * 4;
    check_length(data, stride, h)?;
    let per_byte = 8 / bpp;
    let mask = ((1u16 << bpp) - 1) as u8;
    let mut out = Vec::with_capacity(w * h);
    for row in data.chunks_exact(stride).take(h) {
        out.extend((0..w).map(|x| {
            let shift = 8 - bpp * (x % per_byte + 1);
            (row[x / per_byte] >> shift) & mask
        }));
    }
    Ok(out)
}

/// RLE8 (`nibbles` false) or RLE4 to indices in file row order (bottom row
/// first). Pixels the stream skips stay at index 0.
fn rle(data: &[u8], w: usize, h: usize, nibbles: bool) -> Result<Vec<u8>> {
    let mut out = vec![0u8; w * h];
    let (mut x, mut y, mut i) = (0usize, 0usize, 0usize);
    let truncated = || corrupt(F, "the RLE stream ends without an end-of-bitmap code");
    let mut put = |x: &mut usize, y: usize, v: u8| {
        if *x < w && y < h {
            out[y * w + *x] = v;
        }
        *x += 1;
    };
    loop {
        let (&count, &value) = (
            data.get(i).ok_or_else(truncated)?,
            data.get(i + 1).ok_or_else(truncated)?,
        );
        i += 2;
        match (count, value) {
            (0, 0) => {
                x = 0;
                y += 1;
            }
            (0, 1) => break,
            (0, 2) => {
                let (&dx, &dy) = (
                    data.get(i).ok_or_else(truncated)?,
                    data.get(i + 1).ok_or_else(truncated)?,
                );
                i += 2;
                x += dx as usize;
                y += dy as usize;
            }
            (0, n) => {
                let n = n as usize;
                let len = if nibbles { n.div_ceil(2) } else { n };
                let run = data.get(i..i + len).ok_or_else(truncated)?;
                for k in 0..n {
                    let v = if nibbles {
                        (run[k / 2] >> (4 - 4 * (k % 2))) & 0xF
                    } else {
                        run[k]
                    };
                    put(&mut x, y, v);
                }
                i += len + len % 2;
            }
            (n, v) => {
                for k in 0..n as usize {
                    let v = if nibbles {
                        (v >> (4 - 4 * (k % 2))) & 0xF
                    } else {
                        v
                    };
                    put(&mut x, y, v);
                }
            }
        }
        if y > h {
            break;
        }
    }
    Ok(out)
}
