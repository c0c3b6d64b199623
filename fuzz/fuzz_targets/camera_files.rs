//! Fuzz target `camera_files`: the body is [`cases::camera_files`] (src/cases.rs).
#![no_main]

#[path = "../src/cases.rs"]
mod cases;

libfuzzer_sys::fuzz_target!(|data: &[u8]| cases::camera_files(data));
