//! Solver tests on problems with known optima.

use super::*;
use crate::rng::Rng;
use wasm_bindgen_test::wasm_bindgen_test;

/// Rosenbrock as least squares: r = (10 (y - x^2), 1 - x), minimum at (1, 1).
struct Rosenbrock;

impl BlockProblem for Rosenbrock {
    fn residuals_and_jacobian(&self, p: &BlockParams, _: bool) -> Result<Vec<ResidualBlock>> {
        let (x, y) = (p.global[0], p.global[1]);
        Ok(vec![ResidualBlock {
            block: None,
            residuals: DVector::from_vec(vec![10.0 * (y - x * x), 1.0 - x]),
            jac_global: DMatrix::from_row_slice(2, 2, &[-20.0 * x, 10.0, -1.0, 0.0]),
            jac_block: DMatrix::zeros(2, 0),
        }])
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn rosenbrock_reaches_its_minimum() {
    let initial = BlockParams {
        global: vec![-1.2, 1.0],
        blocks: vec![],
    };
    let r = solve(&Rosenbrock, &initial, &LmOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        (r.params.global[0] - 1.0).abs() < 1e-9 && (r.params.global[1] - 1.0).abs() < 1e-9,
        "{:?}",
        r.params
    );
    assert!(r.cost < 1e-20, "cost {}", r.cost);
    assert!(r.iterations < 100, "{} iterations", r.iterations);
}

/// A linear problem with random structure: r_ij = A_ij g + B_ij b_i - y_ij,
/// whose optimum and covariance have a closed form.
struct Linear {
    rows: Vec<(usize, [f64; 3], [f64; 2], f64)>,
    n_blocks: usize,
}

impl Linear {
    fn new(seed: u64, n_blocks: usize, per_block: usize) -> Linear {
        let mut rng = Rng::new(seed);
        let mut rows = vec![];
        for b in 0..n_blocks {
            for _ in 0..per_block {
                let a = [
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                ];
                let bb = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
                rows.push((b, a, bb, rng.range(-2.0, 2.0)));
            }
        }
        Linear { rows, n_blocks }
    }

    /// The dense Jacobian and right-hand side, columns [g (3), b_0 (2), b_1 (2), ...].
    fn dense(&self) -> (DMatrix<f64>, DVector<f64>) {
        let n = 3 + 2 * self.n_blocks;
        let mut j = DMatrix::zeros(self.rows.len(), n);
        let mut y = DVector::zeros(self.rows.len());
        for (i, (b, a, bb, yy)) in self.rows.iter().enumerate() {
            for k in 0..3 {
                j[(i, k)] = a[k];
            }
            j[(i, 3 + 2 * b)] = bb[0];
            j[(i, 4 + 2 * b)] = bb[1];
            y[i] = *yy;
        }
        (j, y)
    }
}

impl BlockProblem for Linear {
    fn residuals_and_jacobian(&self, p: &BlockParams, _: bool) -> Result<Vec<ResidualBlock>> {
        Ok(self
            .rows
            .iter()
            .map(|(b, a, bb, y)| {
                let g = &p.global;
                let x = &p.blocks[*b];
                let r = a[0] * g[0] + a[1] * g[1] + a[2] * g[2] + bb[0] * x[0] + bb[1] * x[1] - y;
                ResidualBlock {
                    block: Some(*b),
                    residuals: DVector::from_element(1, r),
                    jac_global: DMatrix::from_row_slice(1, 3, a),
                    jac_block: DMatrix::from_row_slice(1, 2, bb),
                }
            })
            .collect())
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn schur_solution_and_covariance_equal_the_dense_least_squares_ones() {
    let problem = Linear::new(11, 12, 8);
    let initial = BlockParams {
        global: vec![0.0; 3],
        blocks: vec![vec![0.0; 2]; 12],
    };
    let r = solve(&problem, &initial, &LmOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let (j, y) = problem.dense();
    let jtj = j.transpose() * &j;
    let inv = jtj
        .clone()
        .try_inverse()
        .unwrap_or_else(|| panic!("singular"));
    let x = &inv * j.transpose() * &y;
    for k in 0..3 {
        assert!((r.params.global[k] - x[k]).abs() < 1e-9, "global {k}");
    }
    for b in 0..12 {
        for k in 0..2 {
            assert!(
                (r.params.blocks[b][k] - x[3 + 2 * b + k]).abs() < 1e-9,
                "block {b}"
            );
        }
    }
    let residual = &j * &x - &y;
    let sigma2 = residual.norm_squared() / (96 - 27) as f64;
    assert!((r.residual_variance - sigma2).abs() < 1e-12 * sigma2);
    assert_eq!((r.n_residuals, r.n_free_params), (96, 27));
    let cov = r
        .covariance_global
        .clone()
        .unwrap_or_else(|| panic!("no covariance"));
    let blocks = r
        .covariance_blocks
        .clone()
        .unwrap_or_else(|| panic!("no covariance"));
    for a in 0..3 {
        for b in 0..3 {
            assert!((cov[(a, b)] - sigma2 * inv[(a, b)]).abs() < 1e-10);
        }
    }
    for (i, c) in blocks.iter().enumerate() {
        for a in 0..2 {
            for b in 0..2 {
                let expected = sigma2 * inv[(3 + 2 * i + a, 3 + 2 * i + b)];
                assert!((c[(a, b)] - expected).abs() < 1e-10, "block {i} covariance");
            }
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn fixed_parameters_stay_and_the_rest_is_optimal_given_them() {
    let problem = Linear::new(12, 5, 6);
    let initial = BlockParams {
        global: vec![0.0, 0.7, 0.0],
        blocks: vec![vec![0.1, 0.2]; 5],
    };
    let mut fixed_blocks = vec![false; 5];
    fixed_blocks[2] = true;
    let options = LmOptions {
        fixed_global: vec![false, true, false],
        fixed_blocks,
        ..LmOptions::default()
    };
    let r = solve(&problem, &initial, &options).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.params.global[1], 0.7);
    assert_eq!(r.params.blocks[2], vec![0.1, 0.2]);
    assert_eq!(r.n_free_params, 10);
    // Dense solution with the held columns moved to the right-hand side.
    let (j, y) = problem.dense();
    let free: Vec<usize> = (0..13).filter(|&c| c != 1 && c != 7 && c != 8).collect();
    let held = &j.column(1) * 0.7 + &j.column(7) * 0.1 + &j.column(8) * 0.2;
    let jf = j.select_columns(&free);
    let x = (jf.transpose() * &jf)
        .try_inverse()
        .unwrap_or_else(|| panic!("singular"))
        * jf.transpose()
        * (y - held);
    assert!((r.params.global[0] - x[0]).abs() < 1e-9 && (r.params.global[2] - x[1]).abs() < 1e-9);
    let cov = r
        .covariance_global
        .unwrap_or_else(|| panic!("no covariance"));
    assert_eq!(cov[(1, 1)], 0.0);
    assert_eq!(
        solve(
            &problem,
            &initial,
            &LmOptions {
                fixed_global: vec![true],
                ..LmOptions::default()
            }
        )
        .map(|_| ())
        .map_err(|e| e.to_string()),
        Err("fixed_global: 1 flags for 3 global parameters".to_string())
    );
}

/// Line fit y = a x + b with exact inliers and three gross outliers.
struct Line {
    points: Vec<(f64, f64)>,
}

impl BlockProblem for Line {
    fn residuals_and_jacobian(&self, p: &BlockParams, _: bool) -> Result<Vec<ResidualBlock>> {
        Ok(self
            .points
            .iter()
            .map(|(x, y)| ResidualBlock {
                block: None,
                residuals: DVector::from_element(1, p.global[0] * x + p.global[1] - y),
                jac_global: DMatrix::from_row_slice(1, 2, &[*x, 1.0]),
                jac_block: DMatrix::zeros(1, 0),
            })
            .collect())
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn robust_losses_resist_outliers() {
    let mut points: Vec<(f64, f64)> = (0..40)
        .map(|i| (i as f64 * 0.25, 2.0 * i as f64 * 0.25 - 1.0))
        .collect();
    points[5].1 += 30.0;
    points[17].1 -= 25.0;
    points[33].1 += 40.0;
    let line = Line { points };
    let initial = BlockParams {
        global: vec![0.0, 0.0],
        blocks: vec![],
    };
    let fit = |loss| {
        let r = solve(
            &line,
            &initial,
            &LmOptions {
                loss,
                ..LmOptions::default()
            },
        )
        .unwrap_or_else(|e| panic!("{e}"));
        (r.params.global[0] - 2.0).abs() + (r.params.global[1] + 1.0).abs()
    };
    // Squared loss: three outliers of ~30 among 40 points bias the line by
    // about 30 * 3 / 40 in offset. Cauchy down-weights them to ~(c/30)^2,
    // leaving a bias below 1e-2; Huber caps their pull at c each.
    assert!(fit(Loss::Squared) > 0.5);
    assert!(
        fit(Loss::Cauchy { scale: 0.5 }) < 1e-2,
        "{}",
        fit(Loss::Cauchy { scale: 0.5 })
    );
    assert!(
        fit(Loss::Huber { scale: 0.5 }) < 0.2,
        "{}",
        fit(Loss::Huber { scale: 0.5 })
    );
}
