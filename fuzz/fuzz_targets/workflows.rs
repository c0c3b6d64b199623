//! Fuzz target `workflows`: the body is [`cases::workflows`] (src/cases.rs).
#![no_main]

#[path = "../src/cases.rs"]
mod cases;

libfuzzer_sys::fuzz_target!(|data: &[u8]| cases::workflows(data));
