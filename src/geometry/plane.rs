//! A plane in a named frame (a laser plane in the camera frame, say), with
//! a 3x3 covariance, and its change of frame: the laser plane and the
//! camera of a sensor on the robot's flange, from the hand-eye transform.
//!
//! A plane is the points `p` with `normal . p = distance_m` (unit normal).
//! Its covariance is over three numbers `(a, b, d)`: `a`, `b` turn the
//! normal by the rotation vector `a e1 + b e2` (`e1`, `e2` of
//! [`tangent_basis`], perpendicular to the normal) and `d` is the distance
//! in metres. A pose covariance (6x6) is over the right perturbation
//! `a_from_b * exp([w, v])` (rotation vector `w` in radians, then translation
//! `v` in metres, both in frame `b`), as the reprojection refinement of the
//! hand-eye transform perturbs it.

use crate::error::{Error, Result};
use nalgebra::{
    Isometry3, Matrix2x3, Matrix3, Matrix3x6, Matrix4, Matrix4x3, Matrix6, Point3, Rotation3,
    Translation3, Unit, UnitQuaternion, Vector3,
};

/// The plane `normal . p = distance_m` in some frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: Unit<Vector3<f64>>,
    /// Signed distance of the plane from the frame's origin along the normal, metres.
    pub distance_m: f64,
}

/// A plane with the covariance of `(a, b, d)` (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneEstimate {
    /// The plane.
    pub plane: Plane,
    /// Covariance of (normal tangent a rad, normal tangent b rad, distance m).
    pub covariance: Matrix3<f64>,
}

/// Two unit vectors `e1`, `e2` with `(e1, e2, normal)` right-handed and
/// orthonormal: `e1` is the normal's cross product with the axis on which
/// the normal has its smallest component (x before y before z on ties), so
/// the basis is a fixed function of the normal.
pub fn tangent_basis(normal: &Unit<Vector3<f64>>) -> (Vector3<f64>, Vector3<f64>) {
    let n = normal.into_inner();
    let mut k = 0;
    for i in 1..3 {
        if n[i].abs() < n[k].abs() {
            k = i;
        }
    }
    let e1 = Vector3::ith(k, 1.0).cross(&n).normalize();
    (e1, n.cross(&e1))
}

fn tangent_rows(normal: &Unit<Vector3<f64>>) -> Matrix2x3<f64> {
    let (e1, e2) = tangent_basis(normal);
    Matrix2x3::from_rows(&[e1.transpose(), e2.transpose()])
}

impl Plane {
    /// The plane of `normal` (any length but 0) at `distance_m`.
    pub fn new(normal: Vector3<f64>, distance_m: f64) -> Result<Plane> {
        Plane::checked("plane", normal, distance_m)
    }

    /// [`Plane::new`] with the error naming `field` (a laser plane's
    /// `laser_plane`, say).
    pub fn checked(field: &str, normal: Vector3<f64>, distance_m: f64) -> Result<Plane> {
        let norm = normal.norm();
        let usable = norm > 1e-12 && norm.is_finite() && distance_m.is_finite();
        if !usable {
            return Err(Error::invalid(
                field,
                format!(
                    "needs a non-zero finite normal and a finite distance, got ({}, {}, {}) and {distance_m}",
                    normal.x, normal.y, normal.z
                ),
            ));
        }
        Ok(Plane {
            normal: Unit::new_normalize(normal),
            distance_m,
        })
    }

    /// The same plane with the normal's sign chosen so that `distance_m >=
    /// 0`: the normal points away from the frame's origin.
    pub fn facing_away(self) -> Plane {
        if self.distance_m < 0.0 {
            Plane {
                normal: -self.normal,
                distance_m: -self.distance_m,
            }
        } else {
            self
        }
    }

    /// Where the ray `lambda * ray` from the frame's origin meets the plane
    /// for some `lambda > 0`; `None` when it runs parallel or meets it behind.
    pub fn intersect_ray(&self, ray: &Vector3<f64>) -> Option<Point3<f64>> {
        let den = self.normal.dot(ray);
        if den.abs() < 1e-12 {
            return None;
        }
        let lambda = self.distance_m / den;
        (lambda > 0.0 && lambda.is_finite()).then(|| Point3::from(ray * lambda))
    }

