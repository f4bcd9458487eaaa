//! `btfsm man [SUBCOMMAND]`: the man page (roff) of the tool or of one
//! subcommand, generated from the argument definitions (clap_mangen).

use super::io::{emit, fail};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::sanitize::shown;
use clap::Args;

#[derive(Debug, Args)]
pub(crate) struct ManArgs {
    /// A subcommand's page instead of the main one (`btfsm-sim.1`)
    pub(super) subcommand: Option<String>,
}

pub(super) fn run(a: ManArgs) -> u8 {
    use clap::CommandFactory;
    let top = super::args::Cli::command();
    let cmd = match a.subcommand.as_deref() {
        None => top,
        Some(name) => match top.find_subcommand(name) {
            Some(c) => c
                .clone()
                .name(format!("btfsm-{name}"))
                .version(env!("CARGO_PKG_VERSION")),
            None => {
                return fail(Diagnostic::error(format!(
                    "no subcommand `{}`",
                    shown(name)
                )));
            }
        },
    };
    let mut out = Vec::new();
    match clap_mangen::Man::new(cmd).render(&mut out) {
        Ok(()) => emit(None, &out),
        Err(e) => fail(Diagnostic::error(format!("cannot write the man page: {e}"))),
    }
}
