//! `cargo bench --bench detect`: detection time on rendered images, one
//! thread, medians of repeated runs: chessboards at VGA, 1.2 MP and 12 MP;
//! Zhang's square grid at VGA through his lens; an asymmetric circle grid
//! and a dot plate at 1.2 MP (perspective-correct centres, the default).
//! Per-stage costs come from callgrind on the `detect_time` example
//! (BENCHMARKS.md), not from clocks inside the library.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use robocal::camera::Camera;
use robocal::detect::{detect, CentreModel, DetectOptions};
use robocal::synth::{board_pose, render, Pinhole, Projection, RenderOptions};
use robocal::target::Target;
use robocal::Distortion;
use std::time::Instant;

fn chessboard_scene(w: u32, h: u32) -> robocal::image::GrayImage {
    let target = Target::parse_spec("chessboard:9x6:30mm").expect("spec");
    let f = 0.85 * w as f64;
    let cam = Pinhole {
        fx: f,
        fy: f,
        cx: (w as f64 - 1.0) / 2.0,
        cy: (h as f64 - 1.0) / 2.0,
        width: w,
        height: h,
    };
    let r = UnitQuaternion::from_euler_angles(0.3, -0.25, 0.1);
    let t = Vector3::new(0.0, 0.0, 0.5) - r * Vector3::new(0.12, 0.075, 0.0);
    let pose = Isometry3::from_parts(Translation3::from(t), r);
    render(
        &cam,
        &target,
        &pose,
        &RenderOptions {
            blur_sigma_px: 0.7 * w as f64 / 1280.0,
            ..RenderOptions::default()
        },
    )
    .expect("render")
    .image
}

/// Zhang's camera (his 1998 calibration, 640x480, k1 -0.2286, k2 0.1904).
fn zhang_camera() -> Camera {
    Camera {
        distortion: Distortion::Brown {
            k1: -0.228601,
            k2: 0.190353,
            k3: 0.0,
            p1: 0.0,
            p2: 0.0,
        },
        ..Camera::pinhole(832.5, 832.53, 303.959, 206.585, 640, 480)
    }
}

fn scene(
    cam: &dyn Projection,
    spec: &str,
    rpy: (f64, f64, f64),
    z: f64,
) -> robocal::image::GrayImage {
    let target = Target::parse_spec(spec).expect("spec");
    let pose = board_pose(&target, rpy, (0.004, 0.01, z));
    let r = render(cam, &target, &pose, &RenderOptions::default()).expect("render");
    assert_eq!(
        r.points.len(),
        target.point_count(),
        "{spec}: whole board in view"
    );
    r.image
}

fn time(
    name: &str,
    img: &robocal::image::GrayImage,
    spec: &str,
    options: &DetectOptions,
    runs: usize,
) {
    let target = Target::parse_spec(spec).expect("spec");
    let mut times = Vec::new();
    for _ in 0..runs {
        let t0 = Instant::now();
        let d = detect(img, &target, options).expect("board found");
        times.push(t0.elapsed().as_secs_f64() * 1000.0);
        assert_eq!(d.points.len(), target.point_count());
    }
    times.sort_by(f64::total_cmp);
    let (w, h) = (img.width, img.height);
    let blank = robocal::image::GrayImage::new(w, h, vec![128; (w * h) as usize]).expect("blank");
    let t0 = Instant::now();
    let _ = detect(&blank, &target, options);
    let blank_ms = t0.elapsed().as_secs_f64() * 1000.0;
    println!(
        "{name:34} median {:8.2} ms  (min {:8.2}, max {:8.2}, {runs} runs); blank image {blank_ms:8.2} ms",
        times[runs / 2],
        times[0],
        times[runs - 1]
    );
}

fn main() {
    // `cargo bench --bench detect -- NAME [RUNS]`: only the cases whose
    // name contains NAME, RUNS times each (for callgrind: RUNS = 1).
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let only = args.first().cloned().unwrap_or_default();
    let runs_override: Option<usize> = args.get(1).and_then(|r| r.parse().ok());
    let time = |name: &str,
                img: &robocal::image::GrayImage,
                spec: &str,
                options: &DetectOptions,
                runs: usize| {
        if name.contains(only.as_str()) {
            time(name, img, spec, options, runs_override.unwrap_or(runs));
        }
    };
    let default = DetectOptions::default();
    for (name, w, h, runs) in [
        ("chessboard VGA 640x480", 640, 480, 31),
        ("chessboard 1.2 MP 1280x960", 1280, 960, 21),
        ("chessboard 12 MP 4000x3000", 4000, 3000, 7),
    ] {
        time(
            name,
            &chessboard_scene(w, h),
            "chessboard:9x6:30mm",
            &default,
            runs,
        );
    }
    let squares = "squares:8x8:12.7mm:22.5778mm";
    for (name, rpy, z) in [
        ("squares 8x8 VGA, frontal", (0.05, 0.1, 0.02), 0.42),
        ("squares 8x8 VGA, 40 deg", (0.5, -0.45, 0.1), 0.48),
    ] {
        time(
            name,
            &scene(&zhang_camera(), squares, rpy, z),
            squares,
            &default,
            31,
        );
    }
    let pin = Camera::example_pinhole();
    for spec in ["circles:4x11:20mm:asymmetric", "dots:7x7:25mm"] {
        let img = scene(&pin, spec, (0.5, -0.4, 0.2), 0.5);
        time(&format!("{spec} 1.2 MP"), &img, spec, &default, 21);
        let ellipse = DetectOptions {
            circle_centres: CentreModel::EllipseCentre,
            ..DetectOptions::default()
        };
        time(&format!("{spec} 1.2 MP ellipse"), &img, spec, &ellipse, 21);
    }
}
