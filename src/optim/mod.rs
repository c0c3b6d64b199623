//! The project's one Levenberg-Marquardt solver, for block-structured
//! least-squares problems: a few global parameters (intrinsics, a hand-eye
//! transform) shared by all residuals, plus per-block parameters (one pose
//! per view) that each residual block touches at most one of. The normal
//! equations are solved by the Schur complement over the blocks, so the
//! cost grows linearly with the number of views.
//!
//! The cost is `0.5 * sum_k rho(|r_k|^2)` over residual blocks `r_k` (for
//! calibration: one block per observed point, 2 residuals in pixels), with
//! `rho` from [`Loss`]. Parameters can be held fixed ([`LmOptions::fixed_global`],
//! [`LmOptions::fixed_blocks`]); manifold parameters (rotations) use
//! [`BlockProblem::retract`].

mod cluster_robust;
pub mod dense;
mod loss;
mod normal;
pub mod student_t;
pub mod wilson;

#[cfg(test)]
mod tests;

pub(crate) use cluster_robust::cluster_robust_from_final;
pub use cluster_robust::{cluster_robust_covariance, ClusterRobust, MIN_CLUSTERS};
pub use loss::Loss;

use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};
use normal::{Mask, Normal};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Parameter values (or a step): the global vector and one vector per block.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlockParams {
    /// Parameters shared by every residual block.
    pub global: Vec<f64>,
    /// Per-block parameters (e.g. one 6-vector pose per view).
    pub blocks: Vec<Vec<f64>>,
}

/// One group of residuals (e.g. the 2 pixel residuals of one point) and its
/// Jacobians. The robust loss applies to the group's squared norm.
#[derive(Clone, Debug)]
pub struct ResidualBlock {
    /// The block whose parameters these residuals depend on, if any.
    pub block: Option<usize>,
    /// The residuals (m values).
    pub residuals: DVector<f64>,
    /// d residuals / d global parameters (m x n_global); may have 0 columns
    /// when Jacobians were not requested.
    pub jac_global: DMatrix<f64>,
    /// d residuals / d block parameters (m x block size); 0 columns when
    /// `block` is `None` or Jacobians were not requested.
    pub jac_block: DMatrix<f64>,
}

/// The residuals of one parameter block (one view's points) stacked, with
/// transposed Jacobians: what [`BlockProblem::residual_runs`] builds
/// directly, without a small matrix per residual group.
#[derive(Clone, Debug)]
pub struct ResidualRun {
    /// The block these residuals depend on, if any.
    pub block: Option<usize>,
    /// Residuals per loss group (2 for a pixel): the robust loss applies
    /// to each group's squared norm, as to a [`ResidualBlock`]'s.
    pub group: usize,
    /// The residuals, group after group.
    pub residuals: DVector<f64>,
    /// d residuals / d global parameters, transposed (n_global x rows).
    pub jac_global_t: DMatrix<f64>,
    /// d residuals / d block parameters, transposed (block size x rows; 0
    /// rows without a block).
    pub jac_block_t: DMatrix<f64>,
}

/// A least-squares problem for [`solve`].
pub trait BlockProblem {
    /// All residual blocks at `params`; with `jacobians == false` the
    /// Jacobian matrices may be left empty. Errors (e.g. a point behind the
    /// camera) make the solver reject the step that led there.
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jacobians: bool,
    ) -> Result<Vec<ResidualBlock>>;

    /// The residuals and Jacobians of [`BlockProblem::residuals_and_jacobian`]
    /// as runs of one block each, for a problem that can build them without
    /// a matrix per residual group (the solver's hot path); `None` (the
    /// default): the solver takes the residual blocks. The same values in
    /// the same order, so the solver's arithmetic is the same either way.
    fn residual_runs(&self, _params: &BlockParams) -> Option<Result<Vec<ResidualRun>>> {
        None
    }

    /// Apply a step; the Jacobians are with respect to this step. Additive
    /// by default; override for rotations (e.g. `R <- exp(delta) R`).
    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        let add = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, d)| x + d).collect::<Vec<f64>>();
        BlockParams {
            global: add(&params.global, &step.global),
            blocks: params
                .blocks
                .iter()
                .zip(&step.blocks)
                .map(|(a, b)| add(a, b))
                .collect(),
        }
    }
}

