//! Each camera effect on a known image, against the statistic it must
//! produce. Tolerances: exact ones (1e-6 and below) where the effect is a
//! deterministic linear filter; sampling ones stated at each assert from the
//! number of draws.

use super::effects::*;
use super::{board_pose, render, Pinhole, RenderOptions, Rng};
use crate::image::filter::Plane;
use crate::target::Target;
use wasm_bindgen_test::wasm_bindgen_test;

/// A vertical step between pixel 49 and 50 (0 | 100): the edge at x = 49.5.
fn step(w: usize, h: usize) -> Plane {
    let data = (0..w * h)
        .map(|i| if i % w >= 50 { 100.0 } else { 0.0 })
        .collect();
    Plane { w, h, data }
}

/// Centroid and variance of the row's derivative (the line spread), px.
fn line_spread(p: &Plane, y: usize) -> (f64, f64) {
    // Away from the border, where a spread loses its light out of the image.
    let row = &p.data[y * p.w + 10..(y + 1) * p.w - 10];
    let d: Vec<f64> = row.windows(2).map(|a| (a[1] - a[0]) as f64).collect();
    let s: f64 = d.iter().sum();
    let m = d
        .iter()
        .enumerate()
        .map(|(i, v)| (i as f64 + 10.5) * v)
        .sum::<f64>()
        / s;
    let v = d
        .iter()
        .enumerate()
        .map(|(i, x)| (i as f64 + 10.5 - m).powi(2) * x)
        .sum::<f64>()
        / s;
    (m, v)
}

fn camera() -> Pinhole {
    Pinhole {
        fx: 800.0,
        fy: 800.0,
        cx: 319.5,
        cy: 239.5,
        width: 640,
        height: 480,
    }
}

