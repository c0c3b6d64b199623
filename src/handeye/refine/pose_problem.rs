//! Maximum-likelihood hand-eye from poses: a weighted nonlinear least
//! squares over every view at once (`A_i X = Z B_i`, both unknowns, no
//! motion pairs), each view's 6-vector residual
//! ([`crate::handeye::refine::pose_residual`]) whitened by the Cholesky factor of its
//! covariance propagated from the robot and camera pose noise
//! ([`crate::handeye::refine::pose_noise`]), a Huber loss on the whitened norm for outlier
//! poses, and the noise levels re-estimated from the residuals between
//! solves (a few rounds).
//!
//! The covariance of `[x, y]` is `(sum_i J_i^T C_i^-1 J_i)^-1` at the
//! solution (inliers; the noise levels are estimated, so no further
//! residual scaling): the Cramér-Rao bound of this noise model evaluated at
//! the estimate.

use crate::error::{Error, Result};
use crate::geometry::{params_from_pose, pose_from_params};
use crate::handeye::refine::pose_noise::{CameraNoise, NoiseModel};
use crate::handeye::refine::pose_residual::{
    linearise, perturb, PoseMeasurement, ViewLinearisation,
};
use crate::handeye::{Pose, Setup};
use crate::optim::{self, BlockParams, BlockProblem, LmOptions, Loss, ResidualBlock};
use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, SMatrix, Vector3, Vector6};

/// Huber threshold on the whitened residual norm of a view: the square root
/// of the 99th percentile of chi-squared with 6 degrees of freedom, so about
/// 1 % of good views are (slightly) down-weighted.
pub const HUBER_SCALE: f64 = 4.1;

/// Rounds of solve / noise re-estimation.
pub const NOISE_ROUNDS: usize = 5;

/// 12 x 12 covariance of `[x rotation, x translation, y rotation, y
/// translation]` (rad, m; perturbations as in [`crate::handeye::refine::pose_residual`]).
pub type Covariance12 = SMatrix<f64, 12, 12>;

/// What the pose refinement found.
#[derive(Debug, Clone)]
pub struct PoseRefinement {
    /// Refined `x`.
    pub x: Pose,
    /// Refined `y`.
    pub y: Pose,
    /// Covariance of `[x, y]`; zero along an unobservable axis.
    pub covariance: Covariance12,
    /// The noise model with its estimated levels.
    pub noise: NoiseModel,
    /// Whether the levels were estimated per component (enough poses).
    pub noise_per_component: bool,
    /// Whitened residual norm of every view (about sqrt(6) for a good view).
    pub whitened_norms: Vec<f64>,
    /// Views whose whitened norm exceeds [`HUBER_SCALE`] (down-weighted).
    pub outliers: Vec<usize>,
    /// Final robust cost `0.5 sum rho(|z_i|^2)`.
    pub cost: f64,
}

/// Settings of [`refine`].
#[derive(Debug, Clone)]
pub struct PoseRefineOptions {
    /// How the camera pose noise is modelled.
    pub camera_noise: CameraNoise,
    /// A unit direction (frame of `x`'s left side) along which `x`'s
    /// translation is unobservable and held (SCARA), if any.
    pub unobservable_translation: Option<Vector3<f64>>,
}

/// The whitened least-squares problem with the weights held fixed.
struct Problem<'a> {
    setup: Setup,
    views: &'a [PoseMeasurement],
    /// `L_i^-1` with `C_i = L_i L_i^T`.
    whiten: Vec<Matrix6<f64>>,
    /// Columns: the basis of `x`'s translation step (last column held when
    /// an axis is unobservable).
    basis: Matrix3<f64>,
}

fn poses_of(p: &[f64]) -> (Pose, Pose) {
    (pose_from_params(&p[0..6]), pose_from_params(&p[6..12]))
}

/// `x`'s translation columns expressed in `basis`.
pub(crate) fn in_basis(j: &SMatrix<f64, 6, 12>, basis: &Matrix3<f64>) -> SMatrix<f64, 6, 12> {
    let mut out = *j;
    let cols = j.fixed_view::<6, 3>(0, 3) * basis;
    out.fixed_view_mut::<6, 3>(0, 3).copy_from(&cols);
    out
}

