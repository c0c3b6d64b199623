//! Camera calibration on renders, fixtures and public sets: Zhang, circles, EKF, rigs, partial views, the seed workflows, exports and pose files.
//!
//! One test binary per capability (issue 34: fewer binaries to link); each
//! module is one former tests/*.rs file.

#[path = "../support/mod.rs"]
mod support;

mod calib_caliscope_starts;
mod calib_circles;
mod calib_datasets;
mod calib_ekf;
mod calib_rig;
mod calib_tilted;
mod calib_zhang;
mod calib_zhang1998;
mod camera_opencv;
mod exports;
mod partial_views;
mod poses;
mod seed001_planar;
mod xytable_kalman;
