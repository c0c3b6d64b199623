//! Euler angles in all 12 axis orders, intrinsic (rotating axes) or
//! extrinsic (fixed axes).
//!
//! For an order `ABC` and angles `(a, b, c)`, each applied about the named
//! axis:
//!
//! - **intrinsic** (`A`, then `B'` about the once-rotated axis, then `C''`):
//!   `R = R_A(a) · R_B(b) · R_C(c)`;
//! - **extrinsic** (about the fixed axes `A`, then `B`, then `C`):
//!   `R = R_C(c) · R_B(b) · R_A(a)`.
//!
//! So extrinsic `XYZ` with `(a, b, c)` equals intrinsic `ZYX` with `(c, b,
//! a)`. Angles are in radians; the returned angles lie in `(-pi, pi]`, with
//! the middle angle in `[-pi/2, pi/2]` for Tait-Bryan orders (three distinct
//! axes) and in `[0, pi]` for proper Euler orders (first axis repeated).
//!
//! **Gimbal lock** (middle angle at ±pi/2 for Tait-Bryan, 0 or pi for proper
//! orders): only the sum or difference of the outer angles is defined. The
//! angle applied last in the product is then set to 0 (the third angle for
//! intrinsic, the first for extrinsic) and the other carries the whole
//! rotation, so the returned angles still reproduce the rotation exactly.

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::Rotation;

/// The axis sequence of Euler angles: the first letter is the axis of the
/// first angle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[allow(clippy::upper_case_acronyms)]
pub enum EulerOrder {
    /// X, Y, Z (Tait-Bryan).
    XYZ,
    /// X, Z, Y (Tait-Bryan).
    XZY,
    /// Y, X, Z (Tait-Bryan).
    YXZ,
    /// Y, Z, X (Tait-Bryan).
    YZX,
    /// Z, X, Y (Tait-Bryan).
    ZXY,
    /// Z, Y, X (Tait-Bryan).
    ZYX,
    /// X, Y, X (proper Euler).
    XYX,
    /// X, Z, X (proper Euler).
    XZX,
    /// Y, X, Y (proper Euler).
    YXY,
    /// Y, Z, Y (proper Euler).
    YZY,
    /// Z, X, Z (proper Euler).
    ZXZ,
    /// Z, Y, Z (proper Euler).
    ZYZ,
}

/// Whether the axes of later angles move with the body (intrinsic) or stay
/// fixed (extrinsic).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EulerKind {
    /// Rotating axes: `R = R_A(a) R_B(b) R_C(c)`.
    Intrinsic,
    /// Fixed axes: `R = R_C(c) R_B(b) R_A(a)`.
    Extrinsic,
}

impl EulerOrder {
    /// All 12 orders, Tait-Bryan first.
    pub const ALL: [EulerOrder; 12] = [
        EulerOrder::XYZ,
        EulerOrder::XZY,
        EulerOrder::YXZ,
        EulerOrder::YZX,
        EulerOrder::ZXY,
        EulerOrder::ZYX,
        EulerOrder::XYX,
        EulerOrder::XZX,
        EulerOrder::YXY,
        EulerOrder::YZY,
        EulerOrder::ZXZ,
        EulerOrder::ZYZ,
    ];

    /// The axis indices (0 = x, 1 = y, 2 = z) in application order.
    pub fn axes(self) -> [usize; 3] {
        match self {
            EulerOrder::XYZ => [0, 1, 2],
            EulerOrder::XZY => [0, 2, 1],
            EulerOrder::YXZ => [1, 0, 2],
            EulerOrder::YZX => [1, 2, 0],
            EulerOrder::ZXY => [2, 0, 1],
            EulerOrder::ZYX => [2, 1, 0],
            EulerOrder::XYX => [0, 1, 0],
            EulerOrder::XZX => [0, 2, 0],
            EulerOrder::YXY => [1, 0, 1],
            EulerOrder::YZY => [1, 2, 1],
            EulerOrder::ZXZ => [2, 0, 2],
            EulerOrder::ZYZ => [2, 1, 2],
        }
    }

    /// The order as three lowercase letters, e.g. `"zyx"`.
    pub fn name(self) -> &'static str {
        match self {
            EulerOrder::XYZ => "xyz",
            EulerOrder::XZY => "xzy",
            EulerOrder::YXZ => "yxz",
            EulerOrder::YZX => "yzx",
            EulerOrder::ZXY => "zxy",
            EulerOrder::ZYX => "zyx",
            EulerOrder::XYX => "xyx",
            EulerOrder::XZX => "xzx",
            EulerOrder::YXY => "yxy",
            EulerOrder::YZY => "yzy",
            EulerOrder::ZXZ => "zxz",
            EulerOrder::ZYZ => "zyz",
        }
    }

    /// The order named by three letters, case-insensitive (`"ZYX"`, `"zyx"`).
    pub fn from_name(name: &str) -> Option<EulerOrder> {
        let lower = name.to_ascii_lowercase();
        EulerOrder::ALL.into_iter().find(|o| o.name() == lower)
    }

    /// The same letters in reverse (`XYZ` -> `ZYX`).
    pub fn reversed(self) -> EulerOrder {
        let [a, b, c] = self.axes();
        let found = EulerOrder::ALL.into_iter().find(|o| o.axes() == [c, b, a]);
        // Every order's reverse is in ALL (proper orders are palindromes).
        found.unwrap_or(self)
    }
}

