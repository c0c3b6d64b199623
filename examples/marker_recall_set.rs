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
//! The poses and conditions must stay the test's (`VIEWS`, `CONDITIONS`
//! there): the bench compares OpenCV with the test's floors.

use robocal::detect::{detect, DetectOptions};
use robocal::synth::{board_pose, render, Pinhole, RenderOptions};
use robocal::target::{marker_board, Target};
use serde_json::{json, Value};

/// A pose: (roll, pitch, yaw) radians, board centre (metres).
type View = ((f64, f64, f64), (f64, f64, f64));

/// tests/detect/detect_marker_recall.rs's `VIEWS`.
const VIEWS: [View; 6] = [
    ((0.1, -0.2, 0.05), (0.0, 0.0, 1.0)),
    ((0.45, 0.3, -0.3), (0.12, -0.05, 1.1)),
    ((-0.35, 0.5, 0.6), (-0.15, 0.08, 1.2)),
    ((0.6, 0.0, 0.2), (0.05, 0.1, 0.95)),
    ((0.0, -0.55, -0.1), (-0.1, -0.1, 1.05)),
    ((0.3, 0.3, 1.2), (0.2, 0.05, 1.25)),
];

/// tests/detect/detect_marker_recall.rs's `CONDITIONS`: (blur sigma px,
/// black, white, noise sigma).
const CONDITIONS: [(f64, f64, f64, f64); 3] = [
    (1.2, 30.0, 220.0, 2.0),
    (1.6, 80.0, 170.0, 2.0),
    (1.4, 100.0, 160.0, 3.0),
];

/// (kind, spec): the test's two boards.
const BOARDS: [(&str, &str); 2] = [
    ("charuco", "charuco:10x7:30mm:22mm:DICT_4X4_50"),
    ("aprilgrid", "aprilgrid:7x5:25mm:0.3"),
];

fn webcam() -> Pinhole {
    Pinhole {
        fx: 900.0,
        fy: 900.0,
        cx: 641.2,
        cy: 358.7,
        width: 1280,
        height: 720,
    }
}

fn save(img: &robocal::image::GrayImage, path: &str) {
    image::GrayImage::from_raw(img.width, img.height, img.pixels.clone())
        .expect("image buffer")
        .save(path)
        .expect("write png");
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
        for (c, &(blur, black, white, noise)) in CONDITIONS.iter().enumerate() {
            let condition = format!("blur {blur}, print {black}/{white}, noise {noise}");
            let set = format!("{kind}_{c}");
            std::fs::create_dir_all(format!("{out}/{set}")).expect("mkdir");
            let mut images = Vec::new();
            for (v, &(rpy, at)) in VIEWS.iter().enumerate() {
                let o = RenderOptions {
                    blur_sigma_px: blur,
                    black,
                    white,
                    noise_sigma: noise,
                    seed: (10 * c + v) as u64,
                    ..RenderOptions::default()
                };
                let r =
                    render(&webcam(), &target, &board_pose(&target, rpy, at), &o).expect("render");
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
