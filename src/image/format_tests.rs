//! Every format variant the module docs promise, written by an independent
//! encoder (or by hand where no encoder writes it: interlaced PNG, tiled
//! TIFF) and read back through [`decode`]. Lossless formats must return
//! every grey level exactly; JPEG within a mean of 2 grey levels (its
//! quantisation at quality 95).

use super::*;
use wasm_bindgen_test::wasm_bindgen_test;

const W: u32 = 67;
const H: u32 = 45;

/// A test card: a diagonal ramp with a checker on top, RGB.
fn card_rgb() -> Vec<u8> {
    let mut rgb = Vec::with_capacity((W * H * 3) as usize);
    for y in 0..H {
        for x in 0..W {
            let ramp = ((x + y) * 255 / (W + H)) as u8;
            let check = ((x / 5) + (y / 5)) % 2 == 0;
            if check {
                rgb.extend_from_slice(&[ramp, 255 - ramp, 40]);
            } else {
                rgb.extend_from_slice(&[20, ramp, 200]);
            }
        }
    }
    rgb
}

/// The grey of the card as `image` computes it (the reference the decoded
/// grey is compared with).
fn card_gray() -> Vec<u8> {
    let rgb = ::image::RgbImage::from_raw(W, H, card_rgb()).expect("card size");
    DynamicImage::ImageRgb8(rgb).into_luma8().into_raw()
}

fn decoded(bytes: &[u8]) -> Decoded {
    match decode(bytes, &DecodeOptions::default()) {
        Ok(d) => d,
        Err(e) => panic!("decode failed: {e}"),
    }
}

fn mean_abs_diff(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len(), "pixel counts");
    a.iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y as f64).abs())
        .sum::<f64>()
        / a.len() as f64
}

fn encode_with_image(format: ::image::ImageFormat, img: DynamicImage) -> Vec<u8> {
    let mut out = Cursor::new(Vec::new());
    img.write_to(&mut out, format).expect("encode");
    out.into_inner()
}

fn png_with(
    color: png::ColorType,
    depth: png::BitDepth,
    palette: Option<Vec<u8>>,
    data: &[u8],
) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, W, H);
        enc.set_color(color);
        enc.set_depth(depth);
        if let Some(p) = palette {
            enc.set_palette(p);
        }
        let mut writer = enc.write_header().expect("png header");
        writer.write_image_data(data).expect("png data");
    }
    out
}

#[wasm_bindgen_test(unsupported = test)]
fn png_grey_rgb_16bit_and_palette_are_exact() {
    let gray = card_gray();
    let d = decoded(&encode_png(&GrayImage::new(W, H, gray.clone()).expect("size")).expect("png"));
    assert_eq!(
        (d.info.format, d.info.channels, d.info.bits_per_channel),
        (ImageFormat::Png, 1, 8)
    );
    assert_eq!(d.gray.pixels, gray);

    let rgb = png_with(png::ColorType::Rgb, png::BitDepth::Eight, None, &card_rgb());
    let d = decoded(&rgb);
    assert_eq!((d.info.channels, d.info.bits_per_channel), (3, 8));
    assert_eq!(d.gray.pixels, gray);

    // 16-bit grey: v * 257 scales back to exactly v.
    let be16: Vec<u8> = gray
        .iter()
        .flat_map(|&v| (v as u16 * 257).to_be_bytes())
        .collect();
    let d = decoded(&png_with(
        png::ColorType::Grayscale,
        png::BitDepth::Sixteen,
        None,
        &be16,
    ));
    assert_eq!((d.info.channels, d.info.bits_per_channel), (1, 16));
    assert_eq!(d.gray.pixels, gray);

    // Palette of the 256 grey levels: indices are the levels.
    let palette: Vec<u8> = (0..=255u8).flat_map(|v| [v, v, v]).collect();
    let d = decoded(&png_with(
        png::ColorType::Indexed,
        png::BitDepth::Eight,
        Some(palette),
        &gray,
    ));
    assert_eq!(d.gray.pixels, gray);
}

