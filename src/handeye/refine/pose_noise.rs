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

/// Smallest variance of any component (rad^2 or m^2): keeps the weights
/// finite on noise-free data.
const VARIANCE_FLOOR: f64 = 1e-24;

/// Most expectation-maximisation steps of one [`NoiseModel::update`]. EM
/// converges linearly, slowly when a level starts orders of magnitude off
/// (a per-view scale started at a 0.5 m camera's value for a 75 mm lens at
/// 2.3 m): 30 steps left the scale 6x off there and the model choice of
/// [`crate::handeye::refine::over_poses`] compared unconverged fits.
const EM_MAX_ITERATIONS: usize = 500;

/// EM stops when no variance changes by more than this (relative, log).
const EM_TOLERANCE: f64 = 1e-5;

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

#[cfg(test)]
/// `tr(a b)` without forming the product (36 multiplications, not 216):
/// the EM step takes 18 such traces per view and step.
fn trace_of_product(a: &Matrix6<f64>, b: &Matrix6<f64>) -> f64 {
    let mut t = 0.0;
    for i in 0..6 {
        for j in 0..6 {
            t += a[(i, j)] * b[(j, i)];
        }
    }
    t
}

/// One EM step on the full matrices (the reference of [`em_step_packed`]):
/// each level scaled by its expected over observed trace (or all by one
/// common factor); true when no level moved by more than [`EM_TOLERANCE`].
#[cfg(test)]
fn em_step<'a>(
    variances: &mut [f64],
    views: impl Iterator<Item = (&'a [Matrix6<f64>], &'a Matrix6<f64>)>,
    per_component: bool,
) -> bool {
    let before = variances.to_vec();
    let k = variances.len();
    let (mut num, mut den) = (vec![0.0; k], vec![0.0; k]);
    let (mut num_all, mut den_all) = (0.0, 0.0);
    for (comps, spread) in views {
        let c = comps
            .iter()
            .zip(variances.iter())
            .fold(Matrix6::zeros(), |acc, (m, s)| acc + m * *s);
        // C is a sum of positive semi-definite components with positive
        // weights: Cholesky inverts it (a third of the work of the general
        // inverse), and fails where the general one would be meaningless.
        let Some(w) = c.cholesky().map(|l| l.inverse()) else {
            continue;
        };
        let ws = w * spread;
        let wsw = ws * w;
        for (j, m) in comps.iter().enumerate() {
            num[j] += trace_of_product(&wsw, m);
            den[j] += trace_of_product(&w, m);
        }
        num_all += ws.trace();
        den_all += 6.0;
    }
    finish_step(
        variances,
        &before,
        (&num, &den),
        (num_all, den_all),
        per_component,
    )
}

/// The 21 entries of a symmetric 6 x 6 matrix's lower triangle, column
/// after column (`(i, j)`, `i >= j`).
const PACKED: usize = 21;

/// Index of `(i, j)`, `i >= j`, in the packed lower triangle.
const fn packed_index(i: usize, j: usize) -> usize {
    // Columns 0..j hold 6 + 5 + ... entries: j * (13 - j) / 2.
    j * (13 - j) / 2 + (i - j)
}

/// The lower triangle of a symmetric matrix, packed.
fn pack(m: &Matrix6<f64>) -> [f64; PACKED] {
    let mut out = [0.0; PACKED];
    for j in 0..6 {
        for i in j..6 {
            out[packed_index(i, j)] = m[(i, j)];
        }
    }
    out
}

/// `tr(a m)` for symmetric `a` and `m` held as packed lower triangles:
/// the diagonal products plus twice the off-diagonal ones.
fn packed_trace(a: &[f64; PACKED], m: &[f64]) -> f64 {
    let (mut diagonal, mut off) = (0.0, 0.0);
    for j in 0..6 {
        let d = packed_index(j, j);
        diagonal += a[d] * m[d];
        for k in d + 1..d + 6 - j {
            off += a[k] * m[k];
        }
    }
    diagonal + 2.0 * off
}

/// The inlier views' fixed EM terms, packed: per view its components' lower
/// triangles one after the other, and its spread.
struct PackedTerms {
    components: usize,
    packed: Vec<f64>,
    spreads: Vec<Matrix6<f64>>,
}

