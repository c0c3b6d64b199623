//! The stripe centre where it runs along an albedo edge of the board: a
//! fronto-parallel 9x6 chessboard 0.5 m away (1 mm = 1.6 px) under a stripe
//! parallel to its rows, slid so a black/white row edge lies `offset` px
//! from the stripe (negative: on the other side), with the laser-off image.
//! Mean signed centre error (px) against the renderer's exact centre, for
//! widths 3, 5, 10 px, with saturation (print 30/220, peak 400: white
//! clips) and without (print 20/100, peak 120), both prints (dark on light,
//! light on dark), seeds 3/4 and 5/6.
//!
//! `cargo run --example laser_edge [ridge]`

use robocal::camera::Camera;
use robocal::laser::{extract_stripe, ScanAxis, StripeMethod, StripeOptions};
use robocal::synth::laser::{stripe_truth, LaserStripe};
use robocal::synth::laser_scene::example_plane;
use robocal::synth::{board_pose, render, RenderOptions};
use robocal::target::Target;

fn main() -> Result<(), robocal::Error> {
    let method = if std::env::args().any(|a| a == "ridge") {
        StripeMethod::Ridge
    } else {
        StripeMethod::CentreOfGravity
    };
    let camera = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.025,
    };
    let offsets: Vec<f64> = (-8..=8).map(|k| k as f64).collect();
    print!("{:>5} {:>4} {:>5} {:>4} |", "width", "sat", "print", "seed");
    for o in &offsets {
        print!(" {o:>5}");
    }
    println!(" | worst  RMS");
    for width in [3.0, 5.0, 10.0] {
        for saturate in [true, false] {
            for light in [false, true] {
                for seed in [3u64, 5] {
                    let mut row = Vec::new();
                    for &off_px in &offsets {
                        // The row edge 12.5 mm below the centre of the board
                        // sits at the stripe (image row 240) when the board
                        // centre is 12.5 mm above it; each px is 1/1.6 mm.
                        let dy = -0.0125 + off_px / 1600.0;
                        let pose = board_pose(&target, (0.0, 0.0, 0.0), (0.0, dy, 0.5));
                        let mut laser = LaserStripe::new(example_plane());
                        laser.width_px = width;
                        laser.seed = seed;
                        let mut base = RenderOptions {
                            seed,
                            ..RenderOptions::default()
                        };
                        if !saturate {
                            base.black = 20.0;
                            base.white = 100.0;
                            laser.peak = 120.0;
                        }
                        if light {
                            base = base.light_on_dark();
                        }
                        let on_o = RenderOptions {
                            laser: Some(laser),
                            seed: seed + 1,
                            ..base.clone()
                        };
                        let off = render(&camera, &target, &pose, &base)?.image;
                        let on = render(&camera, &target, &pose, &on_o)?.image;
                        let truth = stripe_truth(&camera, &pose, &example_plane(), true);
                        let options = StripeOptions {
                            method,
                            axis: Some(ScanAxis::Columns),
                            ..StripeOptions::default()
                        };
                        let s = extract_stripe(&on, Some(&off), &options)?;
                        let (mut sum, mut n) = (0.0, 0);
                        for p in &s.points {
                            // Over the board only (columns 160-480).
                            if !(160.0..480.0).contains(&p.x_px) {
                                continue;
                            }
                            if let Some((_, t)) = truth.iter().find(|(i, _)| *i == p.x_px as usize)
                            {
                                sum += p.y_px - t;
                                n += 1;
                            }
                        }
                        row.push(if n > 0 { sum / n as f64 } else { f64::NAN });
                    }
                    let worst = row.iter().fold(0f64, |a, b| a.max(b.abs()));
                    let rms = (row.iter().map(|v| v * v).sum::<f64>() / row.len() as f64).sqrt();
                    print!(
                        "{width:>5} {:>4} {:>5} {seed:>4} |",
                        if saturate { "yes" } else { "no" },
                        if light { "light" } else { "dark" }
                    );
                    for v in &row {
                        print!(" {v:>5.2}");
                    }
                    println!(" | {worst:.2} {rms:.2}");
                }
            }
        }
    }
    Ok(())
}
