//! Averages of rotations: the quaternion eigenvector mean and the chordal L2
//! mean.

use nalgebra::{Matrix3, Matrix4, UnitQuaternion, Vector4};

use super::{nearest_rotation, Rotation};
use crate::error::{Error, Result};

fn check_weights(count: usize, weights: Option<&[f64]>) -> Result<()> {
    if count == 0 {
        return Err(Error::too_few("rotations to average", 1, 0));
    }
    let Some(w) = weights else { return Ok(()) };
    if w.len() != count {
        return Err(Error::invalid(
            "weights",
            format!("{} weights for {count} rotations", w.len()),
        ));
    }
    if w.iter().any(|v| !v.is_finite() || *v < 0.0) || w.iter().sum::<f64>() <= 0.0 {
        return Err(Error::invalid(
            "weights",
            "weights must be finite, non-negative and not all zero",
        ));
    }
    Ok(())
}

/// The weighted quaternion average of Markley et al. (2007): the eigenvector
/// of the largest eigenvalue of `Σ wᵢ qᵢ qᵢᵀ`. It minimises the weighted sum
/// of squared chordal distances between quaternions, ignores the sign
/// ambiguity `q ≡ -q`, and equals the true mean for a single rotation.
///
/// `weights` defaults to all ones. Errors for no rotations, bad weights, or
/// when the mean is not unique (top two eigenvalues equal, e.g. two rotations
/// 180 degrees apart).
pub fn average_rotations_quaternion(
    rotations: &[Rotation],
    weights: Option<&[f64]>,
) -> Result<Rotation> {
    check_weights(rotations.len(), weights)?;
    let mut m = Matrix4::zeros();
    for (i, r) in rotations.iter().enumerate() {
        let w = weights.map_or(1.0, |w| w[i]);
        let q: Vector4<f64> = r.quaternion().coords;
        m += q * q.transpose() * w;
    }
    if m.iter().any(|v| !v.is_finite()) {
        return Err(Error::invalid("rotations", "have non-finite components"));
    }
    let eig = m.symmetric_eigen();
    let mut order: Vec<usize> = (0..4).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let (l1, l2) = (eig.eigenvalues[order[0]], eig.eigenvalues[order[1]]);
    if l1 - l2 <= 1e-12 * l1.abs().max(f64::MIN_POSITIVE) {
        return Err(Error::degenerate(
            "the rotations have no unique average (they spread evenly, e.g. two 180 degrees apart)",
        ));
    }
    let v = eig.eigenvectors.column(order[0]);
    let q = nalgebra::Quaternion::new(v[3], v[0], v[1], v[2]);
    Ok(UnitQuaternion::from_quaternion(q))
}

/// The weighted chordal L2 mean: the rotation nearest (Frobenius) to `Σ wᵢ
/// Rᵢ`, i.e. the minimiser of `Σ wᵢ ‖R − Rᵢ‖²_F` (Hartley et al., "Rotation
/// averaging", 2013). Same errors as [`average_rotations_quaternion`].
pub fn average_rotations_chordal(
    rotations: &[Rotation],
    weights: Option<&[f64]>,
) -> Result<Rotation> {
    check_weights(rotations.len(), weights)?;
    let mut sum = Matrix3::zeros();
    for (i, r) in rotations.iter().enumerate() {
        let w = weights.map_or(1.0, |w| w[i]);
        sum += r.to_rotation_matrix().into_inner() * w;
    }
    let r = nearest_rotation(&sum).map_err(|e| match e {
        Error::Degenerate { .. } => Error::degenerate(
            "the rotations have no unique chordal mean (they spread evenly over SO(3))",
        ),
        other => other,
    })?;
    Ok(UnitQuaternion::from_rotation_matrix(&r))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{rotation_angle_between, rotation_from_rotvec};
    use crate::rng::Rng;
    use nalgebra::Vector3;
    use std::f64::consts::PI;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn symmetric_spreads_average_to_the_centre() {
        let mut rng = Rng::new(31);
        for _ in 0..300 {
            // Centre near pi on purpose: q and -q both appear among samples.
            let axis = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
            let centre = rotation_from_rotvec(&(axis * rng.range(PI - 0.1, PI)));
            let d = Vector3::new(rng.normal(), rng.normal(), rng.normal()) * 0.2;
            // Pairs centre*exp(±d) are symmetric about the centre: exact mean.
            let rs = [
                centre * rotation_from_rotvec(&d),
                centre * rotation_from_rotvec(&-d),
                centre,
            ];
            let q = average_rotations_quaternion(&rs, None).unwrap();
            let c = average_rotations_chordal(&rs, None).unwrap();
            assert!(rotation_angle_between(&q, &centre) < 1e-12);
            assert!(rotation_angle_between(&c, &centre) < 1e-12);
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn noisy_samples_average_within_the_noise_bound() {
        let mut rng = Rng::new(32);
        let centre = rotation_from_rotvec(&Vector3::new(0.4, -2.0, 1.0));
        let sigma = 0.01; // radians per axis
        let rs: Vec<Rotation> = (0..2000)
            .map(|_| {
                let n = Vector3::new(rng.normal(), rng.normal(), rng.normal()) * sigma;
                centre * rotation_from_rotvec(&n)
            })
            .collect();
        // Mean error ~ sigma * sqrt(3 / n) = 3.9e-4 rad; 5 sigma bound 2e-3.
        for mean in [
            average_rotations_quaternion(&rs, None).unwrap(),
            average_rotations_chordal(&rs, None).unwrap(),
        ] {
            assert!(rotation_angle_between(&mean, &centre) < 2e-3);
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn weights_select_and_errors_are_reported() {
        let a = rotation_from_rotvec(&Vector3::new(0.0, 0.0, 0.5));
        let b = rotation_from_rotvec(&Vector3::new(0.0, 0.0, 1.5));
        let w = [1.0, 0.0];
        let got = average_rotations_quaternion(&[a, b], Some(&w)).unwrap();
        assert!(rotation_angle_between(&got, &a) < 1e-12);
        let got = average_rotations_chordal(&[a, b], Some(&w)).unwrap();
        assert!(rotation_angle_between(&got, &a) < 1e-12);
        // Equal weights about one axis: the mean is the half-way angle 1.0.
        let mid = rotation_from_rotvec(&Vector3::new(0.0, 0.0, 1.0));
        let got = average_rotations_chordal(&[a, b], None).unwrap();
        assert!(rotation_angle_between(&got, &mid) < 1e-12);
        assert_eq!(
            average_rotations_quaternion(&[], None)
                .unwrap_err()
                .to_string(),
            "requires at least 1 rotations to average, got 0"
        );
        assert_eq!(
            average_rotations_chordal(&[a], Some(&[1.0, 2.0]))
                .unwrap_err()
                .to_string(),
            "weights: 2 weights for 1 rotations"
        );
        assert!(average_rotations_quaternion(&[a], Some(&[-1.0])).is_err());
        // Two rotations 180 degrees apart about z have no unique mean.
        let id = Rotation::identity();
        let flip = rotation_from_rotvec(&Vector3::new(0.0, 0.0, PI));
        assert!(matches!(
            average_rotations_quaternion(&[id, flip], None),
            Err(Error::Degenerate { .. })
        ));
    }
}
