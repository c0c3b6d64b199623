//! The seeded random numbers and the image renderer of robocal's synthetic
//! data (scenes, demo data and hand-eye data are in `robocal::synth`).

pub mod render;
pub mod rng;

pub use render::{render, Pinhole, Projection, RenderOptions, Rendered};
pub use rng::Rng;
