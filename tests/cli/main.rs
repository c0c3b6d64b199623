//! The robocal binary: every command, its files and its messages for good and bad input.
//!
//! One test binary per capability (issue 34: fewer binaries to link); each
//! module is one former tests/*.rs file.

#[path = "../support/mod.rs"]
mod support;

mod cli_bad_images;
mod cli_bad_inputs;
mod cli_bad_inputs_scenes;
mod cli_check;
mod cli_detect;
mod cli_export;
mod cli_field;
mod cli_handeye;
mod cli_handeye_focal;
mod cli_handeye_pairing;
mod cli_intrinsics;
mod cli_laser;
mod cli_output;
mod cli_partial_views;
mod cli_polarity;
mod cli_render;
mod cli_render_video;
mod cli_rig;
mod cli_stereo;
mod cli_video;
mod cli_workflows;