impl BlockProblem for Problem<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jacobians: bool,
    ) -> Result<Vec<ResidualBlock>> {
        let (x, y) = poses_of(&params.global);
        Ok(self
            .views
            .iter()
            .zip(&self.whiten)
            .map(|(m, l)| {
                let lin = linearise(self.setup, m, &x, &y);
                let z = l * lin.residual;
                let jac_global = if jacobians {
                    let j = l * in_basis(&lin.jac_params, &self.basis);
                    DMatrix::from_column_slice(6, 12, j.as_slice())
                } else {
                    DMatrix::zeros(6, 0)
                };
                ResidualBlock {
                    block: None,
                    residuals: DVector::from_column_slice(z.as_slice()),
                    jac_global,
                    jac_block: DMatrix::zeros(6, 0),
                }
            })
            .collect())
    }

    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        let (x, y) = poses_of(&params.global);
        let s = &step.global;
        let v = self.basis * Vector3::new(s[3], s[4], s[5]);
        let dx = Vector6::new(s[0], s[1], s[2], v.x, v.y, v.z);
        let dy = Vector6::from_column_slice(&s[6..12]);
        let mut global = params_from_pose(&perturb(&x, &dx)).to_vec();
        global.extend(params_from_pose(&perturb(&y, &dy)));
        BlockParams {
            global,
            blocks: Vec::new(),
        }
    }
}

/// `L^-1` of a covariance (`None` when not positive definite).
pub(crate) fn whitening(c: &Matrix6<f64>) -> Option<Matrix6<f64>> {
    let sym = (c + c.transpose()) * 0.5;
    sym.cholesky()?.l().try_inverse()
}

/// Whitened norms and the robust cost of `(x, y)` under `noise`.
pub fn evaluate(
    setup: Setup,
    views: &[PoseMeasurement],
    noise: &NoiseModel,
    x: &Pose,
    y: &Pose,
) -> Result<(Vec<f64>, f64)> {
    let lins: Vec<ViewLinearisation> = views.iter().map(|m| linearise(setup, m, x, y)).collect();
    evaluate_linearised(&lins, noise)
}

/// [`evaluate`] from the views' linearisations at `(x, y)`.
fn evaluate_linearised(lins: &[ViewLinearisation], noise: &NoiseModel) -> Result<(Vec<f64>, f64)> {
    let loss = Loss::Huber { scale: HUBER_SCALE };
    let mut norms = Vec::with_capacity(lins.len());
    let mut cost = 0.0;
    for (i, lin) in lins.iter().enumerate() {
        let l = whitening(&noise.covariance(i, lin))
            .ok_or_else(|| Error::degenerate(format!("view {i}: singular residual covariance")))?;
        let s = (l * lin.residual).norm_squared();
        norms.push(s.sqrt());
        cost += 0.5 * loss.evaluate(s).0;
    }
    Ok((norms, cost))
}

/// The robust negative log-likelihood `sum_i [0.5 log det C_i + 0.5
/// rho(|z_i|^2)]` of `(x, y)` under `noise`: compares noise models (whose
/// levels were fitted to the same data), unlike the cost alone.
pub fn negative_log_likelihood(
    setup: Setup,
    views: &[PoseMeasurement],
    noise: &NoiseModel,
    x: &Pose,
    y: &Pose,
) -> Result<f64> {
    let lins: Vec<ViewLinearisation> = views.iter().map(|m| linearise(setup, m, x, y)).collect();
    negative_log_likelihood_at(&lins, noise)
}

/// [`negative_log_likelihood`] of views already linearised at `(x, y)`.
pub fn negative_log_likelihood_at(lins: &[ViewLinearisation], noise: &NoiseModel) -> Result<f64> {
    let loss = Loss::Huber { scale: HUBER_SCALE };
    let mut total = 0.0;
    for (i, lin) in lins.iter().enumerate() {
        let c = noise.covariance(i, lin);
        let l = whitening(&c)
            .ok_or_else(|| Error::degenerate(format!("view {i}: singular residual covariance")))?;
        let det = c.determinant();
        if !(det > 0.0) {
            return Err(Error::degenerate(format!(
                "view {i}: singular residual covariance"
            )));
        }
        total += 0.5 * det.ln() + 0.5 * loss.evaluate((l * lin.residual).norm_squared()).0;
    }
    Ok(total)
}

