//! Hand-eye calibration through the library: solvers, ChArUco scenes, the image path, repeatability, rigs on robots.
//!
//! One test binary per capability (issue 34: fewer binaries to link); each
//! module is one former tests/*.rs file.

#[path = "../support/mod.rs"]
mod support;

mod handeye;
mod handeye_charuco;
mod handeye_field;
mod handeye_focal;
mod handeye_grid_boards;
mod handeye_image_path;
mod handeye_repeatability;
mod handeye_rig;
mod handeye_rig_coverage;
mod plan_trials;
