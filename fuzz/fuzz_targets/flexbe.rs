//! Any bytes through the FlexBE behavior reader (the Python is parsed,
//! never run), and every accepted machine through graph, metrics, DOT,
//! write-back and transforms.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| btfsm_fuzzing::flexbe(data));
