//! Industrial calibration workflows from the seed papers, each a thin
//! orchestration over the core solvers with plain-data inputs and reports:
//!
//! - planar eye-to-hand calibration at any height (seed 001):
//!   [`planar`] (one height), [`planar_height`] (parameters against height,
//!   mapping at any height, pixel density), [`planar_solve`] (the whole
//!   workflow from point pairs), [`planar_exact`] (the exact homography
//!   family, the physically grounded alternative), [`crate::api::planar`]
//!   (JSON requests and reports for the CLI and wasm);
//! - XY-table calibration with one circular target (seed 002): [`xytable`]
//!   (batch DLT vs recursive Kalman filter, verification point);
//! - camera-to-reference frame from known motions of one point (seed 000,
//!   Eq. 27-28): [`known_motion`];
//! - [`linear_fit`]: the straight-line fit with the article's statistics.

pub mod known_motion;
pub mod linear_fit;
pub mod planar;
pub mod planar_exact;
pub mod planar_height;
pub mod planar_solve;
pub mod xytable;
