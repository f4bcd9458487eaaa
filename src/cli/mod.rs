//! The command line (SPEC §7), in two steps as fd and ripgrep do: clap parses raw
//! flags into [`args::Cli`], then each command validates what it was given and
//! runs against the library. Only this module prints.

// `eprintln!` and `eprint!` inside `cli` are these, not std's: std's panic
// when stderr cannot be written (a full device turned a failed gate's exit 1
// into 101), and print what they are given raw. These escape every control
// character but newline and tab (`sanitize::stream`) and ignore write
// errors, so that the exit code keeps its documented meaning. Defined before
// the submodules so that their textual scope covers them.
macro_rules! eprintln {
    () => {
        $crate::cli::out::stderr("\n")
    };
    ($($arg:tt)*) => {
        $crate::cli::out::stderr(&format!("{}\n", format_args!($($arg)*)))
    };
}
macro_rules! eprint {
    ($($arg:tt)*) => {
        $crate::cli::out::stderr(&format!($($arg)*))
    };
}

pub(crate) mod args;
pub(crate) mod out;

mod format;
mod io;

// One file per command, each with its flags and one `run`.
mod analyze;
mod compare;
mod completions;
mod convert;
mod dot;
mod edit;
mod effort;
mod lint;
mod log;
mod man;
mod paper;
mod plan;
mod review;
mod sim;
mod ted_pairs;
mod tick;
mod validate;
mod view;

use clap::Parser;
use std::ffi::OsString;
use std::process::ExitCode;

/// Exit codes of the contract.
pub(crate) const EXIT_OK: u8 = 0;
pub(crate) const EXIT_CHECK_FAILED: u8 = 1;
pub(crate) const EXIT_BAD_INPUT: u8 = 2;
/// A result is not the deterministic one: a CPU-time safety cap ended a
/// search before its work budget (`compare`, `stopped_by: time`).
pub(crate) const EXIT_NOT_REPRODUCIBLE: u8 = 3;

/// Runs btfsm with the given arguments (the first is the program name).
pub(crate) fn run<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match args::Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() {
                EXIT_BAD_INPUT
            } else {
                EXIT_OK
            };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    ExitCode::from(execute(cli.command))
}

/// Runs one command: each is one function in its own file.
fn execute(command: args::Command) -> u8 {
    use args::Command;
    io::set_output_root(command.limit_args());
    match command {
        Command::Analyze(a) => analyze::run(a),
        Command::Validate(a) => validate::run(a),
        Command::Dot(a) => dot::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Convert(a) => convert::run(a),
        Command::Effort(a) => effort::run(a),
        Command::Paper(a) => paper::paper(&a),
        Command::Edit(a) => edit::edit(&a),
        Command::Sim(a) => sim::execute(a),
        Command::Tick(a) => tick::execute(a),
        Command::Plan(a) => plan::execute(a),
        Command::Lint(a) => lint::execute(a),
        Command::Review(a) => review::run(a),
        Command::Log(a) => log::execute(a),
        Command::View(a) => view::execute(a),
        Command::TedPairs(a) => ted_pairs::execute(a),
        Command::Completions(a) => completions::run(a),
        Command::Man(a) => man::run(a),
    }
}
