//! Time chessboard detection on PNG files (decoding excluded), one thread;
//! also a blank and a noise image of the first file's size.
//!
//! Usage: cargo run --release --example detect_time -- [--target SPEC]
//! [--repeat N] [--no-blank] [--decode] [--truth benches/out/truth.json] FILES...   (default target chessboard:9x6:30mm, 11 repeats)
//! `--decode` times decoding + detection (as the wasm `detect_target`
//! does, for benches/wasm_detect.mjs). Prints one line per file (median ms, points found) and the median over
//! files; used for profiling (`valgrind --tool=callgrind ... --repeat 1`).

use robocal::detect::{detect, DetectOptions};
use robocal::image::{decode_gray, GrayImage};
use robocal::synth::Rng;
use robocal::target::Target;
use std::time::Instant;

type Points = Vec<[f64; 2]>;

fn median_ms(img: &GrayImage, target: &Target, repeat: usize) -> (f64, Option<Points>) {
    let mut times = Vec::with_capacity(repeat);
    let mut found = None;
    for _ in 0..repeat {
        let t0 = Instant::now();
        let r = detect(img, target, &DetectOptions::default());
        times.push(t0.elapsed().as_secs_f64() * 1000.0);
        found = r
            .ok()
            .map(|d| d.points.iter().map(|p| [p.x_px, p.y_px]).collect());
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], found)
}

/// Ground-truth points per file from render_set's truth.json.
fn load_truth(path: &str) -> std::collections::HashMap<String, Points> {
    let text = std::fs::read_to_string(path).expect("read truth");
    let v: serde_json::Value = serde_json::from_str(&text).expect("truth JSON");
    let mut out = std::collections::HashMap::new();
    for set in v.as_object().expect("sets").values() {
        for im in set["images"].as_array().expect("images") {
            let pts = im["points"]
                .as_array()
                .expect("points")
                .iter()
                .map(|p| [p[0].as_f64().expect("x"), p[1].as_f64().expect("y")])
                .collect();
            out.insert(im["file"].as_str().expect("file").to_string(), pts);
        }
    }
    out
}

/// Mean and max distance; the order may run from either end.
fn errors(found: &Points, truth: &Points) -> Option<(f64, f64)> {
    if found.len() != truth.len() {
        return None;
    }
    let dist = |rev: bool| -> Vec<f64> {
        (0..found.len())
            .map(|i| {
                let t = truth[if rev { truth.len() - 1 - i } else { i }];
                ((found[i][0] - t[0]).powi(2) + (found[i][1] - t[1]).powi(2)).sqrt()
            })
            .collect()
    };
    [dist(false), dist(true)]
        .into_iter()
        .map(|d| {
            let mean = d.iter().sum::<f64>() / d.len() as f64;
            (mean, d.iter().cloned().fold(0.0, f64::max))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut spec = "chessboard:9x6:30mm".to_string();
    let mut repeat = 11usize;
    let mut files = Vec::new();
    let mut blank_noise = true;
    let mut with_decode = false;
    let mut truth = std::collections::HashMap::new();
    let mut errs = Vec::new();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--target" => spec = args.next().expect("--target SPEC"),
            "--no-blank" => blank_noise = false,
            "--decode" => with_decode = true,
            "--truth" => truth = load_truth(&args.next().expect("--truth FILE")),
            "--repeat" => {
                repeat = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .expect("--repeat N")
            }
            _ => files.push(a),
        }
    }
    let target = Target::parse_spec(&spec).expect("target spec");
    let mut medians = Vec::new();
    let mut size = None;
    for f in &files {
        let bytes = std::fs::read(f).expect("read image");
        let img = decode_gray(&bytes).expect("decode image");
        size.get_or_insert((img.width, img.height));
        let (ms, found) = if with_decode {
            let mut times: Vec<f64> = (0..repeat)
                .map(|_| {
                    let t0 = Instant::now();
                    let img = decode_gray(&bytes).expect("decode image");
                    let _ = detect(&img, &target, &DetectOptions::default());
                    t0.elapsed().as_secs_f64() * 1000.0
                })
                .collect();
            times.sort_by(f64::total_cmp);
            (times[repeat / 2], median_ms(&img, &target, 1).1)
        } else {
            median_ms(&img, &target, repeat)
        };
        let abs = std::fs::canonicalize(f).map(|p| p.display().to_string());
        let err = match (&found, abs.ok().and_then(|a| truth.get(&a))) {
            (Some(pts), Some(t)) => errors(pts, t),
            _ => None,
        };
        if let Some(e) = err {
            errs.push(e);
        }
        let n = found.as_ref().map(|p| p.len());
        println!("{f}: {ms:8.3} ms, {n:?} points, error (mean, max) px {err:?}");
        medians.push(ms);
    }
    if !medians.is_empty() {
        medians.sort_by(f64::total_cmp);
        println!(
            "median over {} files: {:.3} ms",
            medians.len(),
            medians[medians.len() / 2]
        );
    }
    if !errs.is_empty() {
        let mean = errs.iter().map(|e| e.0).sum::<f64>() / errs.len() as f64;
        let max = errs.iter().map(|e| e.1).fold(0.0, f64::max);
        println!(
            "found {} of {}; error mean {mean:.4} px, max {max:.4} px",
            errs.len(),
            files.len()
        );
    }
    if !blank_noise {
        return;
    }
    let (w, h) = size.unwrap_or((1280, 960));
    let blank = GrayImage::new(w, h, vec![128; (w * h) as usize]).expect("blank");
    let mut rng = Rng::new(7);
    let noise: Vec<u8> = (0..w * h).map(|_| rng.below(256) as u8).collect();
    let noise = GrayImage::new(w, h, noise).expect("noise");
    println!(
        "blank {w}x{h}: {:.3} ms",
        median_ms(&blank, &target, repeat).0
    );
    println!(
        "noise {w}x{h}: {:.3} ms",
        median_ms(&noise, &target, repeat).0
    );
}
