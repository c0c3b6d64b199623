//! Netpbm reader: PBM (P1 ASCII, P4 binary), PGM (P2, P5), PPM (P3, P6) and
//! PAM (P7), 8 or 16 bits. Samples with a maxval other than 255 / 65535 are
//! rescaled to the full range with rounding (as the `image` crate does).

use super::raster::{Raster, Samples};
use super::{check_alloc, check_size, corrupt, unsupported, DecodeOptions, ImageFormat};
use crate::error::Result;

const F: ImageFormat = ImageFormat::Pnm;

/// A cursor over the file with the header tokenizer.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    /// Skip whitespace and `#` comments (to the end of the line).
    fn skip_space(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            if b == b'#' {
                while self.bytes.get(self.pos).is_some_and(|&c| c != b'\n') {
                    self.pos += 1;
                }
            } else if b.is_ascii_whitespace() {
                self.pos += 1;
            } else {
                break;
            }
        }
    }

    /// The next unsigned decimal number; `what` names it in the error.
    fn number(&mut self, what: &str) -> Result<u32> {
        self.skip_space();
        let start = self.pos;
        let mut value: u32 = 0;
        while let Some(&b) = self.bytes.get(self.pos).filter(|b| b.is_ascii_digit()) {
            value = value
                .checked_mul(10)
                .and_then(|v| v.checked_add((b - b'0') as u32))
                .ok_or_else(|| corrupt(F, format!("{what} is too large")))?;
            self.pos += 1;
        }
        if self.pos == start {
            return Err(match self.bytes.get(self.pos) {
                None => corrupt(F, format!("the file ends before the {what}")),
                Some(&b) => corrupt(F, format!("expected the {what}, found {:?}", b as char)),
            });
        }
        Ok(value)
    }

    /// The next whitespace-delimited word (PAM header keys).
    fn word(&mut self) -> &'a [u8] {
        self.skip_space();
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        &self.bytes[start..self.pos]
    }

    /// Binary data starts after exactly one whitespace byte.
    fn binary_data(&self) -> &'a [u8] {
        self.bytes.get(self.pos + 1..).unwrap_or(&[])
    }
}

struct Header {
    width: u32,
    height: u32,
    channels: u8,
    maxval: u32,
}

fn pam_header(r: &mut Reader) -> Result<Header> {
    let (mut width, mut height, mut depth, mut maxval) = (None, None, None, None);
    loop {
        let key = r.word();
        match key {
            b"ENDHDR" => break,
            b"WIDTH" => width = Some(r.number("width")?),
            b"HEIGHT" => height = Some(r.number("height")?),
            b"DEPTH" => depth = Some(r.number("depth")?),
            b"MAXVAL" => maxval = Some(r.number("maxval")?),
            b"TUPLTYPE" => {
                r.word();
            }
            b"" => return Err(corrupt(F, "the PAM header has no ENDHDR")),
            other => {
                let key = String::from_utf8_lossy(other);
                return Err(corrupt(F, format!("unknown PAM header line {key:?}")));
            }
        }
    }
    match (width, height, depth, maxval) {
        (Some(width), Some(height), Some(depth @ 1..=4), Some(maxval)) => Ok(Header {
            width,
            height,
            channels: depth as u8,
            maxval,
        }),
        (_, _, Some(depth), _) if depth > 4 || depth == 0 => {
            Err(unsupported(F, format!("PAM depth {depth} (use 1 to 4)")))
        }
        _ => Err(corrupt(
            F,
            "the PAM header lacks WIDTH, HEIGHT, DEPTH or MAXVAL",
        )),
    }
}

