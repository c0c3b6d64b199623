//! Unit dual quaternions `q = r + ε d` for rigid transforms, as used by
//! Daniilidis' hand-eye solver (screw motions).
//!
//! For a pose with rotation quaternion `r` and translation `t`:
//! `d = ½ (0, t) r`, and back `t = 2 d r*`. Products compose like the poses:
//! `dq(a_from_b) * dq(b_from_c) = dq(a_from_c)`.

use nalgebra::{Quaternion, Translation3, UnitQuaternion, Vector3};

use super::Pose;
use crate::error::{Error, Result};

/// A dual quaternion `real + ε dual` (`ε² = 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DualQuaternion {
    /// The real part: the rotation quaternion for a unit dual quaternion.
    pub real: Quaternion<f64>,
    /// The dual part: `½ (0, t) real` for a rigid transform.
    pub dual: Quaternion<f64>,
}

impl DualQuaternion {
    /// The unit dual quaternion of a pose. Its real part has `w >= 0` (the
    /// pose is also represented by the negated dual quaternion).
    pub fn from_pose(pose: &Pose) -> Self {
        let mut real = *pose.rotation.quaternion();
        if real.w < 0.0 {
            real = -real;
        }
        let t = pose.translation.vector;
        let dual = Quaternion::from_imag(t) * real * 0.5;
        DualQuaternion { real, dual }
    }

    /// The pose of a (nearly) unit dual quaternion; normalises first. Errors
    /// when the real part is zero or non-finite.
    pub fn to_pose(&self) -> Result<Pose> {
        let n = self.real.norm();
        if !n.is_finite() || n < 1e-12 || !self.dual.coords.iter().all(|v| v.is_finite()) {
            return Err(Error::degenerate(format!(
                "dual quaternion with real-part norm {n} is not a rigid transform"
            )));
        }
        let real = self.real / n;
        let dual = self.dual / n;
        let t: Vector3<f64> = (dual * real.conjugate() * 2.0).imag();
        let rotation = UnitQuaternion::new_unchecked(real);
        Ok(Pose::from_parts(Translation3::from(t), rotation))
    }

    /// The product `self * other` (composition `a_from_b * b_from_c`).
    pub fn mul(&self, other: &DualQuaternion) -> DualQuaternion {
        DualQuaternion {
            real: self.real * other.real,
            dual: self.real * other.dual + self.dual * other.real,
        }
    }

    /// The quaternion conjugate of both parts, `r* + ε d*`. For a unit dual
    /// quaternion it is the inverse transform.
    pub fn conjugate(&self) -> DualQuaternion {
        DualQuaternion {
            real: self.real.conjugate(),
            dual: self.dual.conjugate(),
        }
    }

    /// The 8 components `[rw, rx, ry, rz, dw, dx, dy, dz]`.
    pub fn to_array_wxyz(&self) -> [f64; 8] {
        let (r, d) = (self.real, self.dual);
        [r.w, r.i, r.j, r.k, d.w, d.i, d.j, d.k]
    }

    /// A dual quaternion from `[rw, rx, ry, rz, dw, dx, dy, dz]` (not normalised).
    pub fn from_array_wxyz(v: [f64; 8]) -> Self {
        DualQuaternion {
            real: Quaternion::new(v[0], v[1], v[2], v[3]),
            dual: Quaternion::new(v[4], v[5], v[6], v[7]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::rotation_from_rotvec;
    use crate::rng::Rng;
    use std::f64::consts::PI;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn random_pose(rng: &mut Rng, case: usize) -> Pose {
        let axis = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
        let angle = match case % 4 {
            0 => 0.0,
            1 => PI,
            2 => PI - 1e-9,
            _ => rng.range(0.0, PI),
        };
        let t = Vector3::new(
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
        );
        Pose::from_parts(Translation3::from(t), rotation_from_rotvec(&(axis * angle)))
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn pose_round_trip_product_and_conjugate_match_poses() {
        let mut rng = Rng::new(21);
        for case in 0..3000 {
            let a_from_b = random_pose(&mut rng, case);
            let b_from_c = random_pose(&mut rng, case + 1);
            let dq_ab = DualQuaternion::from_pose(&a_from_b);
            let back = dq_ab.to_pose().unwrap();
            assert!((back.to_homogeneous() - a_from_b.to_homogeneous()).amax() < 1e-14);
            let dq_ac = dq_ab.mul(&DualQuaternion::from_pose(&b_from_c));
            let a_from_c = a_from_b * b_from_c;
            let got = dq_ac.to_pose().unwrap();
            assert!((got.to_homogeneous() - a_from_c.to_homogeneous()).amax() < 1e-13);
            let inv = dq_ab.conjugate().to_pose().unwrap();
            assert!((inv.to_homogeneous() - a_from_b.inverse().to_homogeneous()).amax() < 1e-13);
            // Unit dual quaternion: |r| = 1 and r·d = 0.
            assert!((dq_ab.real.norm() - 1.0).abs() < 1e-15);
            assert!(dq_ab.real.coords.dot(&dq_ab.dual.coords).abs() < 1e-14);
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn known_translation_and_degenerate_input() {
        // Pure translation t: real = 1, dual = (0, t/2).
        let pose = Pose::translation(2.0, -4.0, 6.0);
        let dq = DualQuaternion::from_pose(&pose);
        assert_eq!(
            dq.to_array_wxyz(),
            [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, -2.0, 3.0]
        );
        assert_eq!(DualQuaternion::from_array_wxyz(dq.to_array_wxyz()), dq);
        let zero = DualQuaternion::from_array_wxyz([0.0; 8]);
        assert!(matches!(zero.to_pose(), Err(Error::Degenerate { .. })));
    }
}
