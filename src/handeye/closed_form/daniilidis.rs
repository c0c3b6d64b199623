//! Daniilidis 1999: AX = XB with dual quaternions, rotation and translation
//! from one SVD.

use crate::error::{Error, Result};
use crate::geometry::DualQuaternion;
use crate::handeye::math::{ascending_eigenvectors, skew};
use crate::handeye::{Motion, Pose};
use nalgebra::{DMatrix, Quaternion, SMatrix, Vector3, Vector4};

/// Unit dual quaternion `(q, q')` of a pose as two `[w, x, y, z]` vectors,
/// real part with `w >= 0` ([`DualQuaternion::from_pose`]).
fn dual_quaternion(p: &Pose) -> (Vector4<f64>, Vector4<f64>) {
    let dq = DualQuaternion::from_pose(p);
    let v = |q: &Quaternion<f64>| Vector4::new(q.w, q.i, q.j, q.k);
    (v(&dq.real), v(&dq.dual))
}

/// Solve AX = XB. Per motion the 6x8 block
/// `[a - b, [a + b]x, 0, 0; a' - b', [a' + b']x, a - b, [a + b]x]`
/// (vector parts of the dual quaternions of A and B) annihilates the dual
/// quaternion of X; its two-dimensional null space is combined so that the
/// result is a unit dual quaternion.
pub fn solve(motions: &[Motion]) -> Result<(Pose, Vec<Vector3<f64>>)> {
    let mut normal = DMatrix::zeros(8, 8);
    for m in motions {
        let (a, ad) = dual_quaternion(&m.robot);
        let (b, bd) = dual_quaternion(&m.camera);
        let v = |q: &Vector4<f64>| Vector3::new(q[1], q[2], q[3]);
        let (av, bv, adv, bdv) = (v(&a), v(&b), v(&ad), v(&bd));
        let mut t = SMatrix::<f64, 6, 8>::zeros();
        t.fixed_view_mut::<3, 1>(0, 0).copy_from(&(av - bv));
        t.fixed_view_mut::<3, 3>(0, 1).copy_from(&skew(&(av + bv)));
        t.fixed_view_mut::<3, 1>(3, 0).copy_from(&(adv - bdv));
        t.fixed_view_mut::<3, 3>(3, 1)
            .copy_from(&skew(&(adv + bdv)));
        t.fixed_view_mut::<3, 1>(3, 4).copy_from(&(av - bv));
        t.fixed_view_mut::<3, 3>(3, 5).copy_from(&skew(&(av + bv)));
        let tt = t.transpose() * t;
        normal += DMatrix::from_column_slice(8, 8, tt.as_slice());
    }
    let pairs = ascending_eigenvectors(&normal)?;
    let split = |v: &nalgebra::DVector<f64>| {
        (
            Vector4::new(v[0], v[1], v[2], v[3]),
            Vector4::new(v[4], v[5], v[6], v[7]),
        )
    };
    let (u1, v1) = split(&pairs[0].1);
    let (u2, v2) = split(&pairs[1].1);
    // (l1 u1 + l2 u2) . (l1 v1 + l2 v2) = 0: a homogeneous quadratic in (l1, l2).
    let qa = u1.dot(&v1);
    let qb = u1.dot(&v2) + u2.dot(&v1);
    let qc = u2.dot(&v2);
    let mut candidates = Vec::new();
    for (l1, l2) in quadratic_directions(qa, qb, qc) {
        let u = u1 * l1 + u2 * l2;
        let n = u.norm();
        if n > 1e-12 {
            candidates.push((
                n / (l1 * l1 + l2 * l2).sqrt(),
                u / n,
                (v1 * l1 + v2 * l2) / n,
            ));
        }
    }
    let (_, q, qd) = candidates
        .into_iter()
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .ok_or_else(|| {
            Error::degenerate("Daniilidis: no unit dual quaternion in the null space")
        })?;
    let pose = DualQuaternion {
        real: Quaternion::new(q[0], q[1], q[2], q[3]),
        dual: Quaternion::new(qd[0], qd[1], qd[2], qd[3]),
    }
    .to_pose()?;
    Ok((pose, Vec::new()))
}

/// Directions `(l1, l2)` with `a l1^2 + b l1 l2 + c l2^2 = 0`, solved in the
/// better-conditioned ratio; a negative discriminant (noise) is clamped to 0.
fn quadratic_directions(a: f64, b: f64, c: f64) -> Vec<(f64, f64)> {
    let disc = (b * b - 4.0 * a * c).max(0.0).sqrt();
    if a.abs() >= c.abs() {
        if a.abs() < 1e-300 {
            return vec![(1.0, 0.0), (0.0, 1.0)];
        }
        // s = l1 / l2
        vec![
            ((-b + disc) / (2.0 * a), 1.0),
            ((-b - disc) / (2.0 * a), 1.0),
        ]
    } else {
        // s = l2 / l1
        vec![
            (1.0, (-b + disc) / (2.0 * c)),
            (1.0, (-b - disc) / (2.0 * c)),
        ]
    }
}
