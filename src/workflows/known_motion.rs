//! Camera-to-reference frame from known incremental motions of one point
//! (seed 000, Eq. 27-28): a point is moved by known increments
//! `d_i = (dx, dy, dz)` in the reference frame (a robot or stage) and seen
//! by a calibrated (stereo) camera at `P_i` in the camera frame:
//!
//! `P_i = R (P_ref + d_i) + T`,   i = 0..n (d_0 = 0 for the start).
//!
//! The seed counts 10 unknowns (R as a unit quaternion, T, P_ref). Only R
//! and the combination `c = R P_ref + T` (the start point in the camera
//! frame) are observable: moving the reference origin moves P_ref and T
//! together without changing any P_i. So `T` is reported when the caller
//! knows the start position in the reference frame (e.g. read from the robot
//! controller); otherwise the reference origin is placed at the start
//! position (`P_ref = 0`, `T = c`) and the report says so.
//!
//! Solution: the increments and the camera points differ by a rotation after
//! removing their centroids (`P_i - mean P = R (d_i - mean d)`), solved in
//! closed form (Kabsch/Umeyama with the determinant correction); then
//! `c = mean P - R mean d`. At least three positions with non-collinear
//! increments are needed (the seed recommends four moves or more).

use crate::error::{Error, Result};
use crate::geometry::Pose;
use nalgebra::{Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// Fewest positions (the start plus two moves in different directions).
pub const MIN_POSITIONS: usize = 3;

/// Ratio of the second to the largest spread of the increments below which
/// they count as collinear (rotation about that line undetermined).
const COLLINEAR_RATIO: f64 = 1e-6;

/// Input of [`solve_known_motion`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KnownMotionRequest {
    /// Increment of every position from the start, in the reference frame, mm.
    pub increments_mm: Vec<[f64; 3]>,
    /// The point seen by the camera at each position, camera frame, mm.
    pub points_camera_mm: Vec<[f64; 3]>,
    /// Optional: the start position in the reference frame, mm.
    #[serde(default)]
    pub start_reference_mm: Option<[f64; 3]>,
}

/// Output of [`solve_known_motion`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KnownMotionReport {
    /// The reference frame in the camera frame (translation in metres).
    #[serde(with = "crate::geometry::pose_serde")]
    pub camera_from_reference: Pose,
    /// The start point in the camera frame, mm (`R P_ref + T`).
    pub start_camera_mm: [f64; 3],
    /// The start point in the reference frame, mm: as given, or zero when
    /// the reference origin was placed at the start.
    pub start_reference_mm: [f64; 3],
    /// Whether `start_reference_mm` was given (else the origin is the start).
    pub reference_origin_given: bool,
    /// Per position: predicted minus observed camera point, mm.
    pub residuals_mm: Vec<[f64; 3]>,
    /// RMS of the residual lengths, mm.
    pub rms_mm: f64,
    /// The request, for re-solving.
    pub input: KnownMotionRequest,
}

