//! The normal equations of a block-structured least-squares problem and
//! their solution by the Schur complement over the per-block parameters.
//!
//! ```text
//! [ U    W ] [dg]   [-g_g]      U: global x global, V = diag(V_i): per block,
//! [ W^T  V ] [db] = [-g_b]      W = [W_1 .. W_n]: global x block
//! S = U - sum W_i V_i^-1 W_i^T,  S dg = -g_g + sum W_i V_i^-1 g_i,
//! db_i = V_i^-1 (-g_i - W_i^T dg)
//! ```
//! Each V_i is small (6 for a pose), so the cost is linear in the number
//! of blocks.

use super::dense::{add_times_transpose, times_transpose};
use super::{BlockParams, Loss, ResidualBlock, ResidualRun};
use nalgebra::{DMatrix, DVector};

/// nalgebra hands a product to matrixmultiply when every dimension exceeds
/// this (below it, column by column: other sums).
const GEMM_DIM: usize = 5;

/// Floor of the Marquardt scaling `diag(H)`, so that parameters the data
/// does not constrain still get damped.
const MIN_DIAGONAL: f64 = 1e-9;

/// Smallest unexplained information fraction (1 - R^2) of a parameter
/// before J^T J counts as singular: the parameter is then a combination of
/// the others to 12 digits.
const RANK_TOLERANCE: f64 = 1e-12;

/// J^T J and J^T r, accumulated per block, with robust weights applied.
#[derive(Clone, Debug)]
pub(crate) struct Normal {
    pub u: DMatrix<f64>,
    pub w: Vec<DMatrix<f64>>,
    pub v: Vec<DMatrix<f64>>,
    pub g_global: DVector<f64>,
    pub g_blocks: Vec<DVector<f64>>,
    /// The runs these sums came from, their rows already weighted by
    /// `sqrt(rho')` (empty when built from residual blocks): kept for a
    /// covariance that needs the rows themselves
    /// ([`super::cluster_robust`]), so it need not evaluate them again.
    pub weighted_runs: Vec<ResidualRun>,
}

/// `sum v^2` of one residual group, summed as nalgebra's `norm_squared`
/// sums a short vector (in order from 0), so either path gives the same
/// cost bit for bit.
pub(crate) fn squared_norm(group: &[f64]) -> f64 {
    group.iter().fold(0.0, |acc, v| acc + v * v)
}

/// Which parameters move (true) and which are held.
#[derive(Clone, Debug)]
pub(crate) struct Mask {
    pub global: Vec<bool>,
    pub blocks: Vec<bool>,
}

impl Normal {
    /// Accumulate the weighted normal equations of `residuals`.
    pub fn build(
        layout: &BlockParams,
        residuals: &[ResidualBlock],
        loss: &Loss,
        mask: &Mask,
    ) -> Normal {
        let mut n = Normal::zeros(layout);
        // Residual blocks come in runs that share a parameter block (one
        // view's points): stack each run's weighted rows and accumulate with
        // a few dense products (nalgebra hands them to matrixmultiply),
        // instead of 2-row products per point, which cost 10x more.
        let mut start = 0;
        while start < residuals.len() {
            let block = residuals[start].block;
            let end = residuals[start..]
                .iter()
                .position(|rb| rb.block != block)
                .map_or(residuals.len(), |k| start + k);
            n.add_run(&residuals[start..end], block, loss);
            start = end;
        }
        n.apply_mask(mask);
        n
    }

