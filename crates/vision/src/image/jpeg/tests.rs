//! The JPEG decoder against the pixels that were encoded (jpeg-encoder, a
//! dev-dependency, writes every variant) and against zune-jpeg (the decoder
//! this one replaced, also a dev-dependency only).

use super::{decode, read_header, JpegError};
use jpeg_encoder::{ColorType, Encoder, SamplingFactor};
use wasm_bindgen_test::wasm_bindgen_test;

/// A colour test card: gradients, a checkerboard of 7-pixel squares (sharp
/// edges) and a few saturated patches.
fn card(w: usize, h: usize) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let check = ((x / 7) + (y / 7)) % 2 == 0;
            let (r, g, b) = if y < h / 3 {
                ((x * 255 / w) as u8, (y * 255 / h) as u8, 200u8)
            } else if y < 2 * h / 3 {
                if check {
                    (230, 30, 40)
                } else {
                    (20, 60, 220)
                }
            } else {
                let v = if check { 240 } else { 15 };
                (v, v, v)
            };
            rgb.extend_from_slice(&[r, g, b]);
        }
    }
    rgb
}

fn grey_card(w: usize, h: usize) -> Vec<u8> {
    card(w, h)
        .chunks_exact(3)
        .map(|p| ((p[0] as u32 * 3 + p[1] as u32 * 6 + p[2] as u32) / 10) as u8)
        .collect()
}

struct Options {
    quality: u8,
    sampling: SamplingFactor,
    progressive: bool,
    restart: u16,
}

const PLAIN: Options = Options {
    quality: 95,
    sampling: SamplingFactor::F_1_1,
    progressive: false,
    restart: 0,
};

fn encode(pixels: &[u8], w: usize, h: usize, color: ColorType, o: &Options) -> Vec<u8> {
    let mut out = Vec::new();
    let mut e = Encoder::new(&mut out, o.quality);
    e.set_sampling_factor(o.sampling);
    e.set_progressive(o.progressive);
    if o.restart > 0 {
        e.set_restart_interval(o.restart);
    }
    e.encode(pixels, w as u16, h as u16, color)
        .expect("encodes");
    out
}

fn zune(bytes: &[u8]) -> Vec<u8> {
    use zune_core::colorspace::ColorSpace;
    let mut d = zune_jpeg::JpegDecoder::new(zune_core::bytestream::ZCursor::new(bytes));
    d.decode_headers().expect("zune reads the header");
    let out = match d.input_colorspace().expect("colour space") {
        ColorSpace::Luma => ColorSpace::Luma,
        _ => ColorSpace::RGB,
    };
    d.set_options(d.options().jpeg_set_out_colorspace(out));
    d.decode().expect("zune decodes")
}

/// Mean and maximum absolute difference.
fn diff(a: &[u8], b: &[u8]) -> (f64, u8) {
    assert_eq!(a.len(), b.len());
    let mut sum = 0u64;
    let mut max = 0u8;
    for (&x, &y) in a.iter().zip(b) {
        let d = x.abs_diff(y);
        sum += d as u64;
        max = max.max(d);
    }
    (sum as f64 / a.len() as f64, max)
}