/// An Adam7-interlaced 8-bit grey PNG, written by hand: no encoder on the
/// registries writes interlacing. Deflate as stored blocks.
fn interlaced_png(gray: &[u8]) -> Vec<u8> {
    const PASSES: [(u32, u32, u32, u32); 7] = [
        (0, 0, 8, 8),
        (4, 0, 8, 8),
        (0, 4, 4, 8),
        (2, 0, 4, 4),
        (0, 2, 2, 4),
        (1, 0, 2, 2),
        (0, 1, 1, 2),
    ];
    let mut raw = Vec::new();
    for (x0, y0, dx, dy) in PASSES {
        let cols = (x0..W).step_by(dx as usize).count();
        if cols == 0 {
            continue;
        }
        for y in (y0..H).step_by(dy as usize) {
            raw.push(0); // filter: none
            for x in (x0..W).step_by(dx as usize) {
                raw.push(gray[(y * W + x) as usize]);
            }
        }
    }
    let mut z = vec![0x78, 0x01];
    let blocks: Vec<&[u8]> = raw.chunks(65_535).collect();
    for (i, block) in blocks.iter().enumerate() {
        z.push(u8::from(i + 1 == blocks.len()));
        let n = block.len() as u16;
        z.extend_from_slice(&n.to_le_bytes());
        z.extend_from_slice(&(!n).to_le_bytes());
        z.extend_from_slice(block);
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &v in &raw {
        a = (a + v as u32) % 65_521;
        b = (b + a) % 65_521;
    }
    z.extend_from_slice(&((b << 16) | a).to_be_bytes());
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&W.to_be_bytes());
    ihdr.extend_from_slice(&H.to_be_bytes());
    ihdr.extend_from_slice(&[8, 0, 0, 0, 1]); // 8-bit grey, interlace 1 = Adam7
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    for (kind, data) in [(b"IHDR", ihdr), (b"IDAT", z), (b"IEND", Vec::new())] {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut h = crc32fast::Hasher::new();
        h.update(kind);
        h.update(&data);
        out.extend_from_slice(kind);
        out.extend_from_slice(&data);
        out.extend_from_slice(&h.finalize().to_be_bytes());
    }
    out
}

#[wasm_bindgen_test(unsupported = test)]
fn interlaced_png_is_exact() {
    let gray = card_gray();
    assert_eq!(decoded(&interlaced_png(&gray)).gray.pixels, gray);
}

fn jpeg_with(color: jpeg_encoder::ColorType, data: &[u8], progressive: bool) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = jpeg_encoder::Encoder::new(&mut out, 95);
    enc.set_progressive(progressive);
    enc.encode(data, W as u16, H as u16, color)
        .expect("jpeg encode");
    out
}

#[wasm_bindgen_test(unsupported = test)]
fn jpeg_baseline_progressive_and_cmyk_are_close() {
    let gray = card_gray();
    let rgb = card_rgb();
    for progressive in [false, true] {
        let d = decoded(&jpeg_with(jpeg_encoder::ColorType::Rgb, &rgb, progressive));
        assert_eq!(
            (d.info.format, d.info.width, d.info.height),
            (ImageFormat::Jpeg, W, H)
        );
        let e = mean_abs_diff(&d.gray.pixels, &gray);
        assert!(
            e < 2.0,
            "progressive {progressive}: mean error {e} grey levels"
        );
    }
    let d = decoded(&jpeg_with(jpeg_encoder::ColorType::Luma, &gray, false));
    assert_eq!(d.info.channels, 1);
    assert!(mean_abs_diff(&d.gray.pixels, &gray) < 2.0);
    // CMYK with no black: C, M, Y = 255 - R, G, B (Adobe-inverted storage
    // is the encoder's business; the decoder must give back the colours).
    let cmyk: Vec<u8> = rgb
        .chunks(3)
        .flat_map(|p| [255 - p[0], 255 - p[1], 255 - p[2], 0])
        .collect();
    let d = decoded(&jpeg_with(jpeg_encoder::ColorType::Cmyk, &cmyk, false));
    let e = mean_abs_diff(&d.gray.pixels, &gray);
    assert!(e < 3.0, "CMYK: mean error {e} grey levels");
}

fn tiff_with(compression: tiff::encoder::Compression, gray16: bool, gray: &[u8]) -> Vec<u8> {
    use tiff::encoder::{colortype, TiffEncoder};
    let mut out = Cursor::new(Vec::new());
    let mut enc = TiffEncoder::new(&mut out)
        .expect("tiff")
        .with_compression(compression);
    if gray16 {
        let wide: Vec<u16> = gray.iter().map(|&v| v as u16 * 257).collect();
        enc.write_image::<colortype::Gray16>(W, H, &wide)
            .expect("tiff 16");
    } else {
        enc.write_image::<colortype::Gray8>(W, H, gray)
            .expect("tiff 8");
    }
    out.into_inner()
}

#[wasm_bindgen_test(unsupported = test)]
fn tiff_compressions_and_depths_are_exact() {
    use tiff::encoder::{Compression, DeflateLevel};
    let gray = card_gray();
    for compression in [
        Compression::Uncompressed,
        Compression::Lzw,
        Compression::Deflate(DeflateLevel::Balanced),
        Compression::Packbits,
    ] {
        for wide in [false, true] {
            let d = decoded(&tiff_with(compression, wide, &gray));
            assert_eq!(d.info.format, ImageFormat::Tiff);
            assert_eq!(d.info.bits_per_channel, if wide { 16 } else { 8 });
            assert_eq!(d.gray.pixels, gray, "16-bit {wide}");
        }
    }
}