    /// [`Normal::build`] from runs the problem stacked itself: the same
    /// weighting and products, so the same sums bit for bit.
    pub fn build_from_runs(
        layout: &BlockParams,
        runs: Vec<ResidualRun>,
        loss: &Loss,
        mask: &Mask,
    ) -> Normal {
        let mut n = Normal::zeros(layout);
        let ng = n.u.nrows();
        for mut run in runs {
            let nb = run.block.map_or(0, |b| n.v[b].nrows());
            let global = run.jac_global_t.nrows() == ng && ng > 0;
            let has_block = run.jac_block_t.nrows() == nb && nb > 0;
            let rows = run.residuals.len();
            if !global {
                run.jac_global_t = DMatrix::zeros(ng, rows);
            }
            if !has_block {
                run.jac_block_t = DMatrix::zeros(nb, rows);
            }
            let group = run.group.max(1);
            // Squared loss: every weight is 1, nothing to scale.
            let weighted = !matches!(loss, Loss::Squared);
            for start in (0..rows).step_by(group).filter(|_| weighted) {
                let end = (start + group).min(rows);
                let (_, d_rho) = loss.evaluate(squared_norm(&run.residuals.as_slice()[start..end]));
                let w = d_rho.max(0.0).sqrt();
                if w == 1.0 {
                    // Squared loss, or an inlier of a robust one: the rows
                    // as they are (`x * 1.0 == x`, bit for bit).
                    continue;
                }
                for k in start..end {
                    run.residuals[k] *= w;
                    for c in 0..ng {
                        run.jac_global_t[(c, k)] *= w;
                    }
                    for c in 0..nb {
                        run.jac_block_t[(c, k)] *= w;
                    }
                }
            }
            n.add_stacked(
                &run.jac_global_t,
                &run.jac_block_t,
                &run.residuals,
                run.block,
            );
            n.weighted_runs.push(run);
        }
        n.apply_mask(mask);
        n
    }

    /// Zero normal equations for the parameters of `layout`.
    fn zeros(layout: &BlockParams) -> Normal {
        let ng = layout.global.len();
        Normal {
            u: DMatrix::zeros(ng, ng),
            w: layout
                .blocks
                .iter()
                .map(|b| DMatrix::zeros(ng, b.len()))
                .collect(),
            v: layout
                .blocks
                .iter()
                .map(|b| DMatrix::zeros(b.len(), b.len()))
                .collect(),
            g_global: DVector::zeros(ng),
            g_blocks: layout
                .blocks
                .iter()
                .map(|b| DVector::zeros(b.len()))
                .collect(),
            weighted_runs: Vec::new(),
        }
    }

    /// Add the rows of residual blocks that all touch `block`.
    fn add_run(&mut self, run: &[ResidualBlock], block: Option<usize>, loss: &Loss) {
        let ng = self.u.nrows();
        let nb = block.map_or(0, |b| self.v[b].nrows());
        let rows: usize = run.iter().map(|rb| rb.residuals.len()).sum();
        // Transposed stacks (parameters x rows): column k is one residual.
        let mut jg_t = DMatrix::zeros(ng, rows);
        let mut jb_t = DMatrix::zeros(nb, rows);
        let mut r = DVector::zeros(rows);
        let mut k = 0;
        for rb in run {
            // IRLS: scale J and r by sqrt(rho'), so J^T J gets rho' and the
            // gradient is rho' J^T r.
            let (_, d_rho) = loss.evaluate(rb.residuals.norm_squared());
            let w = d_rho.max(0.0).sqrt();
            let global = rb.jac_global.ncols() == ng && ng > 0;
            let has_block = rb.jac_block.ncols() == nb && nb > 0;
            for i in 0..rb.residuals.len() {
                r[k] = w * rb.residuals[i];
                if global {
                    for c in 0..ng {
                        jg_t[(c, k)] = w * rb.jac_global[(i, c)];
                    }
                }
                if has_block {
                    for c in 0..nb {
                        jb_t[(c, k)] = w * rb.jac_block[(i, c)];
                    }
                }
                k += 1;
            }
        }
        self.add_stacked(&jg_t, &jb_t, &r, block);
    }