/// `(sum_i w_i J_i^T C_i^-1 J_i)^-1` over the free parameters, embedded in
/// 12 x 12 and rotated back from `basis`; `w_i` the Huber weights.
fn parameter_covariance(
    lins: &[ViewLinearisation],
    noise: &NoiseModel,
    basis: &Matrix3<f64>,
    held: bool,
) -> Option<Covariance12> {
    let mut h = Covariance12::zeros();
    for (i, lin) in lins.iter().enumerate() {
        let w = noise.covariance(i, lin).try_inverse()?;
        let z2 = (lin.residual.transpose() * w * lin.residual)[0];
        let weight = Loss::Huber { scale: HUBER_SCALE }.evaluate(z2).1;
        let j = in_basis(&lin.jac_params, basis);
        h += j.transpose() * w * j * weight;
    }
    let free: Vec<usize> = (0..12).filter(|&k| !(held && k == 5)).collect();
    let n = free.len();
    let sub = DMatrix::from_fn(n, n, |a, b| h[(free[a], free[b])]);
    let inv = sub.cholesky()?.inverse();
    let mut cov = Covariance12::zeros();
    for (a, &ka) in free.iter().enumerate() {
        for (b, &kb) in free.iter().enumerate() {
            cov[(ka, kb)] = inv[(a, b)];
        }
    }
    // Back from the basis coordinates of x's translation.
    let mut rot = Covariance12::identity();
    rot.fixed_view_mut::<3, 3>(3, 3).copy_from(basis);
    Some(rot * cov * rot.transpose())
}

/// A basis whose last column is `axis` (identity without one).
pub(crate) fn translation_basis(axis: Option<Vector3<f64>>) -> Matrix3<f64> {
    let Some(k) = axis.map(|a| a.normalize()) else {
        return Matrix3::identity();
    };
    let helper = if k.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = k.cross(&helper).normalize();
    let v = k.cross(&u);
    Matrix3::from_columns(&[u, v, k])
}

/// One re-estimation of the levels at the point where the views were
/// linearised (`lins`): when fewer than half the views are inliers under
/// the current levels (they are far off, e.g. the defaults on a noisier
/// robot), first one robust common scale from the median whitened norm;
/// then the variance-component update over inliers.
fn noise_round(
    noise: &mut NoiseModel,
    lins: &[ViewLinearisation],
    basis: &Matrix3<f64>,
    held: bool,
) -> Result<()> {
    let (mut norms, _) = evaluate_linearised(lins, noise)?;
    if norms.iter().filter(|n| **n <= HUBER_SCALE).count() * 2 < lins.len() {
        noise.rescale_to_median(&norms.iter().map(|n| n * n).collect::<Vec<_>>());
        norms = evaluate_linearised(lins, noise)?.0;
    }
    let inlier: Vec<bool> = norms.iter().map(|n| *n <= HUBER_SCALE).collect();
    let cov = parameter_covariance(lins, noise, basis, held)
        .ok_or_else(|| Error::degenerate("the pose refinement's information matrix is singular"))?;
    noise.update(lins, &inlier, &cov);
    Ok(())
}

/// One noise re-estimation at a fixed `(x, y)` (e.g. a closed form), so
/// that closed forms can be compared under levels fitted to the data.
pub fn estimate_noise(
    setup: Setup,
    views: &[PoseMeasurement],
    noise: &mut NoiseModel,
    x: &Pose,
    y: &Pose,
    axis: Option<Vector3<f64>>,
) -> Result<()> {
    let lins: Vec<ViewLinearisation> = views.iter().map(|m| linearise(setup, m, x, y)).collect();
    estimate_noise_at(&lins, noise, axis)
}

