#![no_main]
// The body lives in gonio::fuzz, shared with the regression test that replays the corpus on stable.
libfuzzer_sys::fuzz_target!(|data: &[u8]| gonio::fuzz::ply(data));
