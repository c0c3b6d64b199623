//! Fuzz target `calib_json`: the body is [`cases::calib_json`] (src/cases.rs).
#![no_main]

#[path = "../src/cases.rs"]
mod cases;

libfuzzer_sys::fuzz_target!(|data: &[u8]| cases::calib_json(data));
