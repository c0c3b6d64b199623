//! Golden TIFF files built in the test: byte orders, strips and tiles, every
//! compression and depth the reader claims, and broken files.

use super::{decode, DecodeOptions, ImageFormat};
use wasm_bindgen_test::wasm_bindgen_test;

/// A one-IFD TIFF: `tags` are (tag, type 3 SHORT or 4 LONG, values); strip
/// (or tile) offsets and byte counts are added for `segments`.
fn tiff(
    big_endian: bool,
    tags: &[(u16, u16, Vec<u32>)],
    segments: &[Vec<u8>],
    tiled: bool,
) -> Vec<u8> {
    let mut tags = tags.to_vec();
    let (offsets_tag, counts_tag) = if tiled { (324, 325) } else { (273, 279) };
    tags.push((offsets_tag, 4, vec![0; segments.len()]));
    tags.push((
        counts_tag,
        4,
        segments.iter().map(|s| s.len() as u32).collect(),
    ));
    tags.sort_by_key(|t| t.0);
    let size = |kind: u16| if kind == 3 { 2 } else { 4 };
    let ifd_len = 2 + 12 * tags.len() + 4;
    let spill: usize = tags
        .iter()
        .map(|(_, k, v)| v.len() * size(*k))
        .filter(|&l| l > 4)
        .sum();
    let mut at = 8 + ifd_len + spill;
    for (tag, _, values) in tags.iter_mut() {
        if *tag == offsets_tag {
            for (v, s) in values.iter_mut().zip(segments) {
                *v = at as u32;
                at += s.len();
            }
        }
    }
    let u16b = |v: u16| {
        if big_endian {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let u32b = |v: u32| {
        if big_endian {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let mut out = if big_endian {
        b"MM\x00\x2a".to_vec()
    } else {
        b"II\x2a\x00".to_vec()
    };
    out.extend(u32b(8));
    out.extend(u16b(tags.len() as u16));
    let mut spill_at = 8 + ifd_len;
    let mut spilled = Vec::new();
    for (tag, kind, values) in &tags {
        out.extend(u16b(*tag));
        out.extend(u16b(*kind));
        out.extend(u32b(values.len() as u32));
        let mut bytes = Vec::new();
        for &v in values {
            if *kind == 3 {
                bytes.extend(u16b(v as u16));
            } else {
                bytes.extend(u32b(v));
            }
        }
        if bytes.len() <= 4 {
            bytes.resize(4, 0);
            out.extend(bytes);
        } else {
            out.extend(u32b(spill_at as u32));
            spill_at += bytes.len();
            spilled.extend(bytes);
        }
    }
    out.extend(u32b(0));
    out.extend(spilled);
    for s in segments {
        out.extend(s);
    }
    out
}

/// Width, height, bits per sample (one per channel), photometric, extra tags.
fn basic(
    w: u32,
    h: u32,
    bits: &[u32],
    photometric: u32,
    compression: u32,
) -> Vec<(u16, u16, Vec<u32>)> {
    vec![
        (256, 4, vec![w]),
        (257, 4, vec![h]),
        (258, 3, bits.to_vec()),
        (259, 3, vec![compression]),
        (262, 3, vec![photometric]),
        (277, 3, vec![bits.len() as u32]),
    ]
}

fn gray(bytes: &[u8]) -> (u8, u8, Vec<u8>) {
    let d = decode(bytes, &DecodeOptions::default()).unwrap();
    assert_eq!(d.info.format, ImageFormat::Tiff);
    (d.info.channels, d.info.bits_per_channel, d.gray.pixels)
}

fn error(bytes: &[u8]) -> String {
    decode(bytes, &DecodeOptions::default())
        .unwrap_err()
        .to_string()
}

fn lzw(data: &[u8]) -> Vec<u8> {
    weezl::encode::Encoder::with_tiff_size_switch(weezl::BitOrder::Msb, 8)
        .encode(data)
        .unwrap()
}

#[wasm_bindgen_test(unsupported = test)]
fn grey_strips_in_both_byte_orders_and_compressions() {
    let rows = [vec![0u8, 100, 200], vec![50, 150, 250]];
    let pixels = vec![0, 100, 200, 50, 150, 250];
    let mut tags = basic(3, 2, &[8], 1, 1);
    tags.push((278, 3, vec![1]));
    assert_eq!(
        gray(&tiff(false, &tags, &rows, false)),
        (1, 8, pixels.clone())
    );
    // PackBits: a literal run of 3, then a repeat; big-endian file.
    let mut tags = basic(3, 2, &[8], 1, 32773);
    tags.push((278, 3, vec![2]));
    let packed = vec![vec![2, 0, 100, 200, 0xFE, 7]];
    assert_eq!(
        gray(&tiff(true, &tags, &packed, false)).2,
        vec![0, 100, 200, 7, 7, 7]
    );
    // LZW with the horizontal predictor: 0, +100, +100 per row.
    let mut tags = basic(3, 2, &[8], 1, 5);
    tags.push((317, 3, vec![2]));
    let diffs = lzw(&[0, 100, 100, 50, 100, 100]);
    assert_eq!(gray(&tiff(false, &tags, &[diffs], false)).2, pixels);
    // WhiteIsZero, deflate.
    let tags = basic(3, 2, &[8], 0, 8);
    let z = fdeflate::compress_to_vec(&[255, 155, 55, 205, 105, 5]);
    assert_eq!(gray(&tiff(true, &tags, &[z], false)).2, pixels);
}

#[wasm_bindgen_test(unsupported = test)]
fn rgb16_lzw_predictor_big_endian() {
    // Pixels: red, green (16-bit), stored as differences to the left pixel.
    let be = |v: &[u16]| v.iter().flat_map(|x| x.to_be_bytes()).collect::<Vec<u8>>();
    let diffs = be(&[65535, 0, 0, 1, 65535, 0]); // green = red + (1, 65535, 0) mod 2^16
    let mut tags = basic(2, 1, &[16, 16, 16], 2, 5);
    tags.push((317, 3, vec![2]));
    // red: 0.21265 * 255 = 54.2; (1/65535) * 0.21265 + 0.71518 -> 182.4.
    assert_eq!(
        gray(&tiff(true, &tags, &[lzw(&diffs)], false)),
        (3, 16, vec![54, 182])
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn tiles_one_bit_and_float() {
    // 20x3 grey+alpha in 16x16 tiles (two across); tile pixel value = x.
    let tile = |x0: u8| -> Vec<u8> {
        (0..16 * 16)
            .flat_map(|i| [x0 + (i % 16) as u8, 255])
            .collect()
    };
    let mut tags = basic(20, 3, &[8, 8], 1, 8);
    tags.push((322, 3, vec![16]));
    tags.push((323, 3, vec![16]));
    let tiles = [
        fdeflate::compress_to_vec(&tile(0)),
        fdeflate::compress_to_vec(&tile(16)),
    ];
    let row: Vec<u8> = (0..20).collect();
    assert_eq!(
        gray(&tiff(false, &tags, &tiles, true)),
        (2, 8, [row.clone(), row.clone(), row].concat())
    );
    // 1-bit BlackIsZero: 10 pixels in 2 bytes.
    let tags = basic(10, 1, &[1], 1, 1);
    let px = gray(&tiff(
        false,
        &tags,
        &[vec![0b1010_0000, 0b0100_0000]],
        false,
    ))
    .2;
    assert_eq!(px, vec![255, 0, 255, 0, 0, 0, 0, 0, 0, 255]);
    // 32-bit float RGB (SampleFormat 3): white and a half grey, clamped.
    let mut tags = basic(2, 1, &[32, 32, 32], 2, 1);
    tags.push((339, 3, vec![3, 3, 3]));
    let f: Vec<u8> = [2.0f32, 1.0, 1.0, 0.5, 0.5, 0.5]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    assert_eq!(
        gray(&tiff(false, &tags, &[f], false)),
        (3, 32, vec![255, 128])
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn broken_and_unsupported_tiffs_say_why() {
    let strip = vec![vec![0u8; 6]];
    assert_eq!(
        error(&tiff(false, &basic(3, 2, &[8], 1, 7), &strip, false)),
        "TIFF variant not supported: compression 7 (use none, LZW, deflate or PackBits)"
    );
    assert_eq!(
        error(&tiff(false, &basic(3, 2, &[8], 3, 1), &strip, false)),
        "TIFF variant not supported: photometric interpretation 3"
    );
    let mut planar = basic(3, 2, &[8, 8, 8], 2, 1);
    planar.push((284, 3, vec![2]));
    assert_eq!(
        error(&tiff(false, &planar, &strip, false)),
        "TIFF variant not supported: planar (separate) sample layout"
    );
    assert_eq!(
        error(&tiff(
            false,
            &basic(3, 2, &[8], 1, 1),
            &[vec![0u8; 4]],
            false
        )),
        "corrupt or truncated TIFF file: segment 0 holds 4 of 6 bytes"
    );
    let mut no_width = basic(3, 2, &[8], 1, 1);
    no_width.remove(0);
    assert_eq!(
        error(&tiff(false, &no_width, &strip, false)),
        "corrupt or truncated TIFF file: required tag 256 is missing"
    );
    let mut bytes = tiff(false, &basic(3, 2, &[8], 1, 1), &strip, false);
    bytes.truncate(bytes.len() - 7);
    assert_eq!(
        error(&bytes),
        "corrupt or truncated TIFF file: segment 0 lies outside the file"
    );
    assert_eq!(
        error(b"II*\x00\xff\x00\x00\x00"),
        "corrupt or truncated TIFF file: an IFD runs past the end"
    );
}
