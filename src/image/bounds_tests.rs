//! Bounded decoding, truncated files and EXIF orientation (issues 36, 37).
//!
//! Every expected image here is computed independently of the code under
//! test: the orientation oracle maps pixel indices by hand from the EXIF
//! definitions, the PNG strips are compared with `image`'s conversion of
//! the whole image, and the truncation messages are quoted in full.

use super::*;

/// A chunk with its length and CRC.
fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let mut h = crc32fast::Hasher::new();
    h.update(kind);
    h.update(data);
    out.extend_from_slice(&h.finalize().to_be_bytes());
    out
}

/// Insert `extra` chunks right after IHDR (byte 33 of every PNG).
fn with_chunks_after_ihdr(png: &[u8], extra: &[Vec<u8>]) -> Vec<u8> {
    let mut out = png[..33].to_vec();
    for c in extra {
        out.extend_from_slice(c);
    }
    out.extend_from_slice(&png[33..]);
    out
}

/// An iCCP chunk whose profile is `zeros` zero bytes, zlib-deflated in
/// 1 MiB pieces (never held inflated).
fn iccp_bomb(zeros: u64) -> Vec<u8> {
    let mut data = b"bomb\0\0".to_vec(); // profile name, compression method 0
    let mut z = fdeflate::Compressor::new(Vec::new()).expect("compressor");
    let block = vec![0u8; 1 << 20];
    let mut left = zeros;
    while left > 0 {
        let n = left.min(block.len() as u64) as usize;
        z.write_data(&block[..n]).expect("deflate");
        left -= n as u64;
    }
    data.extend_from_slice(&z.finish().expect("deflate end"));
    chunk(b"iCCP", &data)
}

fn ramp(w: u32, h: u32) -> GrayImage {
    let pixels = (0..w * h)
        .map(|i| ((i % w) * 7 + (i / w) * 13) as u8)
        .collect();
    GrayImage::new(w, h, pixels).expect("size")
}

#[test]
fn an_iccp_chunk_that_inflates_to_gigabytes_is_skipped() {
    // 1.25 GiB of profile: over the 1 GiB limit, so inflating it at all
    // would fail the decode; skipped, the pixels come through.
    let bomb = iccp_bomb(5 << 28);
    assert!(bomb.len() < 8 << 20, "the chunk is {} bytes", bomb.len());
    let img = ramp(40, 30);
    let png = with_chunks_after_ihdr(&encode_png(&img).expect("png"), &[bomb]);
    assert_eq!(decode_gray(&png).expect("decode").pixels, img.pixels);
    // The whole-image path (previews) skips it too.
    let with_preview = DecodeOptions {
        preview_max_side: Some(8),
        ..Default::default()
    };
    assert_eq!(decode(&png, &with_preview).expect("decode").gray, img);
}

/// A 16-bit RGBA PNG of `w` x `h`: each channel a different ramp.
fn rgba16_png(w: u32, h: u32) -> (Vec<u8>, Vec<u16>) {
    let samples: Vec<u16> = (0..w * h * 4)
        .map(|i| {
            let (p, c) = (i / 4, i % 4);
            ((p % w) * 331 + (p / w) * 97 + c * 9000) as u16
        })
        .collect();
    let be: Vec<u8> = samples.iter().flat_map(|v| v.to_be_bytes()).collect();
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Sixteen);
        let mut writer = enc.write_header().expect("png header");
        writer.write_image_data(&be).expect("png data");
    }
    (out, samples)
}

#[test]
fn a_16_bit_rgba_png_is_converted_in_strips_exactly() {
    // 150 rows: two full strips of 64 and a short one.
    let (w, h) = (53, 150);
    let (png, samples) = rgba16_png(w, h);
    let whole =
        ::image::ImageBuffer::<::image::Rgba<u16>, _>::from_raw(w, h, samples).expect("size");
    let expected = DynamicImage::ImageRgba16(whole).into_luma8().into_raw();
    let d = decode(&png, &DecodeOptions::default()).expect("decode");
    assert_eq!((d.info.channels, d.info.bits_per_channel), (4, 16));
    assert_eq!(d.gray.pixels, expected);
    // The peak: the grey image plus two strips, not 8 bytes a pixel.
    let peak = decode_peak(&png, &DecodeOptions::default()).expect("peak");
    assert_eq!(peak.pixels, (w * h) as u64);
    assert_eq!(peak.bytes, (w * h) as u64 + 2 * (w as u64 * 8) * 64);
}

