//! # robocal-vision
//!
//! The half of robocal's core that does the number crunching: the error
//! type, camera models, calibration targets, image decoding, target
//! detection, the synthetic renderer, the Levenberg-Marquardt solver and
//! the dense matrix updates of the EKF. Everything here is re-exported by
//! the `robocal` crate under the same module paths (`robocal::image`,
//! `robocal::detect`, `robocal::optim`, ...); use it through `robocal`.
//!
//! It is a crate of its own for one reason: the wasm build optimises this
//! crate for speed (opt-level 3: per-pixel loops, solver linear algebra)
//! and the rest of robocal (solver set-up, parsers, reports, exports) for
//! size, which one crate cannot do. The conventions (pixel centres, frames,
//! units, transform names) are those of the `robocal` crate's documentation.
#![deny(missing_docs)]

pub mod camera;
pub mod detect;
pub mod error;
pub mod image;
pub mod number;
pub mod optim;
#[doc(hidden)]
pub mod sorting;
pub mod synth;
pub mod target;
#[doc(hidden)]
pub mod unit_enum;

pub use camera::{Camera, Distortion};
pub use error::{Error, Result};
