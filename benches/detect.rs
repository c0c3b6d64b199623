//! `cargo bench --bench detect`: chessboard detection time on rendered
//! images at VGA, 1.2 MP and 12 MP (medians of repeated runs, one thread).

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use robocal::detect::{detect, DetectOptions};
use robocal::synth::{render, Pinhole, RenderOptions};
use robocal::target::Target;
use std::time::Instant;

fn scene(w: u32, h: u32) -> robocal::image::GrayImage {
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

fn main() {
    let target = Target::parse_spec("chessboard:9x6:30mm").expect("spec");
    for (name, w, h, runs) in [
        ("VGA 640x480", 640, 480, 31),
        ("1.2 MP 1280x960", 1280, 960, 21),
        ("12 MP 4000x3000", 4000, 3000, 7),
    ] {
        let img = scene(w, h);
        let mut times = Vec::new();
        for _ in 0..runs {
            let t0 = Instant::now();
            let d = detect(&img, &target, &DetectOptions::default()).expect("board found");
            times.push(t0.elapsed().as_secs_f64() * 1000.0);
            assert_eq!(d.points.len(), 54);
        }
        times.sort_by(f64::total_cmp);
        let blank =
            robocal::image::GrayImage::new(w, h, vec![128; (w * h) as usize]).expect("blank");
        let t0 = Instant::now();
        let _ = detect(&blank, &target, &DetectOptions::default());
        let blank_ms = t0.elapsed().as_secs_f64() * 1000.0;
        println!("{name:18} median {:8.2} ms  (min {:8.2}, max {:8.2}, {runs} runs); blank image {blank_ms:8.2} ms", times[runs / 2], times[0], times[runs - 1]);
    }
}