#[test]
fn the_peak_of_a_100_mp_rgba16_png_is_known_from_its_header() {
    // Signature, IHDR of 10000 x 10000 RGBA 16-bit, and the start of IDAT:
    // all `decode_peak` needs.
    let mut ihdr = 10_000u32.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&10_000u32.to_be_bytes());
    ihdr.extend_from_slice(&[16, 6, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend_from_slice(&chunk(b"IHDR", &ihdr));
    png.extend_from_slice(&chunk(b"IDAT", &[0x78, 0x01]));
    let peak = decode_peak(&png, &DecodeOptions::default()).expect("peak");
    // 100 MB of grey and two strips of 64 rows of 80 KB: 110.24 MB.
    assert_eq!(peak.bytes, 100_000_000 + 2 * 80_000 * 64);
}

#[test]
fn a_memory_limit_error_gives_the_limit_and_what_to_do() {
    let (png, _) = rgba16_png(100, 100);
    let small = DecodeOptions {
        max_alloc_bytes: 20_000,
        preview_max_side: Some(8),
        ..Default::default()
    };
    assert_eq!(
        decode(&png, &small).unwrap_err().to_string(),
        "PNG image needs more memory to decode than the limit of 20000 bytes: \
         downscale it, or save it as 8-bit grey (all calibration uses); \
         --max-pixels N in the CLI raises the limit to 10 bytes a pixel"
    );
}

/// A JPEG of `gray` (quality 95), with an EXIF APP1 segment holding only
/// the Orientation tag when `orientation` is given.
fn jpeg(gray: &GrayImage, orientation: Option<u16>) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = jpeg_encoder::Encoder::new(&mut out, 95);
    if let Some(o) = orientation {
        // TIFF header (little-endian, IFD at 8), one entry: tag 0x0112
        // SHORT x 1 = o, then no next IFD.
        let mut tiff = b"II*\x00\x08\x00\x00\x00\x01\x00\x12\x01\x03\x00\x01\x00\x00\x00".to_vec();
        tiff.extend_from_slice(&o.to_le_bytes());
        tiff.extend_from_slice(&[0, 0, 0, 0, 0, 0]);
        enc.add_exif_metadata(&tiff).expect("exif");
    }
    enc.encode(
        &gray.pixels,
        gray.width as u16,
        gray.height as u16,
        jpeg_encoder::ColorType::Luma,
    )
    .expect("jpeg");
    out
}

/// What a viewer shows for EXIF orientation `o` of a `w` x `h` image, from
/// the EXIF definitions: the source pixel of each shown pixel.
fn oriented_by_hand(src: &GrayImage, o: u16) -> GrayImage {
    let (w, h) = (src.width, src.height);
    let (ow, oh) = if o >= 5 { (h, w) } else { (w, h) };
    let mut pixels = Vec::with_capacity((w * h) as usize);
    for y in 0..oh {
        for x in 0..ow {
            let (sx, sy) = match o {
                1 => (x, y),
                2 => (w - 1 - x, y),
                3 => (w - 1 - x, h - 1 - y),
                4 => (x, h - 1 - y),
                5 => (y, x),
                6 => (y, h - 1 - x),
                7 => (w - 1 - y, h - 1 - x),
                8 => (w - 1 - y, x),
                _ => unreachable!("orientation {o}"),
            };
            pixels.push(src.pixels[(sy * w + sx) as usize]);
        }
    }
    GrayImage::new(ow, oh, pixels).expect("size")
}

