//! Zhang's closed-form initialisation: intrinsics from the homographies of
//! at least 3 views (2 with zero skew) through the image of the absolute
//! conic, then each view's pose from its homography.

use crate::error::{Error, Result};
use crate::geometry::{nearest_rotation, Pose};
use nalgebra::{DMatrix, Matrix3, Translation3, UnitQuaternion, Vector3};

/// Weight of the zero-skew constraint row relative to the data rows
/// (which are O(1) after normalisation).
const ZERO_SKEW_WEIGHT: f64 = 1e3;

/// The row `v_ij` of Zhang's linear system for homography columns i, j.
fn v_row(h: &Matrix3<f64>, i: usize, j: usize) -> [f64; 6] {
    let (a, b) = (h.column(i), h.column(j));
    [
        a[0] * b[0],
        a[0] * b[1] + a[1] * b[0],
        a[1] * b[1],
        a[2] * b[0] + a[0] * b[2],
        a[2] * b[1] + a[1] * b[2],
        a[2] * b[2],
    ]
}

/// The camera matrix from plane-to-image homographies. `image_size` sets
/// the pixel normalisation that conditions the system.
pub fn intrinsics_from_homographies(
    homographies: &[Matrix3<f64>],
    image_size: (u32, u32),
    zero_skew: bool,
) -> Result<Matrix3<f64>> {
    let required = if zero_skew { 2 } else { 3 };
    if homographies.len() < required {
        return Err(Error::too_few(
            "views for closed-form intrinsics",
            required,
            homographies.len(),
        ));
    }
    // Pixels -> roughly [-1, 1]: n_from_pixel.
    let s = 0.5 * image_size.0.max(image_size.1).max(1) as f64;
    let (w2, h2) = (0.5 * image_size.0 as f64, 0.5 * image_size.1 as f64);
    let n_from_pixel = Matrix3::new(1.0 / s, 0.0, -w2 / s, 0.0, 1.0 / s, -h2 / s, 0.0, 0.0, 1.0);
    let rows = 2 * homographies.len() + usize::from(zero_skew);
    let mut v = DMatrix::zeros(rows.max(6), 6);
    for (k, h) in homographies.iter().enumerate() {
        let hn = n_from_pixel * h;
        let hn = hn / hn.column(0).norm().max(hn.column(1).norm());
        let v12 = v_row(&hn, 0, 1);
        let v11 = v_row(&hn, 0, 0);
        let v22 = v_row(&hn, 1, 1);
        for c in 0..6 {
            v[(2 * k, c)] = v12[c];
            v[(2 * k + 1, c)] = v11[c] - v22[c];
        }
    }
    if zero_skew {
        v[(2 * homographies.len(), 1)] = ZERO_SKEW_WEIGHT;
    }
    let svd = v.svd(false, true);
    let v_t = svd
        .v_t
        .ok_or_else(|| Error::degenerate("closed-form SVD failed"))?;
    let min_i = svd.singular_values.imin();
    let mut b: Vec<f64> = v_t.row(min_i).iter().copied().collect();
    if b[0] < 0.0 {
        b.iter_mut().for_each(|x| *x = -*x);
    }
    let [b11, b12, b22, b13, b23, b33] = [b[0], b[1], b[2], b[3], b[4], b[5]];
    let d = b11 * b22 - b12 * b12;
    let degenerate = || {
        Error::degenerate(
            "the views do not determine the intrinsics (the board must be tilted differently in at least 3 views)",
        )
    };
    if !(d > 0.0) || !(b11 > 0.0) {
        return Err(degenerate());
    }
    let v0 = (b12 * b13 - b11 * b23) / d;
    let lambda = b33 - (b13 * b13 + v0 * (b12 * b13 - b11 * b23)) / b11;
    let alpha2 = lambda / b11;
    let beta2 = lambda * b11 / d;
    if !(alpha2 > 0.0) || !(beta2 > 0.0) {
        return Err(degenerate());
    }
    let (alpha, beta) = (alpha2.sqrt(), beta2.sqrt());
    let gamma = if zero_skew {
        0.0
    } else {
        -b12 * alpha2 * beta / lambda
    };
    let u0 = gamma * v0 / beta - b13 * alpha2 / lambda;
    let k_n = Matrix3::new(alpha, gamma, u0, 0.0, beta, v0, 0.0, 0.0, 1.0);
    let pixel_from_n = n_from_pixel.try_inverse().ok_or_else(degenerate)?;
    let k = pixel_from_n * k_n;
    Ok(k / k[(2, 2)])
}

