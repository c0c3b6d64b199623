//! How far the global parameters move when one block's residuals are left
//! out (a view of a calibration: its points and its pose), linearised at
//! the solution: the leave-one-block-out jackknife without its refits.
//!
//! At the minimum the gradient of all residuals is zero, so leaving block
//! `b` out leaves the gradient `-g_b` of its own residuals, with the pose
//! parameters of `b` eliminated (`g_b - W_b V_b^-1 h_b`, the second term
//! zero at the minimum up to round-off). One Gauss-Newton step on the
//! remaining information `S - S_b` (the Schur complement over the poses,
//! less block `b`'s share `U_b - W_b V_b^-1 W_b^T`) is the refit without
//! `b`: `delta_b = (S - S_b)^-1 (g_b - W_b V_b^-1 h_b)`. The spread of the
//! `delta_b` (`(n - 1) / n * sum (delta_b - mean)(...)^T`) is the jackknife
//! covariance; its cost is one small solve per block, no refit.
//!
//! It measures what the residuals' covariance cannot: when the blocks
//! disagree more than their residual scatter says (errors shared by the
//! points of one view: a corner bias that changes from image to image, a
//! board that is not flat), the spread is wider than `s^2 (J^T J)^-1`.

use super::normal::{Mask, Normal};
use super::{BlockParams, Loss, ResidualBlock};
use nalgebra::{DMatrix, DVector};

/// Fewest blocks for a spread that means anything.
pub const MIN_BLOCKS: usize = 4;

/// The jackknife covariance of the global parameters (rows and columns of
/// held ones zero), from the residual blocks with their Jacobians at the
/// solution. `None` with fewer than [`MIN_BLOCKS`] blocks, or when a block
/// is needed to determine the parameters (the information without it is
/// singular).
pub fn leave_block_out_covariance(
    layout: &BlockParams,
    residuals: &[ResidualBlock],
    loss: &Loss,
    free_global: &[bool],
) -> Option<DMatrix<f64>> {
    let ng = layout.global.len();
    let free: Vec<usize> = (0..ng)
        .filter(|&i| free_global.get(i) == Some(&true))
        .collect();
    let nb = layout.blocks.len();
    if free.is_empty() || nb < MIN_BLOCKS {
        return None;
    }
    let mask = Mask {
        global: (0..ng).map(|i| free_global.get(i) == Some(&true)).collect(),
        blocks: vec![true; nb],
    };
    let full = Normal::build(layout, residuals, loss, &mask);
    let (s, _) = full.schur_undamped()?;
    let pick =
        |m: &DMatrix<f64>| DMatrix::from_fn(free.len(), free.len(), |i, j| m[(free[i], free[j])]);
    let s = pick(&s);
    // Each block's share of S and its gradient, over its own residuals.
    let mut deltas: Vec<DVector<f64>> = Vec::with_capacity(nb);
    for b in 0..nb {
        let own: Vec<ResidualBlock> = residuals
            .iter()
            .filter(|r| r.block == Some(b))
            .map(|r| ResidualBlock {
                block: Some(0),
                ..r.clone()
            })
            .collect();
        if own.is_empty() {
            continue;
        }
        let one = BlockParams {
            global: layout.global.clone(),
            blocks: vec![layout.blocks[b].clone()],
        };
        let part = Normal::build(
            &one,
            &own,
            loss,
            &Mask {
                global: mask.global.clone(),
                blocks: vec![true],
            },
        );
        let v_inv = part.v[0].clone().cholesky()?.inverse();
        let y = &part.w[0] * &v_inv;
        let s_b = &part.u - &y * part.w[0].transpose();
        let g_b = &part.g_global - &y * &part.g_blocks[0];
        let rest = &s - pick(&s_b);
        let g = DVector::from_fn(free.len(), |i, _| g_b[free[i]]);
        deltas.push(rest.cholesky()?.solve(&g));
    }
    let n = deltas.len();
    if n < MIN_BLOCKS {
        return None;
    }
    let mean = deltas.iter().fold(DVector::zeros(free.len()), |a, d| a + d) / n as f64;
    let mut spread = DMatrix::zeros(free.len(), free.len());
    for d in &deltas {
        let e = d - &mean;
        spread += &e * e.transpose();
    }
    spread *= (n - 1) as f64 / n as f64;
    let mut out = DMatrix::zeros(ng, ng);
    for (i, &fi) in free.iter().enumerate() {
        for (j, &fj) in free.iter().enumerate() {
            out[(fi, fj)] = spread[(i, j)];
        }
    }
    Some(out)
}
