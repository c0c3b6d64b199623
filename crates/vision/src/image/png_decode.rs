//! PNG reader: every colour type and bit depth of the standard, Adam7
//! interlacing, palettes and tRNS transparency, with the `png` crate's
//! EXPAND output (palettes to RGB(A), grey below 8 bits scaled to 8, tRNS to
//! an alpha channel, 16 bits kept). Chunk CRCs are checked; the zlib stream
//! is inflated by `fdeflate`.

use super::raster::{Raster, Samples};
use super::{check_alloc, check_size, corrupt, too_large, DecodeOptions, ImageFormat};

#[cfg(test)]
#[path = "png_decode_tests.rs"]
mod tests;
use crate::error::Result;

const F: ImageFormat = ImageFormat::Png;

struct Header {
    width: usize,
    height: usize,
    depth: u8,
    colour: u8,
    interlaced: bool,
}

impl Header {
    /// Samples per pixel in the file.
    fn samples(&self) -> usize {
        match self.colour {
            0 | 3 => 1,
            2 => 3,
            4 => 2,
            _ => 4,
        }
    }

    /// Bytes of one filtered row of `w` pixels (without the filter byte).
    fn row_bytes(&self, w: usize) -> usize {
        (w * self.samples() * self.depth as usize).div_ceil(8)
    }
}

/// Decode a PNG file (see the module docs).
pub(super) fn decode(bytes: &[u8], options: &DecodeOptions) -> Result<Raster> {
    if bytes.get(..8) != Some(b"\x89PNG\r\n\x1a\n") {
        return Err(corrupt(F, "no PNG signature"));
    }
    let mut pos = 8;
    let mut header: Option<Header> = None;
    let mut palette: Vec<u8> = Vec::new();
    let mut trns: Option<Vec<u8>> = None;
    let mut idat: Vec<u8> = Vec::new();
    loop {
        let len = bytes
            .get(pos..pos + 4)
            .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as usize)
            .ok_or_else(|| corrupt(F, "the file ends before the IEND chunk"))?;
        let kind = bytes
            .get(pos + 4..pos + 8)
            .ok_or_else(|| corrupt(F, "the file ends inside a chunk header"))?;
        let name = String::from_utf8_lossy(kind).into_owned();
        let data = bytes
            .get(pos + 8..pos + 8 + len)
            .ok_or_else(|| corrupt(F, format!("the file ends inside chunk {name}")))?;
        let crc = bytes
            .get(pos + 8 + len..pos + 12 + len)
            .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| corrupt(F, format!("the file ends inside chunk {name}")))?;
        let critical = kind[0].is_ascii_uppercase();
        if critical || kind == b"tRNS" {
            if super::png_encode::crc32(&[kind, data]) != crc {
                return Err(corrupt(F, format!("chunk {name} fails its CRC check")));
            }
        }
        pos += 12 + len;
        match kind {
            b"IHDR" => header = Some(read_header(data, options)?),
            b"PLTE" => palette = data.to_vec(),
            b"tRNS" => trns = Some(data.to_vec()),
            b"IDAT" => idat.extend_from_slice(data),
            b"IEND" => break,
            _ if header.is_none() => return Err(corrupt(F, format!("chunk {name} before IHDR"))),
            _ if critical => return Err(corrupt(F, format!("unknown critical chunk {name}"))),
            _ => {}
        }
    }
    let h = header.ok_or_else(|| corrupt(F, "no IHDR chunk"))?;
    if h.colour == 3 && palette.is_empty() {
        return Err(corrupt(F, "an indexed-colour image without a PLTE chunk"));
    }
    let passes = passes(&h);
    let raw_size: usize = passes
        .iter()
        .map(|p| p.rows * (1 + h.row_bytes(p.cols)))
        .sum();
    if raw_size as u64 > options.max_alloc_bytes {
        return Err(too_large(F, options));
    }
    let raw = match fdeflate::decompress_to_vec_bounded(&idat, raw_size) {
        Ok(v) => v,
        Err(fdeflate::BoundedDecompressionError::OutputTooLarge { partial_output }) => {
            partial_output
        }
        Err(fdeflate::BoundedDecompressionError::DecompressionError { inner }) => {
            return Err(corrupt(F, format!("image data: {inner:?}")))
        }
    };
    if raw.len() < raw_size {
        return Err(corrupt(F, "the image data ends early"));
    }
    expand(&h, &palette, trns.as_deref(), raw, &passes, options)
}

