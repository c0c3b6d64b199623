//! Seeded synthetic data: the one generator shared by tests, benchmarks,
//! examples and the web app's demo button. Deterministic for a given seed on
//! every platform (native and wasm).

pub mod demo;
pub mod handeye;
pub mod render;
pub mod rng;
pub mod scene;

pub use render::{render, Pinhole, Projection, RenderOptions, Rendered};
pub use rng::Rng;
pub use scene::Scene;