/// Solver settings. Defaults converge noise-free problems to ~1e-12.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LmOptions {
    /// Most Jacobian evaluations (default 200).
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this
    /// fraction, or when a rejected step's quadratic model predicted less
    /// (default 1e-12: summing ~1e3 squared residuals leaves the cost
    /// uncertain to ~1e-13 relative, so smaller changes are round-off and
    /// further steps only fight it).
    pub cost_tolerance: f64,
    /// Stop when the largest gradient component is below this (default 1e-14).
    pub gradient_tolerance: f64,
    /// Stop when the step is below this relative to the parameters (default 1e-12).
    pub step_tolerance: f64,
    /// Initial damping relative to diag(J^T J) (default 1e-4).
    pub initial_lambda: f64,
    /// Robust loss (default [`Loss::Squared`]).
    pub loss: Loss,
    /// Global parameters held at their initial value (empty: none).
    pub fixed_global: Vec<bool>,
    /// Blocks held at their initial value (empty: none).
    pub fixed_blocks: Vec<bool>,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iterations: 200,
            cost_tolerance: 1e-12,
            gradient_tolerance: 1e-14,
            step_tolerance: 1e-12,
            initial_lambda: 1e-4,
            loss: Loss::Squared,
            fixed_global: vec![],
            fixed_blocks: vec![],
        }
    }
}

/// Why the solver stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// The relative cost decrease (achieved, or predicted for a rejected
    /// step) fell below the tolerance, or the cost is 0.
    CostTolerance,
    /// The gradient fell below the tolerance.
    GradientTolerance,
    /// The step fell below the tolerance.
    StepTolerance,
    /// No step lowered the cost even with very strong damping: a minimum
    /// to machine precision.
    NoDecrease,
    /// The iteration limit was reached.
    MaxIterations,
}

/// The outcome of [`solve`].
#[derive(Clone, Debug)]
pub struct LmResult {
    /// The final parameters.
    pub params: BlockParams,
    /// Cost at the initial parameters.
    pub initial_cost: f64,
    /// Final cost `0.5 sum rho(|r|^2)`.
    pub cost: f64,
    /// Jacobian evaluations done.
    pub iterations: usize,
    /// Why it stopped.
    pub termination: Termination,
    /// Number of scalar residuals.
    pub n_residuals: usize,
    /// Number of parameters that were free to move.
    pub n_free_params: usize,
    /// Residual variance estimate `2 cost / (n_residuals - n_free_params)`.
    pub residual_variance: f64,
    /// Covariance of the global parameters, `(J^T J)^-1` marginalised over
    /// the blocks and scaled by the residual variance; zero rows for held
    /// parameters. `None` when J^T J is singular at the optimum.
    pub covariance_global: Option<DMatrix<f64>>,
    /// Marginal covariance of each block, scaled likewise.
    pub covariance_blocks: Option<Vec<DMatrix<f64>>>,
    /// The normal equations the solver built at `params` (its last
    /// evaluation), for a check that needs them again
    /// ([`cluster_robust_from_final`]); `None` from [`solve_with_floor`].
    pub(crate) final_normal: Option<Arc<FinalNormal>>,
}

/// The normal equations at the solver's final parameters, with what they
/// were built under.
#[derive(Debug)]
pub(crate) struct FinalNormal {
    pub normal: Normal,
    pub mask: Mask,
    pub loss: Loss,
    pub params: BlockParams,
}

impl LmResult {
    /// Standard deviations of the global parameters (sqrt of the covariance diagonal).
    pub fn std_global(&self) -> Option<Vec<f64>> {
        self.covariance_global
            .as_ref()
            .map(|c| c.diagonal().iter().map(|v| v.max(0.0).sqrt()).collect())
    }
}

/// The residuals and Jacobians at one point, as the problem gives them.
enum Evaluation {
    Blocks(Vec<ResidualBlock>),
    Runs(Vec<ResidualRun>),
}

impl Evaluation {
    fn at(problem: &dyn BlockProblem, params: &BlockParams) -> Result<Evaluation> {
        match problem.residual_runs(params) {
            Some(runs) => runs.map(Evaluation::Runs),
            None => problem
                .residuals_and_jacobian(params, true)
                .map(Evaluation::Blocks),
        }
    }

