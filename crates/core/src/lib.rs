//! What every btfsm crate shares and nothing else: positioned diagnostics
//! ([`diagnostic`]), the one output-sanitising layer ([`sanitize`]) and the
//! plain-text table every report prints ([`table`]).

pub mod diagnostic;
pub mod sanitize;
pub mod table;
