//! Two policies split from one input (`A\n%%\nB`), compared in every GED mode
//! with a 20 ms budget; each result must be a certified interval whose edit
//! script costs its upper bound.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| btfsm_fuzzing::compare(data));
