//! The small, low-contrast marker boards of
//! tests/detect/detect_marker_recall.rs (ChArUco 10x7 DICT_4X4_50 with
//! 16-21 px markers, AprilGrid 7x5 with 18-24 px tags; 1280x720, f = 900
//! px; the test's six poses under its three conditions: blur 1.2-1.6 px,
//! print 30 / 220, 80 / 170 and 100 / 160, noise sigma 2-3), rendered with
//! their truth for OpenCV (benches/marker_recall_opencv.py) and detected by
//! robocal in this process (issue 36).
//!
//! Usage: cargo run --example marker_recall_set -- [OUT_DIR]
//! (default benches/out/marker_recall). Writes OUT_DIR/<set>/NNN.png and
//! OUT_DIR/recall.json in examples/recall_table.rs's shape (`[{"set",
//! "kind", "spec", "print", "condition", "images": [{"file", "truth":
//! [[id, x, y]], "robocal": [[id, x, y]] | null, "error"}]}]`) with each
//! set's `"markers": [[id, [[x, y] x 4]]]` (board metres, OpenCV's corner
//! order) for OpenCV's refinement from the board.
//!
//! The scene is `robocal::synth::small_markers`, the test's own: the bench
//! compares OpenCV with the test's floors.

use robocal::detect::{detect, DetectOptions};
use robocal::synth::small_markers;
use robocal::target::{marker_board, Target};
use serde_json::{json, Value};

/// (kind, spec): the test's two boards.
const BOARDS: [(&str, &str); 2] = [
    ("charuco", "charuco:10x7:30mm:22mm:DICT_4X4_50"),
    ("aprilgrid", "aprilgrid:7x5:25mm:0.3"),
];

fn save(img: &robocal::image::GrayImage, path: &str) {
    let png = robocal::image::encode_png(img).expect("encode png");
    std::fs::write(path, png).expect("write png");
}

fn points(p: &[robocal::target::DetectedPoint]) -> Vec<Value> {
    p.iter().map(|p| json!([p.id, p.x_px, p.y_px])).collect()
}

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "benches/out/marker_recall".to_string());
    let mut sets = Vec::new();
    for (kind, spec) in BOARDS {
        let target = Target::parse_spec(spec).expect("spec");
        let markers: Vec<Value> = marker_board::layout(&target)
            .expect("a marker board")
            .markers
            .iter()
            .map(|m| {
                json!([
                    m.id,
                    m.corners
                        .iter()
                        .map(|c| json!([c.x, c.y]))
                        .collect::<Vec<_>>()
                ])
            })
            .collect();
        for (c, k) in small_markers::CONDITIONS.iter().enumerate() {
            let condition = format!(
                "blur {}, print {}/{}, noise {}",
                k.blur, k.black, k.white, k.noise
            );
            let set = format!("{kind}_{c}");
            std::fs::create_dir_all(format!("{out}/{set}")).expect("mkdir");
            let mut images = Vec::new();
            for v in 0..small_markers::VIEWS.len() {
                let r = small_markers::render_view(&target, c, v).expect("render");
                let file = format!("{out}/{set}/{v:03}.png");
                save(&r.image, &file);
                let result = match detect(&r.image, &target, &DetectOptions::default()) {
                    Ok(d) => json!({"robocal": points(&d.points)}),
                    Err(e) => json!({"robocal": null, "error": e.to_string()}),
                };
                eprintln!(
                    "{set} {v}: {} in view, robocal {}",
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
                "set": set, "kind": kind, "spec": spec, "print": "dark_on_light",
                "condition": condition, "markers": markers, "images": images,
            }));
        }
    }
    std::fs::write(format!("{out}/recall.json"), Value::Array(sets).to_string())
        .expect("write json");
}
