//! Fuzz target `robot_poses`: the body is [`cases::robot_poses`] (src/cases.rs).
#![no_main]

#[path = "../src/cases.rs"]
mod cases;

libfuzzer_sys::fuzz_target!(|data: &[u8]| cases::robot_poses(data));
