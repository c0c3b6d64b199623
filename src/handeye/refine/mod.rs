//! The refinements of a closed-form solution, each returning what it found
//! for the orchestrator ([`crate::handeye::solve`]) to write.
//!
//! Over the poses (the default): [`pose_residual`] is one view's residual
//! `A_i X = Z B_i` with its Jacobians, [`pose_noise`] the robot and camera
//! noise models, [`pose_shape`] the per-view camera noise shape predicted
//! from a planar target, [`noise_choice`] picks the model by likelihood,
//! [`pose_problem`] is the maximum-likelihood least squares, [`over_poses`]
//! runs it from the closed forms (noise, covariance, trust checks),
//! [`pose_summary`] is what it reports, and
//! [`pose_resample`] gives the repeatability of its estimate.
//!
//! Over the pixels (`refine` trusted, stochastic, joint_intrinsics):
//! [`pixel_problem`] is the reprojection least squares over the transform,
//! the target pose and optionally the intrinsics; [`over_pixels`] runs it
//! from the best closed form.

pub mod noise_choice;
pub(crate) mod noise_em;
pub mod over_pixels;
pub mod over_poses;
pub mod pixel_problem;
pub mod pixel_summary;
pub mod pose_noise;
pub mod pose_problem;
pub mod pose_resample;
pub mod pose_residual;
pub mod pose_shape;
pub mod pose_summary;

#[cfg(test)]
mod over_poses_reprojection_tests;
#[cfg(test)]
mod over_poses_tests;
#[cfg(test)]
pub(crate) mod pixel_problem_tests;
#[cfg(test)]
mod pose_shape_tests;
