//! `btfsm completions SHELL`: a shell completion script generated from the
//! argument definitions (clap_complete).

use super::io::emit;
use clap::Args;

#[derive(Debug, Args)]
pub(crate) struct CompletionsArgs {
    /// The shell to complete in
    #[arg(value_enum)]
    pub(super) shell: clap_complete::Shell,
}

pub(super) fn run(a: CompletionsArgs) -> u8 {
    use clap::CommandFactory;
    let mut out = Vec::new();
    clap_complete::generate(a.shell, &mut super::args::Cli::command(), "btfsm", &mut out);
    emit(None, &out)
}
