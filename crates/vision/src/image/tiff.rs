//! Baseline TIFF reader (the first image of the file): grey (BlackIsZero or
//! WhiteIsZero), grey+alpha, RGB, RGBA; 1 bit (grey), 8 or 16 bits, 32-bit
//! float; strips or tiles, chunky samples; uncompressed, LZW ([`super::lzw`]),
//! deflate (`fdeflate`), PackBits; horizontal predictor. No JPEG-in-TIFF,
//! palette, CMYK, YCbCr, planar layout or BigTIFF: those are reported as
//! unsupported.

use super::raster::{Raster, Samples};
use super::{check_alloc, check_size, corrupt, unsupported, DecodeOptions, ImageFormat};
use crate::error::Result;

const F: ImageFormat = ImageFormat::Tiff;

struct File<'a> {
    bytes: &'a [u8],
    big_endian: bool,
}

impl File<'_> {
    fn u16(&self, at: usize) -> Result<u16> {
        let b = self
            .bytes
            .get(at..at + 2)
            .ok_or_else(|| corrupt(F, "an IFD runs past the end"))?;
        let b = [b[0], b[1]];
        Ok(if self.big_endian {
            u16::from_be_bytes(b)
        } else {
            u16::from_le_bytes(b)
        })
    }

    fn u32(&self, at: usize) -> Result<u32> {
        let b = self
            .bytes
            .get(at..at + 4)
            .ok_or_else(|| corrupt(F, "an IFD runs past the end"))?;
        let b = [b[0], b[1], b[2], b[3]];
        Ok(if self.big_endian {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        })
    }
}

/// The tags of the first IFD that the reader uses (SHORT/LONG/BYTE values).
#[derive(Default)]
struct Tags {
    entries: Vec<(u16, Vec<u32>)>,
}

impl Tags {
    fn get(&self, tag: u16) -> Option<&[u32]> {
        self.entries
            .iter()
            .find(|(t, _)| *t == tag)
            .map(|(_, v)| v.as_slice())
    }

    fn one(&self, tag: u16, default: Option<u32>) -> Result<u32> {
        match self.get(tag).and_then(|v| v.first()) {
            Some(&v) => Ok(v),
            None => default.ok_or_else(|| corrupt(F, format!("required tag {tag} is missing"))),
        }
    }
}

fn read_ifd(file: &File, at: usize) -> Result<Tags> {
    let count = file.u16(at)? as usize;
    let mut tags = Tags::default();
    for k in 0..count {
        let e = at + 2 + 12 * k;
        let (tag, kind, n) = (file.u16(e)?, file.u16(e + 2)?, file.u32(e + 4)? as usize);
        let size = match kind {
            1 => 1,
            3 => 2,
            4 => 4,
            _ => continue, // types the reader does not need (ASCII, RATIONAL, ...)
        };
        let len = n
            .checked_mul(size)
            .filter(|&l| l <= file.bytes.len())
            .ok_or_else(|| {
                corrupt(
                    F,
                    format!("tag {tag} has {n} values, more than the file holds"),
                )
            })?;
        let base = if len <= 4 {
            e + 8
        } else {
            file.u32(e + 8)? as usize
        };
        let values = (0..n)
            .map(|i| match size {
                1 => file
                    .bytes
                    .get(base + i)
                    .map(|&b| b as u32)
                    .ok_or_else(|| corrupt(F, "a tag value runs past the end")),
                2 => file.u16(base + 2 * i).map(u32::from),
                _ => file.u32(base + 4 * i),
            })
            .collect::<Result<Vec<u32>>>()?;
        tags.entries.push((tag, values));
    }
    Ok(tags)
}

