//! Does the camera's reported std cover the truth when the views share an
//! error, and does the views' check stay quiet when they do not? (issue 35,
//! `src/calib/view_spread.rs`.)
//!
//! `cargo run --release --example view_spread_coverage -- TRIALS [VIEWS]
//! [NOISE_PX] [MAGNIFY]`: TRIALS seeded scenes (seeds 20000 on) of the
//! example Brown camera (1280x960), a 9x6 board of 30 mm in VIEWS views
//! (default 15) with NOISE_PX pixel noise (default 0.2); with MAGNIFY,
//! each view's pixels are also stretched about the image centre by its own
//! factors `1 + m_x` across and `1 + m_y` down, each of std MAGNIFY (an
//! error shared by the corners of an image that its pose cannot absorb,
//! like a focus that changes between images on a sensor that is not
//! square to the lens). Prints, for fx, fy,
//! cx and cy, the share of trials with the truth within 3 reported std,
//! the mean abs(error) / std, and how often the views' check warned.

use nalgebra::Point2;
use robocal::calib::{calibrate, CalibrationOptions, View};
use robocal::camera::Camera;
use robocal::optim::wilson::wilson_interval_95;
use robocal::synth::{Rng, Scene};

const WARNING: &str = "the views disagree more than their residuals say";

fn views(seed: u64, camera: &Camera, n: usize, noise: f64, magnify: f64) -> Vec<View> {
    let scene = Scene::calibration(seed, camera, (9, 6), 0.03, n, noise).expect("scene");
    let (cx, cy) = (camera.width as f64 / 2.0, camera.height as f64 / 2.0);
    let mut rng = Rng::new(seed ^ 0x5eed);
    scene
        .views
        .into_iter()
        .map(|mut v| {
            let (mx, my) = (1.0 + rng.gaussian(magnify), 1.0 + rng.gaussian(magnify));
            for p in &mut v.image_px {
                *p = Point2::new(cx + mx * (p.x - cx), cy + my * (p.y - cy));
            }
            v
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: f64| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(default);
    let trials = arg(0, 50.0) as u64;
    let n_views = arg(1, 15.0) as usize;
    let noise = arg(2, 0.2);
    let magnify = arg(3, 0.0);
    let camera = Camera::example_brown();
    let truth = camera.camera_matrix();
    let want = [truth[(0, 0)], truth[(1, 1)], truth[(0, 2)], truth[(1, 2)]];
    let names = ["fx", "fy", "cx", "cy"];
    let mut covered = [0u64; 4];
    let mut ratio = [0.0f64; 4];
    let (mut warned, mut done, mut all_covered) = (0u64, 0u64, 0u64);
    let mut warned_covered = 0u64;
    for t in 0..trials {
        let seed = 20_000 + t;
        let views = views(seed, &camera, n_views, noise, magnify);
        let report = match calibrate(
            &views,
            (camera.width, camera.height),
            &CalibrationOptions::default(),
        ) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("seed {seed}: {e}");
                continue;
            }
        };
        done += 1;
        let w = report.warnings.iter().find(|w| w.starts_with(WARNING));
        if let Some(w) = w {
            warned += 1;
            if magnify == 0.0 {
                println!("seed {seed}: {}", &w[..w.len().min(260)]);
            }
        }
        let k = report.camera_matrix;
        let got = [k[0][0], k[1][1], k[0][2], k[1][2]];
        let mut all = true;
        for i in 0..4 {
            let std = report.std[names[i]];
            let z = (got[i] - want[i]).abs() / std;
            ratio[i] += z;
            if z <= 3.0 {
                covered[i] += 1;
            } else {
                all = false;
            }
        }
        all_covered += all as u64;
        warned_covered += (all && w.is_some()) as u64;
    }
    println!(
        "{done} trials, {n_views} views, noise {noise} px, magnify {magnify}: warned {warned} ({:.1} %)",
        100.0 * warned as f64 / done.max(1) as f64
    );
    for i in 0..4 {
        let (lo, hi) = wilson_interval_95(covered[i] as usize, done as usize);
        println!(
            "{}: within 3 std {:.1} % ({:.1}-{:.1} %), mean abs(error)/std {:.2}",
            names[i],
            100.0 * covered[i] as f64 / done.max(1) as f64,
            100.0 * lo,
            100.0 * hi,
            ratio[i] / done.max(1) as f64
        );
    }
    println!(
        "all four within 3 std: {:.1} % (warned trials: {warned_covered} of {warned}; the others: {} of {})",
        100.0 * all_covered as f64 / done.max(1) as f64,
        all_covered - warned_covered,
        done - warned
    );
}