/// A tiled (16 x 16), uncompressed 8-bit grey TIFF, written by hand (the
/// `tiff` encoder writes strips only).
fn tiled_tiff(gray: &[u8]) -> Vec<u8> {
    const T: u32 = 16;
    let (across, down) = (W.div_ceil(T), H.div_ceil(T));
    let mut tiles = Vec::new();
    for ty in 0..down {
        for tx in 0..across {
            for y in ty * T..(ty + 1) * T {
                for x in tx * T..(tx + 1) * T {
                    tiles.push(if x < W && y < H {
                        gray[(y * W + x) as usize]
                    } else {
                        0
                    });
                }
            }
        }
    }
    let count = across * down;
    let data_at = 8u32;
    let offsets_at = data_at + tiles.len() as u32;
    let counts_at = offsets_at + 4 * count;
    let ifd_at = counts_at + 4 * count;
    let mut out = b"II*\x00".to_vec();
    out.extend_from_slice(&ifd_at.to_le_bytes());
    out.extend_from_slice(&tiles);
    for i in 0..count {
        out.extend_from_slice(&(data_at + i * T * T).to_le_bytes());
    }
    for _ in 0..count {
        out.extend_from_slice(&(T * T).to_le_bytes());
    }
    // (tag, type 3 = SHORT / 4 = LONG, count, value or offset)
    let entries: [(u16, u16, u32, u32); 10] = [
        (256, 4, 1, W),
        (257, 4, 1, H),
        (258, 3, 1, 8),
        (259, 3, 1, 1),
        (262, 3, 1, 1),
        (277, 3, 1, 1),
        (322, 3, 1, T),
        (323, 3, 1, T),
        (324, 4, count, offsets_at),
        (325, 4, count, counts_at),
    ];
    out.extend_from_slice(&(entries.len() as u16).to_le_bytes());
    for (tag, kind, n, value) in entries {
        out.extend_from_slice(&tag.to_le_bytes());
        out.extend_from_slice(&kind.to_le_bytes());
        out.extend_from_slice(&n.to_le_bytes());
        out.extend_from_slice(&value.to_le_bytes());
    }
    out.extend_from_slice(&0u32.to_le_bytes());
    out
}

#[wasm_bindgen_test(unsupported = test)]
fn tiled_tiff_is_exact() {
    let gray = card_gray();
    assert_eq!(decoded(&tiled_tiff(&gray)).gray.pixels, gray);
}

#[wasm_bindgen_test(unsupported = test)]
fn gif_bmp_pnm_and_webp_round_trip() {
    use ::image::ImageFormat as F;
    let gray = card_gray();
    let rgb = ::image::RgbImage::from_raw(W, H, card_rgb()).expect("card size");
    let luma = ::image::GrayImage::from_raw(W, H, gray.clone()).expect("card size");
    for (format, ours, img) in [
        (
            F::Bmp,
            ImageFormat::Bmp,
            DynamicImage::ImageRgb8(rgb.clone()),
        ),
        (
            F::Pnm,
            ImageFormat::Pnm,
            DynamicImage::ImageRgb8(rgb.clone()),
        ),
        (
            F::Pnm,
            ImageFormat::Pnm,
            DynamicImage::ImageLuma8(luma.clone()),
        ),
        (
            F::WebP,
            ImageFormat::WebP,
            DynamicImage::ImageRgb8(rgb.clone()),
        ),
    ] {
        let d = decoded(&encode_with_image(format, img));
        assert_eq!(d.info.format, ours);
        assert_eq!(d.gray.pixels, gray, "{ours:?}");
    }
    // GIF quantises to a palette: grey levels survive exactly when the
    // picture has at most 256 of them (a grey picture).
    let d = decoded(&encode_with_image(
        F::Gif,
        DynamicImage::ImageLuma8(luma).into_rgba8().into(),
    ));
    assert_eq!(d.info.format, ImageFormat::Gif);
    assert!(mean_abs_diff(&d.gray.pixels, &gray) < 1.0);
}

/// The 28-byte JPEG of the issue that crashed the old hand-written decoder.
pub(crate) fn jpeg_28_bytes() -> Vec<u8> {
    let mut b = vec![0xFF, 0xD8, 0xFF, 0xC4, 0x00, 0x16, 0x00, 0x02, 0x01];
    b.extend_from_slice(&[0; 14]);
    b.extend_from_slice(&[0x00, 0x01, 0x02, 0xFF, 0xD9]);
    b
}

