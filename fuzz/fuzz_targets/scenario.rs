//! Any bytes as a simulator scenario; an accepted one runs for at most 2000
//! steps per policy.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| btfsm_fuzzing::scenario(data));
