//! The `btfsm` binary: parses the command line and dispatches each command
//! to the library crates (ARCHITECTURE.md). Only this crate prints.

#![allow(
    rustdoc::broken_intra_doc_links,
    reason = "doc comments here are clap's help text, where [brackets] are plain text"
)]
#![allow(
    clippy::disallowed_methods,
    reason = "the binary is the one crate that writes to stdout and stderr (cli::out)"
)]

mod cli;

fn main() -> std::process::ExitCode {
    cli::run(std::env::args_os())
}
