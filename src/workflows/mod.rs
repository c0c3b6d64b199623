//! Industrial calibration workflows from the seed papers, each a thin
//! orchestration over the core solvers with plain-data inputs and reports:
//!
//! - planar eye-to-hand calibration at any height (seed 001):
//!   [`planar`] (one height), [`planar_height`] (parameters against height,
//!   mapping at any height, pixel density), [`planar_solve`] (the whole
//!   workflow from point pairs);
//! - [`linear_fit`]: the straight-line fit with the article's statistics.

pub mod linear_fit;
pub mod planar;
pub mod planar_api;
pub mod planar_height;
pub mod planar_solve;
