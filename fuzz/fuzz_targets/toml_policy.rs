//! Any bytes through the TOML policy reader and validator, and every accepted
//! policy through graph, metrics, DOT, write-back and transforms.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| btfsm_fuzzing::toml_policy(data));
