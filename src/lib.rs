//! # robocal
//!
//! Camera and robot hand-eye calibration in pure Rust: target detection,
//! camera intrinsics and lens distortion, hand-eye transforms, exports. The
//! same core runs natively (the `robocal` CLI), in node (the npm package) and
//! in a browser tab (the web app in `www/`), where images never leave the
//! user's machine.
//!
//! The math core never touches files, the DOM or the clock: everything is
//! parsed from `&str`/`&[u8]` and returned as values. Only `src/wasm.rs`
//! (feature `wasm`) and the CLI binary talk to a host.
//!
//! # Conventions
//!
//! Fixed once here; every module, JSON key and export follows them.
//!
//! - **Pixels**: (0, 0) is the *centre* of the top-left pixel, x to the right,
//!   y down. OpenCV uses the same convention. MATLAB is 1-based (its principal
//!   point is ours + 1); Halcon's image coordinates are (row, column), i.e.
//!   (y, x), also with the pixel centre at integer coordinates. Exports convert.
//! - **Camera frame**: x right, y down, z forward (optical axis).
//! - **Units inside**: metres and radians. Millimetres and degrees appear only
//!   at the edges (file parsers and exports), and then in the field name
//!   (`translation_mm`, `rotation_deg`, `rms_px`).
//! - **Transforms** are named `a_from_b`: `a_from_b * p_b = p_a`. They compose
//!   so that inner names cancel: `base_from_camera = base_from_gripper *
//!   gripper_from_camera`. One pose type, [`nalgebra::Isometry3<f64>`].
//! - **Quaternions** always name their component order at a boundary
//!   (`quaternion_xyzw`, `quaternion_wxyz`).
//! - **Matrices** in JSON and text are row-major (`matrix_row_major`).
//! - **Board points** are numbered row by row from the board origin; the
//!   board frame has z = 0 on the board plane.

// `!(x > 0.0)` is how the code refuses NaN together with the values out of
// range (a NaN compares false both ways); clippy's `partial_cmp` rewrite
// would hide that intent.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![deny(missing_docs)]

pub mod api;
pub mod calib;
pub mod camera;
pub mod capture;
pub mod detect;
pub mod error;
pub mod finite;
pub mod geometry;
pub mod handeye;
pub mod image;
pub mod io;
pub mod laser;
pub mod optim;
pub mod report_kind;
pub mod rng;
pub mod synth;
pub mod target;
pub mod workflows;

#[cfg(feature = "wasm")]
pub mod wasm;

/// The layering rules of docs/architecture.md, checked from the imports
/// (native only: it reads the source tree).
#[cfg(all(test, not(target_arch = "wasm32")))]
mod architecture_tests;

pub use camera::{Camera, Distortion};
pub use error::{Error, Result};

/// The crate version, stamped into every report and export.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
