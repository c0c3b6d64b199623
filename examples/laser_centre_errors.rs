//! The stripe centres' errors along the stripe on `laser_mc`'s scenes (the
//! same seeds: rendered pairs, boards slid in their plane every trial), to
//! see what the plane covariance's window can and cannot hold (BENCHMARKS.md
//! section 18, s29). Per image, over the trials:
//!
//! - the centres' true error along the scan (the centre less where the true
//!   plane meets the true board on that scan line, px), its RMS and its
//!   autocorrelation by scan-line lag (pooled over the trials);
//! - the least-squares line through those errors (offset px and slope px
//!   per 100 lines, what [`robocal::laser::fit_plane`]'s own-line removal
//!   takes out of an image's residuals, and what moves the plane at 2
//!   poses): its spread over the trials against the within-line estimate
//!   of it (a sandwich over the line's two parameters whose middle is the
//!   kernel-weighted sum of the line's residuals, made unbiased for
//!   independent errors as `src/laser/covariance.rs` does it), for
//!   Bartlett windows of 20, 40 and 80 lines, a flat-top (trapezoid) of 40
//!   and the quadratic-spectral kernel of 40; the column in brackets is
//!   the spread over the estimate (1 when the estimate is right).
//!
//! With `edge`, per trial image 0's stripe's distance to the nearest row
//! edge of the board (mm, board frame: pose 0's stripe runs along the
//! board's rows) and the mean of its centres' errors.
//!
//! `cargo run --release --example laser_centre_errors [TRIALS] [POSES] [edge]`
//! (default 100 and 2).

use nalgebra::{Matrix2, Point2, Vector2, Vector3};
use robocal::calib::View;
use robocal::camera::Camera;
use robocal::detect::{detect, DetectOptions};
use robocal::geometry::Pose;
use robocal::laser::{extract_stripe, ScanAxis, StripeObservation, StripeOptions};
use robocal::rng::Rng;
use robocal::synth::laser::{laser_pair, LaserStripe};
use robocal::synth::laser_scene::{example_plane, laser_board_poses};
use robocal::target::Target;

/// Scan-line lags of the autocorrelation.
const MAX_LAG: usize = 160;
/// The board's square, m (`laser_mc`'s 9x6 chessboard).
const SQUARE_M: f64 = 0.025;
/// The kernels the line's spread is estimated with: name and window.
const KERNELS: [(&str, f64); 5] = [
    ("bartlett", 20.0),
    ("bartlett", 40.0),
    ("bartlett", 80.0),
    ("flat-top", 40.0),
    ("qs", 40.0),
];

/// A kernel's weight of two centres `lag` scan lines apart.
fn weight(kernel: (&str, f64), lag: usize) -> f64 {
    let (name, m) = kernel;
    let x = lag as f64 / m;
    match name {
        "bartlett" => (1.0 - lag as f64 / (m + 1.0)).max(0.0),
        "flat-top" if x <= 0.5 => 1.0,
        "flat-top" => (2.0 * (1.0 - x)).max(0.0),
        _ if lag == 0 => 1.0,
        _ => {
            let z = 6.0 * std::f64::consts::PI * x / 5.0;
            25.0 / (12.0 * std::f64::consts::PI.powi(2) * x * x) * (z.sin() / z - z.cos())
        }
    }
}

/// Per image, sums over the trials.
#[derive(Clone, Default)]
struct Sums {
    centres: usize,
    /// Autocorrelation sums by lag: sum of products, pairs.
    acf: Vec<(f64, usize)>,
    /// The error line's offset and slope: sums and sums of squares.
    offset: (f64, f64),
    slope: (f64, f64),
    /// Per kernel, the sums of the estimated offset and slope variances.
    estimated: [(f64, f64); KERNELS.len()],
}

