//! The noise model of the pose refinement: how robot and camera pose noise
//! propagate to each view's residual covariance, and how the noise levels
//! are estimated from the residuals.
//!
//! Each view's residual covariance is a sum of variance components,
//! `C_i = sum_k s_k M_ik`: the robot's rotation and translation noise
//! (isotropic, base frame), and the camera's per-axis rotation and
//! translation noise (6 values, camera frame) or, when the image path
//! supplies it, each view's PnP covariance times one scale. The `M_ik` come
//! from the noise Jacobians of [`crate::handeye::refine::pose_residual::linearise`].
//!
//! The levels `s_k` are estimated by the expectation-maximisation fixed
//! point of Gaussian variance components: `s_k <- s_k * sum_i tr(W_i M_ik
//! W_i (r_i r_i^T + J_i P J_i^T)) / sum_i tr(W_i M_ik)` with `W_i = C_i^-1`
//! and `P` the parameter covariance; the `J P J^T` term undoes the shrinkage
//! of residuals at the fitted solution (12 unknowns). It keeps every level
//! positive and its fixed point is the maximum-likelihood one. The isotropic
//! part of the camera rotation noise and the robot rotation noise act alike
//! on the residual and are told apart only through the lever arm; their sum
//! is what the weighting needs.

use crate::handeye::math::skew;
use crate::handeye::refine::noise_em::{
    accelerated_em, em_step_packed, packed_terms, VARIANCE_FLOOR,
};
use crate::handeye::refine::pose_residual::ViewLinearisation;
use nalgebra::{Matrix6, SMatrix, Vector3};
use serde::{Deserialize, Serialize};

/// How the camera pose noise is modelled.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraNoise {
    /// Independent per-axis noise in the camera frame (3 rotation, 3
    /// translation levels), all estimated: for camera poses from any source.
    Diagonal,
    /// Each view's camera pose covariance up to one common scale (e.g. PnP's
    /// `(J^T J)^-1` in the convention of [`crate::handeye::refine::pose_residual`]), the scale
    /// estimated (the pixel variance).
    PerView(Vec<Matrix6<f64>>),
}

/// Fewer poses than this: the noise levels are not estimated per component
/// but [`NoiseLevels::default`] is scaled by one common factor.
pub const MIN_POSES_FOR_NOISE_ESTIMATE: usize = 8;

/// Median of chi-squared with 6 degrees of freedom.
const CHI2_6_MEDIAN: f64 = 5.348;

/// Noise levels (standard deviations) of the robot and camera poses.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseLevels {
    /// Robot rotation noise per axis of `base_from_gripper` (degrees).
    pub robot_rotation_deg: f64,
    /// Robot translation noise per axis (mm).
    pub robot_translation_mm: f64,
    /// Camera rotation noise about the camera's x, y, z axes (degrees);
    /// with per-view covariances (given or predicted), `None`.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub camera_rotation_deg: Option<[f64; 3]>,
    /// Camera translation noise along x, y, z of the camera frame (mm);
    /// with per-view covariances (given or predicted), `None`.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub camera_translation_mm: Option<[f64; 3]>,
    /// With per-view covariances: the estimated scale's square root (px
    /// when they are PnP's `(J^T J)^-1`; pixel noise over focal length for
    /// the predicted shape of [`crate::handeye::refine::pose_shape`]).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub camera_covariance_sigma: Option<f64>,
}

impl Default for NoiseLevels {
    /// Documented defaults, used as the start and, scaled by one factor,
    /// when there are fewer than [`MIN_POSES_FOR_NOISE_ESTIMATE`] poses: a
    /// robot at 0.1 mm / 0.02 deg and a camera pose from PnP of a board at
    /// about 0.5 m (rotation 0.05 deg about x and y, 0.01 deg about the
    /// optical axis; translation 0.05 mm in x and y, 0.3 mm in depth).
    fn default() -> Self {
        NoiseLevels {
            robot_rotation_deg: 0.02,
            robot_translation_mm: 0.1,
            camera_rotation_deg: Some([0.05, 0.05, 0.01]),
            camera_translation_mm: Some([0.05, 0.05, 0.3]),
            camera_covariance_sigma: None,
        }
    }
}

