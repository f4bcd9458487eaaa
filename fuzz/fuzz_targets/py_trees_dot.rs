//! Any bytes through the py_trees DOT render reader, and every accepted
//! tree through graph, metrics, DOT, write-back and transforms.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| btfsm_fuzzing::py_trees_dot(data));
