//! Tests of the square-grid detector.

use super::edges::{edge_on_profile, Profile};
use super::*;
use crate::camera::Camera;
use crate::synth::{render, RenderOptions};
use crate::target::Target;

/// Zhang's lens scaled to 1280x960: f 1665 px, k1 -0.2286, k2 0.1904.
#[cfg(not(target_arch = "wasm32"))]
fn zhang_camera() -> Camera {
    Camera {
        distortion: crate::camera::Distortion::Brown {
            k1: -0.228601,
            k2: 0.190353,
            k3: 0.0,
            p1: 0.0,
            p2: 0.0,
        },
        ..Camera::pinhole(1665.0, 1665.1, 607.9, 413.2, 1280, 960)
    }
}

use crate::synth::board_pose as pose;

/// Mean and max corner error of `model` over `views` (rpy, distance).
#[cfg(not(target_arch = "wasm32"))]
fn errors(model: SideModel, noise: f64, views: &[((f64, f64, f64), f64)]) -> (f64, f64) {
    let target = Target::parse_spec("squares:8x8:12.7mm:22.5778mm").unwrap();
    let cam = zhang_camera();
    let (mut sum, mut max, mut n) = (0.0, 0.0f64, 0.0);
    for (k, (rpy, z)) in views.iter().enumerate() {
        let o = RenderOptions {
            noise_sigma: noise,
            // 8x8 supersampling quantises a near-axis-aligned edge in
            // 1/8 px steps (0.12 px jumps along the side): 32 keeps the
            // truth below the errors measured.
            supersample: 32,
            seed: 10 + k as u64,
            ..RenderOptions::default()
        };
        let r = render(&cam, &target, &pose(&target, *rpy, (0.004, 0.012, *z)), &o).unwrap();
        assert_eq!(r.points.len(), 256, "view {k}");
        let pts = detect_with_model(
            &r.image,
            8,
            8,
            12.7 / 22.5778,
            &DetectOptions::default(),
            model,
        )
        .unwrap_or_else(|e| panic!("view {k}: {e}"));
        // Views turned by more than 45 degrees may start from another
        // corner of the square board (the documented rule): compare
        // with the nearest truth point, and the ids where the turn is small.
        for d in &pts {
            let (e, id) = r
                .points
                .iter()
                .map(|t| {
                    (
                        ((d.x_px - t.x_px).powi(2) + (d.y_px - t.y_px).powi(2)).sqrt(),
                        t.id,
                    )
                })
                .fold((f64::MAX, 0), |a, b| if b.0 < a.0 { b } else { a });
            if rpy.2.abs() < 0.3 {
                assert_eq!(id, d.id, "view {k}");
            }
            sum += e;
            max = max.max(e);
            n += 1.0;
        }
    }
    (sum / n, max)
}

#[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
fn finds_a_small_square_grid_with_exact_corners() {
    // 4x3 squares, pinhole, 640x480, noise-free: the ids follow the
    // documented order and every corner is within 0.03 px of the truth
    // (measured mean 0.0025 px).
    let target = Target::parse_spec("squares:4x3:20mm:32mm").unwrap();
    let cam = Camera::pinhole(700.0, 700.0, 321.3, 238.9, 640, 480);
    let o = RenderOptions {
        noise_sigma: 0.0,
        supersample: 16,
        ..RenderOptions::default()
    };
    let r = render(
        &cam,
        &target,
        &pose(&target, (0.2, -0.3, 0.1), (0.0, 0.0, 0.4)),
        &o,
    )
    .unwrap();
    assert_eq!(r.points.len(), 48);
    let d = crate::detect::detect(&r.image, &target, &DetectOptions::default()).unwrap();
    assert_eq!(d.points.len(), 48);
    let mut sum = 0.0;
    for (p, t) in d.points.iter().zip(&r.points) {
        assert_eq!(p.id, t.id);
        let e = ((p.x_px - t.x_px).powi(2) + (p.y_px - t.y_px).powi(2)).sqrt();
        assert!(e < 0.03, "id {}: {e} px", p.id);
        sum += e;
        let c = p.covariance_px2.unwrap();
        assert!(c[0] >= 0.0 && c[2] >= 0.0 && c[0] < 0.01, "{c:?}");
    }
    eprintln!("mean {} px", sum / 48.0);
    // Cut off: the count is reported.
    let half = crate::image::GrayImage::new(
        320,
        480,
        (0..480)
            .flat_map(|y| r.image.pixels[y * 640..y * 640 + 320].to_vec())
            .collect(),
    )
    .unwrap();
    let e = crate::detect::detect(&half, &target, &DetectOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("of 12 squares of the 4x3 square grid"),
        "{e}"
    );
}

