//! What every btfsm crate shares and nothing else: positioned diagnostics
//! ([`diagnostic`]), the one output-format abstraction ([`output`]), the one
//! output-sanitising layer ([`sanitize`]) and the plain-text table every
//! report prints ([`table`]).

pub mod diagnostic;
pub mod output;
pub mod sanitize;
pub mod table;