    /// The plane as a frame in this plane's frame (`a_from_plane` for a
    /// plane in frame `a`): z along the normal, the origin the plane's
    /// point nearest frame a's origin, x frame a's x axis projected into
    /// the plane (its y axis when x is nearly along the normal).
    pub fn a_from_plane(&self) -> Isometry3<f64> {
        let z = self.normal.into_inner();
        let seed = if z.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let x = (seed - z * z.dot(&seed)).normalize();
        let y = z.cross(&x);
        let r = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, z]));
        Isometry3::from_parts(
            Translation3::from(z * self.distance_m),
            UnitQuaternion::from_rotation_matrix(&r),
        )
    }

    /// The same plane in frame `a`, from the plane in frame `b` and
    /// `a_from_b`: `normal_a = R normal_b`, `d_a = d_b + normal_a . t`.
    pub fn in_frame(&self, a_from_b: &Isometry3<f64>) -> Plane {
        let normal = a_from_b.rotation * self.normal;
        Plane {
            normal,
            distance_m: self.distance_m + normal.dot(&a_from_b.translation.vector),
        }
    }

    /// Signed distance of `p` from the plane (positive on the normal's side), metres.
    pub fn signed_distance_m(&self, p: &Vector3<f64>) -> f64 {
        self.normal.dot(p) - self.distance_m
    }
}

impl PlaneEstimate {
    /// The covariance of `(nx, ny, nz, distance_m)` (rank 3: the normal
    /// stays unit): turning the normal by `a e1 + b e2` moves it by `-a e2
    /// + b e1` to first order.
    pub fn normal_distance_covariance(&self) -> Matrix4<f64> {
        let (e1, e2) = tangent_basis(&self.plane.normal);
        let mut map = Matrix4x3::zeros();
        for r in 0..3 {
            map[(r, 0)] = -e2[r];
            map[(r, 1)] = e1[r];
        }
        map[(3, 2)] = 1.0;
        map * self.covariance * map.transpose()
    }

    /// The plane in frame `a` with its covariance, from the plane in frame
    /// `b`, `a_from_b` and, when known, the 6x6 covariance of `a_from_b`
    /// (independent of the plane's). For the laser plane on the robot:
    /// `laser_in_camera.in_frame(&gripper_from_camera, hand_eye_covariance)`.
    pub fn in_frame(
        &self,
        a_from_b: &Isometry3<f64>,
        pose_covariance: Option<&Matrix6<f64>>,
    ) -> PlaneEstimate {
        let plane = self.plane.in_frame(a_from_b);
        let (j_plane, j_pose) = self.jacobians(a_from_b, &plane);
        let mut covariance = j_plane * self.covariance * j_plane.transpose();
        if let Some(c) = pose_covariance {
            covariance += j_pose * c * j_pose.transpose();
        }
        PlaneEstimate {
            plane,
            covariance: 0.5 * (covariance + covariance.transpose()),
        }
    }

