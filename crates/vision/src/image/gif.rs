//! GIF (87a and 89a): the first image of the file, RGBA, placed on the
//! logical screen at its offset (outside it: transparent black, as the
//! `image` crate does); local or global palette, interlacing, the graphic
//! control extension's transparent colour (alpha 0, colour kept).

use super::lzw::{self, Flavour};
use super::raster::{Raster, Samples};
use super::{check_alloc, check_size, corrupt, DecodeOptions, ImageFormat};
use crate::error::Result;

const F: ImageFormat = ImageFormat::Gif;

struct Cursor<'a> {
    b: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let s = self
            .b
            .get(self.pos..self.pos + n)
            .ok_or_else(|| corrupt(F, "the file ends early"))?;
        self.pos += n;
        Ok(s)
    }

    fn byte(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    fn u16(&mut self) -> Result<usize> {
        let s = self.take(2)?;
        Ok(u16::from_le_bytes([s[0], s[1]]) as usize)
    }

    /// Data sub-blocks up to the terminator, concatenated (or only skipped).
    fn sub_blocks(&mut self, mut into: Option<&mut Vec<u8>>) -> Result<()> {
        loop {
            let n = self.byte()? as usize;
            if n == 0 {
                return Ok(());
            }
            let block = self.take(n)?;
            if let Some(v) = into.as_deref_mut() {
                v.extend_from_slice(block);
            }
        }
    }
}

fn palette(c: &mut Cursor, flags: u8) -> Result<Option<Vec<u8>>> {
    if flags & 0x80 == 0 {
        return Ok(None);
    }
    let entries = 2usize << (flags & 7);
    Ok(Some(c.take(3 * entries)?.to_vec()))
}

/// Decode the first image of a GIF file.
pub(super) fn decode(bytes: &[u8], options: &DecodeOptions) -> Result<Raster> {
    let mut c = Cursor { b: bytes, pos: 0 };
    let magic = c.take(6)?;
    if magic != b"GIF87a" && magic != b"GIF89a" {
        return Err(corrupt(F, "not a GIF header"));
    }
    let (width, height) = (c.u16()?, c.u16()?);
    let flags = c.byte()?;
    c.take(2)?; // background colour, aspect ratio
    let global = palette(&mut c, flags)?;
    check_size(width as u32, height as u32, options)?;
    let size = check_alloc(F, width as u32, height as u32, 4, 1, options)?;
    let mut transparent: Option<u8> = None;
    loop {
        match c.byte()? {
            0x21 => {
                let label = c.byte()?;
                if label == 0xF9 {
                    let n = c.byte()? as usize;
                    let block = c.take(n)?;
                    if n >= 4 && block[0] & 1 == 1 {
                        transparent = Some(block[3]);
                    }
                }
                c.sub_blocks(None)?;
            }
            0x2C => break,
            0x3B => return Err(corrupt(F, "no image frame")),
            other => return Err(corrupt(F, format!("unknown block type 0x{other:02X}"))),
        }
    }
    let (left, top) = (c.u16()?, c.u16()?);
    let (fw, fh) = (c.u16()?, c.u16()?);
    let frame_flags = c.byte()?;
    let local = palette(&mut c, frame_flags)?;
    let colours = local
        .or(global)
        .ok_or_else(|| corrupt(F, "no colour table for the image"))?;
    let min_size = c.byte()?;
    let mut data = Vec::new();
    c.sub_blocks(Some(&mut data))?;
    let frame_pixels = fw * fh;
    check_alloc(F, fw as u32, fh as u32, 5, 1, options)?;
    let mut indices = Vec::with_capacity(frame_pixels);
    lzw::decompress(&data, min_size, Flavour::Gif, &mut indices, frame_pixels)
        .map_err(|e| corrupt(F, e))?;
    // A short stream leaves the rest of the frame at index 0, like gif does.
    indices.resize(frame_pixels, 0);
    let rows = frame_rows(fh, frame_flags & 0x40 != 0);
    let mut canvas = vec![0u8; size];
    for (i, &row) in rows.iter().enumerate() {
        let y = top + row;
        if y >= height || left >= width {
            continue;
        }
        let src = &indices[i * fw..(i + 1) * fw];
        let dst = &mut canvas[(y * width + left) * 4..(y * width + width) * 4];
        for (px, &index) in dst.chunks_exact_mut(4).zip(src) {
            let at = 3 * index as usize;
            if let Some(rgb) = colours.get(at..at + 3) {
                px[..3].copy_from_slice(rgb);
                px[3] = if transparent == Some(index) { 0 } else { 255 };
            }
        }
    }
    Ok(Raster {
        width: width as u32,
        height: height as u32,
        channels: 4,
        samples: Samples::U8(canvas),
    })
}