/// The variance components `s_k` for a camera model.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseModel {
    /// The camera model.
    pub camera: CameraNoise,
    /// `[robot rot, robot trans, camera...]`: 8 values (diagonal) or 3
    /// (per-view scale), in rad^2 and m^2.
    pub variances: Vec<f64>,
    /// Diagonal model only: per view, the pivot of the camera's rotation
    /// noise in the camera frame (`R_c p` for a target point `p`), empty for
    /// the target origin. PnP tilts a board about its centre, not about its
    /// origin (often a corner): rotating about the origin would make the
    /// translation noise strongly correlated with the tilts, which a diagonal
    /// cannot hold. With a pivot, a rotation `w` moves the origin by
    /// `(R_c p) x w`.
    pub pivot_levers: Vec<Vector3<f64>>,
}

impl NoiseModel {
    /// Start from [`NoiseLevels::default`] (per-view: scale 0.2 px squared).
    pub fn new(camera: CameraNoise) -> NoiseModel {
        let d = NoiseLevels::default();
        let r2 = |deg: f64| deg.to_radians().powi(2);
        let m2 = |mm: f64| (mm * 1e-3).powi(2);
        let mut variances = vec![r2(d.robot_rotation_deg), m2(d.robot_translation_mm)];
        match &camera {
            CameraNoise::Diagonal => {
                let (r, t) = (
                    d.camera_rotation_deg.unwrap_or([0.05; 3]),
                    d.camera_translation_mm.unwrap_or([0.1; 3]),
                );
                variances.extend(r.iter().map(|v| r2(*v)));
                variances.extend(t.iter().map(|v| m2(*v)));
            }
            CameraNoise::PerView(_) => variances.push(0.04),
        }
        NoiseModel {
            camera,
            variances,
            pivot_levers: Vec::new(),
        }
    }

    /// The levels as standard deviations in report units.
    pub fn levels(&self) -> NoiseLevels {
        let s: Vec<f64> = self.variances.iter().map(|v| v.sqrt()).collect();
        let deg = |i: usize| s[i].to_degrees();
        let mm = |i: usize| s[i] * 1e3;
        let diagonal = matches!(self.camera, CameraNoise::Diagonal);
        NoiseLevels {
            robot_rotation_deg: deg(0),
            robot_translation_mm: mm(1),
            camera_rotation_deg: diagonal.then(|| [deg(2), deg(3), deg(4)]),
            camera_translation_mm: diagonal.then(|| [mm(5), mm(6), mm(7)]),
            camera_covariance_sigma: (!diagonal).then(|| s[2]),
        }
    }

    /// The component matrices `M_ik` of view `i`.
    pub fn components(&self, view: usize, lin: &ViewLinearisation) -> Vec<Matrix6<f64>> {
        let outer = |j: &SMatrix<f64, 6, 6>, cols: std::ops::Range<usize>| {
            let b = j.columns(cols.start, cols.len());
            b * b.transpose()
        };
        let mut out = vec![outer(&lin.jac_robot, 0..3), outer(&lin.jac_robot, 3..6)];
        match &self.camera {
            CameraNoise::Diagonal => {
                // Noise [w, v_pivot] -> origin noise [w, v_pivot + [R_c p]x w].
                let jc = match self.pivot_levers.get(view) {
                    Some(lever) => {
                        let mut t = Matrix6::identity();
                        t.fixed_view_mut::<3, 3>(3, 0).copy_from(&skew(lever));
                        lin.jac_camera * t
                    }
                    None => lin.jac_camera,
                };
                for k in 0..6 {
                    out.push(outer(&jc, k..k + 1));
                }
            }
            CameraNoise::PerView(covariances) => {
                let s = covariances
                    .get(view)
                    .copied()
                    .unwrap_or_else(Matrix6::zeros);
                out.push(lin.jac_camera * s * lin.jac_camera.transpose());
            }
        }
        out
    }

    /// The residual covariance `C_i = sum_k s_k M_ik` of view `i`.
    pub fn covariance(&self, view: usize, lin: &ViewLinearisation) -> Matrix6<f64> {
        self.components(view, lin)
            .iter()
            .zip(&self.variances)
            .fold(Matrix6::zeros(), |acc, (m, s)| acc + m * *s)
    }