/// The numbers behind the default side model (module docs); about 30 s,
/// run with `cargo test --lib side_models -- --ignored --nocapture`.
#[cfg(not(target_arch = "wasm32"))]
#[test]
#[ignore]
fn side_models_compared_on_distorted_renders() {
    let views = [
        ((0.05, -0.08, 0.03), 0.38),
        // Filling the frame like Zhang's images: the most bent sides.
        ((0.02, 0.06, -0.04), 0.355),
        ((0.5, 0.2, -0.2), 0.47),
        ((-0.3, 0.55, 0.5), 0.47),
    ];
    for noise in [0.0, 2.0] {
        for model in [
            SideModel::Line,
            SideModel::Parabola,
            SideModel::CornerSegments,
        ] {
            let (mean, max) = errors(model, noise, &views);
            eprintln!("noise {noise}: {model:?}: mean {mean:.4} px, max {max:.4} px");
        }
    }
}

#[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
fn an_edge_is_found_at_the_same_place_whatever_its_sampling_phase() {
    // A straight vertical edge (logistic profile, scale 0.4 px: about as
    // sharp as Zhang's photos) from grey 40 to 200, each pixel its
    // integral over the pixel, moved across one pixel (four profile
    // samples) in 20 steps. The edge is symmetric, so its centroid is x0;
    // what the 8-bit pixels, the bilinear samples and the window make of it
    // should not depend on where x0 falls.
    // Measured: error -0.0115 .. +0.0126 px with the window's ends counted
    // by part; -0.0232 .. +0.0265 px counting whole samples (the detector
    // before session 14). Most of what is left is the rounding to 8 bits:
    // at a quarter of the contrast the error triples (+-0.033 px), while a
    // wider window (3 px) or finer samples (0.125 px) leave it as it is.
    // Bound: 0.02 px.
    let (w, h) = (40, 9);
    let mut scratch = Profile::default();
    let mut errs = Vec::new();
    for k in 0..=20 {
        let x0 = 19.5 + k as f64 / 20.0;
        // Each pixel integrates the profile over its width (as a sensor
        // does): the logistic's integral is 0.4 ln(1 + e^((x - x0) / 0.4)).
        let integral = move |x: f64| 0.4 * (1.0 + ((x - x0) / 0.4).exp()).ln();
        let pixels = (0..h)
            .flat_map(|_| {
                (0..w).map(move |x| {
                    let x = x as f64;
                    let v = 40.0 + 160.0 * (integral(x + 0.5) - integral(x - 0.5));
                    v.round() as u8
                })
            })
            .collect();
        let img = GrayImage::new(w, h, pixels).unwrap();
        let base = Point2::new(19.3, 4.0);
        let (s, width) = edge_on_profile(
            &img,
            base,
            Vector2::new(1.0, 0.0),
            (1.0, 2.0, 0.25),
            40.0,
            &mut scratch,
        )
        .expect("edge");
        assert!(width > 0.3 && width < 1.5, "width {width}");
        errs.push(base.x + s - x0);
    }
    let lo = errs.iter().copied().fold(f64::MAX, f64::min);
    let hi = errs.iter().copied().fold(f64::MIN, f64::max);
    eprintln!("edge error over the sampling phase: {lo:+.4} .. {hi:+.4} px");
    assert!(lo.abs() <= 0.02 && hi.abs() <= 0.02, "{errs:?}");
}
