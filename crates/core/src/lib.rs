//! What every btfsm crate shares and nothing else: positioned diagnostics
//! ([`diagnostic`]), the one output-format abstraction ([`output`]), the one
//! output-sanitising layer ([`sanitize`]), the plain-text table every
//! report prints ([`table`]) and the token count every TOML document passes
//! before it is parsed ([`toml_budget`]).

pub mod diagnostic;
pub mod output;
pub mod sanitize;
pub mod table;
pub mod toml_budget;