    /// `0.5 sum rho(|r_k|^2)`, group after group in order.
    fn cost(&self, loss: &Loss) -> f64 {
        match self {
            Evaluation::Blocks(blocks) => blocks
                .iter()
                .map(|b| 0.5 * loss.evaluate(b.residuals.norm_squared()).0)
                .sum(),
            Evaluation::Runs(runs) => runs
                .iter()
                .flat_map(|run| run.residuals.as_slice().chunks(run.group.max(1)))
                .map(|g| 0.5 * loss.evaluate(normal::squared_norm(g)).0)
                .sum(),
        }
    }

    fn n_residuals(&self) -> usize {
        match self {
            Evaluation::Blocks(blocks) => blocks.iter().map(|b| b.residuals.len()).sum(),
            Evaluation::Runs(runs) => runs.iter().map(|r| r.residuals.len()).sum(),
        }
    }

    fn normal(self, layout: &BlockParams, loss: &Loss, mask: &Mask) -> Normal {
        match self {
            Evaluation::Blocks(blocks) => Normal::build(layout, &blocks, loss, mask),
            Evaluation::Runs(runs) => Normal::build_from_runs(layout, runs, loss, mask),
        }
    }
}

/// Damping beyond which the solver gives up finding a lower cost.
const MAX_LAMBDA: f64 = 1e16;

/// Minimise the problem's cost from `initial` with Levenberg-Marquardt.
pub fn solve(
    problem: &dyn BlockProblem,
    initial: &BlockParams,
    options: &LmOptions,
) -> Result<LmResult> {
    let (mut result, normal) = solve_keeping_normal(problem, initial, options, true)?;
    result.final_normal = Some(Arc::new(FinalNormal {
        normal,
        mask: make_mask(initial, options)?,
        loss: options.loss,
        params: result.params.clone(),
    }));
    Ok(result)
}

/// [`solve`] without the covariances, and the cost the Gauss-Newton model
/// at the solver's last point predicts at its minimum (what
/// [`gauss_newton_floor`] gives at `result.params`, from the normal
/// equations the solver already built there instead of a new evaluation).
pub fn solve_with_floor(
    problem: &dyn BlockProblem,
    initial: &BlockParams,
    options: &LmOptions,
) -> Result<(LmResult, f64)> {
    let (result, normal) = solve_keeping_normal(problem, initial, options, false)?;
    let floor = floor_of(&normal, result.cost)?;
    Ok((result, floor))
}

/// The Gauss-Newton floor of normal equations at a point of cost `cost`.
fn floor_of(normal: &Normal, cost: f64) -> Result<f64> {
    let (_, predicted) = normal.solve(0.0).ok_or_else(|| {
        Error::degenerate("the normal equations are singular: no Gauss-Newton step")
    })?;
    Ok((cost - predicted).max(0.0))
}

