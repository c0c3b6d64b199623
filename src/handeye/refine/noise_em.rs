//! The expectation-maximisation of the pose refinement's noise levels
//! ([`crate::handeye::refine::pose_noise`]): the EM step on the views' packed
//! terms, and its acceleration.
//!
//! The step maps the variance components `s` to `s_k * sum_i tr(W_i M_ik
//! W_i S_i) / sum_i tr(W_i M_ik)` (`W_i = C_i^-1`, `S_i` the residual's
//! spread). Its fixed points are the stationary points of the objective
//! `Q(s) = sum_i [log det C_i + tr(W_i S_i)]` (twice the Gaussian negative
//! log-likelihood of the spreads): `dQ/ds_k = sum_i tr(W_i M_ik) - tr(W_i
//! M_ik W_i S_i)`. EM converges linearly, slowly along the likelihood's
//! flat ridge (robot and camera rotation noise act alike), so it is
//! accelerated by squared extrapolation (SQUAREM, Varadhan and Roland,
//! Scand. J. Statist. 2008): two steps give the step `r` and its change
//! `v`, the levels jump to `s0 - 2 a r + a^2 v` (in log variance, so they
//! stay positive, `a = -|r| / |v|`), one more step from there, kept only
//! when `Q` is no larger than at the cycle's start (else the two plain
//! steps stand). It stops at a plain step that moves no level by more than
//! `ACCELERATED_STOP` (tighter than the plain iteration's [`EM_TOLERANCE`])
//! or when a cycle lowered `Q` by less than `OBJECTIVE_STOP`: the
//! plain iteration's maximum, reached in far fewer steps and closer.

use nalgebra::Matrix6;

/// Smallest variance of any component (rad^2 or m^2): keeps the weights
/// finite on noise-free data.
pub(crate) const VARIANCE_FLOOR: f64 = 1e-24;

/// Most expectation-maximisation steps of one [`crate::handeye::refine::pose_noise::NoiseModel::update`]. EM
/// converges linearly, slowly when a level starts orders of magnitude off
/// (a per-view scale started at a 0.5 m camera's value for a 75 mm lens at
/// 2.3 m): 30 steps left the scale 6x off there and the model choice of
/// [`crate::handeye::refine::over_poses`] compared unconverged fits.
pub(crate) const EM_MAX_ITERATIONS: usize = 500;

/// EM stops when no variance changes by more than this (relative, log).
pub(crate) const EM_TOLERANCE: f64 = 1e-5;

/// What one EM step found.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step {
    /// No level moved by more than [`EM_TOLERANCE`] (relative): the plain
    /// iteration's stop (the tests' reference; the accelerated iteration
    /// has its own).
    #[cfg_attr(not(test), allow(dead_code))]
    pub converged: bool,
    /// The objective `Q` at the levels the step started from (infinite
    /// when a view's covariance was not positive definite).
    pub objective: f64,
}

