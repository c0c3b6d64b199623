//! Corner error against the sub-pixel phase of the board: a 9x6 chessboard
//! (30 mm squares, 42 px at 1 m through f = 1400 px, 1280x960, noise-free)
//! is moved across one pixel in eighths (the principal point shifted by
//! k/8 px in x and 3k/32 px in y: multiples of the renderer's 1/32 px
//! supersampling step, so its own quantisation of the edges stays the same
//! from step to step), and each step prints the mean signed error over the
//! board, the mean distance and the largest. Frontal, every corner has the
//! same phase: a detector bias that depends on the phase shows as a mean
//! that moves with it.
//!
//! Usage: cargo run --release --example corner_phase -- [TILT_RAD]
//! (default 0: frontal; 0.5 tilts the board about x). docs/benchmark-history.md,
//! "Session 14: chessboard corners: the fit points' phase".

use robocal::detect::{detect, DetectOptions};
use robocal::synth::{board_pose, render, Pinhole, RenderOptions};
use robocal::target::Target;

fn main() {
    let tilt: f64 = match std::env::args().nth(1) {
        Some(a) => a.parse().expect("TILT_RAD: a number (radians)"),
        None => 0.0,
    };
    let target = Target::parse_spec("chessboard:9x6:30mm").expect("spec");
    let pose = board_pose(&target, (tilt, 0.0, 0.0), (0.0, 0.0, 1.0));
    let options = RenderOptions {
        supersample: 32,
        ..RenderOptions::default()
    };
    for k in 0..=8 {
        let phase = k as f64 / 8.0;
        let cam = Pinhole {
            fx: 1400.0,
            fy: 1400.0,
            cx: 639.5 + phase,
            cy: 479.5 + 0.75 * phase,
            width: 1280,
            height: 960,
        };
        let r = render(&cam, &target, &pose, &options).expect("render");
        let det = detect(&r.image, &target, &DetectOptions::default()).expect("detect");
        let (mut sx, mut sy, mut sum, mut max) = (0.0, 0.0, 0.0, 0.0f64);
        for (d, t) in det.points.iter().zip(&r.points) {
            assert_eq!(d.id, t.id);
            let (ex, ey) = (d.x_px - t.x_px, d.y_px - t.y_px);
            let e = ex.hypot(ey);
            (sx, sy, sum, max) = (sx + ex, sy + ey, sum + e, max.max(e));
        }
        let n = det.points.len() as f64;
        println!(
            "phase {phase:.3} px: mean error ({:+.4}, {:+.4}) px, mean distance {:.4} px, max {max:.4} px",
            sx / n,
            sy / n,
            sum / n
        );
    }
}
