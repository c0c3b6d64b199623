//! AX = ZB (robot-world-hand-eye): per view `A_i X = Z B_i`, from the
//! [`Chain`] as `camera[i] * y^-1 = x^-1 * robot[i]^-1` (see [`solve`]). Shah 2013 (Kronecker
//! rotation, then translation) and Li-Wang-Wu 2010 (simultaneous linear).

use crate::error::{Error, Result};
use crate::handeye::closed_form::axxb::kron;
use crate::handeye::math::{ascending_eigenvectors, least_squares, pose_from, project_to_so3};
use crate::handeye::{Chain, HandEyeMethod, Pose};
use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, Vector3};

/// Minimum number of views for AX = ZB.
pub const MIN_VIEWS: usize = 3;

/// Solve AX = ZB; returns `(x, y)` of the chain.
///
/// The linear systems are written in OpenCV's arrangement, with the camera
/// pose on the left: `camera[i] * y^-1 = x^-1 * robot[i]^-1`, i.e. `A_i =
/// camera[i]`, `X = y^-1`, `Z = x^-1`, `B_i = robot[i]^-1`. The camera pose
/// is usually the noisier measurement; with it as `A_i` its translation is
/// the right-hand side of the translation rows (where least squares assumes
/// the noise) instead of being mixed with its rotation by an inversion.
pub fn solve(method: HandEyeMethod, chain: &Chain) -> Result<(Pose, Pose)> {
    if chain.len() < MIN_VIEWS {
        return Err(Error::too_few("views", MIN_VIEWS, chain.len()));
    }
    let terms: Vec<Terms> = chain
        .camera
        .iter()
        .zip(&chain.robot)
        .map(|(c, r)| Terms::new(c, &r.inverse()))
        .collect();
    let (big_x, big_z) = match method {
        HandEyeMethod::Shah => {
            let (rx, rz) = shah_rotations(&terms)?;
            let (tx, tz) = translations(&terms, &rz)?;
            (pose_from(&rx, &tx), pose_from(&rz, &tz))
        }
        HandEyeMethod::Li => li(&terms)?,
        other => {
            return Err(Error::invalid(
                "method",
                format!("{} solves AX = XB, not AX = ZB", other.name()),
            ))
        }
    };
    Ok((big_z.inverse(), big_x.inverse()))
}

/// One view of `A X = Z B`: rotation matrices and translations of A and B.
struct Terms {
    ra: Matrix3<f64>,
    ta: Vector3<f64>,
    rb: Matrix3<f64>,
    tb: Vector3<f64>,
}

impl Terms {
    fn new(a: &Pose, b: &Pose) -> Terms {
        Terms {
            ra: a.rotation.to_rotation_matrix().into_inner(),
            ta: a.translation.vector,
            rb: b.rotation.to_rotation_matrix().into_inner(),
            tb: b.translation.vector,
        }
    }
}

/// Rotation rows `(R_A (x) I) vec(R_X) - (I (x) R_B^T) vec(R_Z) = 0`
/// (row-major vec).
fn rotation_block(ra: &Matrix3<f64>, rb: &Matrix3<f64>) -> DMatrix<f64> {
    let mut k = DMatrix::zeros(9, 18);
    k.view_mut((0, 0), (9, 9))
        .copy_from(&kron(ra, &Matrix3::identity()));
    k.view_mut((0, 9), (9, 9))
        .copy_from(&(-kron(&Matrix3::identity(), &rb.transpose())));
    k
}

/// Shah: the null vector of the stacked rotation rows holds both rotations
/// with one common scale, fixed by `det(R_X) = 1`, then each is projected
/// onto SO(3).
fn shah_rotations(terms: &[Terms]) -> Result<(Rotation3<f64>, Rotation3<f64>)> {
    let mut normal = DMatrix::zeros(18, 18);
    for v in terms {
        let k = rotation_block(&v.ra, &v.rb);
        normal += k.transpose() * k;
    }
    let pairs = ascending_eigenvectors(&normal)?;
    let v = &pairs[0].1;
    let mx = Matrix3::from_row_slice(&v.as_slice()[0..9]);
    let mz = Matrix3::from_row_slice(&v.as_slice()[9..18]);
    let sign = mx.determinant().signum();
    Ok((project_to_so3(&(mx * sign))?, project_to_so3(&(mz * sign))?))
}

/// Li-Wang-Wu: rotation and translation rows in one linear least squares over
/// 24 unknowns `[vec(R_X), vec(R_Z), t_X, t_Z]`; the translation rows
/// `(I (x) t_B^T) vec(R_Z) - R_A t_X + t_Z = t_A` fix the scale. The
/// rotations are projected onto SO(3) and the translations are kept from the
/// joint solution (as in the paper and OpenCV).
fn li(terms: &[Terms]) -> Result<(Pose, Pose)> {
    let mut normal = DMatrix::zeros(24, 24);
    let mut rhs = DVector::zeros(24);
    for v in terms {
        let mut k = DMatrix::zeros(12, 24);
        k.view_mut((0, 0), (9, 18))
            .copy_from(&rotation_block(&v.ra, &v.rb));
        for r in 0..3 {
            for c in 0..3 {
                k[(9 + r, 9 + 3 * r + c)] = v.tb[c];
                k[(9 + r, 18 + c)] = -v.ra[(r, c)];
            }
            k[(9 + r, 21 + r)] = 1.0;
        }
        let mut b = DVector::zeros(12);
        b.rows_mut(9, 3).copy_from(&v.ta);
        rhs += k.transpose() * b;
        normal += k.transpose() * k;
    }
    let (w, dropped) = least_squares(&normal, &rhs)?;
    if !dropped.is_empty() {
        return Err(Error::degenerate(
            "Li: the linear system is rank deficient (too little motion diversity)",
        ));
    }
    let w = w.as_slice();
    let mx = Matrix3::from_row_slice(&w[0..9]);
    let mz = Matrix3::from_row_slice(&w[9..18]);
    let tx = Vector3::new(w[18], w[19], w[20]);
    let tz = Vector3::new(w[21], w[22], w[23]);
    Ok((
        pose_from(&project_to_so3(&mx)?, &tx),
        pose_from(&project_to_so3(&mz)?, &tz),
    ))
}

/// Translations from `R_A t_X - t_Z = R_Z t_B - t_A` with fixed rotations.
fn translations(terms: &[Terms], rz: &Rotation3<f64>) -> Result<(Vector3<f64>, Vector3<f64>)> {
    let mut normal = DMatrix::zeros(6, 6);
    let mut rhs = DVector::zeros(6);
    for v in terms {
        let (ra, ta, tb) = (&v.ra, &v.ta, &v.tb);
        let mut k = DMatrix::zeros(3, 6);
        k.view_mut((0, 0), (3, 3)).copy_from(ra);
        k.view_mut((0, 3), (3, 3))
            .copy_from(&(-Matrix3::identity()));
        let b = rz * tb - ta;
        rhs += k.transpose() * DVector::from_column_slice(b.as_slice());
        normal += k.transpose() * k;
    }
    let (t, dropped) = least_squares(&normal, &rhs)?;
    if !dropped.is_empty() {
        return Err(Error::degenerate(
            "AX = ZB translation is not observable (robot rotations too similar)",
        ));
    }
    Ok((
        Vector3::new(t[0], t[1], t[2]),
        Vector3::new(t[3], t[4], t[5]),
    ))
}