/// Decode a Netpbm file.
pub(super) fn decode(bytes: &[u8], options: &DecodeOptions) -> Result<Raster> {
    let kind = bytes.get(1).copied().unwrap_or(0);
    let mut r = Reader { bytes, pos: 2 };
    let header = match kind {
        b'7' => pam_header(&mut r)?,
        b'1' | b'4' => Header {
            width: r.number("width")?,
            height: r.number("height")?,
            channels: 1,
            maxval: 1,
        },
        b'2' | b'3' | b'5' | b'6' => Header {
            width: r.number("width")?,
            height: r.number("height")?,
            channels: if matches!(kind, b'3' | b'6') { 3 } else { 1 },
            maxval: r.number("maxval")?,
        },
        other => return Err(unsupported(F, format!("magic P{}", other as char))),
    };
    let Header {
        width,
        height,
        channels,
        maxval,
    } = header;
    check_size(width, height, options)?;
    if maxval == 0 || maxval > 65535 {
        return Err(corrupt(F, format!("maxval {maxval} (must be 1 to 65535)")));
    }
    let wide = maxval > 255;
    let size = check_alloc(F, width, height, channels, 1 + wide as u8, options)?;
    let count = size / (1 + wide as usize);
    let samples = match kind {
        b'1' => Samples::U8(ascii_bits(&mut r, count)?),
        b'4' => Samples::U8(binary_bits(r.binary_data(), width, height)?),
        b'2' | b'3' => {
            let mut values = Vec::with_capacity(count);
            for _ in 0..count {
                let v = r.number("sample")?;
                if v > maxval {
                    return Err(corrupt(F, format!("sample {v} is above maxval {maxval}")));
                }
                values.push(v as u16);
            }
            scaled(values, maxval, wide)
        }
        _ => {
            let data = r.binary_data();
            if data.len() < size {
                return Err(corrupt(
                    F,
                    format!("{} bytes of pixels for {size}", data.len()),
                ));
            }
            let values: Vec<u16> = if wide {
                data[..size]
                    .chunks_exact(2)
                    .map(|b| u16::from_be_bytes([b[0], b[1]]))
                    .collect()
            } else {
                data[..size].iter().map(|&b| b as u16).collect()
            };
            scaled(values, maxval, wide)
        }
    };
    Ok(Raster {
        width,
        height,
        channels,
        samples,
    })
}

/// Rescale samples of `0..=maxval` to 8 or 16 bits (f32 factor, rounded).
fn scaled(values: Vec<u16>, maxval: u32, wide: bool) -> Samples {
    let full = if wide { 65535.0 } else { 255.0 };
    let factor = full / maxval as f32;
    let scale = |v: u16| {
        if factor == 1.0 {
            v
        } else {
            (v as f32 * factor).round() as u16
        }
    };
    if wide {
        Samples::U16(values.into_iter().map(scale).collect())
    } else {
        Samples::U8(values.into_iter().map(|v| scale(v) as u8).collect())
    }
}

/// P1: one '0' (white) or '1' (black) per pixel, whitespace optional.
fn ascii_bits(r: &mut Reader, count: usize) -> Result<Vec<u8>> {
    let mut out = Vec::with_capacity(count);
    while out.len() < count {
        r.skip_space();
        match r.bytes.get(r.pos) {
            Some(b'0') => out.push(255),
            Some(b'1') => out.push(0),
            Some(&b) => {
                return Err(corrupt(
                    F,
                    format!("expected 0 or 1, found {:?}", b as char),
                ))
            }
            None => {
                return Err(corrupt(
                    F,
                    format!("{} of {count} pixels present", out.len()),
                ))
            }
        }
        r.pos += 1;
    }
    Ok(out)
}

