//! Fuzz target `handeye_json`: the body is [`cases::handeye_json`] (src/cases.rs).
#![no_main]

#[path = "../src/cases.rs"]
mod cases;

libfuzzer_sys::fuzz_target!(|data: &[u8]| cases::handeye_json(data));
