//! The `btfsm` binary: everything lives in the library.

fn main() -> std::process::ExitCode {
    btfsm::run(std::env::args_os())
}
