//! Golden BMP files built byte by byte: every layout the reader claims.

use super::{decode, DecodeOptions, ImageFormat};
use wasm_bindgen_test::wasm_bindgen_test;

/// A BMP with a 40-byte INFO header (or 12-byte core header when `dib` is
/// 12); `extra` (masks, palette) sits between header and pixels.
fn bmp(
    dib: u32,
    w: i32,
    h: i32,
    bpp: u16,
    compression: u32,
    extra: &[u8],
    pixels: &[u8],
) -> Vec<u8> {
    let offset = 14 + dib + extra.len() as u32;
    let mut b = b"BM".to_vec();
    b.extend((offset + pixels.len() as u32).to_le_bytes());
    b.extend([0; 4]);
    b.extend(offset.to_le_bytes());
    b.extend(dib.to_le_bytes());
    if dib == 12 {
        for v in [w as u16, h as u16, 1, bpp] {
            b.extend(v.to_le_bytes());
        }
    } else {
        b.extend(w.to_le_bytes());
        b.extend(h.to_le_bytes());
        b.extend(1u16.to_le_bytes());
        b.extend(bpp.to_le_bytes());
        b.extend(compression.to_le_bytes());
        // image size, x/y resolution, colours used (0: 2^bpp), important.
        b.extend([0; 20]);
    }
    b.extend(extra);
    b.extend(pixels);
    b
}

fn gray(bytes: &[u8]) -> (u8, Vec<u8>) {
    let d = decode(bytes, &DecodeOptions::default()).unwrap();
    assert_eq!(d.info.format, ImageFormat::Bmp);
    (d.info.channels, d.gray.pixels)
}

fn error(bytes: &[u8]) -> String {
    decode(bytes, &DecodeOptions::default())
        .unwrap_err()
        .to_string()
}

/// Palette entries B G R 0 for grey levels.
fn grey_palette(levels: &[u8]) -> Vec<u8> {
    levels.iter().flat_map(|&v| [v, v, v, 0]).collect()
}

/// A 4x2 8-bit palette bitmap (for the random-bytes test).
pub(super) fn palette_bmp() -> Vec<u8> {
    bmp(
        40,
        4,
        2,
        8,
        0,
        &grey_palette(&[0, 90, 180, 255]),
        &[0, 1, 2, 3, 3, 2, 1, 0],
    )
}

// Luma of pure red, green, blue and white (see raster.rs).
const RED: u8 = 54;
const GREEN: u8 = 182;
const BLUE: u8 = 18;