fn read_header(d: &[u8], options: &DecodeOptions) -> Result<Header> {
    if d.len() != 13 {
        return Err(corrupt(F, "IHDR is not 13 bytes"));
    }
    let be = |i: usize| u32::from_be_bytes([d[i], d[i + 1], d[i + 2], d[i + 3]]);
    let (width, height) = (be(0), be(4));
    let (depth, colour) = (d[8], d[9]);
    let valid = match colour {
        0 => matches!(depth, 1 | 2 | 4 | 8 | 16),
        3 => matches!(depth, 1 | 2 | 4 | 8),
        2 | 4 | 6 => matches!(depth, 8 | 16),
        _ => false,
    };
    if !valid {
        return Err(corrupt(
            F,
            format!("colour type {colour} with bit depth {depth}"),
        ));
    }
    if d[10] != 0 || d[11] != 0 || d[12] > 1 {
        return Err(corrupt(
            F,
            "unknown compression, filter or interlace method",
        ));
    }
    check_size(width, height, options)?;
    Ok(Header {
        width: width as usize,
        height: height as usize,
        depth,
        colour,
        interlaced: d[12] == 1,
    })
}

/// One Adam7 pass (or the whole image): its first pixel, steps and size.
struct Pass {
    x0: usize,
    y0: usize,
    dx: usize,
    dy: usize,
    cols: usize,
    rows: usize,
}

fn passes(h: &Header) -> Vec<Pass> {
    let layout: &[(usize, usize, usize, usize)] = if h.interlaced {
        &[
            (0, 0, 8, 8),
            (4, 0, 8, 8),
            (0, 4, 4, 8),
            (2, 0, 4, 4),
            (0, 2, 2, 4),
            (1, 0, 2, 2),
            (0, 1, 1, 2),
        ]
    } else {
        &[(0, 0, 1, 1)]
    };
    layout
        .iter()
        .map(|&(x0, y0, dx, dy)| Pass {
            x0,
            y0,
            dx,
            dy,
            cols: h.width.saturating_sub(x0).div_ceil(dx),
            rows: h.height.saturating_sub(y0).div_ceil(dy),
        })
        .filter(|p| p.cols > 0 && p.rows > 0)
        .collect()
}

/// Undo the row filters in place (`rows` of `1 + len` bytes, filter byte
/// first); `bpp` is the filter's byte distance (whole pixel, at least 1).
fn unfilter(data: &mut [u8], rows: usize, len: usize, bpp: usize) -> Result<()> {
    let stride = len + 1;
    for r in 0..rows {
        let (before, rest) = data.split_at_mut(r * stride);
        let prev: &[u8] = if r == 0 {
            &[]
        } else {
            &before[(r - 1) * stride + 1..]
        };
        let (filter, row) = rest[..stride].split_at_mut(1);
        let up = |i: usize| prev.get(i).copied().unwrap_or(0);
        match filter[0] {
            0 => {}
            1 => {
                for i in bpp..len {
                    row[i] = row[i].wrapping_add(row[i - bpp]);
                }
            }
            2 => {
                if !prev.is_empty() {
                    for (v, &u) in row.iter_mut().zip(prev) {
                        *v = v.wrapping_add(u);
                    }
                }
            }
            3 => {
                for i in 0..len {
                    let left = if i >= bpp { row[i - bpp] as u16 } else { 0 };
                    row[i] = row[i].wrapping_add(((left + up(i) as u16) / 2) as u8);
                }
            }
            4 => {
                for i in 0..len {
                    let (a, b) = (if i >= bpp { row[i - bpp] } else { 0 }, up(i));
                    let c = if i >= bpp { up(i - bpp) } else { 0 };
                    row[i] = row[i].wrapping_add(paeth(a, b, c));
                }
            }
            other => return Err(corrupt(F, format!("unknown row filter {other}"))),
        }
    }
    Ok(())
}

#[inline(always)]
fn paeth(a: u8, b: u8, c: u8) -> u8 {
    let p = a as i16 + b as i16 - c as i16;
    let (pa, pb, pc) = (
        (p - a as i16).abs(),
        (p - b as i16).abs(),
        (p - c as i16).abs(),
    );
    if pa <= pb && pa <= pc {
        a
    } else if pb <= pc {
        b
    } else {
        c
    }
}

