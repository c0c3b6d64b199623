//! Render the marker-board comparison sets, detect them with robocal in this
//! process (one thread, decoding excluded) and write everything for
//! benches/compare_markers.py.
//!
//! Usage: cargo run --release --example marker_compare -- OUT_DIR [--views N] [--repeat N]
//!
//! Sets (1280x960 pinhole, f = 1100 px, noise sigma 2 grey levels, blur
//! 0.7 px, seeded): ChArUco 12x9 DICT_5X5_100 full and partial views, the
//! chessboard with the same corner geometry (chessboard:11x8:20mm) at the
//! same poses and noise seeds, AprilGrid 6x6 full and partial views, and
//! board-free images (the chessboard renders, uniform noise and seeded
//! clutter of quads, ellipses and strokes: `synth::clutter`) for false
//! markers. Writes OUT_DIR/<set>/NNN.png and OUT_DIR/markers.json:
//! `{"<set>": {"target", "images": [{"file", "truth": [[id, x, y]],
//! "robocal": {"ms", "points": [[id, x, y]] | null, "error"}}]}}`; the
//! board-free set holds one robocal result per marker spec.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use robocal::detect::{detect, DetectOptions};
use robocal::image::GrayImage;
use robocal::synth::{render, Pinhole, RenderOptions, Rng};
use robocal::target::Target;
use serde_json::{json, Value};
use std::time::Instant;

const CHARUCO: &str = "charuco:12x9:20mm:15mm:DICT_5X5_100";
const CHESS: &str = "chessboard:11x8:20mm";
const APRILGRID: &str = "aprilgrid:6x6:40mm:0.3";

fn camera() -> Pinhole {
    Pinhole {
        fx: 1100.0,
        fy: 1100.0,
        cx: 639.5 + 3.3,
        cy: 479.5 - 2.1,
        width: 1280,
        height: 960,
    }
}

/// A random pose: tilt up to ~40 deg, the board's centre at `centre`
/// (metres, camera frame).
fn pose(target: &Target, rng: &mut Rng, centre: Vector3<f64>) -> Isometry3<f64> {
    let pts = target.object_points();
    let mx = pts.iter().map(|p| p.1.x).fold(0.0, f64::max) / 2.0;
    let my = pts.iter().map(|p| p.1.y).fold(0.0, f64::max) / 2.0;
    let tilt = rng.range(0.0, 0.7);
    let dir = rng.range(0.0, std::f64::consts::TAU);
    let r =
        UnitQuaternion::from_euler_angles(tilt * dir.cos(), tilt * dir.sin(), rng.range(-0.5, 0.5));
    Isometry3::from_parts(
        Translation3::from(centre - r * Vector3::new(mx, my, 0.0)),
        r,
    )
}

/// The board's centre: near the image centre, or (partial) pushed towards a
/// random edge so that roughly a third to a half of the board is outside.
fn centre(rng: &mut Rng, z: f64, partial: bool) -> Vector3<f64> {
    if !partial {
        return Vector3::new(
            rng.range(-0.03, 0.03) * z / 0.4,
            rng.range(-0.02, 0.02) * z / 0.4,
            z,
        );
    }
    let (hx, hy) = (640.0 / 1100.0 * z, 480.0 / 1100.0 * z);
    match rng.below(4) {
        0 => Vector3::new(hx * rng.range(0.75, 1.0), rng.range(-0.3, 0.3) * hy, z),
        1 => Vector3::new(-hx * rng.range(0.75, 1.0), rng.range(-0.3, 0.3) * hy, z),
        2 => Vector3::new(rng.range(-0.3, 0.3) * hx, hy * rng.range(0.75, 1.0), z),
        _ => Vector3::new(rng.range(-0.3, 0.3) * hx, -hy * rng.range(0.75, 1.0), z),
    }
}

fn save(img: &GrayImage, path: &str) {
    let png = robocal::image::encode_png(img).expect("encode png");
    std::fs::write(path, png).expect("write png");
}

