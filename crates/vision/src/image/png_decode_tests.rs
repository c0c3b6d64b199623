//! The PNG reader against the `png` crate (a dev-dependency; the decoder
//! ours replaced) on files of every colour type, depth, filter and
//! interlacing, built from random rows.

use super::{decode, passes, Header};
use crate::image::png_encode::{chunk, crc32};
use crate::image::raster::Samples;
use crate::image::DecodeOptions;
use wasm_bindgen_test::wasm_bindgen_test;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u8 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 24) as u8
    }
}

/// A PNG of random pixels and random row filters.
fn png(
    w: u32,
    h: u32,
    colour: u8,
    depth: u8,
    interlaced: bool,
    trns: Option<&[u8]>,
    rng: &mut Rng,
) -> Vec<u8> {
    let header = Header {
        width: w as usize,
        height: h as usize,
        depth,
        colour,
        interlaced,
    };
    let mut raw = Vec::new();
    for p in passes(&header) {
        for _ in 0..p.rows {
            raw.push(rng.next() % 5);
            for _ in 0..header.row_bytes(p.cols) {
                // Indexed pixels stay within a 16-colour palette.
                let v = rng.next();
                raw.push(if colour == 3 && depth == 8 { v % 20 } else { v });
            }
        }
    }
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&w.to_be_bytes());
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[depth, colour, 0, 0, interlaced as u8]);
    chunk(&mut out, b"IHDR", &ihdr);
    if colour == 3 {
        let plte: Vec<u8> = (0..16 * 3).map(|i| (i * 37 % 256) as u8).collect();
        chunk(&mut out, b"PLTE", &plte);
    }
    if let Some(t) = trns {
        chunk(&mut out, b"tRNS", t);
    }
    chunk(&mut out, b"tEXt", b"Comment\0made by a test");
    let z = fdeflate::compress_to_vec(&raw);
    let (a, b) = z.split_at(z.len() / 2);
    chunk(&mut out, b"IDAT", a);
    chunk(&mut out, b"IDAT", b);
    chunk(&mut out, b"IEND", &[]);
    out
}

/// The png crate's EXPAND output as 16-bit-or-8-bit samples.
fn reference(bytes: &[u8]) -> (u8, Vec<u16>) {
    let mut d = png::Decoder::new(std::io::Cursor::new(bytes));
    d.set_transformations(png::Transformations::EXPAND);
    let mut r = d.read_info().expect("png reads");
    let (colour, depth) = r.output_color_type();
    let mut buf = vec![0; r.output_buffer_size().expect("size")];
    r.next_frame(&mut buf).expect("png decodes");
    let samples = if depth == png::BitDepth::Sixteen {
        buf.chunks_exact(2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
            .collect()
    } else {
        buf.iter().map(|&v| v as u16).collect()
    };
    (colour.samples() as u8, samples)
}

fn ours(bytes: &[u8]) -> (u8, Vec<u16>) {
    let r = decode(bytes, &DecodeOptions::default()).expect("decodes");
    let samples = match r.samples {
        Samples::U8(v) => v.iter().map(|&v| v as u16).collect(),
        Samples::U16(v) => v,
        Samples::F32(_) => panic!("no float PNG"),
    };
    (r.channels, samples)
}

#[wasm_bindgen_test(unsupported = test)]
fn every_colour_type_depth_and_interlacing_matches_the_png_crate() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let kinds: &[(u8, &[u8])] = &[
        (0, &[1, 2, 4, 8, 16]),
        (2, &[8, 16]),
        (3, &[1, 2, 4, 8]),
        (4, &[8, 16]),
        (6, &[8, 16]),
    ];
    for &(colour, depths) in kinds {
        for &depth in depths {
            for interlaced in [false, true] {
                for (w, h) in [(1, 1), (3, 2), (13, 9), (33, 17)] {
                    let trns: Option<Vec<u8>> = match colour {
                        0 => Some(vec![0, if depth == 16 { 7 } else { 1 }]),
                        2 => Some(vec![0, 1, 0, 2, 0, 3]),
                        3 => Some(vec![0, 128, 255]),
                        _ => None,
                    };
                    for t in [None, trns.as_deref()] {
                        let bytes = png(w, h, colour, depth, interlaced, t, &mut rng);
                        let what = format!("colour {colour}, {depth} bits, interlaced {interlaced}, {w}x{h}, tRNS {}", t.is_some());
                        assert_eq!(ours(&bytes), reference(&bytes), "{what}");
                    }
                }
            }
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn damaged_files_say_what_is_wrong() {
    let mut rng = Rng(99);
    let good = png(8, 8, 0, 8, false, None, &mut rng);
    let err = |b: &[u8]| {
        decode(b, &DecodeOptions::default())
            .expect_err("an error")
            .to_string()
    };
    let mut bad_crc = good.clone();
    bad_crc[20] ^= 1; // inside IHDR's data
    assert_eq!(
        err(&bad_crc),
        "corrupt or truncated PNG file: chunk IHDR fails its CRC check"
    );
    assert_eq!(
        err(&good[..good.len() - 12]),
        "corrupt or truncated PNG file: the file ends before the IEND chunk"
    );
    assert_eq!(
        err(&good[..45]),
        "corrupt or truncated PNG file: the file ends inside chunk tEXt"
    );
    assert_eq!(
        err(&good[..38]),
        "corrupt or truncated PNG file: the file ends inside a chunk header"
    );
    let mut depth = good.clone();
    depth[24] = 3;
    let crc_ok = crc32(&[&depth[12..29]]).to_be_bytes();
    depth[29..33].copy_from_slice(&crc_ok);
    assert_eq!(
        err(&depth),
        "corrupt or truncated PNG file: colour type 0 with bit depth 3"
    );
    for i in 8..good.len() {
        let mut damaged = good.clone();
        damaged[i] ^= 0x3C;
        let _ = decode(&damaged, &DecodeOptions::default());
    }
}