/// The frame row each stored row of indices belongs to (interlaced GIFs
/// store rows 0, 8, 16, .., then 4, 12, .., then 2, 6, .., then 1, 3, ..).
fn frame_rows(h: usize, interlaced: bool) -> Vec<usize> {
    if !interlaced {
        return (0..h).collect();
    }
    [(0, 8), (4, 8), (2, 4), (1, 2)]
        .iter()
        .flat_map(|&(start, step)| (start..h).step_by(step))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// A GIF written by hand: `w`x`h` frame at (`left`, `top`) on a
    /// `sw`x`sh` screen, 4-colour palette, LZW from weezl.
    fn gif(
        sw: u16,
        sh: u16,
        frame: (u16, u16, u16, u16),
        indices: &[u8],
        interlaced: bool,
        transparent: Option<u8>,
    ) -> Vec<u8> {
        let mut b = b"GIF89a".to_vec();
        b.extend_from_slice(&sw.to_le_bytes());
        b.extend_from_slice(&sh.to_le_bytes());
        b.extend_from_slice(&[0x81, 0, 0]); // global table of 4 colours
        b.extend_from_slice(&[0, 0, 0, 255, 0, 0, 0, 255, 0, 10, 20, 30]);
        if let Some(t) = transparent {
            b.extend_from_slice(&[0x21, 0xF9, 4, 1, 0, 0, t, 0]);
        }
        b.extend_from_slice(&[0x21, 0xFE, 3, b'h', b'i', b'!', 0]); // a comment
        b.push(0x2C);
        for v in [frame.0, frame.1, frame.2, frame.3] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.push(if interlaced { 0x40 } else { 0 });
        b.push(2);
        let data = weezl::encode::Encoder::new(weezl::BitOrder::Lsb, 2)
            .encode(indices)
            .expect("encodes");
        for chunk in data.chunks(255) {
            b.push(chunk.len() as u8);
            b.extend_from_slice(chunk);
        }
        b.extend_from_slice(&[0, 0x3B]);
        b
    }

    fn rgba(bytes: &[u8]) -> Vec<u8> {
        match decode(bytes, &DecodeOptions::default())
            .expect("decodes")
            .samples
        {
            Samples::U8(v) => v,
            _ => panic!("8-bit samples"),
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn frames_land_on_the_screen_with_their_palette() {
        let indices: Vec<u8> = (0..12).map(|i| (i % 4) as u8).collect();
        let out = rgba(&gif(5, 4, (1, 1, 4, 3), &indices, false, Some(3)));
        assert_eq!(out.len(), 5 * 4 * 4);
        assert_eq!(&out[..20], &[0; 20], "row 0 is outside the frame");
        assert_eq!(&out[20..24], &[0; 4], "column 0 too");
        assert_eq!(
            &out[24..40],
            &[0, 0, 0, 255, 255, 0, 0, 255, 0, 255, 0, 255, 10, 20, 30, 0]
        );
        // Plain GIFs decode like the gif crate decodes them.
        let bytes = gif(5, 4, (1, 1, 4, 3), &indices, false, Some(3));
        let mut reference = gif_crate(&bytes);
        reference.truncate(out.len());
        assert_eq!(out, reference);
    }

    fn gif_crate(bytes: &[u8]) -> Vec<u8> {
        let mut o = ::gif::DecodeOptions::new();
        o.set_color_output(::gif::ColorOutput::RGBA);
        let mut d = o.read_info(std::io::Cursor::new(bytes)).expect("gif reads");
        let (w, h) = (d.width() as usize, d.height() as usize);
        let f = d
            .read_next_frame()
            .expect("frame")
            .expect("a frame")
            .clone();
        let mut canvas = vec![0u8; w * h * 4];
        for fy in 0..f.height as usize {
            for fx in 0..f.width as usize {
                let (x, y) = (f.left as usize + fx, f.top as usize + fy);
                if x < w && y < h {
                    let s = (fy * f.width as usize + fx) * 4;
                    canvas[(y * w + x) * 4..(y * w + x) * 4 + 4]
                        .copy_from_slice(&f.buffer[s..s + 4]);
                }
            }
        }
        canvas
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn interlaced_rows_are_put_back_in_order() {
        let (w, h) = (3usize, 11usize);
        // Stored in interlace order: row r's pixels all carry r % 3.
        let order = frame_rows(h, true);
        let stored: Vec<u8> = order.iter().flat_map(|&r| vec![(r % 3) as u8; w]).collect();
        let out = rgba(&gif(
            w as u16,
            h as u16,
            (0, 0, w as u16, h as u16),
            &stored,
            true,
            None,
        ));
        let palette = [[0u8, 0, 0], [255, 0, 0], [0, 255, 0]];
        for y in 0..h {
            assert_eq!(&out[y * w * 4..y * w * 4 + 3], &palette[y % 3], "row {y}");
        }
        assert_eq!(order, vec![0, 8, 4, 2, 6, 10, 1, 3, 5, 7, 9]);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn bad_files_say_what_is_wrong() {
        let err = |b: &[u8]| {
            decode(b, &DecodeOptions::default())
                .expect_err("an error")
                .to_string()
        };
        let good = gif(4, 4, (0, 0, 4, 4), &[1; 16], false, None);
        assert_eq!(
            err(&good[..30]),
            "corrupt or truncated GIF file: the file ends early"
        );
        assert_eq!(
            err(b"GIF89a\x04\x00\x04\x00\x00\x00\x00\x3B"),
            "corrupt or truncated GIF file: no image frame"
        );
        assert_eq!(
            err(b"GIF89a\x04\x00\x04\x00\x00\x00\x00\x2C\0\0\0\0\x04\0\x04\0\0\x02\x00"),
            "corrupt or truncated GIF file: no colour table for the image"
        );
        for i in 0..good.len() {
            let mut damaged = good.clone();
            damaged[i] ^= 0xA5;
            let _ = decode(&damaged, &DecodeOptions::default());
        }
    }
}