#[wasm_bindgen_test(unsupported = test)]
fn grey_baseline_and_progressive_match_the_encoded_pixels() {
    for (w, h) in [(64, 48), (37, 23), (8, 8), (1, 1)] {
        let grey = grey_card(w, h);
        for progressive in [false, true] {
            let o = Options {
                progressive,
                ..PLAIN
            };
            let bytes = encode(&grey, w, h, ColorType::Luma, &o);
            let img = decode(&bytes, u64::MAX).expect("decodes");
            assert_eq!(
                (img.width, img.height, img.channels),
                (w as u32, h as u32, 1)
            );
            let (mean, _) = diff(&img.pixels, &grey);
            assert!(
                mean < 2.5,
                "{w}x{h} progressive {progressive}: mean error {mean}"
            );
            let (mean, max) = diff(&img.pixels, &zune(&bytes));
            assert!(
                mean < 0.3 && max <= 3,
                "{w}x{h} vs zune-jpeg: mean {mean}, max {max}"
            );
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn colour_in_every_sampling_matches_the_encoded_pixels() {
    let (w, h) = (61, 45);
    let rgb = card(w, h);
    for sampling in [
        SamplingFactor::F_1_1,
        SamplingFactor::F_2_1,
        SamplingFactor::F_2_2,
        SamplingFactor::F_1_2,
        SamplingFactor::F_4_1,
        SamplingFactor::F_2_4,
    ] {
        for progressive in [false, true] {
            for restart in [0, 3] {
                let o = Options {
                    sampling,
                    progressive,
                    restart,
                    ..PLAIN
                };
                let bytes = encode(&rgb, w, h, ColorType::Rgb, &o);
                let img = decode(&bytes, u64::MAX).expect("decodes");
                assert_eq!(
                    (img.width, img.height, img.channels),
                    (w as u32, h as u32, 3)
                );
                let what = format!("{sampling:?} progressive {progressive} restart {restart}");
                let (mean, _) = diff(&img.pixels, &rgb);
                // Subsampled chroma blurs the saturated checkerboard: the
                // error is the format's, so it is bounded by zune-jpeg's
                // (whose interpolating upsampler blurs a little more; at 2x4 it fails).
                let (reference, _) = diff(&zune(&bytes), &rgb);
                assert!(
                    mean < 20.0 && mean <= reference + 0.25,
                    "{what}: mean error {mean}, zune-jpeg's {reference}"
                );
                // The smooth top third (gradients) survives any sampling.
                let top = w * 3 * (h / 3 - 8);
                let (mean, _) = diff(&img.pixels[..top], &rgb[..top]);
                let (reference, _) = diff(&zune(&bytes)[..top], &rgb[..top]);
                assert!(
                    mean < 5.0 && mean <= reference + 0.5,
                    "{what}: mean error {mean} in the gradients, zune-jpeg's {reference}"
                );
            }
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn full_resolution_colour_matches_zune_jpeg_closely() {
    let (w, h) = (80, 40);
    let rgb = card(w, h);
    let bytes = encode(
        &rgb,
        w,
        h,
        ColorType::Rgb,
        &Options {
            quality: 100,
            ..PLAIN
        },
    );
    let img = decode(&bytes, u64::MAX).expect("decodes");
    let (mean, max) = diff(&img.pixels, &rgb);
    assert!(
        mean < 1.0 && max <= 8,
        "vs the card: mean {mean}, max {max}"
    );
    let (mean, max) = diff(&img.pixels, &zune(&bytes));
    assert!(
        mean < 0.3 && max <= 3,
        "vs zune-jpeg: mean {mean}, max {max}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn cmyk_and_ycck_become_rgb() {
    let (w, h) = (24, 16);
    let rgb = card(w, h);
    // Ink amounts (jpeg-encoder stores them inverted, as Adobe does).
    let cmyk: Vec<u8> = rgb
        .chunks_exact(3)
        .flat_map(|p| [255 - p[0], 255 - p[1], 255 - p[2], 0])
        .collect();
    for color in [ColorType::Cmyk, ColorType::CmykAsYcck] {
        let bytes = encode(
            &cmyk,
            w,
            h,
            color,
            &Options {
                quality: 100,
                ..PLAIN
            },
        );
        let img = decode(&bytes, u64::MAX).expect("decodes");
        assert_eq!(img.channels, 3);
        let (mean, _) = diff(&img.pixels, &rgb);
        assert!(mean < 3.0, "{color:?}: mean error {mean}");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn header_gives_size_and_channels() {
    let bytes = encode(&card(30, 20), 30, 20, ColorType::Rgb, &PLAIN);
    let h = read_header(&bytes).expect("header");
    assert_eq!((h.width, h.height, h.channels), (30, 20, 3));
}

fn error(bytes: &[u8]) -> JpegError {
    decode(bytes, u64::MAX).err().expect("an error")
}

#[wasm_bindgen_test(unsupported = test)]
fn unsupported_variants_are_named() {
    let bytes = encode(&grey_card(16, 16), 16, 16, ColorType::Luma, &PLAIN);
    let sof = bytes
        .windows(2)
        .position(|m| m == [0xFF, 0xC0])
        .expect("SOF0");
    let mut arithmetic = bytes.clone();
    arithmetic[sof + 1] = 0xC9;
    assert_eq!(
        error(&arithmetic),
        JpegError::Unsupported("arithmetic-coded JPEG".into())
    );
    let mut lossless = bytes.clone();
    lossless[sof + 1] = 0xC3;
    assert_eq!(
        error(&lossless),
        JpegError::Unsupported("lossless or hierarchical JPEG".into())
    );
    let mut twelve = bytes.clone();
    twelve[sof + 4] = 12;
    assert_eq!(
        error(&twelve),
        JpegError::Unsupported("12-bit samples".into())
    );
    assert_eq!(
        error(b"\xFF\xD8\xFF\xD9"),
        JpegError::Corrupt("no image data before the end-of-image marker".into())
    );
    assert_eq!(
        error(b"GIF89a"),
        JpegError::Corrupt("no start-of-image marker".into())
    );
    assert_eq!(
        error(&bytes[..sof + 6]),
        JpegError::Corrupt("the file ends inside a marker segment".into())
    );
    assert_eq!(decode(&bytes, 100).err(), Some(JpegError::TooLarge));
}

#[wasm_bindgen_test(unsupported = test)]
fn truncated_files_keep_what_was_decoded() {
    let (w, h) = (64, 64);
    let grey = grey_card(w, h);
    let bytes = encode(&grey, w, h, ColorType::Luma, &PLAIN);
    let img = decode(&bytes[..bytes.len() * 2 / 3], u64::MAX)
        .expect("a truncated baseline file still decodes");
    // The top rows are intact.
    let (mean, _) = diff(&img.pixels[..w * 16], &grey[..w * 16]);
    assert!(mean < 2.5, "top rows: mean error {mean}");
}

#[wasm_bindgen_test(unsupported = test)]
fn damaged_files_never_panic() {
    let (w, h) = (40, 32);
    let rgb = card(w, h);
    let mut state = 99u32;
    let mut next = || {
        state = state.wrapping_mul(1664525).wrapping_add(1013904223);
        (state >> 8) as usize
    };
    for (i, o) in [
        PLAIN,
        Options {
            progressive: true,
            sampling: SamplingFactor::F_2_2,
            ..PLAIN
        },
        Options {
            restart: 2,
            sampling: SamplingFactor::F_2_1,
            ..PLAIN
        },
    ]
    .iter()
    .enumerate()
    {
        let bytes = encode(&rgb, w, h, ColorType::Rgb, o);
        for trial in 0..300 {
            let mut damaged = bytes.clone();
            for _ in 0..1 + trial % 8 {
                let at = next() % damaged.len();
                damaged[at] = next() as u8;
            }
            if trial % 5 == 0 {
                damaged.truncate(next() % bytes.len());
            }
            // Either an image of the declared size or an error, no panic.
            if let Ok(img) = decode(&damaged, 1 << 26) {
                assert_eq!(
                    img.pixels.len(),
                    (img.width * img.height) as usize * img.channels as usize,
                    "case {i}"
                );
            }
        }
    }
}

/// The public JPEG photos in ../shared/datasets (camera and phone files)
/// decode like zune-jpeg decodes them, within the IDCTs' rounding.
#[cfg(not(target_arch = "wasm32"))]
#[test]
fn dataset_photos_match_zune_jpeg() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/datasets");
    let mut files: Vec<_> = ["opencv-left-right-9x6", "moveit-handeye-pose-samples"]
        .iter()
        .filter_map(|d| std::fs::read_dir(root.join(d)).ok())
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("jpg")))
        .collect();
    if files.is_empty() {
        eprintln!(
            "skipped: no JPEG photos under {} (the datasets are not in a user's clone)",
            root.display()
        );
        return;
    }
    files.sort();
    for path in files {
        let bytes = std::fs::read(&path).expect("readable");
        let ours = decode(&bytes, u64::MAX).expect("decodes");
        let reference = zune(&bytes);
        let (mean, max) = diff(&ours.pixels, &reference);
        let limit = if ours.channels == 1 {
            (0.05, 2)
        } else {
            (0.8, 30)
        };
        assert!(
            mean < limit.0 && max <= limit.1,
            "{}: mean {mean}, max {max} vs zune-jpeg",
            path.display()
        );
    }
}
