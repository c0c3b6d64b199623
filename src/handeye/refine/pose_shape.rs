//! A per-view camera pose covariance predicted from the pose alone, for
//! camera poses given without image points.
//!
//! PnP's pose covariance differs between views mainly through the distance
//! and tilt of the target relative to the camera, and both are known from
//! each `camera_from_target`. For a nominal planar target (a grid of points
//! on z = 0 of the target frame) the shape of that covariance at a view's
//! pose is `(J^T J)^-1` of the projection in normalised image coordinates
//! (focal length 1); the common scale (pixel noise over focal length) is
//! estimated like [`crate::handeye::refine::pose_noise::CameraNoise::PerView`]'s. Which
//! nominal target (its extent and centre) is taken is decided by likelihood
//! by the caller ([`crate::handeye::refine::over_poses`]).

use crate::handeye::math::skew;
use crate::handeye::refine::pose_residual::PoseMeasurement;
use nalgebra::{Matrix2x3, Matrix6, SMatrix, Vector3};

/// Points per side of the nominal grid.
const GRID_SIDE: usize = 7;

/// A nominal planar target: an axis-aligned rectangle on z = 0 of the
/// target frame, `centre +- half` (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NominalTarget {
    /// Centre (target frame; z ignored).
    pub centre: Vector3<f64>,
    /// Half extents along the target's x and y (metres).
    pub half: [f64; 2],
}

impl NominalTarget {
    /// The grid points of the rectangle (`GRID_SIDE` x `GRID_SIDE`).
    pub fn points(&self) -> Vec<Vector3<f64>> {
        let step = |k: usize| 2.0 * k as f64 / (GRID_SIDE - 1) as f64 - 1.0;
        let mut out = Vec::with_capacity(GRID_SIDE * GRID_SIDE);
        for a in 0..GRID_SIDE {
            for b in 0..GRID_SIDE {
                out.push(Vector3::new(
                    self.centre.x + self.half[0] * step(a),
                    self.centre.y + self.half[1] * step(b),
                    0.0,
                ));
            }
        }
        out
    }

    /// The candidates tried: with a `pivot` (where the cameras look on the
    /// target) away from the origin, the rectangle from the origin to twice
    /// the pivot (a grid whose origin is a corner, as chessboards are);
    /// then squares about the pivot (or the origin) with half extents 5 %,
    /// 10 % and 20 % of the mean viewing distance.
    pub fn candidates(views: &[PoseMeasurement], pivot: Option<Vector3<f64>>) -> Vec<Self> {
        let n = views.len().max(1) as f64;
        let depth = views
            .iter()
            .map(|m| m.camera_from_target.translation.vector.norm())
            .sum::<f64>()
            / n;
        let centre = pivot.map(|p| Vector3::new(p.x, p.y, 0.0));
        let mut out = Vec::new();
        if let Some(c) = centre {
            if c.x.abs() > 0.01 * depth && c.y.abs() > 0.01 * depth {
                out.push(NominalTarget {
                    centre: c,
                    half: [c.x.abs(), c.y.abs()],
                });
            }
        }
        for k in [0.05, 0.1, 0.2] {
            out.push(NominalTarget {
                centre: centre.unwrap_or_else(Vector3::zeros),
                half: [k * depth; 2],
            });
        }
        out
    }
}

/// `(J^T J)^-1` of PnP in normalised image coordinates for `points` seen
/// from `camera_from_target`, in the convention of
/// [`crate::handeye::refine::pose_residual`] (camera frame, left: `exp(w) R`, `t + v`,
/// order `[w, v]`). `None` when a point is behind the camera or the pose is
/// not constrained.
pub fn predicted_covariance(m: &PoseMeasurement, points: &[Vector3<f64>]) -> Option<Matrix6<f64>> {
    let pose = &m.camera_from_target;
    let r = pose.rotation.to_rotation_matrix().into_inner();
    let t = pose.translation.vector;
    let mut jtj = Matrix6::zeros();
    for p in points {
        let rp = r * p;
        let x = rp + t;
        if x.z <= 1e-9 {
            return None;
        }
        let d_proj = Matrix2x3::new(
            1.0 / x.z,
            0.0,
            -x.x / (x.z * x.z),
            0.0,
            1.0 / x.z,
            -x.y / (x.z * x.z),
        );
        // X <- exp(w) R p + t + v: dX = -[R p]x w + v.
        let mut j = SMatrix::<f64, 2, 6>::zeros();
        j.fixed_view_mut::<2, 3>(0, 0)
            .copy_from(&(d_proj * -skew(&rp)));
        j.fixed_view_mut::<2, 3>(0, 3).copy_from(&d_proj);
        jtj += j.transpose() * j;
    }
    jtj.try_inverse()
}

/// [`predicted_covariance`] of every view for one nominal target.
pub fn predicted_covariances(
    views: &[PoseMeasurement],
    target: &NominalTarget,
) -> Option<Vec<Matrix6<f64>>> {
    let points = target.points();
    views
        .iter()
        .map(|m| predicted_covariance(m, &points))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calib::pnp::camera_from_target_with_covariance;
    use crate::camera::Camera;
    use crate::handeye::Pose;
    use nalgebra::{Point2, Translation3, UnitQuaternion};
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn matches_pnp_covariance_over_the_focal_squared() {
        // Same points, ideal pinhole with the principal point at 0: PnP's
        // (J^T J)^-1 in pixels is the normalised one over f^2.
        let f = 1000.0;
        let camera = Camera::pinhole(f, f, 0.0, 0.0, 4000, 4000);
        let target = NominalTarget {
            centre: Vector3::new(0.1, 0.07, 0.0),
            half: [0.1, 0.07],
        };
        let pose = Pose::from_parts(
            Translation3::new(-0.08, 0.03, 0.6),
            UnitQuaternion::from_scaled_axis(Vector3::new(0.3, -0.2, 0.5)),
        );
        let points = target.points();
        let view = crate::calib::View::new(
            "",
            points.iter().map(|p| (*p).into()).collect(),
            points
                .iter()
                .map(|p| {
                    let x = pose * nalgebra::Point3::from(*p);
                    Point2::new(f * x.x / x.z, f * x.y / x.z)
                })
                .collect(),
        );
        let (_, _, pnp) = camera_from_target_with_covariance(&camera, &view).unwrap();
        let m = PoseMeasurement {
            base_from_gripper: Pose::identity(),
            camera_from_target: pose,
        };
        let predicted = predicted_covariance(&m, &points).unwrap() / (f * f);
        let scale = pnp.amax();
        assert!(
            (predicted - pnp).amax() < 1e-6 * scale,
            "{predicted} vs {pnp}"
        );
    }
}