/// [`estimate_noise`] of views already linearised at `(x, y)` (the same
/// numbers: several noise models fitted at one point share them).
pub fn estimate_noise_at(
    lins: &[ViewLinearisation],
    noise: &mut NoiseModel,
    axis: Option<Vector3<f64>>,
) -> Result<()> {
    let basis = translation_basis(axis);
    // Twice: the first pass moves the levels from the defaults to the data,
    // the second judges inliers with those levels.
    for _ in 0..2 {
        noise_round(noise, lins, &basis, axis.is_some())?;
    }
    Ok(())
}

/// Refine `(x, y)` from a starting pair (a closed form) with `noise` as the
/// starting levels. Needs at least 3 views (18 residuals for 12 unknowns).
pub fn refine(
    setup: Setup,
    views: &[PoseMeasurement],
    x0: &Pose,
    y0: &Pose,
    mut noise: NoiseModel,
    options: &PoseRefineOptions,
) -> Result<PoseRefinement> {
    if views.len() < 3 {
        return Err(Error::too_few(
            "poses for the pose refinement",
            3,
            views.len(),
        ));
    }
    let basis = translation_basis(options.unobservable_translation);
    let held = options.unobservable_translation.is_some();
    let lm_options = LmOptions {
        loss: Loss::Huber { scale: HUBER_SCALE },
        fixed_global: (0..12).map(|k| held && k == 5).collect(),
        ..LmOptions::default()
    };
    let (mut x, mut y) = (*x0, *y0);
    let lin_all = |x: &Pose, y: &Pose| -> Vec<ViewLinearisation> {
        views.iter().map(|m| linearise(setup, m, x, y)).collect()
    };
    for _ in 0..NOISE_ROUNDS {
        // Noise levels at the current solution, then a solve with them.
        let lins = lin_all(&x, &y);
        let before = noise.variances.clone();
        noise_round(&mut noise, &lins, &basis, held)?;
        let whiten = lins
            .iter()
            .enumerate()
            .map(|(i, lin)| {
                whitening(&noise.covariance(i, lin)).ok_or_else(|| {
                    Error::degenerate(format!("view {i}: singular residual covariance"))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let problem = Problem {
            setup,
            views,
            whiten,
            basis,
        };
        let mut global = params_from_pose(&x).to_vec();
        global.extend(params_from_pose(&y));
        let lm = optim::solve(
            &problem,
            &BlockParams {
                global,
                blocks: Vec::new(),
            },
            &lm_options,
        )?;
        (x, y) = poses_of(&lm.params.global);
        let change = before
            .iter()
            .zip(&noise.variances)
            .map(|(a, b)| (a.sqrt() - b.sqrt()).abs() / b.sqrt())
            .fold(0.0, f64::max);
        if change < 1e-3 {
            break;
        }
    }
    let lins = lin_all(&x, &y);
    let covariance = parameter_covariance(&lins, &noise, &basis, held)
        .ok_or_else(|| Error::degenerate("the pose refinement's information matrix is singular"))?;
    let (whitened_norms, cost) = evaluate(setup, views, &noise, &x, &y)?;
    let outliers: Vec<usize> = (0..views.len())
        .filter(|&i| whitened_norms[i] > HUBER_SCALE)
        .collect();
    let noise_per_component = views.len() - outliers.len()
        >= crate::handeye::refine::pose_noise::MIN_POSES_FOR_NOISE_ESTIMATE;
    Ok(PoseRefinement {
        x,
        y,
        covariance,
        noise_per_component,
        noise,
        whitened_norms,
        outliers,
        cost,
    })
}

/// The Fisher information `sum_i J_i^T C_i^-1 J_i` of `(x, y)` at the
/// truth under a noise model: its inverse is the Cramér-Rao bound of any
/// unbiased estimate from these poses.
pub fn fisher_information(
    setup: Setup,
    views: &[PoseMeasurement],
    noise: &NoiseModel,
    x: &Pose,
    y: &Pose,
) -> Covariance12 {
    views
        .iter()
        .enumerate()
        .fold(Covariance12::zeros(), |acc, (i, m)| {
            let lin = linearise(setup, m, x, y);
            match noise.covariance(i, &lin).try_inverse() {
                Some(w) => acc + lin.jac_params.transpose() * w * lin.jac_params,
                None => acc,
            }
        })
}
