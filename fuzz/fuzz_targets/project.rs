//! Several files naming each other (subtrees with parameters, includes, a
//! scenario and its policies), split at `\n%%\n`, read under the
//! confinement rule.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| btfsm_fuzzing::project(data));