    /// Add the weighted rows of one run: `jg_t` (global parameters x rows),
    /// `jb_t` (the block's parameters x rows) and the residuals `r`.
    fn add_stacked(
        &mut self,
        jg_t: &DMatrix<f64>,
        jb_t: &DMatrix<f64>,
        r: &DVector<f64>,
        block: Option<usize>,
    ) {
        let ng = self.u.nrows();
        let nb = jb_t.nrows();
        let rows = r.len();
        // The global parameters this run touches: a splined lens's points
        // move a few control values each, so a view's rows are zero in most
        // of its ~200 global columns. The products over the touched ones
        // alone, added into their rows and columns, are the same sums.
        let active: Vec<usize> = (0..ng)
            .filter(|&c| jg_t.row(c).iter().any(|v| *v != 0.0))
            .collect();
        if ng > 0 && active.len() * 4 < ng * 3 {
            let jg = DMatrix::from_fn(active.len(), rows, |i, k| jg_t[(active[i], k)]);
            let u = &jg * jg.transpose();
            let g = &jg * r;
            for (i, &ai) in active.iter().enumerate() {
                for (j, &aj) in active.iter().enumerate() {
                    self.u[(ai, aj)] += u[(i, j)];
                }
                self.g_global[ai] += g[i];
            }
            if let Some(b) = block {
                let w = times_transpose(&jg, jb_t);
                for (i, &ai) in active.iter().enumerate() {
                    for j in 0..nb {
                        self.w[b][(ai, j)] += w[(i, j)];
                    }
                }
            }
        } else if let Some(b) = block.filter(|_| ng > GEMM_DIM && nb > GEMM_DIM && rows > GEMM_DIM)
        {
            self.add_stacked_product(jg_t, jb_t, r, b);
            return;
        } else if ng > 0 {
            add_times_transpose(&mut self.u, 1.0, jg_t, jg_t);
            self.g_global.gemv(1.0, jg_t, r, 1.0);
            if let Some(b) = block {
                add_times_transpose(&mut self.w[b], 1.0, jg_t, jb_t);
            }
        }
        if let Some(b) = block {
            add_times_transpose(&mut self.v[b], 1.0, jb_t, jb_t);
            self.g_blocks[b].gemv(1.0, jb_t, r, 1.0);
        }
    }

    /// `U += J_g J_g^T`, `W_b += J_g J_b^T`, `V_b += J_b J_b^T` as one
    /// product of the stacked rows `J = [J_g; J_b]` into `S = [U W_b; . V_b]`:
    /// matrixmultiply sums each entry of `S + J J^T` over the rows in the
    /// same order as it sums the three products' (every dimension above
    /// [`GEMM_DIM`], so all four go to it), and adds it to the entry the
    /// same way, so the same numbers bit for bit, with two packings (`J`, `J^T`)
    /// instead of six and 4 of its 8 x 8 kernels instead of 7 (15 parameters).
    /// The gradients `g += J r` likewise in one pass over `J`'s columns,
    /// each entry summed in the rows' order as nalgebra's `gemv` sums it
    /// (`g_i + J_ik r_k`, k = 0, 1, ...): the same bits.
    fn add_stacked_product(
        &mut self,
        jg_t: &DMatrix<f64>,
        jb_t: &DMatrix<f64>,
        r: &DVector<f64>,
        b: usize,
    ) {
        let (ng, nb) = (jg_t.nrows(), jb_t.nrows());
        let n = ng + nb;
        // Column-major: column k of J is column k of J_g, then of J_b.
        let mut j = Vec::with_capacity(n * jg_t.ncols());
        for (g, b) in jg_t
            .as_slice()
            .chunks_exact(ng)
            .zip(jb_t.as_slice().chunks_exact(nb))
        {
            j.extend_from_slice(g);
            j.extend_from_slice(b);
        }
        let mut g: Vec<f64> = self
            .g_global
            .iter()
            .chain(self.g_blocks[b].iter())
            .copied()
            .collect();
        for (column, &rk) in j.chunks_exact(n).zip(r.iter()) {
            for (gi, &a) in g.iter_mut().zip(column) {
                *gi += a * rk;
            }
        }
        self.g_global.copy_from_slice(&g[..ng]);
        self.g_blocks[b].copy_from_slice(&g[ng..]);
        let j = DMatrix::from_vec(n, jg_t.ncols(), j);
        // S's columns: U's (and zeros), then W_b's and V_b's.
        let mut s = Vec::with_capacity(n * n);
        for u in self.u.as_slice().chunks_exact(ng) {
            s.extend_from_slice(u);
            s.resize(s.len() + nb, 0.0);
        }
        for (w, v) in self.w[b]
            .as_slice()
            .chunks_exact(ng)
            .zip(self.v[b].as_slice().chunks_exact(nb))
        {
            s.extend_from_slice(w);
            s.extend_from_slice(v);
        }
        let mut s = DMatrix::from_vec(n, n, s);
        add_times_transpose(&mut s, 1.0, &j, &j);
        let s = s.as_slice();
        for (c, u) in self.u.as_mut_slice().chunks_exact_mut(ng).enumerate() {
            u.copy_from_slice(&s[c * n..c * n + ng]);
        }
        let columns = self.w[b]
            .as_mut_slice()
            .chunks_exact_mut(ng)
            .zip(self.v[b].as_mut_slice().chunks_exact_mut(nb));
        for (c, (w, v)) in columns.enumerate() {
            let at = (ng + c) * n;
            w.copy_from_slice(&s[at..at + ng]);
            v.copy_from_slice(&s[at + ng..at + n]);
        }
    }

