//! Any bytes as an action domain, and every accepted one planned into a BT,
//! its FSM and HFSM, each through graph, metrics, DOT and write-back.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| btfsm_fuzzing::domain(data));
