//! Seeded synthetic data: the one generator shared by tests, benchmarks,
//! examples and the web app's demo button. Deterministic for a given seed on
//! every platform (native and wasm).

pub mod demo;
pub mod handeye;
pub mod scene;

// The renderer and the random numbers live in robocal-vision (fast in wasm).
pub use robocal_vision::synth::{
    board_pose, render, rng, Pinhole, Projection, RenderOptions, Rendered, Rng,
};

pub use scene::Scene;
