//! Renders shared by the detection tests: the 1280x960 pinhole with its
//! principal point off the centre, a board rendered at a pose, and the
//! errors of a detection against the renderer's truth by id.

use robocal::synth::{board_pose, render, Pinhole, RenderOptions, Rendered};
use robocal::target::{DetectedPoint, Detection, Target};

/// A `w` x `h` pinhole of focal length `f` px, its principal point 3.3 px
/// right of and 2.1 px above the image centre.
pub(crate) fn camera(w: u32, h: u32, f: f64) -> Pinhole {
    Pinhole {
        fx: f,
        fy: f,
        cx: (w as f64 - 1.0) / 2.0 + 3.3,
        cy: (h as f64 - 1.0) / 2.0 - 2.1,
        width: w,
        height: h,
    }
}

/// The board of `spec` at `board_pose(rpy, at)` through [`camera`]`(1280,
/// 960, 1100)`, the renderer's defaults with `seed`.
pub(crate) fn render_board(
    spec: &str,
    rpy: (f64, f64, f64),
    at: (f64, f64, f64),
    seed: u64,
) -> (Target, Rendered) {
    let target = Target::parse_spec(spec).unwrap();
    let cam = camera(1280, 960, 1100.0);
    let o = RenderOptions {
        seed,
        ..RenderOptions::default()
    };
    let r = render(&cam, &target, &board_pose(&target, rpy, at), &o).unwrap();
    (target, r)
}

/// Per-point errors of the detected points against the truth (by id);
/// every detected id must be in the truth.
pub(crate) fn errors(det: &Detection, truth: &[DetectedPoint]) -> Vec<f64> {
    det.points
        .iter()
        .map(|d| {
            let t = truth
                .iter()
                .find(|t| t.id == d.id)
                .unwrap_or_else(|| panic!("detected id {} is not in view", d.id));
            ((d.x_px - t.x_px).powi(2) + (d.y_px - t.y_px).powi(2)).sqrt()
        })
        .collect()
}

/// The mean of `v` (0 for none).
pub(crate) fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}