#[wasm_bindgen_test(unsupported = test)]
fn rgb24_bottom_up_and_top_down_give_the_same_image() {
    // Top row: red, green; bottom row: blue, white. Rows padded to 8 bytes.
    let top = [0, 0, 255, 0, 255, 0, 0, 0];
    let bottom = [255, 0, 0, 255, 255, 255, 0, 0];
    let up = bmp(40, 2, 2, 24, 0, &[], &[bottom, top].concat());
    let down = bmp(40, 2, -2, 24, 0, &[], &[top, bottom].concat());
    let expected = (3, vec![RED, GREEN, BLUE, 255]);
    assert_eq!(gray(&up), expected);
    assert_eq!(gray(&down), expected);
    // OS/2 core header, one blue pixel.
    assert_eq!(
        gray(&bmp(12, 1, 1, 24, 0, &[], &[255, 0, 0, 0])),
        (3, vec![BLUE])
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn palette_depths_1_4_8() {
    let bw = grey_palette(&[0, 255]);
    let one = bmp(40, 10, 1, 1, 0, &bw, &[0b1010_0000, 0b0100_0000, 0, 0]);
    assert_eq!(gray(&one), (3, vec![255, 0, 255, 0, 0, 0, 0, 0, 0, 255]));
    let four = bmp(
        40,
        3,
        1,
        4,
        0,
        &grey_palette(&[0, 10, 20, 30]),
        &[0x12, 0x30, 0, 0],
    );
    assert_eq!(gray(&four).1, vec![10, 20, 30]);
    let eight = bmp(
        40,
        3,
        1,
        8,
        0,
        &grey_palette(&[0, 10, 20, 30]),
        &[3, 0, 2, 0],
    );
    assert_eq!(gray(&eight).1, vec![30, 0, 20]);
}

#[wasm_bindgen_test(unsupported = test)]
fn direct_colour_16_and_32_bits_with_masks() {
    // 16-bit default 5-5-5: red, then 5-6-5 bitfields: green.
    let rgb555 = bmp(40, 1, 1, 16, 0, &[], &[0x00, 0x7C, 0, 0]);
    assert_eq!(gray(&rgb555), (3, vec![RED]));
    let masks565: Vec<u8> = [0xF800u32, 0x07E0, 0x001F]
        .iter()
        .flat_map(|m| m.to_le_bytes())
        .collect();
    let rgb565 = bmp(40, 1, 1, 16, 3, &masks565, &[0xE0, 0x07, 0, 0]);
    assert_eq!(gray(&rgb565), (3, vec![GREEN]));
    // 32-bit BI_ALPHABITFIELDS: alpha makes it RGBA; the pixel is blue.
    let masks: Vec<u8> = [0xFF_0000u32, 0xFF00, 0xFF, 0xFF00_0000]
        .iter()
        .flat_map(|m| m.to_le_bytes())
        .collect();
    let rgba = bmp(40, 1, 1, 32, 6, &masks, &[255, 0, 0, 128]);
    assert_eq!(gray(&rgba), (4, vec![BLUE]));
    // 32-bit BI_RGB: the fourth byte is ignored.
    assert_eq!(
        gray(&bmp(40, 1, 1, 32, 0, &[], &[0, 255, 0, 7])),
        (3, vec![GREEN])
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn rle8_and_rle4_streams() {
    // 4x2, bottom row first: run of three 1s, end of line; top row: absolute
    // run 2 1 2 (padded), end of bitmap. Index 3 is never written: stays 0.
    let palette = grey_palette(&[0, 255, 128]);
    let stream = [3, 1, 0, 0, 0, 3, 2, 1, 2, 0, 0, 1];
    let rle8 = bmp(40, 4, 2, 8, 1, &palette, &stream);
    assert_eq!(gray(&rle8).1, vec![128, 255, 128, 0, 255, 255, 255, 0]);
    // A delta (right 2) then one pixel.
    let delta = bmp(40, 4, 1, 8, 1, &palette, &[0, 2, 2, 0, 1, 2, 0, 1]);
    assert_eq!(gray(&delta).1, vec![0, 0, 128, 0]);
    let rle4 = bmp(40, 4, 1, 4, 2, &palette, &[4, 0x12, 0, 1]);
    assert_eq!(gray(&rle4).1, vec![255, 128, 255, 128]);
}

#[wasm_bindgen_test(unsupported = test)]
fn broken_bitmaps_say_what_is_wrong() {
    assert_eq!(
        error(b"BM\0\0"),
        "corrupt or truncated BMP file: the header is truncated"
    );
    assert_eq!(
        error(&bmp(40, 2, 2, 24, 0, &[], &[0; 12])),
        "corrupt or truncated BMP file: 12 bytes of pixels for 16"
    );
    let palette = grey_palette(&[0, 255]);
    assert_eq!(
        error(&bmp(40, 2, 2, 8, 1, &palette, &[2, 1, 0, 0])),
        "corrupt or truncated BMP file: the RLE stream ends without an end-of-bitmap code"
    );
    assert_eq!(
        error(&bmp(40, 2, -2, 8, 1, &palette, &[0, 1])),
        "corrupt or truncated BMP file: a top-down bitmap cannot be RLE-compressed"
    );
    assert_eq!(
        error(&bmp(40, 1, 1, 24, 4, &[], &[0; 4])),
        "BMP variant not supported: 24 bits per pixel with compression 4"
    );
    assert_eq!(
        error(&bmp(20, 1, 1, 24, 0, &[], &[0; 4])),
        "BMP variant not supported: a 20-byte info header"
    );
    assert_eq!(
        error(&bmp(40, 0, 1, 24, 0, &[], &[])),
        "image is 0x1 pixels: it has no pixels"
    );
}