/// Solve Eq. (28) in closed form.
pub fn solve_known_motion(request: &KnownMotionRequest) -> Result<KnownMotionReport> {
    let d: Vec<Vector3<f64>> = request
        .increments_mm
        .iter()
        .map(|v| Vector3::from(*v))
        .collect();
    let p: Vec<Vector3<f64>> = request
        .points_camera_mm
        .iter()
        .map(|v| Vector3::from(*v))
        .collect();
    if d.len() != p.len() {
        return Err(Error::invalid(
            "points_camera_mm",
            format!("{} increments but {} camera points", d.len(), p.len()),
        ));
    }
    if d.len() < MIN_POSITIONS {
        return Err(Error::too_few(
            "positions (start and moves)",
            MIN_POSITIONS,
            d.len(),
        ));
    }
    let n = d.len() as f64;
    let md = d.iter().sum::<Vector3<f64>>() / n;
    let mp = p.iter().sum::<Vector3<f64>>() / n;
    let mut sdd = Matrix3::zeros();
    let mut spd = Matrix3::zeros();
    for (a, b) in d.iter().zip(&p) {
        sdd += (a - md) * (a - md).transpose();
        spd += (b - mp) * (a - md).transpose();
    }
    let mut eig: Vec<f64> = sdd.symmetric_eigenvalues().iter().copied().collect();
    eig.sort_by(f64::total_cmp);
    let ratio = if eig[2] > 0.0 {
        (eig[1].max(0.0) / eig[2]).sqrt()
    } else {
        0.0
    };
    if ratio < COLLINEAR_RATIO {
        return Err(Error::degenerate(format!(
            "the {} increments are collinear (spread ratio {ratio:.1e}): the rotation about \
             that line is undetermined; move the point in at least two directions",
            d.len()
        )));
    }
    let svd = spd.svd(true, true);
    let (u, v_t) = match (svd.u, svd.v_t) {
        (Some(u), Some(v_t)) => (u, v_t),
        _ => return Err(Error::degenerate("SVD of the cross-covariance failed")),
    };
    let sign = (u * v_t).determinant().signum();
    let r = u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, sign)) * v_t;
    let rotation = Rotation3::from_matrix_unchecked(r);
    let c = mp - r * md;
    let start_reference = request
        .start_reference_mm
        .map(Vector3::from)
        .unwrap_or_else(Vector3::zeros);
    let t = c - r * start_reference;
    let residuals_mm: Vec<[f64; 3]> = d
        .iter()
        .zip(&p)
        .map(|(a, b)| (r * a + c - b).into())
        .collect();
    let rms_mm = (residuals_mm
        .iter()
        .map(|e| Vector3::from(*e).norm_squared())
        .sum::<f64>()
        / n)
        .sqrt();
    Ok(KnownMotionReport {
        camera_from_reference: Pose::from_parts(
            Translation3::from(t * 1e-3),
            UnitQuaternion::from_rotation_matrix(&rotation),
        ),
        start_camera_mm: c.into(),
        start_reference_mm: start_reference.into(),
        reference_origin_given: request.start_reference_mm.is_some(),
        residuals_mm,
        rms_mm,
        input: request.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn scene(noise: &mut dyn FnMut() -> f64) -> (KnownMotionRequest, Pose) {
        let camera_from_reference = Pose::from_parts(
            Translation3::new(-0.25, -0.1, 1.85),
            UnitQuaternion::from_euler_angles(0.4, -0.3, 2.0),
        );
        let start = Vector3::new(100.0, -50.0, 20.0);
        let increments: Vec<[f64; 3]> = vec![
            [0.0, 0.0, 0.0],
            [50.0, 0.0, 0.0],
            [0.0, 50.0, 0.0],
            [0.0, 0.0, 50.0],
            [50.0, 50.0, 50.0],
        ];
        let points = increments
            .iter()
            .map(|d| {
                let q = camera_from_reference
                    * nalgebra::Point3::from((start + Vector3::from(*d)) * 1e-3);
                [
                    q.x * 1e3 + noise(),
                    q.y * 1e3 + noise(),
                    q.z * 1e3 + noise(),
                ]
            })
            .collect();
        let req = KnownMotionRequest {
            increments_mm: increments,
            points_camera_mm: points,
            start_reference_mm: Some(start.into()),
        };
        (req, camera_from_reference)
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn noise_free_frame_is_exact() {
        let (req, truth) = scene(&mut || 0.0);
        let r = solve_known_motion(&req).unwrap();
        let e = r.camera_from_reference.inverse() * truth;
        assert!(
            e.translation.vector.norm() < 1e-12,
            "{} m",
            e.translation.vector.norm()
        );
        assert!(e.rotation.angle() < 1e-12, "{} rad", e.rotation.angle());
        assert!(r.rms_mm < 1e-9);
        // Without the start position, the rotation is the same and T = c.
        let mut req = req;
        req.start_reference_mm = None;
        let r2 = solve_known_motion(&req).unwrap();
        assert!(r2.camera_from_reference.rotation.angle_to(&truth.rotation) < 1e-12);
        let c = Vector3::from(r2.start_camera_mm) * 1e-3;
        assert!((r2.camera_from_reference.translation.vector - c).norm() < 1e-12);
        assert!(!r2.reference_origin_given);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn noisy_frame_within_bounds() {
        // sigma = 0.1 mm per coordinate, 50 mm lever arms: rotation error of
        // order sigma / (50 mm * sqrt(n)) = 1e-3 rad; bound 5e-3 rad. Start
        // point error about sigma / sqrt(n) = 0.05 mm; bound 0.5 mm.
        let mut rng = Rng::new(3);
        let (req, truth) = scene(&mut || rng.gaussian(0.1));
        let r = solve_known_motion(&req).unwrap();
        let e = r.camera_from_reference.inverse() * truth;
        assert!(e.rotation.angle() < 5e-3, "{} rad", e.rotation.angle());
        assert!(
            e.translation.vector.norm() * 1e3 < 0.5 + 150.0 * 5e-3,
            "{} mm",
            e.translation.vector.norm() * 1e3
        );
        assert!(r.rms_mm < 0.3, "{} mm", r.rms_mm);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn bad_input_is_refused_clearly() {
        let (mut req, _) = scene(&mut || 0.0);
        req.points_camera_mm.pop();
        assert_eq!(
            solve_known_motion(&req).unwrap_err().to_string(),
            "points_camera_mm: 5 increments but 4 camera points"
        );
        req.increments_mm.truncate(2);
        req.points_camera_mm.truncate(2);
        assert_eq!(
            solve_known_motion(&req).unwrap_err().to_string(),
            "requires at least 3 positions (start and moves), got 2"
        );
        let (mut req, _) = scene(&mut || 0.0);
        req.increments_mm = vec![
            [0.0; 3],
            [10.0, 0.0, 0.0],
            [20.0, 0.0, 0.0],
            [30.0, 0.0, 0.0],
            [40.0, 0.0, 0.0],
        ];
        assert!(solve_known_motion(&req)
            .unwrap_err()
            .to_string()
            .starts_with("the 5 increments are collinear"));
    }
}