/// Decode the first image of a TIFF file.
pub(super) fn decode(bytes: &[u8], options: &DecodeOptions) -> Result<Raster> {
    let file = File {
        bytes,
        big_endian: bytes.starts_with(b"MM"),
    };
    let tags = read_ifd(&file, file.u32(4)? as usize)?;
    let (width, height) = (tags.one(256, None)?, tags.one(257, None)?);
    check_size(width, height, options)?;
    let photometric = tags.one(262, None)?;
    let spp = tags.one(277, Some(1))?;
    let bits = tags.one(258, Some(1))?;
    if tags.get(258).is_some_and(|b| b.iter().any(|&x| x != bits)) {
        return Err(unsupported(F, "different bit depths per channel"));
    }
    let float = tags.one(339, Some(1))? == 3;
    let channels = match (photometric, spp) {
        (0 | 1, 1 | 2) | (2, 3 | 4) => spp as u8,
        (0 | 1 | 2, _) => return Err(unsupported(F, format!("{spp} samples per pixel"))),
        (p, _) => return Err(unsupported(F, format!("photometric interpretation {p}"))),
    };
    match (bits, float, channels) {
        (1, false, 1) | (8 | 16, false, _) | (32, true, _) => {}
        _ => {
            return Err(unsupported(
                F,
                format!(
                    "{bits}-bit {} samples",
                    if float { "float" } else { "integer" }
                ),
            ))
        }
    }
    if tags.one(284, Some(1))? != 1 {
        return Err(unsupported(F, "planar (separate) sample layout"));
    }
    let compression = tags.one(259, Some(1))?;
    if !matches!(compression, 1 | 5 | 8 | 32946 | 32773) {
        return Err(unsupported(
            F,
            format!("compression {compression} (use none, LZW, deflate or PackBits)"),
        ));
    }
    let predictor = tags.one(317, Some(1))?;
    if predictor != 1 && (predictor != 2 || float) {
        return Err(unsupported(F, format!("predictor {predictor}")));
    }
    let bytes_per_sample = (bits as u8).div_ceil(8);
    check_alloc(F, width, height, channels, bytes_per_sample, options)?;
    // Segments: tiles when TileWidth is present, else strips.
    let (seg_w, seg_h, offsets, counts) = match tags.get(322) {
        Some(_) => (
            tags.one(322, None)?,
            tags.one(323, None)?,
            tags.get(324),
            tags.get(325),
        ),
        None => (
            width,
            tags.one(278, Some(height))?.clamp(1, height),
            tags.get(273),
            tags.get(279),
        ),
    };
    let (offsets, counts) = offsets
        .zip(counts)
        .ok_or_else(|| corrupt(F, "no strip or tile offsets"))?;
    if seg_w == 0 || seg_h == 0 {
        return Err(corrupt(F, "a zero tile size"));
    }
    let across = width.div_ceil(seg_w) as usize;
    let segments = across * height.div_ceil(seg_h) as usize;
    if offsets.len() < segments || counts.len() < segments {
        return Err(corrupt(
            F,
            format!(
                "{} segments listed for {segments}",
                offsets.len().min(counts.len())
            ),
        ));
    }
    let (w, ch) = (width as usize, channels as usize);
    let row_bytes = |cols: usize| (cols * ch * bits as usize).div_ceil(8);
    let mut out = vec![0u8; row_bytes(w) * height as usize];
    for s in 0..segments {
        let (x0, y0) = ((s % across) * seg_w as usize, (s / across) * seg_h as usize);
        // Strips hold only the image's rows; tiles are always whole.
        let rows = if tags.get(322).is_some() {
            seg_h as usize
        } else {
            (seg_h as usize).min(height as usize - y0)
        };
        let seg_row = row_bytes(seg_w as usize);
        let start = offsets[s] as usize;
        let raw = start
            .checked_add(counts[s] as usize)
            .and_then(|end| bytes.get(start..end))
            .ok_or_else(|| corrupt(F, format!("segment {s} lies outside the file")))?;
        let mut data = decompress(compression, raw, seg_row * rows, s)?;
        if predictor == 2 {
            undo_predictor(&mut data, seg_row, ch, bits, file.big_endian);
        }
        // Copy the visible part of each segment row into the image.
        let visible = row_bytes((seg_w as usize).min(w.saturating_sub(x0)));
        for r in 0..rows.min((height as usize).saturating_sub(y0)) {
            let dst = (y0 + r) * row_bytes(w) + row_bytes(x0);
            out[dst..dst + visible].copy_from_slice(&data[r * seg_row..r * seg_row + visible]);
        }
    }
    let invert = photometric == 0;
    let samples = match (bits, float) {
        (1, _) => Samples::U8(
            out.chunks(row_bytes(w))
                .flat_map(|row| (0..w).map(move |x| ((row[x / 8] >> (7 - x % 8)) & 1) * 255))
                .map(|v| if invert { 255 - v } else { v })
                .collect(),
        ),
        (8, _) => Samples::U8(if invert {
            out.iter().map(|v| 255 - v).collect()
        } else {
            out
        }),
        (16, _) => Samples::U16(
            out.chunks_exact(2)
                .map(|b| {
                    if file.big_endian {
                        u16::from_be_bytes([b[0], b[1]])
                    } else {
                        u16::from_le_bytes([b[0], b[1]])
                    }
                })
                .map(|v| if invert { 65535 - v } else { v })
                .collect(),
        ),
        _ => Samples::F32(
            out.chunks_exact(4)
                .map(|b| {
                    let b = [b[0], b[1], b[2], b[3]];
                    if file.big_endian {
                        f32::from_be_bytes(b)
                    } else {
                        f32::from_le_bytes(b)
                    }
                })
                .map(|v| if invert { 1.0 - v } else { v })
                .collect(),
        ),
    };
    Ok(Raster {
        width,
        height,
        channels,
        samples,
    })
}

