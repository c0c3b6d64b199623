//! Fuzz target `image_decode`: the body is [`cases::image_decode`] (src/cases.rs).
#![no_main]

#[path = "../src/cases.rs"]
mod cases;

libfuzzer_sys::fuzz_target!(|data: &[u8]| cases::image_decode(data));
