//! LZW decompression for GIF (codes packed least-significant bit first) and
//! TIFF (most-significant bit first, code width switched one code early):
//! variable-width codes of up to 12 bits with clear and end codes.

/// The two flavours of LZW.
#[derive(Clone, Copy, PartialEq, Debug)]
pub(super) enum Flavour {
    /// GIF: LSB-first codes, minimum code size from the file.
    Gif,
    /// TIFF (compression 5): MSB-first, 8-bit literals, early width change.
    Tiff,
}

const MAX_CODES: usize = 4096;

/// Decompress `data` into `out` (appended), stopping at the end code, at the
/// end of the data or when `out` reaches `limit` bytes. `min_size` is the
/// literal width (GIF's LZW minimum code size; 8 for TIFF).
pub(super) fn decompress(
    data: &[u8],
    min_size: u8,
    flavour: Flavour,
    out: &mut Vec<u8>,
    limit: usize,
) -> Result<(), &'static str> {
    if !(1..=11).contains(&min_size) {
        return Err("bad LZW minimum code size");
    }
    let clear = 1usize << min_size;
    let end = clear + 1;
    let early = usize::from(flavour == Flavour::Tiff);
    // Each code's string: its prefix code, last byte and length.
    let mut prefix = vec![0u16; MAX_CODES];
    let mut suffix = vec![0u8; MAX_CODES];
    let mut length = vec![0u16; MAX_CODES];
    for c in 0..clear {
        suffix[c] = c as u8;
        length[c] = 1;
    }
    let mut next = end + 1;
    let mut width = min_size as u32 + 1;
    let mut prev: Option<usize> = None;
    let (mut acc, mut bits, mut pos) = (0u32, 0u32, 0usize);
    loop {
        while bits < width {
            let Some(&b) = data.get(pos) else {
                return Ok(()); // no end code: keep what was decoded
            };
            pos += 1;
            match flavour {
                Flavour::Gif => acc |= (b as u32) << bits,
                Flavour::Tiff => acc = (acc << 8) | b as u32,
            }
            bits += 8;
        }
        let code = match flavour {
            Flavour::Gif => {
                let c = acc & ((1 << width) - 1);
                acc >>= width;
                c
            }
            Flavour::Tiff => (acc >> (bits - width)) & ((1 << width) - 1),
        } as usize;
        bits -= width;
        if flavour == Flavour::Tiff {
            acc &= (1u32 << bits).wrapping_sub(1);
        }
        if code == clear {
            next = end + 1;
            width = min_size as u32 + 1;
            prev = None;
            continue;
        }
        if code == end {
            return Ok(());
        }
        let start = out.len();
        match prev {
            None => {
                if code >= clear {
                    return Err("LZW data starts with a code that is not a literal");
                }
                out.push(code as u8);
            }
            Some(p) => {
                let (string, extra) = if code < next {
                    (code, None)
                } else if code == next && next < MAX_CODES {
                    (p, Some(()))
                } else {
                    return Err("invalid LZW code");
                };
                write_string(string, &prefix, &suffix, &length, out);
                let first = out[start];
                if extra.is_some() {
                    out.push(first);
                }
                if next < MAX_CODES {
                    prefix[next] = p as u16;
                    suffix[next] = first;
                    length[next] = length[p].saturating_add(1);
                    next += 1;
                }
            }
        }
        prev = Some(code);
        if next + early >= 1 << width && width < 12 {
            width += 1;
        }
        if out.len() >= limit {
            out.truncate(limit);
            return Ok(());
        }
    }
}

/// Append the string of `code` (written back to front along its prefixes).
fn write_string(code: usize, prefix: &[u16], suffix: &[u8], length: &[u16], out: &mut Vec<u8>) {
    let n = length[code] as usize;
    let start = out.len();
    out.resize(start + n, 0);
    let mut c = code;
    for slot in out[start..].iter_mut().rev() {
        *slot = suffix[c];
        c = prefix[c] as usize;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn sample(n: usize) -> Vec<u8> {
        // Runs and repeats (long strings, table resets) and noise.
        let mut state = 5u32;
        (0..n)
            .map(|i| {
                state = state.wrapping_mul(1103515245).wrapping_add(12345);
                if i % 1000 < 600 {
                    (i / 50 % 7) as u8
                } else {
                    (state >> 16) as u8
                }
            })
            .collect()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn reads_what_weezl_writes_in_both_flavours() {
        for n in [0, 1, 2, 100, 5000, 200_000] {
            let data = sample(n);
            let tiff = weezl::encode::Encoder::with_tiff_size_switch(weezl::BitOrder::Msb, 8)
                .encode(&data)
                .expect("encodes");
            let mut out = Vec::new();
            decompress(&tiff, 8, Flavour::Tiff, &mut out, usize::MAX).expect("decodes");
            assert_eq!(out, data, "TIFF, {n} bytes");
            for min in [2u8, 4, 8] {
                let small: Vec<u8> = data.iter().map(|&b| b & ((1 << min) - 1) as u8).collect();
                let gif = weezl::encode::Encoder::new(weezl::BitOrder::Lsb, min)
                    .encode(&small)
                    .expect("encodes");
                let mut out = Vec::new();
                decompress(&gif, min, Flavour::Gif, &mut out, usize::MAX).expect("decodes");
                assert_eq!(out, small, "GIF, {min}-bit literals, {n} bytes");
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn bad_codes_are_errors_and_limits_hold() {
        let mut out = Vec::new();
        // 9-bit codes, LSB first: 0x1FF is far beyond the table.
        assert_eq!(
            decompress(&[0xFF, 0xFF], 8, Flavour::Gif, &mut out, 100),
            Err("LZW data starts with a code that is not a literal")
        );
        assert_eq!(
            decompress(&[], 0, Flavour::Gif, &mut out, 100),
            Err("bad LZW minimum code size")
        );
        let data = sample(10_000);
        let tiff = weezl::encode::Encoder::with_tiff_size_switch(weezl::BitOrder::Msb, 8)
            .encode(&data)
            .expect("encodes");
        let mut out = Vec::new();
        decompress(&tiff, 8, Flavour::Tiff, &mut out, 1234).expect("decodes");
        assert_eq!(out, &data[..1234]);
        // Damaged streams end in an error or a shorter output, never a panic.
        for i in 0..tiff.len() {
            let mut damaged = tiff.clone();
            damaged[i] ^= 0x5A;
            let mut out = Vec::new();
            let _ = decompress(&damaged, 8, Flavour::Tiff, &mut out, 20_000);
            assert!(out.len() <= 20_000);
        }
    }
}
