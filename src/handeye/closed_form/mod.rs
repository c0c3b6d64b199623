//! The closed-form solvers: AX = XB over motion pairs ([`axxb`]:
//! Tsai-Lenz, Park-Martin, Horaud, Chou-Kamel, Andreff; [`daniilidis`]:
//! dual quaternions), AX = ZB over the views ([`axzb`]: Shah, Li), the
//! observable part when every motion rotates about one axis ([`scara`]),
//! and the motions they take ([`motion`]); [`solve_method`] runs one of
//! them on a chain.

pub mod axxb;
pub mod axzb;
pub mod daniilidis;
pub mod motion;
pub mod scara;

use crate::error::Result;
use crate::handeye::math::mean_pose;
use crate::handeye::{Chain, HandEyeMethod, Motion, MotionPairs, Pose};
use motion::build_motions;
use nalgebra::Vector3;

/// Solve one method on a chain; returns `(x, y, unobservable directions)`.
pub fn solve_method(
    method: HandEyeMethod,
    chain: &Chain,
    pairs: MotionPairs,
) -> Result<(Pose, Pose, Vec<Vector3<f64>>)> {
    if method.is_axzb() {
        return solve_with_motions(method, chain, &[]);
    }
    solve_with_motions(method, chain, &build_motions(chain, pairs).kept)
}

/// [`solve_method`] with the chain's motions built once by the caller
/// (unused by the AX = ZB methods): at 1,000 poses each build is half a
/// million motions.
pub(crate) fn solve_with_motions(
    method: HandEyeMethod,
    chain: &Chain,
    motions: &[Motion],
) -> Result<(Pose, Pose, Vec<Vector3<f64>>)> {
    if method.is_axzb() {
        let (x, y) = axzb::solve(method, chain)?;
        return Ok((x, y, Vec::new()));
    }
    let (x, unobservable) = axxb::solve(method, motions)?;
    let y = estimate_target(chain, &x)?;
    Ok((x, y, unobservable))
}

/// The target pose `y` that best fits `x`: the mean of the per-view
/// `robot[i] * x * camera[i]` (chordal rotation mean, mean translation).
pub fn estimate_target(chain: &Chain, x: &Pose) -> Result<Pose> {
    let implied: Vec<Pose> = (0..chain.len())
        .map(|i| chain.implied_target(i, x))
        .collect();
    mean_pose(&implied)
}