/// P4: rows of bits, MSB first, each row padded to a byte; 1 is black.
fn binary_bits(data: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    let (w, h) = (width as usize, height as usize);
    let stride = w.div_ceil(8);
    if data.len() < stride * h {
        return Err(corrupt(
            F,
            format!("{} bytes of pixels for {}", data.len(), stride * h),
        ));
    }
    let mut out = Vec::with_capacity(w * h);
    for row in data.chunks_exact(stride).take(h) {
        out.extend((0..w).map(|x| {
            if (row[x / 8] >> (7 - x % 8)) & 1 == 1 {
                0
            } else {
                255
            }
        }));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::{decode as decode_any, DecodeOptions, ImageFormat};
    use wasm_bindgen_test::wasm_bindgen_test;

    fn info_and_gray(bytes: &[u8]) -> (u8, u8, Vec<u8>) {
        let d = decode_any(bytes, &DecodeOptions::default()).unwrap();
        assert_eq!(d.info.format, ImageFormat::Pnm);
        (d.info.channels, d.info.bits_per_channel, d.gray.pixels)
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn every_netpbm_kind_decodes() {
        // P2 with a comment and maxval 15: 15 -> 255, 5 -> 85.
        let p2 = b"P2\n# comment\n3 1\n15\n0 5 15\n";
        assert_eq!(info_and_gray(p2), (1, 8, vec![0, 85, 255]));
        // P5 16-bit big-endian: 0x8000 -> (32768 + 128) / 257 = 128.
        let p5 = [&b"P5 2 1 65535\n"[..], &[0x80, 0x00, 0xFF, 0xFF]].concat();
        assert_eq!(info_and_gray(&p5), (1, 16, vec![128, 255]));
        // P3 and P6: pure red -> 2126 * 255 / 10000 = 54.
        assert_eq!(info_and_gray(b"P3 1 1 255 255 0 0"), (3, 8, vec![54]));
        let p6 = [&b"P6 2 1 255\n"[..], &[255, 0, 0, 0, 255, 0]].concat();
        assert_eq!(info_and_gray(&p6), (3, 8, vec![54, 182]));
        // PBM: 1 is black.
        assert_eq!(info_and_gray(b"P1 3 1\n1 0 1"), (1, 8, vec![0, 255, 0]));
        assert_eq!(info_and_gray(b"P1 3 1\n101"), (1, 8, vec![0, 255, 0]));
        let p4 = [&b"P4 10 1\n"[..], &[0b1010_0000, 0b0100_0000]].concat();
        let (_, _, px) = info_and_gray(&p4);
        assert_eq!(px, vec![0, 255, 0, 255, 255, 255, 255, 255, 255, 0]);
        // PAM grey+alpha.
        let p7 = [
            &b"P7\nWIDTH 2\nHEIGHT 1\nDEPTH 2\nMAXVAL 255\nTUPLTYPE GRAYSCALE_ALPHA\nENDHDR\n"[..],
            &[10, 255, 20, 0],
        ]
        .concat();
        assert_eq!(info_and_gray(&p7), (2, 8, vec![10, 20]));
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn bad_netpbm_files_say_what_is_wrong() {
        let err = |b: &[u8]| {
            decode_any(b, &DecodeOptions::default())
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            err(b"P5 4 4 255\n\x01\x02"),
            "corrupt or truncated PNM file: 2 bytes of pixels for 16"
        );
        assert_eq!(
            err(b"P2 2 1 255 7"),
            "corrupt or truncated PNM file: the file ends before the sample"
        );
        assert_eq!(
            err(b"P2 2 1 10 7 11"),
            "corrupt or truncated PNM file: sample 11 is above maxval 10"
        );
        assert_eq!(
            err(b"P5 2 x"),
            "corrupt or truncated PNM file: expected the height, found 'x'"
        );
        assert_eq!(
            err(b"P6 1 1 70000\n"),
            "corrupt or truncated PNM file: maxval 70000 (must be 1 to 65535)"
        );
        assert_eq!(
            err(b"P5 0 3 255\n"),
            "image is 0x3 pixels: it has no pixels"
        );
        assert_eq!(
            err(b"P7\nWIDTH 1\nHEIGHT 1\nDEPTH 5\nMAXVAL 255\nENDHDR\n"),
            "PNM variant not supported: PAM depth 5 (use 1 to 4)"
        );
        assert_eq!(
            err(b"P1 2 2 1 0 x"),
            "corrupt or truncated PNM file: expected 0 or 1, found 'x'"
        );
    }
}
