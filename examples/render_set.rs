//! Render the benchmark image sets with ground truth (used by
//! benches/compare_opencv.py).
//!
//! Usage: cargo run --release --example render_set -- OUT_DIR [--quick]
//! Writes OUT_DIR/<set>/NNN.png and OUT_DIR/truth.json:
//! `{"<set>": {"target": SPEC, "opencv_pattern": [cols, rows], "images":
//! [{"file", "points": [[x_px, y_px], ...] in id order}]}}`.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use robocal::camera::Camera;
use robocal::synth::{render, Projection, RenderOptions, Rng};
use robocal::target::Target;
use serde_json::json;

struct Set {
    name: &'static str,
    spec: &'static str,
    camera: Camera,
    count: usize,
    max_tilt_rad: f64,
    min_tilt_rad: f64,
    fill: f64,
    blur: f64,
}

fn pose(target: &Target, cam: &Camera, rng: &mut Rng, set: &Set) -> Isometry3<f64> {
    let pts = target.object_points();
    let (mx, my) = (
        pts.iter().map(|p| p.1.x).fold(0.0, f64::max),
        pts.iter().map(|p| p.1.y).fold(0.0, f64::max),
    );
    let tilt = rng.range(set.min_tilt_rad, set.max_tilt_rad);
    let dir = rng.range(0.0, std::f64::consts::TAU);
    let roll = rng.range(-0.5, 0.5);
    let r = UnitQuaternion::from_euler_angles(tilt * dir.cos(), tilt * dir.sin(), roll);
    // Distance so that the board spans `fill` of the image width.
    let span = (mx * mx + my * my).sqrt();
    let dist = cam.fx * span / (set.fill * cam.width as f64);
    let off = (rng.range(-0.1, 0.1) * dist, rng.range(-0.08, 0.08) * dist);
    let t = Vector3::new(off.0, off.1, dist) - r * Vector3::new(mx / 2.0, my / 2.0, 0.0);
    Isometry3::from_parts(Translation3::from(t), r)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = std::path::PathBuf::from(
        args.first()
            .cloned()
            .unwrap_or_else(|| "benches/out".into()),
    );
    let quick = args.iter().any(|a| a == "--quick");
    let n = |k: usize| if quick { k.div_ceil(4) } else { k };
    let pin = Camera::example_pinhole();
    let brown = Camera::example_brown();
    let vga = Camera::pinhole(560.0, 560.0, 319.5, 239.5, 640, 480);
    let big = Camera::pinhole(3400.0, 3400.0, 1999.5, 1499.5, 4000, 3000);
    let sets = [
        Set {
            name: "chessboard_vga",
            spec: "chessboard:9x6:30mm",
            camera: vga,
            count: n(20),
            min_tilt_rad: 0.0,
            max_tilt_rad: 0.7,
            fill: 0.6,
            blur: 0.7,
        },
        Set {
            name: "chessboard_1280_sigma2",
            spec: "chessboard:9x6:30mm",
            camera: pin.clone(),
            count: n(20),
            min_tilt_rad: 0.0,
            max_tilt_rad: 0.7,
            fill: 0.6,
            blur: 0.7,
        },
        Set {
            name: "chessboard_distorted_steep",
            spec: "chessboard:9x6:30mm",
            camera: brown,
            count: n(20),
            min_tilt_rad: 0.8,
            max_tilt_rad: 1.1,
            fill: 0.7,
            blur: 1.0,
        },
        Set {
            name: "chessboard_blurred",
            spec: "chessboard:9x6:30mm",
            camera: pin.clone(),
            count: n(10),
            min_tilt_rad: 0.0,
            max_tilt_rad: 0.6,
            fill: 0.6,
            blur: 2.5,
        },
        Set {
            name: "chessboard_12mp",
            spec: "chessboard:9x6:30mm",
            camera: big,
            count: n(4),
            min_tilt_rad: 0.0,
            max_tilt_rad: 0.6,
            fill: 0.6,
            blur: 1.5,
        },
        Set {
            name: "circles_asymmetric_4x11",
            spec: "circles:4x11:20mm:asymmetric",
            camera: pin.clone(),
            count: n(10),
            min_tilt_rad: 0.0,
            max_tilt_rad: 0.6,
            fill: 0.5,
            blur: 0.7,
        },
        Set {
            name: "circles_asymmetric_steep_distorted",
            spec: "circles:4x11:20mm:asymmetric",
            camera: Camera::example_brown(),
            count: n(10),
            min_tilt_rad: 0.7,
            max_tilt_rad: 0.87,
            fill: 0.5,
            blur: 0.7,
        },
        Set {
            name: "circles_symmetric_steep_distorted",
            spec: "circles:7x5:20mm",
            camera: Camera::example_brown(),
            count: n(10),
            min_tilt_rad: 0.7,
            max_tilt_rad: 0.87,
            fill: 0.5,
            blur: 0.7,
        },
        Set {
            name: "circles_symmetric_7x5",
            spec: "circles:7x5:20mm",
            camera: pin,
            count: n(10),
            min_tilt_rad: 0.0,
            max_tilt_rad: 0.6,
            fill: 0.5,
            blur: 0.7,
        },
    ];
    let mut truth = serde_json::Map::new();
    let mut rng = Rng::new(20240611);
    for set in &sets {
        let target = Target::parse_spec(set.spec).expect("valid spec");
        let dir = out.join(set.name);
        std::fs::create_dir_all(&dir).expect("create output folder");
        let mut images = Vec::new();
        let mut k = 0;
        while images.len() < set.count {
            k += 1;
            let p = pose(&target, &set.camera, &mut rng, set);
            let o = RenderOptions {
                seed: rng.next_u64(),
                blur_sigma_px: set.blur,
                vignetting: rng.range(0.0, 0.4),
                gradient: rng.range(-0.3, 0.3),
                noise_sigma: 2.0,
                ..RenderOptions::default()
            };
            let r = render(&set.camera as &dyn Projection, &target, &p, &o).expect("render");
            if r.points.len() != target.point_count() || k > 10 * set.count {
                continue; // keep only views with the whole board inside
            }
            let file = dir.join(format!("{:03}.png", images.len()));
            std::fs::write(&file, robocal::image::encode_png(&r.image).expect("png"))
                .expect("write png");
            let pts: Vec<[f64; 2]> = r.points.iter().map(|q| [q.x_px, q.y_px]).collect();
            images.push(json!({"file": file.to_string_lossy(), "points": pts}));
        }
        let (cols, rows) = match target {
            Target::Chessboard { cols, rows, .. } | Target::CircleGrid { cols, rows, .. } => {
                (cols, rows)
            }
            _ => (0, 0),
        };
        truth.insert(
            set.name.into(),
            json!({"target": set.spec, "opencv_pattern": [cols, rows], "images": images}),
        );
        eprintln!("{}: {} images", set.name, set.count);
    }
    std::fs::write(
        out.join("truth.json"),
        serde_json::to_string(&truth).expect("json"),
    )
    .expect("write truth");
}