#[test]
fn every_exif_orientation_is_applied_as_viewers_do() {
    // 48 x 32, not symmetric under any of the eight transforms.
    let src = ramp(48, 32);
    let stored = decode_gray(&jpeg(&src, None)).expect("plain jpeg");
    for o in 1..=8u16 {
        let d = decode(&jpeg(&src, Some(o)), &DecodeOptions::default()).expect("decode");
        let expected = oriented_by_hand(&stored, o);
        assert_eq!(d.gray, expected, "orientation {o}");
        assert_eq!(
            (d.info.width, d.info.height),
            (expected.width, expected.height)
        );
        // The page's preview is turned the same way.
        let with_preview = DecodeOptions {
            preview_max_side: Some(100),
            ..Default::default()
        };
        let preview = decode(&jpeg(&src, Some(o)), &with_preview)
            .expect("decode")
            .preview
            .expect("preview");
        assert_eq!(
            (preview.width, preview.height),
            (expected.width, expected.height),
            "preview, orientation {o}"
        );
        let preview_grey: Vec<u8> = preview.pixels.chunks(4).map(|p| p[0]).collect();
        assert_eq!(preview_grey, expected.pixels, "preview, orientation {o}");
        let applied = if o == 1 { None } else { Some(o as u8) };
        assert_eq!(d.info.exif_orientation, applied, "orientation {o}");
    }
    let info = decode(&jpeg(&src, Some(6)), &DecodeOptions::default()).expect("decode");
    assert_eq!(
        serde_json::to_string(&info.info).expect("json"),
        r#"{"format":"jpeg","width":32,"height":48,"channels":1,"bits_per_channel":8,"exif_orientation":6}"#
    );
}

#[test]
fn a_png_exif_chunk_orientation_is_applied() {
    let src = ramp(20, 12);
    let mut tiff = b"MM\x00*\x00\x00\x00\x08\x00\x01\x01\x12\x00\x03\x00\x00\x00\x01".to_vec();
    tiff.extend_from_slice(&[0, 8, 0, 0, 0, 0, 0, 0]);
    let png = with_chunks_after_ihdr(&encode_png(&src).expect("png"), &[chunk(b"eXIf", &tiff)]);
    let d = decode(&png, &DecodeOptions::default()).expect("decode");
    assert_eq!(d.gray, oriented_by_hand(&src, 8));
    assert_eq!(d.info.exif_orientation, Some(8));
}

fn truncated(format: &str, n: usize) -> String {
    format!(
        "the {format} file is truncated: it ends after {n} bytes, before the end of its image \
         data (an interrupted copy or download?): copy it again from the camera or its source"
    )
}

#[test]
fn jpeg_and_png_cut_anywhere_are_named_truncated() {
    let src = ramp(64, 48);
    let files = [
        ("JPEG", jpeg(&src, Some(6))),
        ("PNG", encode_png(&src).expect("png")),
    ];
    for (format, bytes) in files {
        for percent in [10, 50, 90] {
            let n = bytes.len() * percent / 100;
            let err = decode_gray(&bytes[..n]).unwrap_err().to_string();
            assert_eq!(err, truncated(format, n), "{format} cut at {percent} %");
        }
        // One byte short: a JPEG without its EOI, a PNG without IEND's CRC.
        let n = bytes.len() - 1;
        let err = decode_gray(&bytes[..n]).unwrap_err().to_string();
        assert_eq!(err, truncated(format, n), "{format} one byte short");
        assert!(decode_gray(&bytes).is_ok(), "{format} whole");
    }
}

#[test]
fn a_gif_over_the_memory_limit_gives_the_limit_and_what_to_do() {
    // A GIF screen of 1000 x 1000 (4 MB as RGBA) under a 100 kB limit.
    let mut gif = b"GIF89a".to_vec();
    gif.extend_from_slice(&1000u16.to_le_bytes());
    gif.extend_from_slice(&1000u16.to_le_bytes());
    gif.extend_from_slice(&[0, 0, 0]);
    gif.extend_from_slice(b",\0\0\0\0\xe8\x03\xe8\x03\0\x02\x02\x4c\x01\0;");
    let options = DecodeOptions {
        max_alloc_bytes: 100_000,
        ..Default::default()
    };
    assert_eq!(
        decode(&gif, &options).unwrap_err().to_string(),
        "GIF image is 1000x1000: decoding it needs 4000000 bytes, more than the memory limit \
         of 100000 bytes: downscale it, \
         or save it as 8-bit grey (all calibration uses); --max-pixels N in the CLI raises the \
         limit to 10 bytes a pixel"
    );
}
