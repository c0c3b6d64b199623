//! Render every target kind in both prints, in a usual and a hard
//! (small, blurred, low-contrast) condition, detect it with robocal and
//! write everything for benches/recall_table.py (which runs OpenCV 4.14 on
//! the same PNGs): the per-kind recall table of BENCHMARKS.md (issue 36).
//!
//! Usage: cargo run --example recall_table -- OUT_DIR [--views N]
//!
//! 1280x960 pinhole, f = 1100 px, seeded poses tilted up to ~40 degrees.
//! Usual: the board about 55 % of the image width across, noise sigma 2,
//! blur 0.7 px, print 30 / 220. Hard: twice as far (half the size: markers
//! and squares 12-25 px), blur 1.4 px, print 80 / 170, noise sigma 2.
//! Writes OUT_DIR/<kind>_<print>_<condition>/NNN.png and OUT_DIR/recall.json:
//! `[{"set", "kind", "spec", "print", "condition", "images": [{"file",
//! "truth": [[id, x, y]], "robocal": [[id, x, y]] | null, "error",
//! "robocal_ms"}]}]` (`robocal_ms`: the wall time of the one `detect` call,
//! one thread; meaningful in a release build).

use robocal::detect::{detect, DetectOptions};
use robocal::synth::{board_pose, render, Pinhole, RenderOptions, Rng};
use robocal::target::{Polarity, Target};
use serde_json::{json, Value};

/// (kind, spec detected, spec rendered light on dark (circle grids carry
/// their print in the spec)).
const KINDS: [(&str, &str, &str); 7] = [
    ("chessboard", "chessboard:8x6:30mm", ""),
    ("charuco", "charuco:12x9:20mm:15mm:DICT_5X5_100", ""),
    ("aprilgrid", "aprilgrid:6x6:40mm:0.3", ""),
    ("arucogrid", "arucogrid:5x7:30mm:8mm:DICT_6X6_250", ""),
    (
        "circles_sym",
        "circles:7x5:20mm",
        "circles:7x5:20mm:light-on-dark",
    ),
    (
        "circles_asym",
        "circles:4x11:20mm:asymmetric",
        "circles:4x11:20mm:asymmetric:light-on-dark",
    ),
    ("dots", "dots:7x7:25mm", ""),
];

fn camera() -> Pinhole {
    Pinhole {
        fx: 1100.0,
        fy: 1100.0,
        cx: 642.8,
        cy: 477.4,
        width: 1280,
        height: 960,
    }
}

fn save(img: &robocal::image::GrayImage, path: &str) {
    let png = robocal::image::encode_png(img).expect("encode png");
    std::fs::write(path, png).expect("write png");
}

fn points(p: &[robocal::target::DetectedPoint]) -> Vec<Value> {
    p.iter().map(|p| json!([p.id, p.x_px, p.y_px])).collect()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut out = None;
    let mut views = 6usize;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--views" => views = args.next().and_then(|v| v.parse().ok()).expect("--views N"),
            _ => out = Some(a),
        }
    }
    let out = out.expect("usage: recall_table OUT_DIR [--views N]");
    let cam = camera();
    let mut sets = Vec::new();
    for (kind, spec, inverted_spec) in KINDS {
        for print in [Polarity::DarkOnLight, Polarity::LightOnDark] {
            let print_name = match print {
                Polarity::DarkOnLight => "dark_on_light",
                Polarity::LightOnDark => "light_on_dark",
            };
            // Circle grids carry the print in their spec; the others are
            // rendered inverted and detected without a print option.
            let (render_spec, detect_spec, render_print) = match (print, inverted_spec) {
                (Polarity::LightOnDark, s) if !s.is_empty() => (s, s, Polarity::DarkOnLight),
                _ => (spec, spec, print),
            };
            let target = Target::parse_spec(render_spec).expect("spec");
            let det_target = Target::parse_spec(detect_spec).expect("spec");
            let pts = target.object_points();
            let wx = pts.iter().map(|p| p.1.x).fold(0.0, f64::max);
            let wy = pts.iter().map(|p| p.1.y).fold(0.0, f64::max);
            let usual_z = 1100.0 * wx.max(wy) / (0.55 * 1280.0);
            for (condition, z, blur, black, white) in [
                ("usual", usual_z, 0.7, 30.0, 220.0),
                ("hard", 2.0 * usual_z, 1.4, 80.0, 170.0),
            ] {
                let set = format!("{kind}_{print_name}_{condition}");
                std::fs::create_dir_all(format!("{out}/{set}")).expect("mkdir");
                let mut rng = Rng::new(7);
                let mut images = Vec::new();
                for k in 0..views {
                    let rpy = (
                        rng.range(-0.45, 0.45),
                        rng.range(-0.45, 0.45),
                        rng.range(-0.6, 0.6),
                    );
                    let at = (rng.range(-0.05, 0.05) * z, rng.range(-0.04, 0.04) * z, z);
                    // The print last: it swaps the black and white set here.
                    let o = RenderOptions {
                        seed: 300 + k as u64,
                        blur_sigma_px: blur,
                        black,
                        white,
                        ..RenderOptions::default()
                    }
                    .printed(render_print);
                    let r =
                        render(&cam, &target, &board_pose(&target, rpy, at), &o).expect("render");
                    let file = format!("{out}/{set}/{k:03}.png");
                    save(&r.image, &file);
                    let start = std::time::Instant::now();
                    let detected = detect(&r.image, &det_target, &DetectOptions::default());
                    let ms = start.elapsed().as_secs_f64() * 1e3;
                    let result = match detected {
                        Ok(d) => json!({"robocal": points(&d.points), "robocal_ms": ms}),
                        Err(e) => {
                            json!({"robocal": null, "error": e.to_string(), "robocal_ms": ms})
                        }
                    };
                    eprintln!(
                        "{set} {k}: {} in view, robocal {}",
                        r.points.len(),
                        result["robocal"].as_array().map_or(0, Vec::len)
                    );
                    let mut image = json!({"file": file, "truth": points(&r.points)});
                    if let (Some(m), Value::Object(r)) = (image.as_object_mut(), result) {
                        m.extend(r);
                    }
                    images.push(image);
                }
                sets.push(json!({
                    "set": set, "kind": kind, "spec": detect_spec, "print": print_name,
                    "condition": condition, "images": images,
                }));
            }
        }
    }
    std::fs::write(format!("{out}/recall.json"), Value::Array(sets).to_string())
        .expect("write json");
}