#[wasm_bindgen_test(unsupported = test)]
fn the_28_byte_jpeg_is_a_named_defect() {
    let bytes = jpeg_28_bytes();
    assert_eq!(bytes.len(), 28);
    let err = decode_gray(&bytes).unwrap_err().to_string();
    assert_eq!(
        err,
        "corrupt or truncated JPEG file: Format error decoding Jpeg: Error decoding huffman values: Bad Huffman Table"
    );
}

/// A 200-byte TIFF of a 64 x 64 image whose tiles claim 2^30 x 2^30 pixels.
pub(crate) fn tiff_huge_tiles() -> Vec<u8> {
    let entries: [(u16, u16, u32); 10] = [
        (256, 3, 64),
        (257, 3, 64),
        (258, 3, 8),
        (259, 3, 1),
        (262, 3, 1),
        (277, 3, 1),
        (322, 4, 1 << 30),
        (323, 4, 1 << 30),
        (324, 4, 8),
        (325, 4, 16),
    ];
    let mut out = b"II*\x00".to_vec();
    out.extend_from_slice(&8u32.to_le_bytes());
    out.extend_from_slice(&(entries.len() as u16).to_le_bytes());
    for (tag, kind, value) in entries {
        out.extend_from_slice(&tag.to_le_bytes());
        out.extend_from_slice(&kind.to_le_bytes());
        out.extend_from_slice(&1u32.to_le_bytes());
        out.extend_from_slice(&value.to_le_bytes());
    }
    out.extend_from_slice(&0u32.to_le_bytes());
    out.resize(200, 0);
    out
}

#[wasm_bindgen_test(unsupported = test)]
fn tiff_with_huge_tiles_is_refused_without_allocating() {
    let err = decode_gray(&tiff_huge_tiles()).unwrap_err().to_string();
    // 64-bit: the tiles lie beyond the end of the file; 32-bit (wasm): the
    // decoder stops earlier, a 2^30-pixel tile overflowing its sizes.
    let expected = if cfg!(target_pointer_width = "32") {
        "corrupt or truncated TIFF file: Format error decoding Tiff: platform or format size \
         limits exceeded"
    } else {
        "the TIFF file is truncated: it ends after 200 bytes"
    };
    assert!(err.starts_with(expected), "{err}");
}

#[wasm_bindgen_test(unsupported = test)]
fn the_memory_limit_names_the_limit() {
    let gray = card_gray();
    let bytes = encode_png(&GrayImage::new(W, H, gray).expect("size")).expect("png");
    let options = DecodeOptions {
        max_alloc_bytes: 1000,
        ..Default::default()
    };
    let err = decode(&bytes, &options).unwrap_err().to_string();
    assert_eq!(
        err,
        "PNG image needs more memory to decode than the limit of 1000 bytes: downscale it, \
         or save it as 8-bit grey (all calibration uses); --max-pixels N in the CLI raises \
         the limit to 10 bytes a pixel"
    );
    let options = DecodeOptions {
        max_pixels: 3000,
        ..Default::default()
    };
    let err = decode(&bytes, &options).unwrap_err().to_string();
    assert_eq!(
        err,
        "image is 67x45 = 3015 pixels, more than the limit of 3000 pixels: downscale it first, or raise the limit (--max-pixels in the CLI, \"max_pixels\" in the JSON options)"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn grey_palettes_are_listed_as_grey_true_colour_as_rgb() {
    use ::image::ImageFormat as F;
    let gray = card_gray();
    let luma = ::image::GrayImage::from_raw(W, H, gray.clone()).expect("card size");
    let rgb = ::image::RgbImage::from_raw(W, H, card_rgb()).expect("card size");
    // `image` writes a grey image as an 8-bit BMP with a grey palette and
    // expands the palette to RGB when it reads the file back.
    let bmp = encode_with_image(F::Bmp, DynamicImage::ImageLuma8(luma.clone()));
    assert_eq!(u16::from_le_bytes([bmp[28], bmp[29]]), 8, "bits per pixel");
    let d = decoded(&bmp);
    assert_eq!((d.info.channels, d.info.bits_per_channel), (1, 8));
    assert_eq!(d.gray.pixels, gray);
    let gif = encode_with_image(F::Gif, DynamicImage::ImageLuma8(luma).into_rgba8().into());
    assert_eq!(decoded(&gif).info.channels, 1);
    let colour = decoded(&encode_with_image(F::Bmp, DynamicImage::ImageRgb8(rgb)));
    assert_eq!((colour.info.channels, colour.info.bits_per_channel), (3, 8));
    // A 24-bit BMP stays RGB even when its pixels are grey: the file is RGB.
    let grey_rgb =
        DynamicImage::ImageLuma8(::image::GrayImage::from_raw(W, H, gray).expect("card size"))
            .into_rgb8();
    let d = decoded(&encode_with_image(
        F::Bmp,
        DynamicImage::ImageRgb8(grey_rgb),
    ));
    assert_eq!(d.info.channels, 3);
}