fn axis_rotation(axis: usize, angle: f64) -> Rotation {
    let mut v = Vector3::zeros();
    v[axis] = 1.0;
    UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_unchecked(v), angle)
}

/// The rotation of Euler angles `(a, b, c)` (radians) in `order`; see the
/// module docs for the intrinsic and extrinsic products.
pub fn rotation_from_euler(order: EulerOrder, kind: EulerKind, angles: [f64; 3]) -> Rotation {
    let [i, j, k] = order.axes();
    let [a, b, c] = angles;
    let (ra, rb, rc) = (
        axis_rotation(i, a),
        axis_rotation(j, b),
        axis_rotation(k, c),
    );
    match kind {
        EulerKind::Intrinsic => ra * rb * rc,
        EulerKind::Extrinsic => rc * rb * ra,
    }
}

/// Euler angles `(a, b, c)` (radians) of a rotation in `order`, such that
/// [`rotation_from_euler`] gives the rotation back (to ~1e-15), including at
/// gimbal lock (see the module docs for the ranges and the lock convention).
pub fn euler_from_rotation(rotation: &Rotation, order: EulerOrder, kind: EulerKind) -> [f64; 3] {
    match kind {
        EulerKind::Intrinsic => intrinsic_angles(rotation, order),
        EulerKind::Extrinsic => {
            let [c, b, a] = intrinsic_angles(rotation, order.reversed());
            [a, b, c]
        }
    }
}

/// Below this |cos b| (Tait-Bryan) or |sin b| (proper) the outer angles are
/// treated as locked; setting the third angle to 0 then costs at most this
/// much rotation error. Above it the first angle may carry an error of ~1e-16
/// / |cos b|, which the residual-based third angle absorbs exactly.
const GIMBAL_LOCK: f64 = 4.0 * f64::EPSILON;

/// The angle of a rotation matrix that is (nearly) a rotation about `axis`.
fn angle_about(m: &Matrix3<f64>, axis: usize) -> f64 {
    let (p, q) = ((axis + 1) % 3, (axis + 2) % 3);
    m[(q, p)].atan2(m[(p, p)])
}