fn clean(effects: Effects) -> RenderOptions {
    RenderOptions {
        noise_sigma: 0.0,
        blur_sigma_px: 0.0,
        effects,
        ..RenderOptions::default()
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn gamma_maps_a_ramp_and_the_print_levels() {
    // Encoded = 255 (v / 255)^(1 / 2.2): half scale comes from 255 * 0.5^2.2.
    assert!((response(255.0 * 0.5f64.powf(2.2), 2.2) - 127.5).abs() < 1e-9);
    for i in 1..=255 {
        let v = i as f64;
        let ratio = (response(v, 2.2) / 255.0).ln() / (v / 255.0).ln().min(-1e-300);
        if i < 255 {
            assert!(
                (ratio - 1.0 / 2.2).abs() < 1e-12,
                "log slope at {i}: {ratio}"
            );
        }
    }
    assert_eq!(response(255.0, 2.2), 255.0);
    assert_eq!(response(0.0, 2.2), 0.0);
    // A frontal board without noise or blur: black 30 reads
    // round(255 (30/255)^(1/2.2)) = 96, white 220 reads 238.
    let target = Target::parse_spec("chessboard:9x6:30mm").unwrap();
    let pose = board_pose(&target, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0));
    let fx = Effects {
        gamma: Some(2.2),
        ..Effects::default()
    };
    let img = render(&camera(), &target, &pose, &clean(fx)).unwrap().image;
    let count = |g: u8| img.pixels.iter().filter(|&&p| p == g).count();
    assert!(
        count(96) > 15_000 && count(238) > 15_000,
        "{} {}",
        count(96),
        count(238)
    );
    assert_eq!(count(30) + count(220), 0, "linear levels left");
}

#[wasm_bindgen_test(unsupported = test)]
fn defocus_disc_spreads_an_edge_over_its_radius() {
    let optics = Optics {
        defocus_px: 4.0,
        field_curvature_px: 0.0,
        astigmatism_px: 0.0,
        coma_px: 0.0,
    };
    let out = apply_optics(&step(100, 41), &optics);
    let (m, v) = line_spread(&out, 20);
    // A uniform disc of radius R has a line spread of variance R^2 / 4; the
    // bilinear gather of a pixel step and the finite difference add a
    // triangle (1/6 px^2). 96 rays sample the disc: 2 % on the width.
    let expected = (4.0f64.powi(2) / 4.0 + 1.0 / 6.0).sqrt();
    assert!(
        (m - 49.5).abs() < 0.01,
        "edge centroid {m} px, expected 49.5"
    );
    assert!(
        (v.sqrt() / expected - 1.0).abs() < 0.02,
        "line spread sigma {} px, expected {expected}",
        v.sqrt()
    );
    // Nothing moves beyond the disc (radius 4 px plus the bilinear pixel).
    let row = &out.data[20 * 100..21 * 100];
    assert!(
        row[..44].iter().all(|&g| g.abs() < 1e-3)
            && row[56..90].iter().all(|&g| (g - 100.0).abs() < 1e-3)
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn astigmatism_and_coma_keep_the_centroid_and_stretch_radially() {
    // A 640x480-sized field: the PSF changes slowly over its own width.
    let (w, h) = (641usize, 481usize);
    let (px, py) = (600usize, 450usize); // rho = 0.82, towards the corner
    let mut data = vec![0.0f32; w * h];
    data[py * w + px] = 1000.0;
    let optics = Optics {
        defocus_px: 1.0,
        field_curvature_px: 0.0,
        astigmatism_px: 3.0,
        coma_px: 2.0,
    };
    let out = apply_optics(&Plane { w, h, data }, &optics);
    let (mut s, mut mx, mut my) = (0.0, 0.0, 0.0);
    for (i, v) in out.data.iter().enumerate() {
        let v = *v as f64;
        s += v;
        mx += v * (i % w) as f64;
        my += v * (i / w) as f64;
    }
    let (mx, my) = (mx / s, my / s);
    let (mut rr, mut tt) = (0.0, 0.0);
    let r = (px as f64 - 320.0).hypot(py as f64 - 240.0);
    let (ex, ey) = ((px as f64 - 320.0) / r, (py as f64 - 240.0) / r);
    for (i, v) in out.data.iter().enumerate() {
        let (dx, dy) = ((i % w) as f64 - mx, (i / w) as f64 - my);
        rr += *v as f64 * (ex * dx + ey * dy).powi(2);
        tt += *v as f64 * (-ey * dx + ex * dy).powi(2);
    }
    // Each scene point spreads with its own PSF by bilinear splats, which
    // keep the first moment: the centroid holds to f32 rounding.
    assert!(
        (mx - px as f64).abs() < 1e-4 && (my - py as f64).abs() < 1e-4,
        "centroid ({mx}, {my}) px, point at ({px}, {py})"
    );
    assert!(
        rr / s > 2.0 * tt / s,
        "radial variance {} vs tangential {} px^2",
        rr / s,
        tt / s
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn motion_blur_spreads_a_point_along_its_direction() {
    let (w, h) = (101usize, 101usize);
    let mut data = vec![0.0f32; w * h];
    data[50 * w + 50] = 1000.0;
    let m = MotionBlur {
        length_px: 10.0,
        angle_rad: 0.5,
    };
    let out = apply_motion(&Plane { w, h, data }, &m);
    let (c, s) = (m.angle_rad.cos(), m.angle_rad.sin());
    let (mut sum, mut along, mut across, mut mean_a) = (0.0, 0.0, 0.0, 0.0);
    for (i, v) in out.data.iter().enumerate() {
        let (dx, dy) = ((i % w) as f64 - 50.0, (i / w) as f64 - 50.0);
        let v = *v as f64;
        sum += v;
        mean_a += v * (c * dx + s * dy);
        along += v * (c * dx + s * dy).powi(2);
        across += v * (-s * dx + c * dy).powi(2);
    }
    // A segment of length L has variance L^2 / 12 (41 samples: L^2 (1 -
    // 1/41^2) / 12); the bilinear gather adds 1/6 px^2 in every direction.
    let length = (12.0 * (along / sum - 1.0 / 6.0)).sqrt();
    assert!((sum - 1000.0).abs() < 1e-2, "energy {sum}");
    assert!(
        (mean_a / sum).abs() < 1e-6,
        "centroid moved by {} px",
        mean_a / sum
    );
    assert!(
        (length - 10.0).abs() < 0.05,
        "spread length {length} px, stated 10"
    );
    assert!(
        (across / sum - 1.0 / 6.0).abs() < 0.01,
        "across {} px^2",
        across / sum
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn bayer_demosaic_keeps_flat_fields_and_edges() {
    let (w, h) = (40usize, 30usize);
    let perfect = Bayer {
        channel_gain: [1.0, 1.0, 1.0],
    };
    let mut flat = vec![123.0; w * h];
    mosaic(&mut flat, w, &perfect);
    assert!(demosaic_to_grey(&flat, w, h)
        .iter()
        .all(|g| (g - 123.0).abs() < 1e-9));
    // White-balance residuals scale a flat field by sum(luma * gain) only.
    let off = Bayer {
        channel_gain: [0.95, 1.0, 1.05],
    };
    let mut flat = vec![100.0; w * h];
    mosaic(&mut flat, w, &off);
    let k = 100.0 * (LUMA[0] * 0.95 + LUMA[1] + LUMA[2] * 1.05);
    assert!(demosaic_to_grey(&flat, w, h)
        .iter()
        .all(|g| (g - k).abs() < 1e-9));
    // An edge: each site's filters are symmetric, but they differ between
    // the sites, so an edge moves with its phase on the mosaic (up to
    // 0.25 px at a perfect balance for this 20 -> 200 step); the two phases cancel:
    // their mean stays on the edge to 1e-6 px (the plane is f32) with a
    // perfect balance and to 0.02 px with 5 % residuals.
    for (bayer, tol) in [(perfect, 1e-6f64), (off, 0.02)] {
        let mut shifts = Vec::new();
        for at in [20usize, 21] {
            let mut edge: Vec<f64> = (0..w * h)
                .map(|i| if i % w >= at { 200.0 } else { 20.0 })
                .collect();
            mosaic(&mut edge, w, &bayer);
            let grey = demosaic_to_grey(&edge, w, h);
            let plane = Plane {
                w,
                h,
                data: grey.iter().map(|&g| g as f32).collect(),
            };
            for y in 0..h {
                let (m, _) = line_spread(&plane, y);
                shifts.push(m - (at as f64 - 0.5));
                assert!(
                    (m - (at as f64 - 0.5)).abs() < 0.3,
                    "row {y}: edge moved {m} px"
                );
            }
        }
        let mean = shifts.iter().sum::<f64>() / shifts.len() as f64;
        eprintln!(
            "demosaic edge shifts: first {:.4}, last {:.4}, mean {mean:.2e} px",
            shifts[0],
            shifts[shifts.len() - 1]
        );
        assert!(
            mean.abs() < tol,
            "mean edge shift {mean} px over both phases"
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn shot_noise_variance_grows_with_the_signal_at_the_gain() {
    let s = SensorNoise {
        full_well_e: 6000.0,
        gain_dn_per_e: 255.0 / 6000.0,
        read_noise_e: 4.0,
    };
    let mut rng = Rng::new(3);
    let n = 40_000;
    let levels = [10.0, 50.0, 100.0, 150.0, 200.0];
    let vars: Vec<f64> = levels
        .iter()
        .map(|&v| {
            let mut x = vec![v; n];
            sensor_noise(&mut x, &s, &mut rng);
            let m = x.iter().sum::<f64>() / n as f64;
            assert!((m - v).abs() < 0.05, "mean {m} at {v} grey levels");
            x.iter().map(|g| (g - m).powi(2)).sum::<f64>() / n as f64
        })
        .collect();
    // Least-squares line var = slope * v + intercept; expected slope = gain
    // (0.0425 grey levels per grey level), intercept (gain * read)^2 =
    // 0.0289. Each variance has a relative standard error sqrt(2 / n) =
    // 0.7 %: the slope holds to 3 %, the intercept to 0.1 grey levels^2.
    let mx = levels.iter().sum::<f64>() / 5.0;
    let my = vars.iter().sum::<f64>() / 5.0;
    let sxy: f64 = levels
        .iter()
        .zip(&vars)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum();
    let sxx: f64 = levels.iter().map(|x| (x - mx).powi(2)).sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    assert!(
        (slope / s.gain_dn_per_e - 1.0).abs() < 0.03,
        "slope {slope}, gain {}",
        s.gain_dn_per_e
    );
    assert!(
        (intercept - (s.gain_dn_per_e * s.read_noise_e).powi(2)).abs() < 0.1,
        "intercept {intercept}"
    );
    // Beyond the full well the signal clips at full scale.
    let mut x = vec![300.0; 100];
    sensor_noise(&mut x, &s, &mut rng);
    assert!(x.iter().all(|&g| g <= 255.0 + 1e-9));
}

#[wasm_bindgen_test(unsupported = test)]
fn jpeg_keeps_the_mean_and_bounds_the_error() {
    let target = Target::parse_spec("chessboard:9x6:30mm").unwrap();
    let pose = board_pose(&target, (0.3, -0.2, 0.1), (0.0, 0.0, 1.0));
    let plain = render(&camera(), &target, &pose, &RenderOptions::default())
        .unwrap()
        .image;
    let mut last_rms = 0.0;
    for (q, rms_max) in [(95u8, 2.0), (75, 3.5), (50, 5.0)] {
        let out = jpeg_round_trip(&plain.pixels, 640, 480, q).unwrap();
        let n = out.len() as f64;
        let diff: Vec<f64> = out
            .iter()
            .zip(&plain.pixels)
            .map(|(a, b)| *a as f64 - *b as f64)
            .collect();
        let mean = diff.iter().sum::<f64>() / n;
        let rms = (diff.iter().map(|d| d * d).sum::<f64>() / n).sqrt();
        assert!(
            mean.abs() < 0.2,
            "quality {q}: mean change {mean} grey levels"
        );
        eprintln!("quality {q}: mean {mean:.3}, RMS {rms:.3} grey levels");
        assert!(
            rms < rms_max && rms > last_rms,
            "quality {q}: RMS error {rms} grey levels"
        );
        last_rms = rms;
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn rolling_shutter_shifts_each_row_by_the_stated_amount() {
    let target = Target::parse_spec("chessboard:9x6:30mm").unwrap();
    let pose = board_pose(&target, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0));
    let skew = 0.004;
    let fx = Effects {
        rolling_shutter_px_per_row: skew,
        ..Effects::default()
    };
    let base = RenderOptions::default();
    let ideal = render(&camera(), &target, &pose, &base).unwrap();
    let skewed = render(
        &camera(),
        &target,
        &pose,
        &RenderOptions {
            effects: fx,
            ..base
        },
    )
    .unwrap();
    for (a, b) in ideal.points.iter().zip(&skewed.points) {
        assert!((b.x_px - a.x_px - skew * (a.y_px - 239.5)).abs() < 1e-9);
        assert_eq!(b.y_px, a.y_px);
    }
    // The image moves with the truth: the detector finds the shifted corners
    // as well as the unshifted ones (noise sigma 2: ~0.02 px).
    let det = crate::detect::detect(&skewed.image, &target, &Default::default()).unwrap();
    let err: f64 = det
        .points
        .iter()
        .zip(&skewed.points)
        .map(|(d, t)| (d.x_px - t.x_px).hypot(d.y_px - t.y_px))
        .sum::<f64>()
        / det.points.len() as f64;
    assert!(err < 0.05, "mean corner error {err} px on the skewed image");
}

#[wasm_bindgen_test(unsupported = test)]
fn paper_texture_has_its_rms_and_the_print_its_levels() {
    let paper = Paper {
        rms: 0.05,
        wavelength_m: 0.04,
        seed: 9,
    };
    let t = Texture::new(&paper);
    let n = 400;
    let vals: Vec<f64> = (0..n * n)
        .map(|i| t.at((i % n) as f64 * 0.005, (i / n) as f64 * 0.005))
        .collect();
    let mean = vals.iter().sum::<f64>() / vals.len() as f64;
    let rms = (vals.iter().map(|v| v * v).sum::<f64>() / vals.len() as f64).sqrt();
    // Over 2 m x 2 m (25-50 wavelengths) the cross terms of the waves
    // average out to a few percent.
    assert!(mean.abs() < 0.005, "texture mean {mean}");
    assert!(
        (rms / 0.05 - 1.0).abs() < 0.1,
        "texture RMS {rms}, stated 0.05"
    );
    // The print: without texture the squares read exactly black 30 and
    // white 220; with it their means stay within 2 %.
    let target = Target::parse_spec("chessboard:9x6:30mm").unwrap();
    let pose = board_pose(&target, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0));
    for fx in [
        Effects::default(),
        Effects {
            paper: Some(paper),
            ..Effects::default()
        },
    ] {
        let textured = fx.paper.is_some();
        let img = render(&camera(), &target, &pose, &clean(fx)).unwrap().image;
        // Square centres: corner (i, j) sits at truth; the square to its
        // lower right is dark when i + j is even.
        let r = render(&camera(), &target, &pose, &clean(Effects::default())).unwrap();
        let (mut dark, mut light) = (Vec::new(), Vec::new());
        for p in &r.points {
            let (i, j) = (p.id % 9, p.id / 9);
            if i == 8 || j == 5 {
                continue;
            }
            let (x, y) = (
                (p.x_px + 12.0).round() as u32,
                (p.y_px + 12.0).round() as u32,
            );
            let g = img.get(x, y).unwrap() as f64;
            if (i + j) % 2 == 0 {
                dark.push(g)
            } else {
                light.push(g)
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let (md, ml) = (mean(&dark), mean(&light));
        if textured {
            assert!(
                (md / 30.0 - 1.0).abs() < 0.02 && (ml / 220.0 - 1.0).abs() < 0.02,
                "{md} {ml}"
            );
        } else {
            assert_eq!((md, ml), (30.0, 220.0));
        }
    }
}
