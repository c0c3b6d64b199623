//! The per-view runs of [`CalibProblem`] (the solver's fast path) against
//! its residual blocks: the same fit, bit for bit.

use super::*;
use crate::optim::{
    cluster_robust_covariance, cluster_robust_from_final, gauss_newton_floor, solve,
    solve_with_floor, LmOptions, Loss,
};
use crate::synth::Scene;

/// The calibration problem without its runs: the solver takes the blocks.
struct BlocksOnly<'a>(&'a CalibProblem<'a>);

impl BlockProblem for BlocksOnly<'_> {
    fn residuals_and_jacobian(
        &self,
        params: &BlockParams,
        jacobians: bool,
    ) -> Result<Vec<ResidualBlock>> {
        self.0.residuals_and_jacobian(params, jacobians)
    }

    fn retract(&self, params: &BlockParams, step: &BlockParams) -> BlockParams {
        self.0.retract(params, step)
    }
}

#[test]
fn the_runs_give_the_blocks_fit_bit_for_bit() {
    // 8 views of the example Brown camera (0.2 px noise), every seventh
    // point left out, from a camera 2 % off and the true poses: plain, with
    // a held aspect ratio, with the board warp, and under a Huber loss that
    // down-weights some points. Parameters, cost, iterations and covariance
    // must be equal to the last bit, and the floor the solver keeps equal to
    // a new evaluation's.
    let truth = Camera::example_brown();
    let scene = Scene::calibration(3, &truth, (9, 6), 0.03, 8, 0.2).unwrap();
    let views = &scene.views;
    let used: Vec<Vec<bool>> = views
        .iter()
        .map(|v| (0..v.object_m.len()).map(|i| i % 7 != 3).collect())
        .collect();
    let start_camera = Camera {
        fx: truth.fx * 1.02,
        fy: truth.fy * 1.02,
        cx: truth.cx + 3.0,
        ..truth.clone()
    };
    let cases = [
        (None, None, Loss::Squared),
        (Some(truth.fy / truth.fx), None, Loss::Squared),
        (None, BoardExtent::of(views), Loss::Squared),
        (None, None, Loss::Huber { scale: 0.25 }),
    ];
    for (aspect, warp, loss) in cases {
        let problem = CalibProblem {
            template: &start_camera,
            views,
            used: &used,
            aspect,
            warp,
        };
        let start = BlockParams {
            global: problem.global_of(&start_camera),
            blocks: scene
                .camera_from_target
                .iter()
                .map(block_from_pose)
                .collect(),
        };
        let mut fixed = vec![false; start.global.len()];
        fixed[1] = aspect.is_some();
        fixed[4] = true;
        let lm = LmOptions {
            loss,
            fixed_global: fixed,
            ..LmOptions::default()
        };
        assert!(problem.residual_runs(&start).is_some());
        let fast = solve(&problem, &start, &lm).unwrap();
        let blocks = solve(&BlocksOnly(&problem), &start, &lm).unwrap();
        assert!(fast.iterations > 2, "{}", fast.iterations);
        assert_eq!(fast.params, blocks.params);
        assert_eq!(fast.cost.to_bits(), blocks.cost.to_bits());
        assert_eq!(fast.initial_cost.to_bits(), blocks.initial_cost.to_bits());
        assert_eq!(fast.iterations, blocks.iterations);
        assert_eq!(fast.termination, blocks.termination);
        assert_eq!(fast.covariance_global, blocks.covariance_global);
        assert_eq!(fast.covariance_blocks, blocks.covariance_blocks);
        // The views' check from the normal equations the solver kept at
        // its last evaluation: the cluster-robust covariance and its
        // degrees of freedom equal, bit for bit, to those from a new
        // evaluation of the views' runs.
        let free: Vec<bool> = (fast.covariance_global.as_ref().unwrap())
            .diagonal()
            .iter()
            .map(|v| *v > 0.0)
            .collect();
        let runs = problem.residual_runs(&fast.params).unwrap().unwrap();
        let evaluated = cluster_robust_covariance(&fast.params, &runs, &loss, &free).unwrap();
        let last = fast.final_normal.as_deref().unwrap();
        let kept = cluster_robust_from_final(last, &fast.params, &loss, &free)
            .expect("the solver's normal equations are reusable")
            .unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
        assert_eq!(
            bits(kept.covariance.as_slice()),
            bits(evaluated.covariance.as_slice())
        );
        assert_eq!(bits(&kept.dof), bits(&evaluated.dof));
        // Normal equations built otherwise are not taken: another loss,
        // other parameters, other free parameters.
        let other = if loss == Loss::Squared {
            Loss::Huber { scale: 1.0 }
        } else {
            Loss::Squared
        };
        assert!(cluster_robust_from_final(last, &fast.params, &other, &free).is_none());
        assert!(cluster_robust_from_final(last, &start, &loss, &free).is_none());
        let mut fewer = free.clone();
        fewer[0] = false;
        assert!(cluster_robust_from_final(last, &fast.params, &loss, &fewer).is_none());
        // From residual blocks: no rows kept, nothing reused.
        assert!(blocks
            .final_normal
            .as_deref()
            .unwrap()
            .normal
            .weighted_runs
            .is_empty());
        assert!(cluster_robust_from_final(
            blocks.final_normal.as_deref().unwrap(),
            &blocks.params,
            &loss,
            &free
        )
        .is_none());
        let few = LmOptions {
            max_iterations: 2,
            ..lm.clone()
        };
        let (short, floor) = solve_with_floor(&problem, &start, &few).unwrap();
        assert!(short.final_normal.is_none());
        let again = gauss_newton_floor(&BlocksOnly(&problem), &short.params, &few).unwrap();
        assert_eq!(floor.to_bits(), again.to_bits());
        assert!(floor < short.cost, "{floor} {}", short.cost);
    }
}