    /// Held parameters get an identity row and column and zero gradient,
    /// so their step is exactly 0.
    fn apply_mask(&mut self, mask: &Mask) {
        for (k, &free) in mask.global.iter().enumerate() {
            if free {
                continue;
            }
            self.u.row_mut(k).fill(0.0);
            self.u.column_mut(k).fill(0.0);
            self.u[(k, k)] = 1.0;
            self.g_global[k] = 0.0;
            for w in &mut self.w {
                w.row_mut(k).fill(0.0);
            }
        }
        for (b, &free) in mask.blocks.iter().enumerate() {
            if !free {
                self.v[b].fill_with_identity();
                self.w[b].fill(0.0);
                self.g_blocks[b].fill(0.0);
            }
        }
    }

    /// Largest gradient component.
    pub fn gradient_max(&self) -> f64 {
        let g = self.g_global.amax();
        self.g_blocks.iter().map(|g| g.amax()).fold(g, f64::max)
    }

    /// Solve `(H + lambda D) delta = -g` with D the clamped diagonal of H.
    /// Returns the step and the cost reduction the quadratic model predicts,
    /// or `None` when the damped system is not positive definite.
    pub fn solve(&self, lambda: f64) -> Option<(BlockParams, f64)> {
        let damp = |m: &DMatrix<f64>| {
            let mut d = m.clone();
            for i in 0..d.nrows() {
                d[(i, i)] += lambda * m[(i, i)].max(MIN_DIAGONAL);
            }
            d
        };
        let (s, v_inv) = self.schur(damp)?;
        let mut rhs = -self.g_global.clone();
        for (b, w) in self.w.iter().enumerate() {
            rhs += w * (&v_inv[b] * &self.g_blocks[b]);
        }
        let dg = s.cholesky()?.solve(&rhs);
        let mut predicted = -0.5 * self.g_global.dot(&dg);
        for i in 0..dg.len() {
            predicted += 0.5 * lambda * self.u[(i, i)].max(MIN_DIAGONAL) * dg[i] * dg[i];
        }
        let mut blocks = Vec::with_capacity(self.v.len());
        for (b, w) in self.w.iter().enumerate() {
            let db = &v_inv[b] * (-&self.g_blocks[b] - w.transpose() * &dg);
            predicted -= 0.5 * self.g_blocks[b].dot(&db);
            for i in 0..db.len() {
                predicted += 0.5 * lambda * self.v[b][(i, i)].max(MIN_DIAGONAL) * db[i] * db[i];
            }
            blocks.push(db.iter().copied().collect());
        }
        Some((
            BlockParams {
                global: dg.iter().copied().collect(),
                blocks,
            },
            predicted,
        ))
    }

    /// The Schur complement of the (damped) system and the inverted blocks.
    fn schur(
        &self,
        damp: impl Fn(&DMatrix<f64>) -> DMatrix<f64>,
    ) -> Option<(DMatrix<f64>, Vec<DMatrix<f64>>)> {
        let mut s = damp(&self.u);
        let mut v_inv = Vec::with_capacity(self.v.len());
        for (b, v) in self.v.iter().enumerate() {
            let inv = damp(v).cholesky()?.inverse();
            let y = &self.w[b] * &inv;
            add_times_transpose(&mut s, -1.0, &y, &self.w[b]);
            v_inv.push(inv);
        }
        Some((s, v_inv))
    }

    /// `S = U - sum W_i V_i^-1 W_i^T` and the `V_i^-1`, undamped.
    pub fn schur_undamped(&self) -> Option<(DMatrix<f64>, Vec<DMatrix<f64>>)> {
        self.schur(|m| m.clone())
    }

