//! # robocal-vision
//!
//! The pixel-level half of robocal's core: the error type,
//! camera models, calibration targets, image decoding, target
//! detection and the synthetic renderer. Everything here is re-exported by
//! the `robocal` crate under the same module paths (`robocal::image`,
//! `robocal::detect`, ...); use it through `robocal`.
//!
//! It is a crate of its own for one reason: the wasm build optimises this
//! crate for speed (opt-level 3: the decoders', detectors' and renderer's
//! per-pixel loops) and the rest of robocal (solvers, parsers, exports) for
//! size, which one crate cannot do. The conventions (pixel centres, frames,
//! units, transform names) are those of the `robocal` crate's documentation.
#![deny(missing_docs)]

pub mod camera;
pub mod detect;
pub mod error;
pub mod image;
#[doc(hidden)]
pub mod sorting;
pub mod synth;
pub mod target;

pub use camera::{Camera, Distortion};
pub use error::{Error, Result};
