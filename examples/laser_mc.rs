//! A seeded Monte Carlo of the laser plane on rendered images: per trial
//! and board pose a laser-off and a laser-on image (new noise and speckle
//! seeds every trial; speckle 0.2, a 5 px stripe that saturates on the
//! white squares), then the whole `robocal laser plane --pairs` pipeline
//! (board detection, PnP, stripe extraction, fit). The normal (deg) and
//! distance (mm) errors against the truth are compared with the reported
//! covariance: RMS over the trials against the RMS of the reported std
//! (the bound), and the share of trials within 3 std (normal: chi^2(2) <
//! 11.83, distance: |e| < 3 std).
//!
//! `cargo run --example laser_mc [TRIALS] [POSES,...]` (default 200 and
//! 2,4,10).

use nalgebra::{Matrix2, Matrix4, Vector2, Vector3};
use robocal::api::laser::{laser_plane, LaserPlaneSettings, LaserView};
use robocal::camera::Camera;
use robocal::synth::laser::LaserStripe;
use robocal::synth::laser_scene::{example_plane, laser_board_poses};
use robocal::synth::{render, RenderOptions};
use robocal::target::Target;

fn main() -> Result<(), robocal::Error> {
    let mut args = std::env::args().skip(1);
    let trials: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(200);
    let poses: Vec<usize> = args
        .next()
        .map(|a| a.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or_else(|| vec![2, 4, 10]);
    let camera = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.025,
    };
    // The truth of synth::laser_scene::example_plane, written out.
    let truth_n = Vector3::new(0.0, -0.5, 0.1).normalize();
    let truth_d = 0.1 * 0.5 / 0.26f64.sqrt();
    println!("laser plane Monte Carlo on renders: {trials} trials, pairs, cog, image_px");
    println!(
        "{:>5} | {:>9} {:>9} {:>6} | {:>8} {:>8} {:>6} | {:>7} {:>7} | {:>6} | {:>6}",
        "poses",
        "RMS deg",
        "bound",
        "ratio",
        "RMS mm",
        "bound",
        "ratio",
        "cov n",
        "cov d",
        "var f",
        "failed"
    );
    for &n_poses in &poses {
        let board_poses = laser_board_poses(n_poses);
        let (mut se_n, mut sb_n, mut se_d, mut sb_d, mut vf) = (0.0, 0.0, 0.0, 0.0, 0.0);
        let (mut cover_n, mut cover_d, mut done, mut failed) = (0usize, 0usize, 0usize, 0usize);
        for trial in 0..trials {
            let mut views = Vec::new();
            for (i, pose) in board_poses.iter().enumerate() {
                let seed = 1_000_003 * n_poses as u64 + 1009 * trial as u64 + 17 * i as u64;
                let off_options = RenderOptions {
                    seed,
                    ..RenderOptions::default()
                };
                let mut laser = LaserStripe::new(example_plane());
                laser.seed = seed ^ 0x5EED;
                let on_options = RenderOptions {
                    seed: seed + 1,
                    laser: Some(laser),
                    ..RenderOptions::default()
                };
                views.push(LaserView {
                    name: format!("pose {i}"),
                    board: render(&camera, &target, pose, &off_options)?.image,
                    stripe: Some(render(&camera, &target, pose, &on_options)?.image),
                });
            }
            let report = match laser_plane(&camera, &target, &views, &LaserPlaneSettings::default())
            {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("{n_poses} poses, trial {trial}: {e}");
                    failed += 1;
                    continue;
                }
            };
            done += 1;
            let p = &report.laser_plane;
            let n = Vector3::from(p.normal_camera);
            let c = Matrix4::from_fn(|r, k| p.covariance[r][k]);
            let a = n.cross(&Vector3::x()).normalize();
            let b = n.cross(&a);
            let e = n - truth_n;
            let e2 = Vector2::new(e.dot(&a), e.dot(&b));
            let cnn = c.fixed_view::<3, 3>(0, 0).into_owned();
            let c2 = Matrix2::new(
                a.dot(&(cnn * a)),
                a.dot(&(cnn * b)),
                b.dot(&(cnn * a)),
                b.dot(&(cnn * b)),
            );
            se_n += e2.norm_squared();
            sb_n += c2.trace();
            if let Some(inv) = c2.try_inverse() {
                if (e2.transpose() * inv * e2)[0] <= 11.829 {
                    cover_n += 1;
                }
            }
            let ed = p.distance_m - truth_d;
            se_d += ed * ed;
            sb_d += c[(3, 3)];
            if ed.abs() <= 3.0 * c[(3, 3)].sqrt() {
                cover_d += 1;
            }
            vf += report.variance_factor;
        }
        let t = done.max(1) as f64;
        let (rn, bn) = (
            (se_n / t).sqrt().to_degrees(),
            (sb_n / t).sqrt().to_degrees(),
        );
        let (rd, bd) = ((se_d / t).sqrt() * 1e3, (sb_d / t).sqrt() * 1e3);
        println!(
            "{n_poses:>5} | {rn:>9.5} {bn:>9.5} {:>6.2} | {rd:>8.4} {bd:>8.4} {:>6.2} | {:>6.1}% {:>6.1}% | {:>6.1} | {failed:>6}",
            rn / bn,
            rd / bd,
            100.0 * cover_n as f64 / t,
            100.0 * cover_d as f64 / t,
            vf / t
        );
    }
    Ok(())
}
