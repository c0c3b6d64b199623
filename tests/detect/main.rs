//! Detection on renders and public images: chessboards, circle grids, markers, the fuzz regressions.
//!
//! One test binary per capability (issue 34: fewer binaries to link); each
//! module is one former tests/*.rs file.

#[path = "../support/mod.rs"]
mod support;

mod detect_circles;
mod detect_circles_asym;
mod detect_datasets;
mod detect_grid_boards;
mod detect_marker_recall;
mod detect_markers;
mod detect_markers_datasets;
mod detect_polarity;
mod detect_polarity_datasets;
mod detect_render;
mod fuzz_regressions;
mod renders;
