//! `btfsm ted-pairs FILE` (hidden): the ordered tree edit distance of each
//! pair of trees in bracket notation (`metrics::ted::tree_text`), one pair
//! per line separated by a tab, printed as one JSON object per line
//! (`ted`, `exact`, `lower_bound`, `script_cost`, `moves`, `work`,
//! `stopped_by`, `peak_bytes`, and
//! `micros`, the distance's time, for the benchmark). It lets
//! tests/differential/ted.py check thousands of pairs against the `apted`
//! and `zss` packages, and bench/ted_vs_apted.py time them, in one process.

use super::EXIT_BAD_INPUT;
use super::io::{emit_text, fail, print_diagnostics};
use btfsm_core::diagnostic::Diagnostic;
use btfsm_core::sanitize::shown;
use btfsm_format::source;
use btfsm_metrics::ted::{self, TedOptions, TreeEdit, tree_text};
use clap::Args;
use std::collections::BTreeMap;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub(crate) struct TedPairsArgs {
    /// File of pairs, one per line: `TREE<TAB>TREE` (or `-` for stdin)
    pub file: PathBuf,
    /// Work budget per pair, in table cells
    #[arg(long, default_value_t = ted::DEFAULT_MAX_WORK)]
    pub max_work: u64,
    #[command(flatten)]
    pub limits: super::args::LimitArgs,
}

pub(super) fn execute(a: TedPairsArgs) -> u8 {
    let limits = a.limits.limits();
    let name = a.file.display().to_string();
    let file = match source::read(&a.file, &name, &limits, false) {
        Ok(f) => f,
        Err(d) => {
            print_diagnostics(&mut std::io::stderr().lock(), &d);
            return EXIT_BAD_INPUT;
        }
    };
    let opts = TedOptions {
        max_work: a.max_work,
        ..TedOptions::default()
    };
    let mut out = String::new();
    for (i, line) in file.text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let mut ids = BTreeMap::new();
        let parsed: Result<Vec<_>, _> = line
            .split('\t')
            .map(|t| tree_text::parse(t, &mut ids, limits.max_nodes))
            .collect();
        let trees = match parsed {
            Ok(t) if t.len() == 2 => t,
            Ok(t) => {
                return fail(Diagnostic::error(format!(
                    "{}:{}: {} trees on the line, expected 2 separated by a tab",
                    shown(&name),
                    i + 1,
                    t.len()
                )));
            }
            Err(e) => {
                return fail(Diagnostic::error(format!(
                    "{}:{}: {e}",
                    shown(&name),
                    i + 1
                )));
            }
        };
        let start = std::time::Instant::now();
        let r = ted::ted(&trees[0], &trees[1], &opts);
        let micros = start.elapsed().as_micros();
        let script = ted::edit_script(&trees[0], &trees[1], &r.mapping);
        let cost: u64 = script.iter().map(TreeEdit::cost).sum();
        let moves = script
            .iter()
            .filter(|e| matches!(e, TreeEdit::Move { .. }))
            .count();
        out.push_str(&format!(
            "{{\"ted\": {}, \"exact\": {}, \"lower_bound\": {}, \"script_cost\": {cost}, \"moves\": {moves}, \"work\": {}, \"stopped_by\": {}, \"peak_bytes\": {}, \"micros\": {micros}}}\n",
            r.upper,
            r.exact(),
            r.lower,
            r.work,
            r.stopped_by.map_or("null".to_string(), |s| format!("\"{}\"", s.as_str())),
            r.peak_bytes
        ));
    }
    emit_text(None, out)
}