    /// Scale every level by one factor so that the median squared whitened
    /// norm `norms2` matches chi-squared(6)'s median (5.348): a robust first
    /// step when the current levels are far off (then every view looks like
    /// an outlier and none would take part in [`NoiseModel::update`]).
    pub fn rescale_to_median(&mut self, norms2: &[f64]) {
        if norms2.is_empty() {
            return;
        }
        let mut sorted = norms2.to_vec();
        sorted.sort_by(f64::total_cmp);
        let n = sorted.len();
        let median = if n % 2 == 1 {
            sorted[n / 2]
        } else {
            0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
        };
        let f = median / CHI2_6_MEDIAN;
        if f.is_finite() && f > 0.0 {
            for v in &mut self.variances {
                *v = (*v * f).max(VARIANCE_FLOOR);
            }
        }
    }

    /// Re-estimate the levels from residuals at a solution: `lins` per
    /// view, `inlier` marks the views that take part (outliers would inflate
    /// the levels), `param_cov` the 12 x 12 covariance at that solution.
    /// With fewer than [`MIN_POSES_FOR_NOISE_ESTIMATE`] inliers only a
    /// common scale of all components is estimated.
    pub fn update(
        &mut self,
        lins: &[ViewLinearisation],
        inlier: &[bool],
        param_cov: &SMatrix<f64, 12, 12>,
    ) {
        let used = inlier.iter().filter(|u| **u).count();
        if used == 0 {
            return;
        }
        let per_component = used >= MIN_POSES_FOR_NOISE_ESTIMATE;
        // The components and the spread of each inlier view do not depend
        // on the levels: computed once, not once per EM step (at 1,000
        // poses and 500 steps they were most of the refinement's time).
        let fixed = packed_terms(&self.view_terms(lins, inlier, param_cov));
        if per_component {
            accelerated_em(&mut self.variances, &fixed);
        } else {
            em_step_packed(&mut self.variances, &fixed, false);
        }
    }