/// One strip or tile to exactly `expected` bytes.
fn decompress(compression: u32, raw: &[u8], expected: usize, segment: usize) -> Result<Vec<u8>> {
    let short = |got: usize| {
        corrupt(
            F,
            format!("segment {segment} holds {got} of {expected} bytes"),
        )
    };
    let mut data = match compression {
        1 => raw
            .get(..expected)
            .ok_or_else(|| short(raw.len()))?
            .to_vec(),
        5 => {
            let mut out = Vec::with_capacity(expected);
            super::lzw::decompress(raw, 8, super::lzw::Flavour::Tiff, &mut out, expected)
                .map_err(|e| corrupt(F, format!("segment {segment}: LZW: {e}")))?;
            out
        }
        8 | 32946 => match fdeflate::decompress_to_vec_bounded(raw, expected) {
            Ok(v) => v,
            Err(fdeflate::BoundedDecompressionError::OutputTooLarge { partial_output }) => {
                partial_output
            }
            Err(fdeflate::BoundedDecompressionError::DecompressionError { inner }) => {
                return Err(corrupt(F, format!("segment {segment}: deflate: {inner:?}")))
            }
        },
        _ => packbits(raw, expected),
    };
    if data.len() < expected {
        return Err(short(data.len()));
    }
    data.truncate(expected);
    Ok(data)
}

/// PackBits (Apple): a signed count n, then n + 1 literal bytes (n >= 0) or
/// one byte repeated 1 - n times (n < 0; -128 is a no-op).
fn packbits(raw: &[u8], expected: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(expected);
    let mut i = 0;
    while out.len() < expected && i < raw.len() {
        let n = raw[i] as i8;
        i += 1;
        if n >= 0 {
            let end = (i + n as usize + 1).min(raw.len());
            out.extend_from_slice(&raw[i..end]);
            i = end;
        } else if n != -128 {
            if let Some(&b) = raw.get(i) {
                out.extend(std::iter::repeat(b).take((1 - n as isize) as usize));
            }
            i += 1;
        }
    }
    out
}

/// Predictor 2: each sample is stored as the difference to the same channel
/// of the pixel on its left (8 or 16 bits; 16-bit in the file's byte order).
fn undo_predictor(data: &mut [u8], row_bytes: usize, channels: usize, bits: u32, big_endian: bool) {
    for row in data.chunks_mut(row_bytes) {
        match bits {
            8 => {
                for i in channels..row.len() {
                    row[i] = row[i].wrapping_add(row[i - channels]);
                }
            }
            16 => {
                let get = |r: &[u8], i: usize| {
                    let b = [r[2 * i], r[2 * i + 1]];
                    if big_endian {
                        u16::from_be_bytes(b)
                    } else {
                        u16::from_le_bytes(b)
                    }
                };
                for i in channels..row.len() / 2 {
                    let v = get(row, i).wrapping_add(get(row, i - channels));
                    let b = if big_endian {
                        v.to_be_bytes()
                    } else {
                        v.to_le_bytes()
                    };
                    row[2 * i..2 * i + 2].copy_from_slice(&b);
                }
            }
            _ => {}
        }
    }
}