/// camera_from_target of a view from its homography and the camera
/// matrix (the target plane is z = 0 in target coordinates).
pub fn pose_from_homography(k: &Matrix3<f64>, h: &Matrix3<f64>) -> Result<Pose> {
    let k_inv = k
        .try_inverse()
        .ok_or_else(|| Error::degenerate("singular camera matrix"))?;
    let m = k_inv * h;
    let scale = 1.0 / m.column(0).norm();
    if !scale.is_finite() {
        return Err(Error::degenerate("degenerate homography"));
    }
    // The target is in front of the camera: t_z > 0.
    let sign = if m[(2, 2)] < 0.0 { -scale } else { scale };
    let r1: Vector3<f64> = m.column(0) * sign;
    let r2: Vector3<f64> = m.column(1) * sign;
    let t: Vector3<f64> = m.column(2) * sign;
    let r = Matrix3::from_columns(&[r1, r2, r1.cross(&r2)]);
    let rotation = nearest_rotation(&r)?;
    Ok(Pose::from_parts(
        Translation3::from(t),
        UnitQuaternion::from_rotation_matrix(&rotation),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::rotation_from_rotvec;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn exact_homographies_give_the_exact_camera_and_poses() {
        let k = Matrix3::new(910.0, 1.5, 655.0, 0.0, 905.0, 470.0, 0.0, 0.0, 1.0);
        let poses: Vec<Pose> = [
            Vector3::new(0.3, -0.1, 0.05),
            Vector3::new(-0.2, 0.35, -0.1),
            Vector3::new(0.1, 0.2, 0.4),
            Vector3::new(-0.4, -0.1, 0.2),
        ]
        .iter()
        .enumerate()
        .map(|(i, r)| {
            Pose::from_parts(
                Translation3::new(-0.1 + 0.05 * i as f64, -0.08, 0.6),
                rotation_from_rotvec(r),
            )
        })
        .collect();
        let hs: Vec<Matrix3<f64>> = poses
            .iter()
            .map(|p| {
                let r = p.rotation.to_rotation_matrix();
                let t = p.translation.vector;
                k * Matrix3::from_columns(&[
                    r.matrix().column(0).into_owned(),
                    r.matrix().column(1).into_owned(),
                    t,
                ]) * 3.7
            })
            .collect();
        let est =
            intrinsics_from_homographies(&hs, (1280, 960), false).unwrap_or_else(|e| panic!("{e}"));
        assert!((est - k).amax() < 1e-8, "{est}");
        for (h, pose) in hs.iter().zip(&poses) {
            let p = pose_from_homography(&k, h).unwrap_or_else(|e| panic!("{e}"));
            assert!((p.translation.vector - pose.translation.vector).norm() < 1e-12);
            assert!(p.rotation.angle_to(&pose.rotation) < 1e-12);
        }
        let k0 = Matrix3::new(910.0, 0.0, 655.0, 0.0, 905.0, 470.0, 0.0, 0.0, 1.0);
        let hs0: Vec<Matrix3<f64>> = hs
            .iter()
            .map(|h| k0 * k.try_inverse().unwrap_or_default() * h)
            .collect();
        let est0 = intrinsics_from_homographies(&hs0[..2], (1280, 960), true)
            .unwrap_or_else(|e| panic!("{e}"));
        assert!((est0 - k0).amax() < 1e-8, "{est0}");
        assert_eq!(
            intrinsics_from_homographies(&hs[..2], (1280, 960), false).map_err(|e| e.to_string()),
            Err("requires at least 3 views for closed-form intrinsics, got 2".to_string())
        );
    }
}
