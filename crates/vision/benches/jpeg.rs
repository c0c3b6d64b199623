//! `cargo bench -p robocal-vision --bench jpeg`: our JPEG decoder against
//! zune-jpeg (the crate it replaced) on encoded renders: 12 MP and 1.2 MP,
//! grey and colour, baseline and progressive (medians of repeated runs).
//! With `--write DIR` it also saves the JPEGs (for the wasm comparison,
//! bench/wasm_jpeg.mjs).

use jpeg_encoder::{ColorType, Encoder, SamplingFactor};
use robocal_vision::image::jpeg::decode;
use std::time::Instant;

/// A busy colour picture: the card of the decoder's tests at any size.
fn picture(w: usize, h: usize) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let check = ((x / 37) + (y / 37)) % 2 == 0;
            let ramp = ((x + y) * 255 / (w + h)) as u8;
            let (r, g, b) = if check {
                (ramp, 200 - ramp / 2, 40)
            } else {
                (30, ramp, 255 - ramp)
            };
            // Fine texture so that AC coefficients are not all zero.
            let n = ((x * 7 + y * 13) % 17) as u8;
            rgb.extend_from_slice(&[
                r.saturating_add(n),
                g.saturating_add(n),
                b.saturating_add(n),
            ]);
        }
    }
    rgb
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn zune(bytes: &[u8]) -> usize {
    let mut d = zune_jpeg::JpegDecoder::new(zune_core::bytestream::ZCursor::new(bytes));
    d.decode().expect("zune decodes").len()
}

fn main() {
    let write = std::env::args().skip_while(|a| a != "--write").nth(1);
    for (w, h, runs) in [(1280usize, 960usize, 15), (4000, 3000, 5)] {
        let rgb = picture(w, h);
        let grey: Vec<u8> = rgb.chunks_exact(3).map(|p| p[1]).collect();
        for (name, progressive, colour) in [
            ("grey baseline", false, false),
            ("colour 4:2:0 baseline", false, true),
            ("colour 4:2:0 progressive", true, true),
        ] {
            let mut bytes = Vec::new();
            let mut e = Encoder::new(&mut bytes, 90);
            e.set_sampling_factor(SamplingFactor::F_2_2);
            e.set_progressive(progressive);
            let (data, color) = if colour {
                (&rgb, ColorType::Rgb)
            } else {
                (&grey, ColorType::Luma)
            };
            e.encode(data, w as u16, h as u16, color).expect("encodes");
            if let Some(dir) = &write {
                let file = format!("{dir}/{w}x{h}-{}.jpg", name.replace([' ', ':'], "-"));
                std::fs::write(&file, &bytes).expect("writes");
            }
            let mut ours = Vec::new();
            let mut theirs = Vec::new();
            for _ in 0..runs {
                let t0 = Instant::now();
                let d = decode(&bytes, u64::MAX).expect("decodes");
                ours.push(t0.elapsed().as_secs_f64() * 1e3);
                assert_eq!(d.width as usize, w);
                let t0 = Instant::now();
                zune(&bytes);
                theirs.push(t0.elapsed().as_secs_f64() * 1e3);
            }
            let (a, b) = (median(ours), median(theirs));
            println!(
                "{w}x{h} {name:26} ours {a:8.2} ms   zune-jpeg {b:8.2} ms   ratio {:.2}",
                a / b
            );
        }
    }
}
