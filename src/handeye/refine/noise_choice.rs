//! Which camera noise model the pose refinement ([`crate::handeye::refine::over_poses`])
//! uses, decided by likelihood at a given `(x, y)`: the diagonal model about
//! the target origin or about where the camera looks on the target, or a
//! per-view shape predicted from the poses for one of the nominal targets of
//! [`crate::handeye::refine::pose_shape`] (Akaike's criterion between them).

use crate::error::Result;
use crate::handeye::refine::pose_noise::{CameraNoise, NoiseModel, MIN_POSES_FOR_NOISE_ESTIMATE};
use crate::handeye::refine::pose_problem::{estimate_noise_at, negative_log_likelihood_at};
use crate::handeye::refine::pose_residual::{linearise, PoseMeasurement, ViewLinearisation};
use crate::handeye::refine::pose_shape::{predicted_covariances, NominalTarget};
use crate::handeye::{Pose, Setup};
use nalgebra::Vector3;

/// Where the camera looks on the target: the mean intersection of the
/// optical axes with the target plane z = 0 (target frame), the pivot of
/// the diagonal camera noise model ([`NoiseModel::pivot_levers`]). `None`
/// when an axis is nearly parallel to the plane or the mean is not finite
/// (then the target origin is the pivot).
pub fn board_pivot(views: &[PoseMeasurement]) -> Option<Vector3<f64>> {
    let mut sum = Vector3::zeros();
    for m in views {
        let target_from_camera = m.camera_from_target.inverse();
        let origin = target_from_camera.translation.vector;
        let axis = target_from_camera.rotation * Vector3::z();
        if axis.z.abs() < 0.1 {
            return None;
        }
        sum += origin - axis * (origin.z / axis.z);
    }
    let p = sum / views.len().max(1) as f64;
    p.iter().all(|v| v.is_finite()).then_some(p)
}

/// `R_c p` per view for a pivot `p` (target frame).
pub fn pivot_levers(views: &[PoseMeasurement], pivot: &Vector3<f64>) -> Vec<Vector3<f64>> {
    views
        .iter()
        .map(|m| m.camera_from_target.rotation * pivot)
        .collect()
}

/// A camera noise model with its levels fitted, and how it is reported.
#[derive(Debug, Clone)]
pub struct ChosenNoise {
    /// The model and its levels.
    pub noise: NoiseModel,
    /// `diagonal`, `per_view` or `predicted_pnp` (the report's `camera_noise_model`).
    pub name: String,
    /// Diagonal model: the pivot of the camera rotation noise (target frame,
    /// metres), when it beat the target origin.
    pub pivot: Option<[f64; 3]>,
    /// `predicted_pnp`: the nominal target.
    pub nominal: Option<NominalTarget>,
}

impl ChosenNoise {
    /// Same model and shape (the levels may differ).
    pub fn same_model(&self, other: &ChosenNoise) -> bool {
        self.name == other.name && self.pivot == other.pivot && self.nominal == other.nominal
    }
}

/// Fit the requested camera model at `(x, y)`; a [`CameraNoise::Diagonal`]
/// request also tries the board pivot and, with `predict_shape` and at
/// least [`MIN_POSES_FOR_NOISE_ESTIMATE`] poses, the predicted per-view
/// shapes, and keeps the likeliest (with too few poses the documented
/// diagonal defaults stand).
pub fn choose_noise_model(
    setup: Setup,
    views: &[PoseMeasurement],
    camera_noise: CameraNoise,
    x: &Pose,
    y: &Pose,
    axis: Option<Vector3<f64>>,
    predict_shape: bool,
) -> Result<ChosenNoise> {
    let diagonal = matches!(camera_noise, CameraNoise::Diagonal);
    let mut chosen = ChosenNoise {
        name: if diagonal { "diagonal" } else { "per_view" }.to_string(),
        noise: NoiseModel::new(camera_noise),
        pivot: None,
        nominal: None,
    };
    // Every model is fitted at (x, y): the views linearised there once.
    let lins: Vec<ViewLinearisation> = views.iter().map(|m| linearise(setup, m, x, y)).collect();
    estimate_noise_at(&lins, &mut chosen.noise, axis)?;
    if !diagonal {
        return Ok(chosen);
    }
    // The diagonal camera noise about the target origin or about where the
    // camera looks on the target: the one the data make more likely.
    if let Some(p) = board_pivot(views) {
        let mut pivoted = NoiseModel::new(CameraNoise::Diagonal);
        pivoted.pivot_levers = pivot_levers(views, &p);
        let better = estimate_noise_at(&lins, &mut pivoted, axis).and_then(|_| {
            let with = negative_log_likelihood_at(&lins, &pivoted)?;
            let without = negative_log_likelihood_at(&lins, &chosen.noise)?;
            Ok(with < without)
        });
        if better.unwrap_or(false) {
            chosen.noise = pivoted;
            chosen.pivot = Some([p.x, p.y, p.z]);
        }
    }
    // Camera poses without their covariances: a per-view shape predicted
    // from each pose for a nominal target, when the data make it more
    // likely than the diagonal (Akaike).
    if predict_shape && views.len() >= MIN_POSES_FOR_NOISE_ESTIMATE {
        let shaped = choose_predicted_shape(views, &lins, &chosen.noise, axis, board_pivot(views));
        if let Some((noise, target)) = shaped {
            chosen = ChosenNoise {
                noise,
                name: "predicted_pnp".to_string(),
                pivot: None,
                nominal: Some(target),
            };
        }
    }
    Ok(chosen)
}

/// Starts of the predicted shape's scale (pixel noise over focal length,
/// squared): 0.2 px at 1000 px down to 0.02 px at 100 000 px. The levels'
/// likelihood has a flat ridge (robot and camera rotation noise act alike),
/// along which expectation-maximisation crawls: from a start orders of
/// magnitude off (0.2 px / 1000 px for a 75 mm lens at 2.3 m, 31 250 px) it
/// stops far from the maximum, and the choice between nominal targets then
/// compares unconverged fits. The likeliest fit over these starts is kept.
const SHAPE_SCALE_STARTS: [f64; 4] = [4e-8, 4e-10, 4e-12, 4e-14];

/// The likeliest per-view predicted shape ([`crate::handeye::refine::pose_shape`]) over the
/// nominal target candidates, if it is more likely than `diagonal` (whose
/// levels were fitted at `(x, y)`, where `lins` linearised the views); its
/// levels fitted there too.
fn choose_predicted_shape(
    views: &[PoseMeasurement],
    lins: &[ViewLinearisation],
    diagonal: &NoiseModel,
    axis: Option<Vector3<f64>>,
    pivot: Option<Vector3<f64>>,
) -> Option<(NoiseModel, NominalTarget)> {
    // Akaike: each estimated level costs 1 in negative log-likelihood; the
    // diagonal has 8 levels, the predicted shape 3.
    let mut best_nll =
        negative_log_likelihood_at(lins, diagonal).ok()? + diagonal.variances.len() as f64;
    let mut best = None;
    for target in NominalTarget::candidates(views, pivot) {
        let Some(covs) = predicted_covariances(views, &target) else {
            continue;
        };
        for start in SHAPE_SCALE_STARTS {
            let mut model = NoiseModel::new(CameraNoise::PerView(covs.clone()));
            model.variances[2] = start;
            if estimate_noise_at(lins, &mut model, axis).is_err() {
                continue;
            }
            if let Ok(nll) = negative_log_likelihood_at(lins, &model) {
                let nll = nll + model.variances.len() as f64;
                if nll < best_nll {
                    best_nll = nll;
                    best = Some((model, target));
                }
            }
        }
    }
    best
}