    /// d(a, b, d in frame a) / d(a, b, d in frame b) and / d(pose perturbation).
    fn jacobians(&self, a_from_b: &Isometry3<f64>, out: &Plane) -> (Matrix3<f64>, Matrix3x6<f64>) {
        let r = a_from_b.rotation.to_rotation_matrix().into_inner();
        let t = a_from_b.translation.vector;
        let n_a = out.normal.into_inner();
        let (e1, e2) = tangent_basis(&self.plane.normal);
        // Turning the normal in b by w (in b) turns it in a by R w.
        let turn_b = Matrix3::from_columns(&[e1, e2, Vector3::zeros()]);
        let rows_a = tangent_rows(&out.normal);
        // d_a = d_b + n_a . t with dn_a = (R w) x n_a: d(d_a) = (n_a x t) . (R w).
        let lever = n_a.cross(&t).transpose() * r;
        let mut j_plane = Matrix3::zeros();
        j_plane
            .fixed_view_mut::<2, 3>(0, 0)
            .copy_from(&(rows_a * r * turn_b));
        j_plane
            .fixed_view_mut::<1, 3>(2, 0)
            .copy_from(&(lever * turn_b));
        j_plane[(2, 2)] = 1.0;
        let mut j_pose = Matrix3x6::zeros();
        j_pose.fixed_view_mut::<2, 3>(0, 0).copy_from(&(rows_a * r));
        j_pose.fixed_view_mut::<1, 3>(2, 0).copy_from(&lever);
        j_pose
            .fixed_view_mut::<1, 3>(2, 3)
            .copy_from(&(n_a.transpose() * r));
        (j_plane, j_pose)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::pose_from_params;
    use nalgebra::{Point3, Translation3, UnitQuaternion};
    use wasm_bindgen_test::wasm_bindgen_test;

    fn gripper_from_camera() -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(0.04, -0.02, 0.15),
            UnitQuaternion::from_scaled_axis(Vector3::new(0.3, -0.2, 1.1)),
        )
    }

    /// (a, b, d) of `p` around the reference plane `at`: the tangent part of
    /// `at.normal x p.normal` (first order in the turn) and the distance.
    fn coordinates(at: &Plane, p: &Plane) -> Vector3<f64> {
        let turn = at.normal.cross(&p.normal);
        let (e1, e2) = tangent_basis(&at.normal);
        Vector3::new(e1.dot(&turn), e2.dot(&turn), p.distance_m)
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn points_stay_on_the_plane_and_the_basis_is_orthonormal() {
        let laser = Plane::new(Vector3::new(0.1, -0.8, -0.5), 0.2).unwrap();
        let x = gripper_from_camera();
        let in_gripper = laser.in_frame(&x);
        let (e1, e2) = tangent_basis(&laser.normal);
        for (s, u) in [(0.0, 0.0), (0.1, -0.3), (-0.2, 0.05)] {
            let p = laser.normal.into_inner() * laser.distance_m + e1 * s + e2 * u;
            assert!(laser.signed_distance_m(&p).abs() < 1e-15);
            let q = x * Point3::from(p);
            assert!(in_gripper.signed_distance_m(&q.coords).abs() < 1e-15);
        }
        assert!(
            e1.dot(&e2).abs() < 1e-15 && (e1.cross(&e2) - laser.normal.into_inner()).norm() < 1e-15
        );
        assert!(Plane::new(Vector3::zeros(), 1.0).is_err());
    }

    /// The propagation's Jacobians against central differences, in the
    /// plane's (a, b, d) and in the pose perturbation `x * exp([w, v])`.
    #[wasm_bindgen_test(unsupported = test)]
    fn covariance_propagation_matches_central_differences() {
        let laser = Plane::new(Vector3::new(0.1, -0.8, -0.5), 0.2).unwrap();
        let x = gripper_from_camera();
        let out = laser.in_frame(&x);
        let est = PlaneEstimate {
            plane: laser,
            covariance: Matrix3::identity(),
        };
        let (j_plane, j_pose) = est.jacobians(&x, &out);
        let (e1, e2) = tangent_basis(&laser.normal);
        let h = 1e-6;
        let moved = |k: usize, s: f64| {
            let turn = match k {
                0 => e1 * s,
                1 => e2 * s,
                _ => Vector3::zeros(),
            };
            Plane {
                normal: UnitQuaternion::from_scaled_axis(turn) * laser.normal,
                distance_m: laser.distance_m + if k == 2 { s } else { 0.0 },
            }
        };
        for k in 0..3 {
            let fd = (coordinates(&out, &moved(k, h).in_frame(&x))
                - coordinates(&out, &moved(k, -h).in_frame(&x)))
                / (2.0 * h);
            assert!(
                (fd - j_plane.column(k)).norm() < 1e-8,
                "plane {k}: {fd} vs {}",
                j_plane.column(k)
            );
        }
        for k in 0..6 {
            let mut d = [0.0; 6];
            d[k] = h;
            let plus = laser.in_frame(&(x * pose_from_params(&d)));
            d[k] = -h;
            let minus = laser.in_frame(&(x * pose_from_params(&d)));
            let fd = (coordinates(&out, &plus) - coordinates(&out, &minus)) / (2.0 * h);
            assert!(
                (fd - j_pose.column(k)).norm() < 1e-8,
                "pose {k}: {fd} vs {}",
                j_pose.column(k)
            );
        }
        // The covariance adds the pose's share and stays symmetric.
        let with_pose = est.in_frame(&x, Some(&(Matrix6::identity() * 1e-6)));
        let plane_only = est.in_frame(&x, None);
        assert!((with_pose.covariance - with_pose.covariance.transpose()).norm() == 0.0);
        assert!(with_pose.covariance[(2, 2)] > plane_only.covariance[(2, 2)]);
    }
}