    /// Each inlier view's noise components and the spread of its residual
    /// (the residual's outer product plus the parameters' share).
    fn view_terms(
        &self,
        lins: &[ViewLinearisation],
        inlier: &[bool],
        param_cov: &SMatrix<f64, 12, 12>,
    ) -> Vec<(Vec<Matrix6<f64>>, Matrix6<f64>)> {
        lins.iter()
            .enumerate()
            .filter(|(i, _)| inlier[*i])
            .map(|(i, lin)| {
                let spread = lin.residual * lin.residual.transpose()
                    + lin.jac_params * param_cov * lin.jac_params.transpose();
                (self.components(i, lin), spread)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::handeye::refine::noise_em::{
        em_step, pack, packed_index, packed_trace, plain_em, trace_of_product, EM_MAX_ITERATIONS,
        EM_TOLERANCE, PACKED,
    };
    use crate::handeye::refine::pose_residual::{linearise, PoseMeasurement};
    use crate::handeye::refine::pose_shape::{predicted_covariances, NominalTarget};
    use crate::handeye::Setup;
    use crate::rng::Rng;
    use crate::synth::handeye_looking::{looking_scene, perturbed, LookingConfig};
    use wasm_bindgen_test::wasm_bindgen_test;

    /// [`NoiseModel::update`] with plain EM steps (as it was before the
    /// acceleration): the per-view terms once, up to [`EM_MAX_ITERATIONS`]
    /// steps until one moves no level by more than [`EM_TOLERANCE`].
    fn plain_update(
        model: &mut NoiseModel,
        lins: &[ViewLinearisation],
        inlier: &[bool],
        param_cov: &SMatrix<f64, 12, 12>,
    ) {
        let used = inlier.iter().filter(|u| **u).count();
        let fixed = packed_terms(&model.view_terms(lins, inlier, param_cov));
        if used >= MIN_POSES_FOR_NOISE_ESTIMATE {
            plain_em(
                &mut model.variances,
                &fixed,
                EM_MAX_ITERATIONS,
                EM_TOLERANCE,
            );
        } else {
            em_step_packed(&mut model.variances, &fixed, false);
        }
    }

    /// [`plain_update`] as it was before the per-view terms were computed
    /// once: components and spread recomputed at every EM step; with
    /// `full`, also as it was before the packed step: every matrix and
    /// trace on all 36 entries ([`em_step`]).
    fn update_per_step(
        model: &mut NoiseModel,
        lins: &[ViewLinearisation],
        inlier: &[bool],
        param_cov: &SMatrix<f64, 12, 12>,
        full: bool,
    ) {
        let used = inlier.iter().filter(|u| **u).count();
        let per_component = used >= MIN_POSES_FOR_NOISE_ESTIMATE;
        for _ in 0..if per_component { EM_MAX_ITERATIONS } else { 1 } {
            let per_step = model.view_terms(lins, inlier, param_cov);
            let converged = if full {
                let views = per_step
                    .iter()
                    .map(|(comps, spread)| (comps.as_slice(), spread));
                em_step(&mut model.variances, views, per_component)
            } else {
                em_step_packed(
                    &mut model.variances,
                    &packed_terms(&per_step),
                    per_component,
                )
                .converged
            };
            if converged {
                break;
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn packed_traces_are_the_full_ones() {
        let a = Matrix6::from_fn(|i, j| 1.0 / (1.0 + i as f64 + j as f64));
        let m = Matrix6::from_fn(|i, j| ((i * j) as f64).sin() + ((i + j) as f64).cos());
        let m = m + m.transpose();
        let full = trace_of_product(&a, &m);
        let packed = packed_trace(&pack(&a), &pack(&m));
        assert!(
            (full - packed).abs() <= 1e-14 * full.abs(),
            "{full} {packed}"
        );
        assert_eq!(packed_index(5, 5), PACKED - 1);
        assert_eq!(packed_index(1, 0), 1);
        assert_eq!(packed_index(1, 1), 6);
    }

    /// 60 noisy views (robot 0.1 mm / 0.02 deg, camera 0.05 deg / 0.05-0.3
    /// mm) linearised at the truth, a parameter covariance of the right
    /// size, and the models: diagonal, diagonal with pivots, per-view
    /// (predicted PnP shape) from its default start and from a scale 1e4
    /// times too small.
    fn scene(
        setup: Setup,
    ) -> (
        Vec<ViewLinearisation>,
        SMatrix<f64, 12, 12>,
        Vec<NoiseModel>,
    ) {
        let config = LookingConfig {
            setup,
            views: 60,
            distance_m: 0.5,
            grid: (9, 6, 0.03),
            max_tilt_deg: 30.0,
            max_roll_deg: 60.0,
        };
        let scene = looking_scene(&config, 17);
        let mut rng = Rng::new(18);
        let (r, c) = (0.02f64.to_radians(), 0.05f64.to_radians());
        let views: Vec<PoseMeasurement> = scene
            .base_from_gripper
            .iter()
            .zip(&scene.camera_from_target)
            .map(|(b, t)| PoseMeasurement {
                base_from_gripper: perturbed(&mut rng, b, [r; 3], [1e-4; 3]),
                camera_from_target: perturbed(&mut rng, t, [c, c, c / 5.0], [5e-5, 5e-5, 3e-4]),
            })
            .collect();
        let lins: Vec<ViewLinearisation> = views
            .iter()
            .map(|m| linearise(setup, m, &scene.x_true, &scene.y_true))
            .collect();
        let param_cov =
            SMatrix::<f64, 12, 12>::from_fn(|i, j| 1e-9 / (1.0 + (i as f64 - j as f64).abs()));
        let mut pivoted = NoiseModel::new(CameraNoise::Diagonal);
        pivoted.pivot_levers = views
            .iter()
            .map(|m| m.camera_from_target.rotation * Vector3::new(0.12, 0.075, 0.0))
            .collect();
        let target = NominalTarget::candidates(&views, None)[0];
        let shaped = NoiseModel::new(CameraNoise::PerView(
            predicted_covariances(&views, &target).unwrap(),
        ));
        let mut far = shaped.clone();
        far.variances[2] *= 1e-4;
        let models = vec![NoiseModel::new(CameraNoise::Diagonal), pivoted, shaped, far];
        (lins, param_cov, models)
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn the_plain_update_gives_the_levels_of_the_per_step_computation() {
        // Every fifth view an outlier, or 6 inliers (the common scale): the
        // plain update with the per-view terms computed once gives the same
        // levels bit for bit as recomputing them at every step, and the
        // packed step the levels of the full matrices to 1e-10 (relative).
        for setup in [Setup::EyeInHand, Setup::EyeToHand] {
            let (lins, param_cov, models) = scene(setup);
            let many: Vec<bool> = (0..lins.len()).map(|i| i % 5 != 2).collect();
            let few: Vec<bool> = (0..lins.len()).map(|i| i < 6).collect();
            for model in models {
                for inlier in [&many, &few] {
                    let mut once = model.clone();
                    plain_update(&mut once, &lins, inlier, &param_cov);
                    let mut reference = model.clone();
                    update_per_step(&mut reference, &lins, inlier, &param_cov, false);
                    assert_eq!(once.variances, reference.variances);
                    assert_ne!(once.variances, model.variances);
                    let mut full = model.clone();
                    update_per_step(&mut full, &lins, inlier, &param_cov, true);
                    for (a, b) in once.variances.iter().zip(&full.variances) {
                        assert!((a - b).abs() <= 1e-10 * b, "{a} vs {b}");
                    }
                }
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn the_accelerated_update_reaches_the_plain_em_maximum() {
        // The maximum: plain EM until no level moves by 1e-12 (relative).
        // The accelerated update reaches it: the objective within 1e-10
        // (relative) and every inlier view's residual covariance within
        // 1e-4 (largest entry difference over the largest entry). The levels themselves
        // only where they are identified: the robot's isotropic translation
        // noise and the camera's three translation levels add the same
        // covariance (both frames' isotropic translation noise is the same
        // matrix), so their split is not, and each iteration stops at its
        // own point of that line; the per-view models' 3 levels within 1e-3.
        // With 6 inliers it is the plain common scale.
        for setup in [Setup::EyeInHand, Setup::EyeToHand] {
            let (lins, param_cov, models) = scene(setup);
            let many: Vec<bool> = (0..lins.len()).map(|i| i % 5 != 2).collect();
            let few: Vec<bool> = (0..lins.len()).map(|i| i < 6).collect();
            for model in models {
                let fixed = packed_terms(&model.view_terms(&lins, &many, &param_cov));
                let objective = |m: &NoiseModel| {
                    em_step_packed(&mut m.variances.clone(), &fixed, true).objective
                };
                let mut maximum = model.clone();
                let long = plain_em(&mut maximum.variances, &fixed, 200_000, 1e-12);
                assert!(long < 200_000, "the plain EM did not converge");
                let mut plain = model.clone();
                let plain_steps = plain_em(
                    &mut plain.variances,
                    &fixed,
                    EM_MAX_ITERATIONS,
                    EM_TOLERANCE,
                );
                let mut fast = model.clone();
                let fast_steps = accelerated_em(&mut fast.variances, &fixed);
                let covariance_off = |m: &NoiseModel| {
                    (0..lins.len())
                        .filter(|i| many[*i])
                        .map(|i| {
                            let reference = maximum.covariance(i, &lins[i]);
                            (m.covariance(i, &lins[i]) - reference).amax() / reference.amax()
                        })
                        .fold(0.0, f64::max)
                };
                let levels_off = |m: &NoiseModel| {
                    m.variances
                        .iter()
                        .zip(&maximum.variances)
                        .map(|(a, b)| ((a - b) / b).abs())
                        .fold(0.0, f64::max)
                };
                let q = objective(&maximum);
                eprintln!(
                    "{setup:?}, {} levels: maximum after {long} steps; plain {plain_steps} steps, covariances off by {:.1e}, objective by {:.1e}; accelerated {fast_steps} steps, {:.1e}, {:.1e}",
                    model.variances.len(),
                    covariance_off(&plain),
                    (objective(&plain) - q) / q.abs(),
                    covariance_off(&fast),
                    (objective(&fast) - q) / q.abs(),
                );
                assert!(covariance_off(&fast) <= 1e-4);
                assert!((objective(&fast) - q).abs() <= 1e-10 * q.abs());
                if model.variances.len() == 3 {
                    assert!(levels_off(&fast) <= 1e-3, "{:?}", fast.variances);
                }
                // As close as the plain update (or within 1e-8), in fewer steps than the
                // plain iteration takes to the maximum.
                assert!(covariance_off(&fast) <= covariance_off(&plain).max(1e-8));
                assert!(fast_steps < long, "{fast_steps} vs {long}");
                let mut fast = model.clone();
                fast.update(&lins, &few, &param_cov);
                let mut plain = model.clone();
                plain_update(&mut plain, &lins, &few, &param_cov);
                assert_eq!(fast.variances, plain.variances);
            }
        }
    }
}