    /// Undamped marginal covariances (unscaled: (J^T J)^-1) of the global
    /// parameters and of each block, with zero rows and columns for held
    /// parameters. `None` when J^T J is singular (unobservable parameters).
    pub fn covariances(&self, mask: &Mask) -> Option<(DMatrix<f64>, Vec<DMatrix<f64>>)> {
        let (s, v_inv) = self.schur(|m| m.clone())?;
        // Rank test on the correlation form: the squared Cholesky pivot of
        // parameter i is the fraction of its information not explained by
        // the parameters before it (1 - R^2).
        let d: Vec<f64> = s.diagonal().iter().map(|v| v.sqrt()).collect();
        if d.iter().any(|v| !(*v > 0.0) || !v.is_finite()) {
            return None;
        }
        let scaled = DMatrix::from_fn(s.nrows(), s.ncols(), |i, j| s[(i, j)] / (d[i] * d[j]));
        let chol = scaled.cholesky()?;
        if chol
            .l_dirty()
            .diagonal()
            .iter()
            .any(|p| p * p < RANK_TOLERANCE)
        {
            return None;
        }
        let mut s_inv = chol.inverse();
        for i in 0..s_inv.nrows() {
            for j in 0..s_inv.ncols() {
                s_inv[(i, j)] /= d[i] * d[j];
            }
        }
        for (k, &free) in mask.global.iter().enumerate() {
            if !free {
                s_inv.row_mut(k).fill(0.0);
                s_inv.column_mut(k).fill(0.0);
            }
        }
        let mut blocks = Vec::with_capacity(v_inv.len());
        for (b, inv) in v_inv.into_iter().enumerate() {
            if !mask.blocks[b] {
                blocks.push(DMatrix::zeros(inv.nrows(), inv.ncols()));
                continue;
            }
            // Sigma_bb = V^-1 + Y^T S^-1 Y with Y = W V^-1.
            let y = &self.w[b] * &inv;
            blocks.push(&inv + y.transpose() * &s_inv * &y);
        }
        Some((s_inv, blocks))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reproducible pseudo-random matrix (entries in -1..1).
    fn noise(rows: usize, cols: usize, seed: u64) -> DMatrix<f64> {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        DMatrix::from_fn(rows, cols, |_, _| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
    }

    #[test]
    fn stacked_product_is_the_three_products_bit_for_bit() {
        // 176 rows (a ChArUco view) and 600 (past matrixmultiply's depth
        // block of 256, where it adds the blocks to the entry one by one).
        for (seed, (ng, rows)) in [(9, 176), (15, 600), (6, 12), (9, 6)]
            .into_iter()
            .enumerate()
        {
            let seed = seed as u64;
            let jg = noise(ng, rows, seed);
            let jb = noise(6, rows, seed + 10);
            let start = Normal {
                u: noise(ng, ng, seed + 20),
                w: vec![noise(ng, 6, seed + 30)],
                v: vec![noise(6, 6, seed + 40)],
                g_global: DVector::from_column_slice(noise(ng, 1, seed + 60).as_slice()),
                g_blocks: vec![DVector::from_column_slice(
                    noise(6, 1, seed + 70).as_slice(),
                )],
                weighted_runs: Vec::new(),
            };
            let r = DVector::from_column_slice(noise(rows, 1, seed + 50).as_slice());
            let mut stacked = start.clone();
            stacked.add_stacked_product(&jg, &jb, &r, 0);
            let mut three = start;
            add_times_transpose(&mut three.u, 1.0, &jg, &jg);
            add_times_transpose(&mut three.w[0], 1.0, &jg, &jb);
            add_times_transpose(&mut three.v[0], 1.0, &jb, &jb);
            three.g_global.gemv(1.0, &jg, &r, 1.0);
            three.g_blocks[0].gemv(1.0, &jb, &r, 1.0);
            assert_eq!(stacked.u, three.u, "U, {ng} x {rows}");
            assert_eq!(stacked.w, three.w, "W, {ng} x {rows}");
            assert_eq!(stacked.v, three.v, "V, {ng} x {rows}");
            assert_eq!(stacked.g_global, three.g_global, "g, {ng} x {rows}");
            assert_eq!(stacked.g_blocks, three.g_blocks, "g_b, {ng} x {rows}");
        }
    }
}
