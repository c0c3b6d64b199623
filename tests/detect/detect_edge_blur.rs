//! Corners under a lens blur that grows toward the image corners (issue 42):
//! the mean radial error against the renderer's exact truth, per ring of
//! the image, must stay near zero. A bias there is what moves a calibrated
//! focal length (outward: a longer fx).
//!
//! The scene is not the one the detector was tuned on (benches/corner_study.py:
//! 640x480, fx 600, a 9x6 board, seed 42): a 960x720 camera with another
//! distortion, a 10x7 board of 25 mm squares, five poses reaching into the
//! corners, seeds 7-11. The optics: defocus 0.6 px at the centre, field
//! curvature 1.5 px, astigmatism 1.5 px and coma 1.5 px at the corners
//! (src/synth/effects.rs; the PSF's centroid stays on the truth, its skew
//! grows with the radius), the renderer's 0.7 px blur, vignetting 0.2 and
//! noise sigma 1.

use robocal::camera::Camera;
use robocal::detect::{detect, DetectOptions};
use robocal::synth::effects::{Effects, Optics};
use robocal::synth::{board_pose, render, RenderOptions};
use robocal::target::Target;

fn camera() -> Camera {
    Camera {
        distortion: robocal::Distortion::Brown {
            k1: -0.12,
            k2: 0.03,
            k3: 0.0,
            p1: 0.0004,
            p2: -0.0002,
        },
        ..Camera::pinhole(760.0, 761.0, 483.1, 357.4, 960, 720)
    }
}

const POSES: [((f64, f64, f64), (f64, f64, f64)); 5] = [
    ((0.05, -0.1, 0.02), (0.0, 0.0, 0.31)),
    ((0.15, 0.1, 0.05), (0.075, 0.05, 0.37)),
    ((-0.1, 0.15, -0.05), (-0.075, 0.05, 0.37)),
    ((0.1, -0.15, 0.1), (0.075, -0.05, 0.37)),
    ((-0.15, -0.1, -0.1), (-0.075, -0.05, 0.37)),
];

/// (radius / half-diagonal, radial error px) of every detected corner.
fn radial_errors(optics: Option<Optics>) -> Vec<(f64, f64)> {
    let cam = camera();
    let target = Target::parse_spec("chessboard:10x7:25mm").unwrap();
    let (cx, cy) = (483.1, 357.4);
    let half_diagonal = f64::hypot(cx, cy);
    let mut out = Vec::new();
    for (k, (rpy, at)) in POSES.into_iter().enumerate() {
        let o = RenderOptions {
            seed: 7 + k as u64,
            noise_sigma: 1.0,
            vignetting: 0.2,
            effects: Effects {
                optics: optics.clone(),
                ..Effects::default()
            },
            ..RenderOptions::default()
        };
        let r = render(&cam, &target, &board_pose(&target, rpy, at), &o).unwrap();
        assert_eq!(
            r.points.len(),
            target.point_count(),
            "view {k}: board in view"
        );
        let det = detect(&r.image, &target, &DetectOptions::default())
            .unwrap_or_else(|e| panic!("view {k}: {e}"));
        assert_eq!(det.points.len(), r.points.len(), "view {k}: every corner");
        for (d, t) in det.points.iter().zip(&r.points) {
            assert_eq!(d.id, t.id);
            let (dx, dy) = (t.x_px - cx, t.y_px - cy);
            let radius = dx.hypot(dy);
            let (ux, uy) = (dx / radius, dy / radius);
            out.push((
                radius / half_diagonal,
                (d.x_px - t.x_px) * ux + (d.y_px - t.y_px) * uy,
            ));
        }
    }
    out
}

/// Mean radial error and count of the corners with `lo <= r < hi`.
fn ring(errors: &[(f64, f64)], lo: f64, hi: f64) -> (f64, usize) {
    let sel: Vec<f64> = errors
        .iter()
        .filter(|(r, _)| *r >= lo && *r < hi)
        .map(|e| e.1)
        .collect();
    (sel.iter().sum::<f64>() / sel.len().max(1) as f64, sel.len())
}

/// Bounds on the mean radial error per ring, pixels: issue 42's goal
/// (0.02 px) outside, half of it inside. Measured: inner -0.0014 px (125
/// corners), middle -0.0034 (190), outer -0.0069 (35).
const INNER_TOLERANCE_PX: f64 = 0.01;
const OUTER_TOLERANCE_PX: f64 = 0.02;

#[test]
fn corners_under_edge_blur_have_no_radial_bias() {
    let strong = Optics {
        defocus_px: 0.6,
        field_curvature_px: 1.5,
        astigmatism_px: 1.5,
        coma_px: 1.5,
    };
    let e = radial_errors(Some(strong));
    let (inner, n_inner) = ring(&e, 0.0, 0.3);
    let (middle, n_middle) = ring(&e, 0.3, 0.6);
    let (outer, n_outer) = ring(&e, 0.6, 9.0);
    println!(
        "edge blur: mean radial error inner {inner:+.4} px ({n_inner}), middle \
         {middle:+.4} ({n_middle}), outer {outer:+.4} ({n_outer})"
    );
    assert!(
        n_inner >= 20 && n_outer >= 20,
        "{n_inner} / {n_outer} corners"
    );
    assert!(
        inner.abs() < INNER_TOLERANCE_PX,
        "inner ring: {inner:+.4} px"
    );
    assert!(
        outer.abs() < OUTER_TOLERANCE_PX,
        "outer ring: {outer:+.4} px"
    );
}