/// Unfiltered rows to output samples with the EXPAND rules.
fn expand(
    h: &Header,
    palette: &[u8],
    trns: Option<&[u8]>,
    mut raw: Vec<u8>,
    passes: &[Pass],
    options: &DecodeOptions,
) -> Result<Raster> {
    let file_samples = h.samples();
    let sixteen = h.depth == 16;
    let bpp = (file_samples * h.depth as usize).div_ceil(8).max(1);
    let alpha_from_trns = trns.is_some() && matches!(h.colour, 0 | 2 | 3);
    let channels = match h.colour {
        0 => 1,
        2 | 3 => 3,
        4 => 2,
        _ => 4,
    } + usize::from(alpha_from_trns);
    let out_bytes = 1 + usize::from(sixteen);
    let size = check_alloc(
        F,
        h.width as u32,
        h.height as u32,
        channels as u8,
        out_bytes as u8,
        options,
    )?;
    let mut offset = 0;
    for p in passes {
        let len = h.row_bytes(p.cols);
        unfilter(
            &mut raw[offset..offset + p.rows * (len + 1)],
            p.rows,
            len,
            bpp,
        )?;
        offset += p.rows * (len + 1);
    }
    // The common case: 8-bit, not interlaced, no tRNS: the rows themselves.
    if !h.interlaced && h.depth == 8 && h.colour != 3 && !alpha_from_trns {
        let len = h.row_bytes(h.width);
        let mut out = Vec::with_capacity(size);
        for row in raw.chunks_exact(len + 1) {
            out.extend_from_slice(&row[1..]);
        }
        return Ok(Raster {
            width: h.width as u32,
            height: h.height as u32,
            channels: channels as u8,
            samples: Samples::U8(out),
        });
    }
    let max = (1u32 << h.depth) - 1;
    let key: Option<[u16; 3]> = match (trns, h.colour) {
        (Some(t), 0) if t.len() >= 2 => Some([u16::from_be_bytes([t[0], t[1]]); 3]),
        (Some(t), 2) if t.len() >= 6 => Some(std::array::from_fn(|i| {
            u16::from_be_bytes([t[2 * i], t[2 * i + 1]])
        })),
        _ => None,
    };
    let mut out = vec![0u16; h.width * h.height * channels];
    let mut offset = 0;
    let mut px = [0u16; 4];
    for p in passes {
        let len = h.row_bytes(p.cols);
        for r in 0..p.rows {
            let row = &raw[offset + 1..offset + 1 + len];
            offset += len + 1;
            let y = p.y0 + r * p.dy;
            for c in 0..p.cols {
                for (s, v) in px.iter_mut().enumerate().take(file_samples) {
                    *v = sample(row, c * file_samples + s, h.depth);
                }
                let at = (y * h.width + p.x0 + c * p.dx) * channels;
                let o = &mut out[at..at + channels];
                match h.colour {
                    3 => {
                        let i = px[0] as usize;
                        for (k, v) in o[..3].iter_mut().enumerate() {
                            *v = palette.get(3 * i + k).copied().unwrap_or(0) as u16;
                        }
                        if alpha_from_trns {
                            o[3] = trns.and_then(|t| t.get(i)).copied().unwrap_or(255) as u16;
                        }
                    }
                    0 | 2 => {
                        let n = file_samples;
                        let transparent = key.is_some_and(|k| px[..n] == k[..n]);
                        let scale = if sixteen { 1 } else { 255 / max as u16 };
                        for k in 0..n {
                            o[k] = px[k] * scale;
                        }
                        if alpha_from_trns {
                            o[n] = if transparent {
                                0
                            } else if sixteen {
                                65535
                            } else {
                                255
                            };
                        }
                    }
                    _ => o.copy_from_slice(&px[..channels]),
                }
            }
        }
    }
    let samples = if sixteen {
        Samples::U16(out)
    } else {
        Samples::U8(out.into_iter().map(|v| v as u8).collect())
    };
    Ok(Raster {
        width: h.width as u32,
        height: h.height as u32,
        channels: channels as u8,
        samples,
    })
}

/// Sample `i` of a row packed at `depth` bits (big-endian, MSB first).
#[inline(always)]
fn sample(row: &[u8], i: usize, depth: u8) -> u16 {
    match depth {
        16 => u16::from_be_bytes([row[2 * i], row[2 * i + 1]]),
        8 => row[i] as u16,
        d => {
            let bit = i * d as usize;
            let shift = 8 - d as usize - bit % 8;
            ((row[bit / 8] >> shift) & ((1u8 << d) - 1)) as u16
        }
    }
}