/// The least-squares line through one image's errors `(scan line, px)` and
/// the within-line estimate of its covariance per kernel, added to `s`.
fn line_fit(e: &[(i64, f64)], s: &mut Sums) {
    let n = e.len();
    if n < 10 {
        return;
    }
    let mean_line = e.iter().map(|x| x.0 as f64).sum::<f64>() / n as f64;
    let x: Vec<Vector2<f64>> = e
        .iter()
        .map(|x| Vector2::new(1.0, (x.0 as f64 - mean_line) / 100.0))
        .collect();
    let (mut a, mut b) = (Matrix2::zeros(), Vector2::zeros());
    for (xk, ek) in x.iter().zip(e) {
        a += xk * xk.transpose();
        b += xk * ek.1;
    }
    let Some(inv) = a.try_inverse() else {
        return;
    };
    let beta = inv * b;
    s.offset.0 += beta[0];
    s.offset.1 += beta[0] * beta[0];
    s.slope.0 += beta[1];
    s.slope.1 += beta[1] * beta[1];
    let r: Vec<f64> = x
        .iter()
        .zip(e)
        .map(|(xk, ek)| ek.1 - xk.dot(&beta))
        .collect();
    for (kernel, sum) in KERNELS.iter().zip(s.estimated.iter_mut()) {
        // The kernel-weighted middle and its expectation for independent
        // unit errors with the line removed; each parameter's middle scaled
        // by information / expectation.
        let (mut meat, mut kept) = (Matrix2::zeros(), Matrix2::zeros());
        for k in 0..n {
            for l in 0..n {
                let w = weight(*kernel, (e[k].0 - e[l].0).unsigned_abs() as usize);
                if w == 0.0 {
                    continue;
                }
                let xx = x[k] * x[l].transpose();
                meat += xx * (w * r[k] * r[l]);
                let p = x[k].dot(&(inv * x[l]));
                kept += xx * (w * (if k == l { 1.0 } else { 0.0 } - p));
            }
        }
        let m = Matrix2::new(
            meat[(0, 0)] * a[(0, 0)] / kept[(0, 0)],
            0.0,
            0.0,
            meat[(1, 1)] * a[(1, 1)] / kept[(1, 1)],
        );
        let c = inv * m * inv;
        sum.0 += c[(0, 0)];
        sum.1 += c[(1, 1)];
    }
}

