//! Fuzz target `targets_detections`: the body is [`cases::targets_detections`] (src/cases.rs).
#![no_main]

#[path = "../src/cases.rs"]
mod cases;

libfuzzer_sys::fuzz_target!(|data: &[u8]| cases::targets_detections(data));
