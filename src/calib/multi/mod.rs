//! Several cameras calibrated together: a stereo pair ([`stereo`]: its
//! joint problem in `stereo_problem`, rectification and E, F in
//! [`stereo_rectify`]) and an N-camera rig ([`rig`]: the co-observation
//! graph in `rig_graph`, each camera alone in `rig_init`, the joint problem
//! in `rig_problem`, the report in [`rig_report`]). Both joint problems
//! build their residual and Jacobian blocks with one helper,
//! `block_problem`;
//! `same_images` refuses one image set given for two cameras. Both check
//! their extrinsics' std against leave-views-out refits (`rig_jackknife`,
//! `stereo_jackknife`).

mod block_problem;
pub mod rig;
pub mod rig_frame_check;
mod rig_graph;
mod rig_init;
mod rig_jackknife;
mod rig_problem;
pub mod rig_report;
mod same_images;
pub mod stereo;
mod stereo_jackknife;
mod stereo_problem;
pub mod stereo_rectify;
#[cfg(test)]
mod stereo_tests;
