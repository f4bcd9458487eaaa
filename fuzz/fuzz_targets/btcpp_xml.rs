//! Any bytes through the BehaviorTree.CPP XML importer, and every accepted
//! tree through graph, metrics, DOT, write-back and transforms.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| btfsm_fuzzing::btcpp_xml(data));