/// The solve, with the covariances when asked, and the normal equations at
/// the final parameters.
fn solve_keeping_normal(
    problem: &dyn BlockProblem,
    initial: &BlockParams,
    options: &LmOptions,
    with_covariance: bool,
) -> Result<(LmResult, Normal)> {
    let mask = make_mask(initial, options)?;
    let mut params = initial.clone();
    let evaluation = Evaluation::at(problem, &params)?;
    let n_residuals = evaluation.n_residuals();
    let initial_cost = evaluation.cost(&options.loss);
    if !initial_cost.is_finite() {
        return Err(Error::invalid(
            "initial",
            "the cost at the initial parameters is not finite",
        ));
    }
    let mut cost = initial_cost;
    let mut lambda = options.initial_lambda;
    let mut iterations = 0;
    let mut normal = evaluation.normal(&params, &options.loss, &mask);
    let termination = 'outer: loop {
        if cost == 0.0 {
            break Termination::CostTolerance;
        }
        if normal.gradient_max() <= options.gradient_tolerance {
            break Termination::GradientTolerance;
        }
        if iterations >= options.max_iterations {
            break Termination::MaxIterations;
        }
        iterations += 1;
        // Raise the damping until a step lowers the cost.
        loop {
            if lambda > MAX_LAMBDA {
                break 'outer Termination::NoDecrease;
            }
            let Some((step, predicted)) = normal.solve(lambda) else {
                lambda *= 10.0;
                continue;
            };
            let candidate = problem.retract(&params, &step);
            let new_evaluation = match Evaluation::at(problem, &candidate) {
                Ok(r) => r,
                Err(_) => {
                    lambda *= 10.0;
                    continue;
                }
            };
            let new_cost = new_evaluation.cost(&options.loss);
            if !(new_cost < cost) {
                if predicted <= options.cost_tolerance * cost {
                    // The model promised only round-off: at the minimum.
                    break 'outer Termination::CostTolerance;
                }
                lambda *= 10.0;
                continue;
            }
            let ratio = if predicted > 0.0 {
                (cost - new_cost) / predicted
            } else {
                0.0
            };
            lambda *= if ratio > 0.75 {
                1.0 / 3.0
            } else if ratio < 0.25 {
                2.0
            } else {
                1.0
            };
            lambda = lambda.max(1e-15);
            let decrease = cost - new_cost;
            let small_step = step_norm(&step)
                <= options.step_tolerance * (step_norm(&params) + options.step_tolerance);
            params = candidate;
            cost = new_cost;
            normal = new_evaluation.normal(&params, &options.loss, &mask);
            if decrease <= options.cost_tolerance * (cost + decrease) {
                break 'outer Termination::CostTolerance;
            }
            if small_step {
                break 'outer Termination::StepTolerance;
            }
            break;
        }
    };
    let n_free_params = mask.global.iter().filter(|f| **f).count()
        + params
            .blocks
            .iter()
            .zip(&mask.blocks)
            .filter(|(_, f)| **f)
            .map(|(b, _)| b.len())
            .sum::<usize>();
    let dof = n_residuals.saturating_sub(n_free_params);
    let residual_variance = if dof > 0 {
        2.0 * cost / dof as f64
    } else {
        0.0
    };
    let covariances = if with_covariance {
        normal.covariances(&mask)
    } else {
        None
    };
    let result = LmResult {
        initial_cost,
        cost,
        iterations,
        termination,
        n_residuals,
        n_free_params,
        residual_variance,
        covariance_global: covariances.as_ref().map(|(g, _)| g * residual_variance),
        covariance_blocks: covariances
            .map(|(_, b)| b.into_iter().map(|c| c * residual_variance).collect()),
        params,
        final_normal: None,
    };
    Ok((result, normal))
}

/// The cost the Gauss-Newton model of `problem` at `params` predicts at
/// its minimum: the cost there less the undamped step's predicted
/// decrease (never below 0). Near a minimum this is the cost a full solve
/// reaches, to second order; a screen, not a bound.
pub fn gauss_newton_floor(
    problem: &dyn BlockProblem,
    params: &BlockParams,
    options: &LmOptions,
) -> Result<f64> {
    let mask = make_mask(params, options)?;
    let residuals = problem.residuals_and_jacobian(params, true)?;
    let cost: f64 = residuals
        .iter()
        .map(|b| 0.5 * options.loss.evaluate(b.residuals.norm_squared()).0)
        .sum();
    let normal = Normal::build(params, &residuals, &options.loss, &mask);
    floor_of(&normal, cost)
}

fn step_norm(p: &BlockParams) -> f64 {
    let global: f64 = p.global.iter().map(|v| v * v).sum();
    let blocks: f64 = p.blocks.iter().flatten().map(|v| v * v).sum();
    (global + blocks).sqrt()
}

fn make_mask(initial: &BlockParams, options: &LmOptions) -> Result<Mask> {
    let global = if options.fixed_global.is_empty() {
        vec![true; initial.global.len()]
    } else if options.fixed_global.len() == initial.global.len() {
        options.fixed_global.iter().map(|f| !f).collect()
    } else {
        return Err(Error::invalid(
            "fixed_global",
            format!(
                "{} flags for {} global parameters",
                options.fixed_global.len(),
                initial.global.len()
            ),
        ));
    };
    let blocks = if options.fixed_blocks.is_empty() {
        vec![true; initial.blocks.len()]
    } else if options.fixed_blocks.len() == initial.blocks.len() {
        options.fixed_blocks.iter().map(|f| !f).collect()
    } else {
        return Err(Error::invalid(
            "fixed_blocks",
            format!(
                "{} flags for {} blocks",
                options.fixed_blocks.len(),
                initial.blocks.len()
            ),
        ));
    };
    Ok(Mask { global, blocks })
}
