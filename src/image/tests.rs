//! Unit tests of the decoder front (src/image/mod.rs).

use super::messages::pixel_count;
use super::*;
use wasm_bindgen_test::wasm_bindgen_test;

fn gradient(w: u32, h: u32) -> GrayImage {
    let pixels = (0..w * h)
        .map(|i| ((i % w) * 255 / w.max(1)) as u8)
        .collect();
    GrayImage::new(w, h, pixels).unwrap()
}

#[wasm_bindgen_test(unsupported = test)]
fn png_round_trip_keeps_every_pixel() {
    let img = gradient(37, 21);
    let bytes = encode_png(&img).unwrap();
    let decoded = decode(
        &bytes,
        &DecodeOptions {
            preview_max_side: Some(10),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(decoded.gray, img);
    assert_eq!(decoded.info.format, ImageFormat::Png);
    assert_eq!(
        (
            decoded.info.width,
            decoded.info.height,
            decoded.info.channels
        ),
        (37, 21, 1)
    );
    let preview = decoded.preview.unwrap();
    assert_eq!((preview.width, preview.height), (10, 6));
    assert_eq!(preview.pixels.len(), 10 * 6 * 4);
}

#[wasm_bindgen_test(unsupported = test)]
fn pgm_round_trip_keeps_every_pixel() {
    let img = gradient(5, 3);
    assert_eq!(decode_gray(&encode_pgm(&img)).unwrap(), img);
}

#[wasm_bindgen_test(unsupported = test)]
fn garbage_is_not_an_image() {
    let err = decode_gray(b"hello, this is text").unwrap_err();
    assert_eq!(
        err.to_string(),
        "not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF, WebP"
    );
    assert_eq!(
        decode_gray(&[]).unwrap_err().to_string(),
        "not an image: the file is empty"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn truncated_png_is_reported_as_truncated() {
    let bytes = encode_png(&gradient(64, 64)).unwrap();
    let n = bytes.len() / 2;
    let err = decode_gray(&bytes[..n]).unwrap_err().to_string();
    assert_eq!(
        err,
        format!(
            "the PNG file is truncated: it ends after {n} bytes, before the end of its \
             image data (an interrupted copy or download?): copy it again from the camera \
             or its source"
        )
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn oversized_header_is_refused_before_allocating() {
    // A PGM header announcing 20000 x 20000 pixels with no data behind it.
    let bytes = b"P5\n20000 20000\n255\n".to_vec();
    let err = decode_gray(&bytes).unwrap_err().to_string();
    // 100 MP natively, 64 MP in wasm.
    let limit = if cfg!(target_arch = "wasm32") {
        "64.0 MP"
    } else {
        "100.0 MP"
    };
    assert_eq!(
        err,
        format!("image is 20000x20000 = 400.0 MP, more than the limit of {limit}: downscale it first, or raise the limit (--max-pixels in the CLI, \"max_pixels\" in the JSON options)")
    );
    // Counts that print alike in megapixels are given exactly.
    assert_eq!(pixel_count(120_000, 100_000), "120000 pixels");
    assert_eq!(pixel_count(12_300_000, 100_000_000), "12.3 MP");
}

#[wasm_bindgen_test(unsupported = test)]
fn random_bytes_never_panic() {
    // Seeded xorshift: random prefixes of real headers and pure noise.
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let png = encode_png(&gradient(16, 16)).unwrap();
    // Real headers of every format, cut anywhere and followed by noise.
    let headers: [&[u8]; 8] = [
        &png,
        b"BM\x46\x00\x00\x00\x00\x00\x00\x00\x36\x00\x00\x00\x28\x00\x00\x00",
        b"P6 4 4 255\n",
        b"P1 4 4\n",
        b"P7\nWIDTH 2\nHEIGHT 2\nDEPTH 4\nMAXVAL 65535\nENDHDR\n",
        b"GIF89a\x04\x00\x04\x00\xf0\x00\x00",
        b"II*\x00\x08\x00\x00\x00",
        b"\xff\xd8\xff\xe0\x00\x10JFIF\x00",
    ];
    for i in 0..800 {
        let len = (next() % 200) as usize;
        let mut bytes: Vec<u8> = (0..len).map(|_| next() as u8).collect();
        if i % 4 != 3 {
            let header = headers[(next() % headers.len() as u64) as usize];
            let keep = (next() as usize) % (header.len() + 1);
            bytes = [&header[..keep], &bytes[..]].concat();
        }
        let _ = decode(
            &bytes,
            &DecodeOptions {
                preview_max_side: Some(8),
                ..Default::default()
            },
        );
    }
}