/// Decomposes `R = R_i(a) R_j(b) R_k(c)`.
fn intrinsic_angles(rotation: &Rotation, order: EulerOrder) -> [f64; 3] {
    let r = rotation.to_rotation_matrix().into_inner();
    let [i, j, k0] = order.axes();
    let proper = i == k0;
    // The third axis distinct from i and j, and the parity of (i, j, k).
    let k = 3 - i - j;
    let s = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
    let (b, locked, a) = if proper {
        let sin_b = r[(i, j)].hypot(r[(i, k)]);
        let b = sin_b.atan2(r[(i, i)]);
        (b, sin_b < GIMBAL_LOCK, r[(j, i)].atan2(-s * r[(k, i)]))
    } else {
        let cos_b = r[(i, i)].hypot(r[(i, j)]);
        let b = (s * r[(i, k)]).atan2(cos_b);
        (b, cos_b < GIMBAL_LOCK, (-s * r[(j, k)]).atan2(r[(k, k)]))
    };
    let rb_inv = axis_rotation(j, -b).to_rotation_matrix().into_inner();
    if locked {
        // c = 0 and R_i(a) = R R_j(b)ᵀ.
        return [angle_about(&(r * rb_inv), i), b, 0.0];
    }
    // c from the residual R_k0(c) = R_j(b)ᵀ R_i(a)ᵀ R, so that any error in a
    // is absorbed and the angles reproduce R.
    let ra_inv = axis_rotation(i, -a).to_rotation_matrix().into_inner();
    let residual = Rotation3::from_matrix_unchecked(rb_inv * ra_inv * r);
    [a, b, angle_about(residual.matrix(), k0)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::rotation_angle_between;
    use crate::rng::Rng;
    use std::f64::consts::{FRAC_PI_2, PI};
    use wasm_bindgen_test::wasm_bindgen_test;

    fn rot(axis: usize, deg: f64) -> Rotation {
        axis_rotation(axis, deg.to_radians())
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn products_follow_the_documented_formulas() {
        let (a, b, c) = (0.3, -0.7, 1.9);
        let zyx_in = rotation_from_euler(EulerOrder::ZYX, EulerKind::Intrinsic, [a, b, c]);
        let zyx_by_hand = rot(2, a.to_degrees()) * rot(1, b.to_degrees()) * rot(0, c.to_degrees());
        assert!(rotation_angle_between(&zyx_in, &zyx_by_hand) < 1e-15);
        // Extrinsic XYZ (a, b, c) = Rz(c) Ry(b) Rx(a) = intrinsic ZYX (c, b, a).
        let xyz_ex = rotation_from_euler(EulerOrder::XYZ, EulerKind::Extrinsic, [a, b, c]);
        let zyx_rev = rotation_from_euler(EulerOrder::ZYX, EulerKind::Intrinsic, [c, b, a]);
        assert!(rotation_angle_between(&xyz_ex, &zyx_rev) < 1e-15);
        // A single angle: intrinsic ZYX (90°, 0, 0) is Rz(90°): x -> y.
        let rz = rotation_from_euler(EulerOrder::ZYX, EulerKind::Intrinsic, [FRAC_PI_2, 0.0, 0.0]);
        let x_rotated = rz * Vector3::x();
        assert!((x_rotated - Vector3::y()).norm() < 1e-15);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn known_angles_come_back() {
        for order in EulerOrder::ALL {
            let proper = order.axes()[0] == order.axes()[2];
            let angles = if proper {
                [0.4, 1.1, -2.5]
            } else {
                [0.4, -1.1, 2.5]
            };
            for kind in [EulerKind::Intrinsic, EulerKind::Extrinsic] {
                let r = rotation_from_euler(order, kind, angles);
                let got = euler_from_rotation(&r, order, kind);
                for (g, e) in got.iter().zip(angles) {
                    assert!((g - e).abs() < 1e-13, "{order:?} {kind:?}: {got:?}");
                }
            }
        }
    }

    fn random_angles(rng: &mut Rng, case: usize, proper: bool) -> [f64; 3] {
        let mut a = [rng.range(-PI, PI), rng.range(-PI, PI), rng.range(-PI, PI)];
        let lock_at = if proper {
            [0.0, PI]
        } else {
            [FRAC_PI_2, -FRAC_PI_2]
        };
        // Every third case sits on or within 1e-15..1e-5 of gimbal lock.
        match case % 6 {
            0 => a[1] = lock_at[0],
            1 => a[1] = lock_at[1],
            2 => {
                a[1] = lock_at[case % 2] + rng.range(-1.0, 1.0) * 10f64.powf(rng.range(-15.0, -5.0))
            }
            3 => a = [0.0; 3],
            _ => {}
        }
        a
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn random_round_trips_in_all_24_conventions_including_gimbal_lock() {
        let mut rng = Rng::new(11);
        for order in EulerOrder::ALL {
            let proper = order.axes()[0] == order.axes()[2];
            for kind in [EulerKind::Intrinsic, EulerKind::Extrinsic] {
                for case in 0..300 {
                    let angles = random_angles(&mut rng, case, proper);
                    let r = rotation_from_euler(order, kind, angles);
                    let got = euler_from_rotation(&r, order, kind);
                    let back = rotation_from_euler(order, kind, got);
                    let err = rotation_angle_between(&r, &back);
                    assert!(
                        err < 1e-13,
                        "{order:?} {kind:?} {angles:?} -> {got:?}: {err}"
                    );
                    let mid = got[1];
                    if proper {
                        assert!((0.0..=PI).contains(&mid));
                    } else {
                        assert!(mid.abs() <= FRAC_PI_2);
                    }
                    assert!(got.iter().all(|v| v.abs() <= PI));
                }
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn gimbal_lock_sets_the_last_applied_angle_to_zero() {
        // Intrinsic ZYX with pitch +90°: only a - c is defined; c = 0.
        let r = rotation_from_euler(EulerOrder::ZYX, EulerKind::Intrinsic, [0.5, FRAC_PI_2, 0.2]);
        let got = euler_from_rotation(&r, EulerOrder::ZYX, EulerKind::Intrinsic);
        assert!((got[0] - 0.3).abs() < 1e-12 && got[2] == 0.0, "{got:?}");
        let r = rotation_from_euler(EulerOrder::ZYZ, EulerKind::Extrinsic, [0.5, 0.0, 0.2]);
        let got = euler_from_rotation(&r, EulerOrder::ZYZ, EulerKind::Extrinsic);
        assert!(got[0] == 0.0 && (got[2] - 0.7).abs() < 1e-12, "{got:?}");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn names_parse_and_reverse() {
        assert_eq!(EulerOrder::from_name("ZYX"), Some(EulerOrder::ZYX));
        assert_eq!(EulerOrder::from_name("zxz"), Some(EulerOrder::ZXZ));
        assert_eq!(EulerOrder::from_name("zzx"), None);
        assert_eq!(EulerOrder::XZY.reversed(), EulerOrder::YZX);
        assert_eq!(EulerOrder::ZXZ.reversed(), EulerOrder::ZXZ);
    }
}