/// robocal's detection: median time of `repeat` calls and the points.
fn robocal(img: &GrayImage, target: &Target, repeat: usize) -> Value {
    let opts = DetectOptions::default();
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..repeat {
        let t0 = Instant::now();
        let r = detect(img, target, &opts);
        times.push(t0.elapsed().as_secs_f64() * 1000.0);
        last = Some(r);
    }
    times.sort_by(f64::total_cmp);
    let ms = times[times.len() / 2];
    match last.expect("repeat >= 1") {
        Ok(d) => {
            let pts: Vec<Value> = d
                .points
                .iter()
                .map(|p| json!([p.id, p.x_px, p.y_px]))
                .collect();
            json!({"ms": ms, "points": pts})
        }
        Err(e) => json!({"ms": ms, "points": null, "error": e.to_string()}),
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut out = None;
    let (mut views, mut repeat) = (10usize, 5usize);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--views" => views = args.next().and_then(|v| v.parse().ok()).expect("--views N"),
            "--repeat" => {
                repeat = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .expect("--repeat N")
            }
            _ => out = Some(a),
        }
    }
    let out = out.expect("usage: marker_compare OUT_DIR [--views N] [--repeat N]");
    let cam = camera();
    let mut sets = serde_json::Map::new();
    // (set, spec rendered, spec detected, distance, partial, pose seed)
    let plan = [
        ("charuco_full", CHARUCO, CHARUCO, 0.42, false, 1u64),
        ("chessboard_same_poses", CHESS, CHESS, 0.42, false, 1),
        ("charuco_partial", CHARUCO, CHARUCO, 0.42, true, 2),
        ("aprilgrid_full", APRILGRID, APRILGRID, 0.6, false, 3),
        ("aprilgrid_partial", APRILGRID, APRILGRID, 0.6, true, 4),
    ];
    for (name, spec, det_spec, z, partial, seed) in plan {
        let target = Target::parse_spec(spec).expect("spec");
        let det_target = Target::parse_spec(det_spec).expect("spec");
        std::fs::create_dir_all(format!("{out}/{name}")).expect("mkdir");
        let mut rng = Rng::new(seed);
        let mut images = Vec::new();
        for k in 0..views {
            let c = centre(&mut rng, z, partial);
            let p = pose(&target, &mut rng, c);
            let o = RenderOptions {
                seed: 100 + k as u64,
                ..RenderOptions::default()
            };
            let r = render(&cam, &target, &p, &o).expect("render");
            let file = format!("{out}/{name}/{k:03}.png");
            save(&r.image, &file);
            let truth: Vec<Value> = r
                .points
                .iter()
                .map(|p| json!([p.id, p.x_px, p.y_px]))
                .collect();
            let det = robocal(&r.image, &det_target, repeat);
            eprintln!(
                "{name} {k}: {} in view, robocal {}",
                r.points.len(),
                det["ms"]
            );
            images.push(json!({"file": file, "truth": truth, "robocal": det}));
        }
        sets.insert(name.into(), json!({"target": spec, "images": images}));
    }
    // Board-free: the chessboard renders, uniform noise and clutter, each
    // searched for both marker boards.
    let mut free = Vec::new();
    let mut files: Vec<String> = (0..views)
        .map(|k| format!("{out}/chessboard_same_poses/{k:03}.png"))
        .collect();
    std::fs::create_dir_all(format!("{out}/noise")).expect("mkdir");
    let mut rng = Rng::new(99);
    for k in 0..3 {
        let px = (0..1280 * 960).map(|_| rng.below(256) as u8).collect();
        let img = GrayImage::new(1280, 960, px).expect("noise image");
        let file = format!("{out}/noise/{k:03}.png");
        save(&img, &file);
        files.push(file);
    }
    std::fs::create_dir_all(format!("{out}/clutter")).expect("mkdir");
    for k in 0..views as u64 {
        let img = robocal::synth::clutter(1280, 960, 500 + k, 2.0);
        let file = format!("{out}/clutter/{k:03}.png");
        save(&img, &file);
        files.push(file);
    }
    for file in files {
        let img =
            robocal::image::decode_gray(&std::fs::read(&file).expect("read")).expect("decode");
        let mut res = serde_json::Map::new();
        for spec in [CHARUCO, APRILGRID] {
            res.insert(
                spec.into(),
                robocal(&img, &Target::parse_spec(spec).expect("spec"), repeat),
            );
        }
        free.push(json!({"file": file, "robocal": res}));
    }
    sets.insert(
        "board_free".into(),
        json!({"targets": [CHARUCO, APRILGRID], "images": free}),
    );
    std::fs::write(
        format!("{out}/markers.json"),
        Value::Object(sets).to_string(),
    )
    .expect("write json");
}
