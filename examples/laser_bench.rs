//! Laser-line measurements (docs/laser.md):
//! 1. stripe centre error vs the renderer's truth for both extractors
//!    (widths 2-15 px, noise, blur, speckle), with the laser-off image;
//! 2. a seeded Monte Carlo of the plane fit at the level of stripe centres
//!    (no images: exact board poses, Gaussian centre noise along the scan):
//!    normal (deg) and distance (mm) error against the bound the injected
//!    noise implies, for 2, 4 and 10 board poses.
//!
//! `cargo run --example laser_bench [TRIALS]` (default 200).

use nalgebra::{Matrix2, Vector2, Vector3};
use robocal::camera::Camera;
use robocal::laser::{
    extract_stripe, fit_plane, PlaneFitOptions, ScanAxis, StripeMethod, StripeOptions,
};
use robocal::rng::Rng;
use robocal::synth::laser::{stripe_truth, LaserStripe};
use robocal::synth::laser_scene::{example_plane, laser_board_poses, stripe_observations};
use robocal::synth::{board_pose, render, RenderOptions};
use robocal::target::Target;

fn main() -> Result<(), robocal::Error> {
    let trials: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(200);
    let camera = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
    stripe_errors(&camera)?;
    monte_carlo(&camera, trials)
}

fn stripe_errors(camera: &Camera) -> Result<(), robocal::Error> {
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.025,
    };
    let pose = board_pose(&target, (0.2, -0.15, 0.1), (0.0, 0.0, 0.5));
    let truth = stripe_truth(camera, &pose, &example_plane(), true);
    println!(
        "stripe centre error vs truth (px; mean |e|, RMS, centres), laser-off image subtracted"
    );
    println!(
        "{:>6} {:>6} {:>5} {:>8} | {:>22} | {:>22}",
        "width", "noise", "blur", "speckle", "cog", "ridge"
    );
    let cases = [
        (2.0, 2.0, 0.7, 0.2),
        (3.0, 2.0, 0.7, 0.2),
        (5.0, 2.0, 0.7, 0.2),
        (8.0, 2.0, 0.7, 0.2),
        (11.0, 2.0, 0.7, 0.2),
        (15.0, 2.0, 0.7, 0.2),
        (5.0, 0.0, 0.0, 0.0),
        (5.0, 5.0, 0.7, 0.2),
        (5.0, 2.0, 1.5, 0.2),
        (5.0, 2.0, 0.7, 0.5),
    ];
    for (width, noise, blur, speckle) in cases {
        let mut laser = LaserStripe::new(example_plane());
        laser.width_px = width;
        laser.speckle = speckle;
        let off_o = RenderOptions {
            noise_sigma: noise,
            blur_sigma_px: blur,
            seed: 3,
            ..RenderOptions::default()
        };
        let on_o = RenderOptions {
            laser: Some(laser),
            seed: 4,
            ..off_o.clone()
        };
        let off = render(camera, &target, &pose, &off_o)?.image;
        let on = render(camera, &target, &pose, &on_o)?.image;
        let mut cells = Vec::new();
        for method in [StripeMethod::CentreOfGravity, StripeMethod::Ridge] {
            let options = StripeOptions {
                method,
                axis: Some(ScanAxis::Columns),
                ..StripeOptions::default()
            };
            let s = extract_stripe(&on, Some(&off), &options)?;
            let (mut sa, mut s2, mut n) = (0.0, 0.0, 0);
            for p in &s.points {
                if let Some((_, t)) = truth.iter().find(|(i, _)| *i == p.x_px as usize) {
                    let e = p.y_px - t;
                    sa += e.abs();
                    s2 += e * e;
                    n += 1;
                }
            }
            let k = n.max(1) as f64;
            cells.push(format!("{:>7.3} {:>7.3} {:>6}", sa / k, (s2 / k).sqrt(), n));
        }
        println!(
            "{width:>6} {noise:>6} {blur:>5} {speckle:>8} | {} | {}",
            cells[0], cells[1]
        );
    }
    Ok(())
}

fn monte_carlo(camera: &Camera, trials: usize) -> Result<(), robocal::Error> {
    let truth = example_plane();
    let noise = 0.3;
    println!("\nplane Monte Carlo: {trials} trials, centre noise {noise} px, every 4th column, image-space residual");
    println!(
        "{:>5} | {:>11} {:>11} {:>7} | {:>11} {:>11} {:>7} | {:>9}",
        "poses", "RMS deg", "bound deg", "ratio", "RMS mm", "bound mm", "ratio", "cover 3sd"
    );
    for n_poses in [2usize, 4, 10] {
        let poses = laser_board_poses(n_poses);
        let mut rng = Rng::new(1000 + n_poses as u64);
        let (mut se_a, mut sb_a, mut se_d, mut sb_d) = (0.0, 0.0, 0.0, 0.0);
        let (mut cover_n, mut cover_d) = (0usize, 0usize);
        for _ in 0..trials {
            let obs = stripe_observations(camera, &poses, &truth, (0.2, 0.15), 4, noise, &mut rng)?;
            let fit = fit_plane(&obs, &PlaneFitOptions::default())?;
            // The bound: the reported covariance (the residuals' sandwich,
            // for independent centres (J^T J)^-1 with the injected std).
            let c = fit.estimate.normal_distance_covariance();
            let n = fit.estimate.plane.normal.into_inner();
            let a = n.cross(&Vector3::x()).normalize();
            let b = n.cross(&a);
            let e = n - truth.normal.into_inner();
            let e2 = Vector2::new(e.dot(&a), e.dot(&b));
            let cnn = c.fixed_view::<3, 3>(0, 0).into_owned();
            let c2 = Matrix2::new(
                a.dot(&(cnn * a)),
                a.dot(&(cnn * b)),
                b.dot(&(cnn * a)),
                b.dot(&(cnn * b)),
            );
            se_a += e2.norm_squared();
            sb_a += c2.trace();
            if let Some(inv) = c2.try_inverse() {
                // chi^2(2) at the 3-sigma probability 0.9973.
                if (e2.transpose() * inv * e2)[0] <= 11.829 {
                    cover_n += 1;
                }
            }
            let ed = fit.estimate.plane.distance_m - truth.distance_m;
            se_d += ed * ed;
            sb_d += c[(3, 3)];
            if ed.abs() <= 3.0 * c[(3, 3)].sqrt() {
                cover_d += 1;
            }
        }
        let t = trials as f64;
        let (ra, ba) = (
            (se_a / t).sqrt().to_degrees(),
            (sb_a / t).sqrt().to_degrees(),
        );
        let (rd, bd) = ((se_d / t).sqrt() * 1e3, (sb_d / t).sqrt() * 1e3);
        println!(
            "{n_poses:>5} | {ra:>11.5} {ba:>11.5} {:>7.3} | {rd:>11.5} {bd:>11.5} {:>7.3} | n {:>5.1} % d {:>5.1} %",
            ra / ba, rd / bd,
            100.0 * cover_n as f64 / t, 100.0 * cover_d as f64 / t
        );
    }
    Ok(())
}