fn main() -> Result<(), robocal::Error> {
    let mut args = std::env::args().skip(1);
    let trials: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100);
    let n_poses: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(2);
    let edge = args.any(|a| a == "edge");
    let camera = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: SQUARE_M,
    };
    // synth::laser_scene::example_plane's truth, as in laser_mc.
    let truth_n = Vector3::new(0.0, -0.5, 0.1).normalize();
    let truth_d = 0.1 * 0.5 / 0.26f64.sqrt();
    let board_poses = laser_board_poses(n_poses);
    let mut sums = vec![
        Sums {
            acf: vec![(0.0, 0); MAX_LAG + 1],
            ..Sums::default()
        };
        n_poses
    ];
    for trial in 0..trials {
        // laser_mc's slides and seeds.
        let mut slide = Rng::new(7_000_003 * n_poses as u64 + 31 * trial as u64 + 5);
        for (i, (pose0, s)) in board_poses.iter().zip(sums.iter_mut()).enumerate() {
            let v = Vector3::new(
                slide.range(-SQUARE_M, SQUARE_M),
                slide.range(-SQUARE_M, SQUARE_M),
                0.0,
            );
            let pose = pose0 * Pose::from_parts(v.into(), nalgebra::UnitQuaternion::identity());
            let seed = 1_000_003 * n_poses as u64 + 1009 * trial as u64 + 17 * i as u64;
            let mut laser = LaserStripe::new(example_plane());
            laser.seed = seed ^ 0x5EED;
            let (board, on) = laser_pair(&camera, &target, &pose, &laser, seed)?;
            let detection = detect(&board, &target, &DetectOptions::default())?;
            let view = View::from_detection(format!("pose {i}"), &detection);
            let (lo, hi) =
                view.object_m
                    .iter()
                    .fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
                        (
                            [lo[0].min(p.x), lo[1].min(p.y)],
                            [hi[0].max(p.x), hi[1].max(p.y)],
                        )
                    });
            let stripe = extract_stripe(&on, Some(&board), &StripeOptions::default())?;
            let along_y = stripe.axis == ScanAxis::Columns;
            // The true error per scan line, inside the corners' extent.
            let (mut e, mut board_y) = (Vec::new(), 0.0);
            for p in &stripe.points {
                let px = Point2::new(p.x_px, p.y_px);
                let Ok(o) = StripeObservation::new(&camera, &pose, &px, along_y, p.std_px, i)
                else {
                    continue;
                };
                let q = pose.inverse() * o.point_camera;
                if q.x < lo[0] || q.x > hi[0] || q.y < lo[1] || q.y > hi[1] {
                    continue;
                }
                let r = (truth_n.dot(&o.point_camera.coords) - truth_d)
                    / truth_n.dot(&o.along_scan_m_per_px);
                let line = if along_y { p.x_px } else { p.y_px };
                e.push((line.round() as i64, r));
                board_y += q.y;
            }
            if e.is_empty() {
                continue;
            }
            if edge && i == 0 {
                let y = board_y / e.len() as f64 / SQUARE_M;
                let mean = e.iter().map(|x| x.1).sum::<f64>() / e.len() as f64;
                println!(
                    "edge {trial} d {:.2} mm offset {mean:+.4} px",
                    (y - y.round()).abs() * SQUARE_M * 1e3
                );
            }
            s.centres += e.len();
            line_fit(&e, s);
            for a in 0..e.len() {
                for b in a..e.len() {
                    let lag = (e[b].0 - e[a].0).unsigned_abs() as usize;
                    if lag > MAX_LAG {
                        break;
                    }
                    s.acf[lag].0 += e[a].1 * e[b].1;
                    s.acf[lag].1 += 1;
                }
            }
        }
    }
    let t = trials.max(1) as f64;
    for (i, s) in sums.iter().enumerate() {
        let c0 = s.acf[0].0 / s.acf[0].1.max(1) as f64;
        println!(
            "image {i}: {} centres per trial, RMS error {:.4} px",
            s.centres / trials.max(1),
            c0.sqrt()
        );
        let (mut line, mut cumulative) = (String::from("  autocorrelation:"), 0.0);
        let mut sums_line = String::from("  1 + 2 sum to lag:");
        for (lag, (sum, pairs)) in s.acf.iter().enumerate() {
            let rho = sum / (*pairs).max(1) as f64 / c0;
            cumulative += if lag == 0 { rho } else { 2.0 * rho };
            if lag <= 10 || lag % 10 == 0 {
                line += &format!(" {lag}:{rho:.2}");
            }
            if lag % 20 == 0 {
                sums_line += &format!(" {lag}:{cumulative:.1}");
            }
        }
        println!("{line}\n{sums_line}");
        let spread = |(sum, sq): (f64, f64)| (sq / t - (sum / t).powi(2)).max(0.0).sqrt();
        let (so, ss) = (spread(s.offset), spread(s.slope));
        println!(
            "  error line over the trials: offset mean {:+.4} spread {so:.4} px, slope mean {:+.4} spread {ss:.4} px / 100 lines",
            s.offset.0 / t,
            s.slope.0 / t
        );
        for (kernel, (vo, vs)) in KERNELS.iter().zip(&s.estimated) {
            let (eo, es) = ((vo / t).sqrt(), (vs / t).sqrt());
            println!(
                "    {:<8} {:>3}: estimated offset {eo:.4} ({:.2}), slope {es:.4} ({:.2})",
                kernel.0,
                kernel.1,
                so / eo,
                ss / es
            );
        }
    }
    Ok(())
}