#[cfg(test)]
/// `tr(a b)` without forming the product (36 multiplications, not 216):
/// the EM step takes 18 such traces per view and step.
pub(crate) fn trace_of_product(a: &Matrix6<f64>, b: &Matrix6<f64>) -> f64 {
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
pub(crate) fn em_step<'a>(
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
pub(crate) const PACKED: usize = 21;

/// Index of `(i, j)`, `i >= j`, in the packed lower triangle.
pub(crate) const fn packed_index(i: usize, j: usize) -> usize {
    // Columns 0..j hold 6 + 5 + ... entries: j * (13 - j) / 2.
    j * (13 - j) / 2 + (i - j)
}

/// The lower triangle of a symmetric matrix, packed.
pub(crate) fn pack(m: &Matrix6<f64>) -> [f64; PACKED] {
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
pub(crate) fn packed_trace(a: &[f64; PACKED], m: &[f64]) -> f64 {
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
pub(crate) struct PackedTerms {
    components: usize,
    packed: Vec<f64>,
    spreads: Vec<Matrix6<f64>>,
}

/// [`em_step`] on packed terms: the same expectation-maximisation step with
/// the symmetric matrices' halves (`C`, `W S W` and every trace from 21
/// entries, not 36) and, for a common factor alone, no per-level traces.
/// Equal to [`em_step`] in exact arithmetic; in floating point the sums
/// differ in order (relative differences of the order of 1e-15 per step).
/// Also gives the objective at the levels it started from.
pub(crate) fn em_step_packed(
    variances: &mut [f64],
    terms: &PackedTerms,
    per_component: bool,
) -> Step {
    let before = variances.to_vec();
    let k = terms.components;
    let (mut num, mut den) = (vec![0.0; k], vec![0.0; k]);
    let (mut num_all, mut den_all) = (0.0, 0.0);
    let mut objective = 0.0;
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
        let Some(cholesky) = c.cholesky() else {
            objective = f64::INFINITY;
            continue;
        };
        let l = cholesky.l_dirty();
        let diagonal = (0..6).fold(1.0, |p, i| p * l[(i, i)]);
        let w = cholesky.inverse();
        let ws = w * spread;
        num_all += ws.trace();
        den_all += 6.0;
        objective += 2.0 * diagonal.ln() + ws.trace();
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
    let converged = finish_step(
        variances,
        &before,
        (&num, &den),
        (num_all, den_all),
        per_component,
    );
    Step {
        converged,
        objective,
    }
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
pub(crate) fn packed_terms(terms: &[(Vec<Matrix6<f64>>, Matrix6<f64>)]) -> PackedTerms {
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

/// Log of each variance.
fn logs(variances: &[f64]) -> Vec<f64> {
    variances.iter().map(|v| v.ln()).collect()
}

/// Plain EM steps from `variances` until one moves no level by more than
/// `tolerance` or `max_steps` were taken; the number of steps.
#[cfg(test)]
pub(crate) fn plain_em(
    variances: &mut [f64],
    terms: &PackedTerms,
    max_steps: usize,
    tolerance: f64,
) -> usize {
    for step in 1..=max_steps {
        let before = logs(variances);
        em_step_packed(variances, terms, true);
        if moved(&before, &logs(variances)) < tolerance {
            return step;
        }
    }
    max_steps
}

/// The per-component levels by SQUAREM-accelerated EM (module docs), at
/// most [`EM_MAX_ITERATIONS`] steps; the number of steps.
pub(crate) fn accelerated_em(variances: &mut [f64], terms: &PackedTerms) -> usize {
    accelerated_em_to(variances, terms, ACCELERATED_STOP)
}

/// Largest level change (log) from `before` to `after`.
fn moved(before: &[f64], after: &[f64]) -> f64 {
    before
        .iter()
        .zip(after)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// [`accelerated_em`], stopping at a plain step that moves no level by
/// more than `tolerance` (relative).
pub(crate) fn accelerated_em_to(
    variances: &mut [f64],
    terms: &PackedTerms,
    tolerance: f64,
) -> usize {
    let floor = VARIANCE_FLOOR.ln();
    let mut steps = 0;
    let mut last_objective = f64::INFINITY;
    while steps < EM_MAX_ITERATIONS {
        let l0 = logs(variances);
        let first = em_step_packed(variances, terms, true);
        steps += 1;
        // Levels can drift without changing the fit (a level decaying
        // towards zero at a constant rate, which no extrapolation jumps, or
        // along the line of levels that add the same covariance): a cycle
        // that lowered Q by less than OBJECTIVE_STOP ends at the maximum.
        if last_objective - first.objective < OBJECTIVE_STOP {
            break;
        }
        last_objective = first.objective;
        let l1 = logs(variances);
        if moved(&l0, &l1) < tolerance || steps == EM_MAX_ITERATIONS {
            break;
        }
        em_step_packed(variances, terms, true);
        steps += 1;
        let l2 = logs(variances);
        if moved(&l1, &l2) < tolerance || steps == EM_MAX_ITERATIONS {
            break;
        }
        let r: Vec<f64> = l1.iter().zip(&l0).map(|(a, b)| a - b).collect();
        let v: Vec<f64> = (0..l0.len()).map(|j| l2[j] - 2.0 * l1[j] + l0[j]).collect();
        let norm = |x: &[f64]| x.iter().map(|e| e * e).sum::<f64>().sqrt();
        let (rn, vn) = (norm(&r), norm(&v));
        // a = -1 lands on the second step's levels: nothing to try.
        if !(vn > 0.0) || !(rn > vn) {
            continue;
        }
        let a = -rn / vn;
        let jumped: Vec<f64> = (0..l0.len())
            .map(|j| (l0[j] - 2.0 * a * r[j] + a * a * v[j]).max(floor))
            .collect();
        let mut trial: Vec<f64> = jumped.iter().map(|l| l.exp()).collect();
        let third = em_step_packed(&mut trial, terms, true);
        steps += 1;
        if third.objective.is_finite() && third.objective <= first.objective {
            variances.copy_from_slice(&trial);
            if moved(&jumped, &logs(variances)) < tolerance {
                break;
            }
        }
    }
    steps
}

/// The accelerated EM stops at a plain step that moves no level by more
/// than this (relative): tighter than the plain iteration's
/// [`EM_TOLERANCE`], whose steps are small long before the maximum.
const ACCELERATED_STOP: f64 = 1e-8;

/// The accelerated EM also stops after a cycle that lowers the objective
/// `Q` (twice the negative log-likelihood, nats) by less than this.
const OBJECTIVE_STOP: f64 = 1e-9;
