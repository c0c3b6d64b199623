//! The renderer's bowed board: mrcal's two-parameter paraboloid
//! (`calib::BoardWarp`) over the extent of the target's points.

use crate::target::Target;
use nalgebra::{Isometry3, Vector3};

/// A bowed board: mrcal's paraboloid over the points' extent.
pub(crate) struct Bow {
    lo: (f64, f64),
    size: (f64, f64),
    warp: [f64; 2],
}

impl Bow {
    /// `None` for a flat board (or one whose points span no area).
    pub(crate) fn of(target: &Target, warp: [f64; 2]) -> Option<Bow> {
        if warp == [0.0, 0.0] {
            return None;
        }
        let pts = target.object_points();
        let lo = pts.iter().fold((f64::INFINITY, f64::INFINITY), |a, p| {
            (a.0.min(p.1.x), a.1.min(p.1.y))
        });
        let hi = pts
            .iter()
            .fold((f64::NEG_INFINITY, f64::NEG_INFINITY), |a, p| {
                (a.0.max(p.1.x), a.1.max(p.1.y))
            });
        let size = (hi.0 - lo.0, hi.1 - lo.1);
        (size.0 > 0.0 && size.1 > 0.0).then_some(Bow { lo, size, warp })
    }

    /// The z offset of board point (x, y).
    pub(crate) fn z(&self, x: f64, y: f64) -> f64 {
        let xr = 2.0 * (x - self.lo.0) / self.size.0 - 1.0;
        let yr = 2.0 * (y - self.lo.1) / self.size.1 - 1.0;
        self.warp[0] * (1.0 - xr * xr) + self.warp[1] * (1.0 - yr * yr)
    }

    /// Where the ray (camera frame) meets the bowed board, in board (x, y),
    /// from its plane hit `start`: fixed-point steps along the ray (the
    /// bow's slope is tiny, each step gains orders of magnitude).
    pub(crate) fn hit(
        &self,
        target_from_camera: &Isometry3<f64>,
        ray: &Vector3<f64>,
        start: (f64, f64),
    ) -> (f64, f64) {
        let o = target_from_camera.translation.vector;
        let d = target_from_camera.rotation * ray;
        if d.z.abs() < 1e-12 {
            return start;
        }
        let mut xy = start;
        for _ in 0..4 {
            let t = (self.z(xy.0, xy.1) - o.z) / d.z;
            xy = (o.x + t * d.x, o.y + t * d.y);
        }
        xy
    }
}
