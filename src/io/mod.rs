//! Text formats at the edge of the core: parsers take `&str`/`&[u8]`,
//! writers return `String`. No filesystem here.

pub mod csv_table;
pub mod export;
pub mod export_camera;
pub mod export_transform;
pub mod import_camera;
pub mod workflow_csv;

#[cfg(test)]
mod export_tests;