/// [`em_step`] on packed terms: the same expectation-maximisation step with
/// the symmetric matrices' halves (`C`, `W S W` and every trace from 21
/// entries, not 36) and, for a common factor alone, no per-level traces.
/// Equal to [`em_step`] in exact arithmetic; in floating point the sums
/// differ in order (relative differences of the order of 1e-15 per step).
fn em_step_packed(variances: &mut [f64], terms: &PackedTerms, per_component: bool) -> bool {
    let before = variances.to_vec();
    let k = terms.components;
    let (mut num, mut den) = (vec![0.0; k], vec![0.0; k]);
    let (mut num_all, mut den_all) = (0.0, 0.0);
    for (v, spread) in terms.spreads.iter().enumerate() {
        let comps = &terms.packed[v * k * PACKED..(v + 1) * k * PACKED];
        let mut c_packed = [0.0; PACKED];
        for (m, s) in comps.chunks_exact(PACKED).zip(variances.iter()) {
            for e in 0..PACKED {
                c_packed[e] += m[e] * *s;
            }
        }
        let mut c = Matrix6::zeros();
        for j in 0..6 {
            for i in j..6 {
                let value = c_packed[packed_index(i, j)];
                c[(i, j)] = value;
                c[(j, i)] = value;
            }
        }
        let Some(w) = c.cholesky().map(|l| l.inverse()) else {
            continue;
        };
        let ws = w * spread;
        num_all += ws.trace();
        den_all += 6.0;
        if !per_component {
            continue;
        }
        let mut wsw = [0.0; PACKED];
        for j in 0..6 {
            for i in j..6 {
                let mut t = 0.0;
                for m in 0..6 {
                    t += ws[(i, m)] * w[(m, j)];
                }
                wsw[packed_index(i, j)] = t;
            }
        }
        let w_packed = pack(&w);
        for (j, m) in comps.chunks_exact(PACKED).enumerate() {
            num[j] += packed_trace(&wsw, m);
            den[j] += packed_trace(&w_packed, m);
        }
    }
    finish_step(
        variances,
        &before,
        (&num, &den),
        (num_all, den_all),
        per_component,
    )
}

/// The levels from one step's traces; true when none moved by more than
/// [`EM_TOLERANCE`] (relative).
fn finish_step(
    variances: &mut [f64],
    before: &[f64],
    (num, den): (&[f64], &[f64]),
    (num_all, den_all): (f64, f64),
    per_component: bool,
) -> bool {
    if per_component {
        for j in 0..variances.len() {
            if den[j] > 0.0 {
                variances[j] = (variances[j] * num[j] / den[j]).max(VARIANCE_FLOOR);
            }
        }
        let change = before
            .iter()
            .zip(variances.iter())
            .map(|(a, b)| (a / b).ln().abs())
            .fold(0.0, f64::max);
        change < EM_TOLERANCE
    } else {
        if den_all > 0.0 {
            let f = num_all / den_all;
            for v in variances.iter_mut() {
                *v = (*v * f).max(VARIANCE_FLOOR);
            }
        }
        false
    }
}

/// The view terms of [`NoiseModel::view_terms`], packed.
fn packed_terms(terms: &[(Vec<Matrix6<f64>>, Matrix6<f64>)]) -> PackedTerms {
    let components = terms.first().map_or(0, |(comps, _)| comps.len());
    let mut packed = Vec::with_capacity(terms.len() * components * PACKED);
    for (comps, _) in terms {
        for m in comps {
            packed.extend_from_slice(&pack(m));
        }
    }
    PackedTerms {
        components,
        packed,
        spreads: terms.iter().map(|(_, s)| *s).collect(),
    }
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
        for _ in 0..if per_component { EM_MAX_ITERATIONS } else { 1 } {
            if em_step_packed(&mut self.variances, &fixed, per_component) {
                break;
            }
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
    use crate::handeye::refine::pose_residual::{linearise, PoseMeasurement};
    use crate::handeye::refine::pose_shape::{predicted_covariances, NominalTarget};
    use crate::handeye::Setup;
    use crate::rng::Rng;
    use crate::synth::handeye_looking::{looking_scene, perturbed, LookingConfig};
    use wasm_bindgen_test::wasm_bindgen_test;

    /// [`NoiseModel::update`] as it was before the per-view terms were
    /// computed once: components and spread recomputed at every EM step;
    /// with `full`, also as it was before the packed step: every matrix
    /// and trace on all 36 entries ([`em_step`]).
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

    #[wasm_bindgen_test(unsupported = test)]
    fn the_update_gives_the_levels_of_the_per_step_computation() {
        // 60 noisy views (robot 0.1 mm / 0.02 deg, camera 0.05 deg / 0.05-0.3
        // mm) linearised at the truth, every fifth view an outlier, a
        // parameter covariance of the right size; diagonal (with pivots),
        // per-view (predicted PnP shape) and, with 6 inliers, the common
        // scale: the same levels bit for bit, so the refinement's results are
        // unchanged by computing the per-view terms once.
        for setup in [Setup::EyeInHand, Setup::EyeToHand] {
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
            let many: Vec<bool> = (0..views.len()).map(|i| i % 5 != 2).collect();
            let few: Vec<bool> = (0..views.len()).map(|i| i < 6).collect();
            for model in [NoiseModel::new(CameraNoise::Diagonal), pivoted, shaped] {
                for inlier in [&many, &few] {
                    let mut fast = model.clone();
                    fast.update(&lins, inlier, &param_cov);
                    let mut reference = model.clone();
                    update_per_step(&mut reference, &lins, inlier, &param_cov, false);
                    assert_eq!(fast.variances, reference.variances);
                    assert_ne!(fast.variances, model.variances);
                    // The packed step against the full matrices: the same
                    // levels to 1e-10 (relative).
                    let mut full = model.clone();
                    update_per_step(&mut full, &lins, inlier, &param_cov, true);
                    for (a, b) in fast.variances.iter().zip(&full.variances) {
                        assert!((a - b).abs() <= 1e-10 * b, "{a} vs {b}");
                    }
                }
            }
        }
    }
}
